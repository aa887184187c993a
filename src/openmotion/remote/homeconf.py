"""Homing settings in user units: the API's names for control.home.homeconf (no logic
here; the conversion and its checks live in the control layer)."""

from ..control.home.homeconf import (
    MODES,
    USER_KEYS,
    choices,
    default_home,
    home_configs,
    home_from_user,
    home_to_user,
    sequence,
)

__all__ = ["MODES", "USER_KEYS", "choices", "default_home", "home_configs", "home_from_user",
           "home_to_user", "sequence"]
