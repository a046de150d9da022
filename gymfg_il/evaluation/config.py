"""What an evaluation run is (``python -m gymfg_il.eval`` is built from it), and running it:
the plan (what flies, on which seeds), the flights, and the JSON and plots it writes."""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import ConfigError, join_problems
from gymfg_il.evaluation.runner import evaluate, flight_for
from gymfg_il.evaluation.trace import Trace
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.tasks.library import MANEUVERS
from gymfg_il.typecheck import seed_problem
from gymfg_il.workers import Workers

TASKS = ("altitude", "roll", "pitch", "heading", "airspeed", "sideslip", "level", *MANEUVERS)


@dataclass
class EvalConfig:
    """An evaluation: the task's controller and each policy fly the same seeded episodes.

    Attributes:
        policy: a trained policy (checkpoint folder) to fly beside the controller;
            repeatable. A policy flies its own flight (aircraft, task and options, agent
            rate, episode time, from its config.json) unless a flag below changes it.
        task: a target task (altitude, roll, pitch, heading, airspeed, sideslip: the rudder's
            task, level) or a maneuver (turn, climb-turn, waypoints, formation, approach);
            default: the policy's, else altitude.
        dynamic: moving targets (the family's dynamic task) instead of fixed ones (default:
            the policy's, else fixed).
        aircraft: JSBSim model: c172p, f15, A320 or any other JSBSim ships (default: the
            policy's, else c172p).
        episodes: episodes per agent.
        seed: seed of the first episode; episode i uses seed+i (the bundled demonstrations
            use seeds from 1000, so the default seeds are held out).
        episode_time_s: episode length in seconds (default: the policy's, else 90).
        agent_hz: agent rate in Hz, a divisor of 120 (default: the policy's, else 10; a
            policy is not flown at another rate than it was trained at).
        workers: worker processes flying episodes in parallel; results are identical to one
            worker.
        ray: fly the episodes as tasks on a Ray cluster instead: auto (the one this machine
            is in), local (start one here) or HOST:PORT; results identical to one worker.
        json: write the rows as JSON to this file.
        plots: write Figure-1 plots (one PNG per agent) to this folder.
        plot_episodes: episodes (rows) per plot.
        turbulence: fly in JSBSim's turbulence: none, light, moderate or severe (seeded per
            episode; default: the policy's flight's, else none).
        wind_kt: a steady wind from a direction drawn per episode (default: the policy's
            flight's, else none).
        pilot: also fly the synthetic pilot (a model of a person at the controls) on the
            same seeds: its row is pilot:synthetic-DEVICE.
        device: the synthetic pilot's device: keyboard, joystick or mouse.
        skill: the synthetic pilot's level, 0 (a novice) to 1 (an ace).
    """

    policy: list[Path] = field(default_factory=list, metadata={"repeat": True})
    task: str | None = None
    dynamic: bool | None = None
    aircraft: str | None = None
    episodes: int = 10
    seed: int = 0
    episode_time_s: float | None = field(default=None, metadata={"flag": "--episode-time"})
    agent_hz: int | None = None
    workers: int = 1
    ray: str | None = None
    json: Path | None = None
    plots: Path | None = None
    plot_episodes: int = 4
    turbulence: Literal["none", "light", "moderate", "severe"] | None = None
    wind_kt: float | None = None
    pilot: Literal["synthetic"] | None = None
    device: Literal["keyboard", "joystick", "mouse"] = "keyboard"
    skill: float = 0.7

    def __post_init__(self) -> None:
        self.policy = [Path(p) for p in self.policy]
        problems = []
        if self.task is not None and self.task not in TASKS:
            problems.append(f"task={self.task!r}: choose one of {', '.join(TASKS)}")
        if not 0.0 <= self.skill <= 1.0:
            problems.append(f"skill={self.skill}: want 0 (a novice) .. 1 (an ace)")
        for name in ("episodes", "workers", "plot_episodes"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                problems.append(f"{name}={value!r} must be an integer >= 1")
        if isinstance(self.episodes, int) and (problem := seed_problem(self.seed, self.episodes)):
            problems.append(problem)
        self.json = None if self.json is None else Path(self.json)
        self.plots = None if self.plots is None else Path(self.plots)
        problems += filter(
            None, [unwritable(self.json, "--json"), unwritable(self.plots, "--plots")]
        )
        if problems:
            raise ConfigError(join_problems("eval", problems))

    @property
    def seeds(self) -> list[int]:
        return list(range(self.seed, self.seed + self.episodes))


def unwritable(path: Path | None, flag: str) -> str | None:
    """Why ``path`` (a file or folder to write, its folders made as needed) cannot be
    written, or None: checked before anything flies, so that a run's results are not lost
    at its end."""
    if path is None:
        return None
    if flag == "--json" and path.is_dir():
        return f"{flag} {path} is a folder; give a file name (e.g. {path / 'rows.json'})"
    # the nearest part of the path that exists must be a folder this process may write in
    there = path if flag != "--json" else path.parent
    while not there.exists() and there != there.parent:
        there = there.parent
    if not there.is_dir():
        return (
            f"{flag} {path}: {there} is a file, so no folder can be made there; give another path"
        )
    if not os.access(there, os.W_OK | os.X_OK):
        return f"{flag} {path}: cannot write in {there} (permission denied); give another path"
    return None


@dataclass
class EvalRun:
    """What an evaluation flew and found."""

    flight: FlightSpec
    rows: list[dict[str, Any]]
    traces: dict[str, list[Trace]]
    notes: list[str]
    written: list[Path] = field(default_factory=list)


def _meta(path: Path) -> dict[str, Any]:
    """A policy's config; a LeRobot checkpoint's completed with the flight, rate and
    observation of the dataset it was trained on, when that dataset is here."""
    meta = AgentSpec.policy(path).meta()
    if not meta.get("lerobot"):
        return meta
    root = meta.get("dataset")
    if not root or not (Path(root) / "meta" / "info.json").is_file():
        meta["spec_note"] = f"its training dataset ({root}) is not here to say what it flew"
        return meta
    from gymfg_il.learning.data import dataset_flight

    spec, why, found = dataset_flight(Path(root))
    meta.update(found, spec=spec.to_dict() if spec else None, spec_note=why)
    return meta


def plan(cfg: EvalConfig) -> tuple[FlightSpec, dict[str, AgentSpec], list[str]]:
    """What flies (the flight, the agents by row name) and the notes on flags that changed a
    policy's own flight; a clear error for a policy that cannot fly it."""
    metas = {path: _meta(path) for path in cfg.policy}
    flight, notes = flight_for(
        metas,
        task=cfg.task,
        dynamic=cfg.dynamic,
        aircraft=cfg.aircraft,
        agent_hz=cfg.agent_hz,
        episode_time_s=cfg.episode_time_s,
        turbulence=cfg.turbulence,
        wind_kt=cfg.wind_kt,
    )
    env = flight.make_env()
    try:
        for path in metas:  # loaded whole now: a damaged policy fails before anything flies
            AgentSpec.policy(path).make(env)
    finally:
        env.close()
    agents = {"controller": AgentSpec.controller()}
    if cfg.pilot == "synthetic":
        agents[f"pilot:synthetic-{cfg.device}"] = AgentSpec.synthetic(cfg.device, cfg.skill)
    names = [p.name for p in cfg.policy]
    for path in cfg.policy:  # a folder name twice (run1/policy, run2/policy): the whole path
        agents[f"policy:{path.name if names.count(path.name) == 1 else path}"] = AgentSpec.policy(
            path
        )
    return flight, agents, notes


def run_eval(
    cfg: EvalConfig, progress: Callable[[int], Callable[[str], None]] | None = None
) -> EvalRun:
    """Plan, fly every agent on ``cfg.seeds`` and write the JSON rows and plots asked for.

    ``progress(total)`` is called once the workers run (a bar made earlier would start a
    thread, and workers then could not be forked) and returns the per-episode callback."""
    flight, agents, notes = plan(cfg)
    seeds = cfg.seeds
    with Workers(min(cfg.workers, len(seeds)), ray=cfg.ray) as pool:
        tick = progress(len(agents) * len(seeds)) if progress else None
        rows, traces = evaluate(flight, agents, seeds, pool, tick)
    run = EvalRun(flight, rows, traces, notes)
    if cfg.json:
        try:
            cfg.json.parent.mkdir(parents=True, exist_ok=True)
            cfg.json.write_text(json.dumps({"rows": rows}, indent=2))
        except OSError as err:  # the folder changed while the episodes flew
            raise ConfigError(f"--json {cfg.json}: cannot write there ({err.strerror})") from None
        run.written.append(cfg.json)
    if cfg.plots:
        from gymfg_il.evaluation.plots import figure1, primary_control
        from gymfg_il.evaluation.tracks import ground_tracks, has_track

        label, model = flight.task_label.rsplit(":", 1)[-1], flight.aircraft
        for name, episodes in traces.items():
            path = cfg.plots / f"{label}_{model}_{name.replace(':', '-')}.png"
            title = f"{name}: {label} on {model}"
            control = primary_control(episodes[0].variable)
            figure1(episodes[: cfg.plot_episodes], control, title, path)
            run.written.append(path)
        first = next(iter(traces.values()))
        if first and has_track(first[0]):  # gates, a runway, a lead: where, not when
            path = cfg.plots / f"{label}_{model}_tracks.png"
            title = f"{label} on {model}: ground track and vertical profile"
            run.written.append(ground_tracks(traces, title, path, cfg.plot_episodes))
    return run
