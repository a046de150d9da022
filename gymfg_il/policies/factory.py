"""Policies found by name: each policy type is a configuration class and a modeling class,
registered under one name (``register_policy``). The built-in ones register themselves in
their ``configuration_<name>`` modules, which are found and imported here; a policy defined
elsewhere (a plugin, a test) registers the same way and trains, saves, loads and flies with
no edit to this package."""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.policies.configuration import PolicyConfig

C = TypeVar("C", bound=type[PolicyConfig])


@dataclass(frozen=True)
class PolicyType:
    """One registered policy type.

    Attributes:
        name: what ``--policy`` and config.json's ``type`` call it.
        config: its configuration class.
        modeling: its ``torch.nn.Module`` class, taking ``(config, obs_stats,
            action_stats)``, or where to import it from (``"package.module:Class"``, so that
            finding a policy by name needs no torch).
    """

    name: str
    config: type[PolicyConfig]
    modeling: type | str

    def modeling_class(self) -> type:
        if not isinstance(self.modeling, str):
            return self.modeling
        module, _, name = self.modeling.partition(":")
        cls: type = getattr(importlib.import_module(module), name)
        return cls


_REGISTRY: dict[str, PolicyType] = {}
LISTED_FIRST = ("mlp", "gru", "chunk", "vision")  # how --policy lists the built-in types


def register_policy(name: str, modeling: type | str) -> Callable[[C], C]:
    """A class decorator registering a ``PolicyConfig`` subclass as policy type ``name``,
    flown and trained by ``modeling`` (a class or ``"module:Class"``)."""

    def register(config: C) -> C:
        if not (isinstance(config, type) and issubclass(config, PolicyConfig)):
            raise TypeError(f"policy {name!r}: {config!r} is not a PolicyConfig subclass")
        known = _REGISTRY.get(name)
        if known is not None and known.config.__qualname__ != config.__qualname__:
            raise ConfigError(
                f"policy type {name!r} is taken by {known.config.__qualname__}; "
                "register yours under another name"
            )
        config.type = name
        _REGISTRY[name] = PolicyType(name, config, modeling)
        return config

    return register


def _builtin() -> None:
    """Import every ``configuration_<name>`` module of this package (each registers its
    policy type)."""
    import gymfg_il.policies as package

    for module in pkgutil.iter_modules(package.__path__):
        if module.name.startswith("configuration_"):
            importlib.import_module(f"{package.__name__}.{module.name}")


def policy_types() -> dict[str, PolicyType]:
    """Every registered policy type by name: ``LISTED_FIRST``, then the rest as registered."""
    _builtin()
    first = [n for n in LISTED_FIRST if n in _REGISTRY]
    return {n: _REGISTRY[n] for n in [*first, *(n for n in _REGISTRY if n not in first)]}


def bc_types() -> dict[str, PolicyType]:
    """The types ``train bc`` trains (``policy_types`` but those made another way, PPO's)."""
    return {n: t for n, t in policy_types().items() if t.config.retrains_as is None}


def policy_type(name: str) -> PolicyType:
    types = policy_types()
    if name not in types:
        raise ConfigError(f"unknown policy {name!r}; choose one of {', '.join(types)}")
    return types[name]


def make_config(name: str, **settings: Any) -> PolicyConfig:
    """The configuration of policy type ``name`` with ``settings`` (the rest at defaults)."""
    return policy_type(name).config(**settings)


def make_policy(
    config: PolicyConfig,
    obs_stats: dict[str, np.ndarray],
    action_stats: dict[str, np.ndarray],
) -> Any:
    """A fresh policy module for ``config`` with normalisation from the given statistics."""
    return policy_type(config.type).modeling_class()(config, obs_stats, action_stats)
