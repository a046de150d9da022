"""Moved to ``gymfg_il.cockpit.session`` (the cockpit session, a loop of stages in
``gymfg_il.cockpit``); this path keeps working for now, with a DeprecationWarning."""

from gymfg_il.moved import forward

__getattr__ = forward(__name__, "gymfg_il.cockpit.session")
