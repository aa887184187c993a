"""Pure motion-profile math: no clocks, no state. Units: pulses, pulses/s, seconds."""

from .segments import Phase, Profile, ProfileBuilder, Samples, State, empty_profile

__all__ = ["Phase", "Profile", "ProfileBuilder", "Samples", "State", "empty_profile"]
