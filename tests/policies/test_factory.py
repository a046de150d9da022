"""A policy type is one configuration and one modeling class, registered by name: a type
defined here, in a test module, trains through `train bc` (its setting a flag like the
built-in ones'), saves, loads and flies, with no edit anywhere else."""

import json
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
import torch
from torch import nn

from gymfg_il import train
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.errors import ConfigError
from gymfg_il.evaluation.trace import trace_of
from gymfg_il.learning.bc import train_bc
from gymfg_il.learning.config import TrainConfig
from gymfg_il.policies import factory
from gymfg_il.policies.checkpoint import load_policy
from gymfg_il.policies.configuration import PolicyConfig
from gymfg_il.policies.normalize import NormalizedPolicy
from gymfg_il.policies.window import Window
from gymfg_il.rollout import Rollout
from gymfg_il.rollout.agents import AgentSpec

SAMPLE = Path(__file__).resolve().parents[2] / "datasets/sample-altitude-c172p/dataset"


@dataclass
class LinearConfig(PolicyConfig):
    """A linear map from the last few observations to the action.

    Attributes:
        previous: observations the policy sees (the current one and those before it).
    """

    previous: int = 2

    def problems(self) -> list[str]:
        return [] if self.previous >= 1 else [f"previous={self.previous} must be >= 1"]

    @property
    def stateful(self) -> bool:
        return True  # in flight it keeps the observations before

    @property
    def window(self) -> Window:
        return Window(observation=tuple(range(1 - self.previous, 1)))


class LinearPolicy(NormalizedPolicy):
    seen_shapes: ClassVar[list[tuple[int, ...]]] = []  # the batches' shapes, as training gave them

    def __init__(self, config, obs_stats, action_stats):
        super().__init__(config, obs_stats, action_stats)
        self.net = nn.Linear(self.n_obs * config.previous, self.n_act)

    def forward(self, history):
        return self.net(self.normalized(history).flatten(1))

    def loss(self, history, action):
        LinearPolicy.seen_shapes.append(tuple(history.shape))
        return nn.functional.mse_loss(self.forward(history), self.action_norm(action))

    @torch.no_grad()
    def act(self, obs, state=None):
        previous = self.config.previous
        history = obs.unsqueeze(1).repeat(1, previous, 1) if state is None else state
        history = torch.cat([history[:, 1:], obs.unsqueeze(1)], dim=1)
        return self.action_norm.inverse(self.forward(history)), history


@pytest.fixture
def linear(monkeypatch):
    """The linear type registered as a plugin would register it, for this test only."""
    monkeypatch.setattr(factory, "_REGISTRY", dict(factory.policy_types()))
    return factory.register_policy("linear", LinearPolicy)(LinearConfig)


def test_a_policy_registered_elsewhere_trains_saves_loads_and_flies(linear, tmp_path, capsys):
    with pytest.raises(SystemExit):
        train.main(["bc", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert "--policy {mlp,gru,chunk,vision,linear}" in help_text
    assert "--previous PREVIOUS linear: observations the policy sees" in help_text
    LinearPolicy.seen_shapes.clear()
    out = tmp_path / "p"
    argv = ["bc", "--dataset", str(SAMPLE), "--policy", "linear", "--previous", "3"]
    assert train.main([*argv, "--epochs", "3", "--out", str(out), "--no-progress"]) == 0
    assert "training 3 epoch(s) x" in capsys.readouterr().err  # the estimate came first
    info = json.loads((SAMPLE / "meta/info.json").read_text())
    n_obs = len(info["features"]["observation.state"]["names"])
    assert {shape[1:] for shape in LinearPolicy.seen_shapes} == {(3, n_obs)}  # its window
    meta = json.loads((out / "config.json").read_text())
    assert meta["type"] == "linear" and meta["policy"] == {"type": "linear", "previous": 3}
    log = json.loads((out / "train_log.json").read_text())
    assert log["train_loss"][-1] < log["train_loss"][0]
    policy, _ = load_policy(out)
    assert isinstance(policy, LinearPolicy) and policy.config == LinearConfig(previous=3)
    env = AircraftEnv("altitude", "c172p", episode_time_s=5)
    flown = trace_of(Rollout(env, [AgentSpec.policy(out).make(env)]).episode(4))
    assert len(flown.actions) == 50 and np.isfinite(flown.actions).all()


def test_a_registered_type_trains_from_python_too(linear, tmp_path):
    result = train_bc(
        TrainConfig(dataset=SAMPLE, out=tmp_path / "p", policy=LinearConfig(), epochs=1)
    )
    assert result.meta["train"]["policy"] == "linear"
    assert load_policy(result.out)[0].config == LinearConfig(previous=2)


def test_a_type_name_is_registered_once(linear):
    @dataclass
    class Other(PolicyConfig):
        """Another configuration."""

    with pytest.raises(ConfigError, match="'linear' is taken by LinearConfig"):
        factory.register_policy("linear", LinearPolicy)(Other)
    with pytest.raises(ConfigError, match="previous=0 must be >= 1"):
        factory.make_config("linear", previous=0)


def test_the_builtin_types_are_found_by_name():
    assert list(factory.policy_types())[:4] == ["mlp", "gru", "chunk", "vision"]
    for name, ptype in factory.policy_types().items():
        assert ptype.config.type == name
        assert ptype.config().to_dict()["type"] == name


SMALL = {
    "mlp": {"hidden": [8]},
    "gru": {"hidden": 8},
    "chunk": {"hidden": [8], "history": 2, "chunk": 3},
    "ppo": {"hidden": [8]},
}


@pytest.mark.parametrize("name", ["mlp", "gru", "chunk", "vision", "ppo"])
def test_a_type_is_stateful_exactly_when_its_act_carries_state(name):
    """Every consumer honours ``stateful`` (resets the state, calls the policy at every
    step): a type whose ``act`` hands back a state must say so."""
    names = ["roll_deg", "roll_deg_target", "roll_deg_error"]
    unit = {"mean": np.zeros(3), "std": np.ones(3)}
    if name == "vision":
        config = factory.policy_type(name).config.for_observation(
            names, image_size=16, pool=1, channels=[4], hidden=[8]
        )
        inputs = (torch.zeros(1, 16, 16, 3, dtype=torch.uint8), torch.zeros(1, 3))
    else:
        config = factory.make_config(name, **SMALL[name])
        inputs = torch.zeros(1, 3)
    policy = factory.make_policy(config, unit, {"mean": np.zeros(4), "std": np.ones(4)})
    _, state = policy.eval().act(inputs, None)
    assert config.stateful == (state is not None)
