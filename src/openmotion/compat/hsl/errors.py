"""HSL return codes: 0 or a negative error code, with HSL_M_get_error_message text.

The real library's code table is NOT FOUND (seed-facts 2.5); these codes are ours, one per
rule, named after what was wrong. A getter returns its value; when it fails it returns an
`HslError` instead: an int (the negative code) that also carries the message, so
`isinstance(r, HslError)` or `r == ERR_InvalidAxis` tell a failure from a value.
"""

from __future__ import annotations

from ...errors import InfeasibleError, MotionError

ERR_NoError = 0
ERR_NotInitial = -1
ERR_InvalidCard = -2
ERR_InvalidModule = -3
ERR_InvalidAxis = -4
ERR_InvalidParameter = -5
ERR_AxisBusy = -6
ERR_NoMotion = -7
ERR_Infeasible = -8
ERR_SpeedRange = -9
ERR_AxisState = -10
ERR_Limit = -11
ERR_ArcGeometry = -12
ERR_NotSupported = -13
ERR_ConfigMismatch = -14

MESSAGES = {
    ERR_NoError: "no error",
    ERR_NotInitial: "the card is not initialised (HSL_initial)",
    ERR_InvalidCard: "invalid card number",
    ERR_InvalidModule: "invalid module (connect index) number",
    ERR_InvalidAxis: "invalid axis number",
    ERR_InvalidParameter: "invalid parameter",
    ERR_AxisBusy: "the axis is moving",
    ERR_NoMotion: "the function needs a running motion",
    ERR_Infeasible: "the motion cannot do this now (too few pulses left, or decelerating)",
    ERR_SpeedRange: "the speed is outside the speed range (fix_speed_range)",
    ERR_AxisState: "the axis cannot move (E-stop, alarm, limit stop or servo off)",
    ERR_Limit: "the motion would pass a limit",
    ERR_ArcGeometry: "the arc's centre and end do not make an arc",
    ERR_NotSupported: "not supported on this axis or module",
    ERR_ConfigMismatch: "the setting contradicts the machine file's wiring",
}
#: Codes the host library finds before sending anything (no network time is charged).
HOST_SIDE = frozenset({ERR_NotInitial, ERR_InvalidCard, ERR_InvalidModule, ERR_InvalidAxis,
                       ERR_InvalidParameter, ERR_NotSupported, ERR_ConfigMismatch})


class HslError(int):
    """A failed getter's result: the negative code as an int, plus `.message`."""

    message: str

    def __new__(cls, code: int, message: str = "") -> HslError:
        obj = super().__new__(cls, code)
        obj.message = message or MESSAGES.get(code, "unknown error")
        return obj

    def __repr__(self) -> str:
        return f"HslError({int(self)}, {self.message!r})"


class Refusal(Exception):
    """Raised inside the facade to return `code` with `message`."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code
        self.message = message


_STATE_WORDS = ("emergency stop", "ErrorStop", "alarm", "disabled", "servo off",
                "RDY inactive", "is active; motion towards it")
_BUSY_WORDS = ("a motion is running", "stopping; wait", "homing in progress",
               "already belongs", "homing already running", "group is busy")


def classify(err: MotionError) -> int:
    """The HSL code of a core refusal (by kind, then by the rule its message names)."""
    text = str(err)
    code = getattr(err, "code", None)
    if "speed range" in text:
        return ERR_SpeedRange
    if "soft limit" in text or "travel" in text:
        return ERR_Limit
    if any(w in text for w in _STATE_WORDS):
        return ERR_AxisState
    if any(w in text for w in _BUSY_WORDS):
        return ERR_AxisBusy
    if "needs a running move" in text:
        return ERR_NoMotion
    if "arc" in text and code is not None:
        return ERR_ArcGeometry
    if isinstance(err, InfeasibleError):
        return ERR_Infeasible
    return ERR_InvalidParameter


def error_message(code: int) -> str:
    """HSL_M_get_error_message: the text of a return code."""
    if isinstance(code, HslError):
        return code.message
    if isinstance(code, int) and code in MESSAGES:
        return MESSAGES[code]
    return f"unknown error code {code!r}"
