"""Moved to ``gymfg_il.cockpit.inputs.synthetic_pilot`` (the synthetic pilot as the cockpit
session's input); this path keeps working for now, with a DeprecationWarning."""

from gymfg_il.moved import forward

GONE = {
    "SyntheticDriver": "the synthetic pilot is the session's input, no longer an on_frame "
    "hook: ManualConfig(pilot='synthetic') flies it (cockpit.inputs.synthetic_pilot."
    "SyntheticInput; what it pressed: session.stages.input.sent)",
}
__getattr__ = forward(__name__, "gymfg_il.cockpit.inputs.synthetic_pilot", GONE)
