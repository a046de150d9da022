"""What an evaluation run is: ``EvalConfig`` (``python -m gymfg_il.eval`` is built from it).
What it flies is settled by ``evaluation.plan``, the flying and the files it writes by
``evaluation.runner``."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from gymfg_il.envs.options import FlightOptions
from gymfg_il.errors import ConfigError, join_problems
from gymfg_il.tasks.library import TRACKED_TASKS
from gymfg_il.typecheck import seed_problem


@dataclass
class EvalConfig(FlightOptions):
    """An evaluation: the task's controller and each policy fly the same seeded episodes.

    The flight options (``FlightOptions``) change the policies' own flight where they are
    set (each change is printed; see ``evaluation.plan``); without a policy they are over
    the defaults.

    Attributes:
        policy: a trained policy (checkpoint folder) to fly beside the controller;
            repeatable. A policy flies its own flight (aircraft, task and options, agent
            rate, episode time, weather, from its config.json) unless a flight option
            changes it; never at another rate than it was trained at.
        episodes: episodes per agent.
        seed: seed of the first episode; episode i uses seed+i (the bundled demonstrations
            use seeds from 1000, so the default seeds are held out).
        workers: worker processes flying episodes in parallel; results are identical to one
            worker.
        ray: fly the episodes as tasks on a Ray cluster instead: auto (the one this machine
            is in), local (start one here) or HOST:PORT; results identical to one worker.
        json: write the rows as JSON to this file.
        plots: write Figure-1 plots (one PNG per agent) to this folder.
        plot_episodes: episodes (rows) per plot.
        pilot: also fly the synthetic pilot (a model of a person at the controls) on the
            same seeds: its row is pilot:synthetic-DEVICE, and each policy is set beside it
            as beside the controller.
        device: the synthetic pilot's device: keyboard, joystick or mouse.
        skill: the synthetic pilot's level, 0 (a novice) to 1 (an ace).
    """

    policy: list[Path] = field(default_factory=list, metadata={"repeat": True})
    episodes: int = 10
    seed: int = 0
    workers: int = 1
    ray: str | None = None
    json: Path | None = None
    plots: Path | None = None
    plot_episodes: int = 4
    pilot: Literal["synthetic"] | None = None
    device: Literal["keyboard", "joystick", "mouse"] = "keyboard"
    skill: float = 0.7

    def __post_init__(self) -> None:
        self.policy = [Path(p) for p in self.policy]
        problems = []
        if self.task is not None and self.task not in TRACKED_TASKS:
            problems.append(f"task={self.task!r}: choose one of {', '.join(TRACKED_TASKS)}")
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
