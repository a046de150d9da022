"""Moved to ``gymfg_il.rl.envs`` (the training envs; what PPO maximises is composed in
``gymfg_il.rl.reward``); this path keeps working for now, with a DeprecationWarning."""

from gymfg_il.moved import forward

__getattr__ = forward(__name__, "gymfg_il.rl.envs")
