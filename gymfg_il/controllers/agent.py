"""Moved to ``gymfg_il.agent`` (the Agent protocol sits below every package that flies one);
this path keeps working for now, with a DeprecationWarning."""

from gymfg_il.moved import forward

__getattr__ = forward(__name__, "gymfg_il.agent")
