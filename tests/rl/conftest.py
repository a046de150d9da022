"""The PPO tests' starting policy: an MLP cloned from the tiny altitude demonstrations."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def bc_policy(tiny_dataset, tmp_path_factory):
    """An MLP cloned from the tiny altitude demonstrations (30-s episodes) without memory
    (``remembering_bc`` has one); tests read it, never write it."""
    from gymfg_il.learning.bc import train_bc
    from gymfg_il.learning.config import TrainConfig
    from gymfg_il.policies.configuration_mlp import MLPConfig

    out = tmp_path_factory.mktemp("rl") / "bc"
    policy = MLPConfig(memory="none")
    train_bc(TrainConfig(dataset=tiny_dataset, out=out, epochs=3, seed=0, policy=policy))
    return out


@pytest.fixture(scope="session")
def remembering_bc(tiny_dataset, tmp_path_factory):
    """An MLP cloned from the tiny altitude demonstrations with ``--memory vertical`` (the
    climb-rate and pitch loops' integrals); tests read it, never write it."""
    from gymfg_il.learning.bc import train_bc
    from gymfg_il.learning.config import TrainConfig
    from gymfg_il.policies.configuration_mlp import MLPConfig

    out = tmp_path_factory.mktemp("rl") / "bc-vertical"
    policy = MLPConfig(memory="vertical")
    train_bc(TrainConfig(dataset=tiny_dataset, out=out, epochs=3, seed=0, policy=policy))
    return out
