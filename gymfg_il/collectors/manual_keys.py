"""Moved to ``gymfg_il.cockpit.inputs.keys`` (the cockpit session's inputs); this path keeps
working for now, with a DeprecationWarning."""

from gymfg_il.moved import forward

__getattr__ = forward(__name__, "gymfg_il.cockpit.inputs.keys")
