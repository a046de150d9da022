"""Moved to ``gymfg_il.rl.grouped.forward`` (the grouped sampler's own package); this path
keeps working for now, with a DeprecationWarning."""

from gymfg_il.moved import forward

__getattr__ = forward(__name__, "gymfg_il.rl.grouped.forward")
