"""What a PPO run starts from (``Start``): the cloned MLP named by ``--init`` (or a fresh one,
from scratch), what its config.json says, and the flight the run trains in, with the notes
on what differs from the policy's own flight."""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import torch

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.envs.options import FlightOptions
from gymfg_il.errors import ConfigError
from gymfg_il.rl.config import PPORunConfig

INIT_TYPES = ("mlp", "ppo")  # what --init takes: an MLP's network
SCRATCH_SEEDS = (0, 1)  # the controller's flights whose statistics normalise a scratch policy


@dataclass
class Start:
    """What a run starts from: the actor's module, what its config.json says, the flight the
    run trains in, and the notes on what differs from the policy's own flight."""

    module: Any
    meta: dict[str, Any]
    flight: FlightSpec
    notes: list[str] = field(default_factory=list)


def starting_policy(cfg: PPORunConfig) -> Start:
    """The actor to start from (``cfg.init``'s, or a fresh MLP) and the flight to train in;
    a clear error for a policy that is not an MLP or a task or aircraft not its own."""
    return scratch_policy(cfg) if cfg.init is None else _cloned(cfg)


def _cloned(cfg: PPORunConfig) -> Start:
    assert cfg.init is not None
    from gymfg_il.policies.checkpoint import load_policy, read_config
    from gymfg_il.policies.lerobot_checkpoint import find_pretrained

    # a LeRobot run's folder says it is one (its checkpoint is inside); a FIFO or a missing
    # config.json is named by read_config
    meta = read_config(find_pretrained(cfg.init) or cfg.init)
    settings = meta["policy"]
    if not isinstance(settings, dict):
        raise ConfigError(
            f"--init {cfg.init}: its config.json's policy entry is {type(settings).__name__}, "
            "not the settings a policy records; train the MLP again"
        )
    kind = settings.get("type", meta["type"])
    if kind not in INIT_TYPES:
        raise ConfigError(
            f"--init {cfg.init} is a {kind} policy; PPO fine-tunes MLP policies only, for now "
            "(train one with `train bc --policy mlp`; an MLP carries a memory of its task's "
            "loops with --memory vertical or loops, which PPO keeps)"
        )
    if not meta.get("spec"):
        raise ConfigError(
            f"--init {cfg.init} records no flight spec (its dataset predates them): train it "
            "again on a dataset rebuilt with `collect recover`"
        )
    flight, notes = _flight_of(cfg, FlightSpec.from_dict(meta["spec"]))
    module, meta = load_policy(cfg.init)
    if getattr(module.config, "dropout", 0.0):
        raise ConfigError(
            f"--init {cfg.init} uses dropout ({module.config.dropout}); PPO's likelihoods need "
            "a network without it: train the MLP with --dropout 0"
        )
    _check_observation(cfg, flight, meta)
    return Start(module, meta, flight, notes)


def _flight_of(cfg: PPORunConfig, own: FlightSpec) -> tuple[FlightSpec, list[str]]:
    """The flight a run from a policy of flight ``own`` trains in: ``own``, with the flight
    options ``cfg`` gives in place of its own (a note on each), its task, aircraft and rate
    kept; a clear error where ``cfg`` asks another."""
    if not own.is_solo:
        raise ConfigError(f"--init {cfg.init} flies a team flight; PPO here trains solo flights")
    asked = cfg.given()
    for name in ("task", "aircraft", "agent_hz"):
        if name in asked and asked[name] != getattr(own, name):
            given = asked[name]
            raise ConfigError(
                f"--{name.replace('_', '-')} {given}: {cfg.init} flies {name} "
                f"{getattr(own, name)}; fine-tuning keeps the policy's own {name} (drop the "
                f"flag, or start from a policy of {given})"
            )
    changes = {k: v for k, v in asked.items() if v != getattr(own, k)}
    notes = [
        f"note: {cfg.init} was trained with {k}={getattr(own, k)!r}; training it with "
        f"{k}={v!r} as asked"
        for k, v in changes.items()
    ]
    return own.replace(**changes), notes


def _check_observation(cfg: PPORunConfig, flight: FlightSpec, meta: dict[str, Any]) -> None:
    """A clear error where the flight observes other variables than the policy was trained
    on (a flight option that changes the task's observation)."""
    env = flight.make_env()
    names = list(env.task.observation_names)
    env.close()
    own = meta.get("observation_names")
    if own is not None and list(own) != names:
        raise ConfigError(
            f"--init {cfg.init} observes {len(own)} variables ({', '.join(own)}); the flight "
            f"asked observes {len(names)} ({', '.join(names)}): drop the flight option that "
            "changes the task, or start from a policy trained on it"
        )


def scratch_policy(cfg: PPORunConfig) -> Start:
    """A fresh MLP for the flight ``cfg`` names, normalised by the statistics of the
    controller's flights of ``SCRATCH_SEEDS``; its last layer starts near zero, so its first
    actions are about the controller's mean action."""
    from gymfg_il.policies.configuration_mlp import MLPConfig
    from gymfg_il.policies.modeling_mlp import MLPPolicy
    from gymfg_il.rollout.agents import AgentSpec
    from gymfg_il.rollout.seeded import fly_many

    flight = FlightOptions(**cfg.given()).flight()
    flown = [e.solo for e in fly_many(flight, AgentSpec.controller(), SCRATCH_SEEDS)]
    obs = np.vstack([t.observations for t in flown])
    act = np.vstack([t.actions for t in flown])
    stats = [{"mean": a.mean(0), "std": a.std(0)} for a in (obs, act)]
    torch.manual_seed(cfg.seed)
    module = MLPPolicy(MLPConfig(hidden=list(cfg.hidden)), *stats)
    last = module.net[-1]
    assert isinstance(last, torch.nn.Linear)
    with torch.no_grad():
        last.weight.mul_(0.01)
        last.bias.zero_()
    env = flight.make_env()
    names = list(env.task.observation_names)
    env.close()
    from gymfg_il.sim.properties import ACTION_NAMES

    meta = {
        "observation_names": names,
        "action_names": list(ACTION_NAMES),
        "fps": flight.agent_hz,
        "dataset": None,
        "camera": None,
        "obs_stats": {k: v.tolist() for k, v in stats[0].items()},
        "action_stats": {k: v.tolist() for k, v in stats[1].items()},
    }
    return Start(module, meta, flight)


def stats_of(module: Any, name: str) -> dict[str, np.ndarray]:
    norm = getattr(module, name)
    return {"mean": norm.mean.double().cpu().numpy(), "std": norm.std.double().cpu().numpy()}


def as_ppo(actor: Any) -> Any:
    """A copy of the actor on the CPU, in eval mode, whose config is a ``ppo`` policy's (its
    network and its memory, which a policy flown computes itself)."""
    from gymfg_il.policies.configuration_ppo import PPOConfig

    module = copy.deepcopy(actor).cpu().eval()
    own = actor.config
    module.config = PPOConfig(
        hidden=list(own.hidden),
        memory=own.memory,
        memory_flight=own.memory_flight,
        memory_observation=list(own.memory_observation),
    )
    return module


def meta_of(start: Start) -> dict[str, Any]:
    """What the result keeps of the starting policy's config.json: what it observes (and,
    with a memory, the memory's own columns) and acts on, its rate, and its data and BC run
    (DAgger trains the result again on them)."""
    keep = ("observation_names", "action_names", "fps", "dataset", "train", "camera")
    meta = {k: start.meta[k] for k in keep if k in start.meta}
    if start.meta.get("memory_names"):  # a policy without memory: its config.json as before
        meta["memory_names"] = start.meta["memory_names"]
    return meta
