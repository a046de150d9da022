"""What a collection session flies and where it writes: one dataclass, from CLI or recipe.

A recipe is a TOML file with a ``[collector]`` table holding these fields, e.g.
``collectors/sample.toml``; ``python -m gymfg_il.collect collectors/NAME.toml`` runs it.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, Literal

from gymfg_il.datasets.videos import check_views
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import ConfigError, join_problems
from gymfg_il.sim.timing import DEFAULT_AGENT_HZ
from gymfg_il.typecheck import seed_problem, type_problems


@dataclass
class CollectConfig:
    """A collection session.

    Attributes:
        kind: who flies: ``autopilot`` (the task's PID controller) or ``manual`` (a person).
        aircraft: JSBSim model (c172p, f15, A320, or any other JSBSim ships).
        task: a target task (altitude, roll, pitch, heading, airspeed, sideslip: the rudder's
            task, level) or a maneuver (turn, climb-turn, waypoints, formation, approach).
        dynamic: moving targets instead of fixed ones.
        episodes: episodes to record (manual: 0 = until you quit).
        episode_time_s: seconds per episode (default: the task's own: 90 for most, 120 for
            waypoints, 180 for approach).
        agent_hz: agent rate = the dataset's fps, a divisor of 120.
        seed: seed of the first episode (episode i uses seed + i); from 1000, so that
            `eval`, whose seeds start at 0, flies cases the demonstrations never showed.
        noise: autopilot only: DART-style noise: std of Gaussian noise added to the executed
            surfaces (the dataset keeps the demonstrator's clean action as the label), so the
            demonstrations show how to recover from small deviations; 0 = none. Without it,
            behaviour cloning from a PID's demonstrations fails (0% of held-out c172p roll
            episodes with 40 demonstrations against 100% at 0.02). 0.05 by default: at 0.02
            an A320 heading policy from 40 demonstrations crashed 2 of 16 held-out episodes
            and an F-15 altitude policy missed 1; at 0.05 all nine target rows (altitude,
            roll, heading on c172p, f15, A320) reached >= 98.5% of the controller's return
            and 16 of 16 on two sets of demonstrations and held-out seeds. A vision policy
            needs it too: it must read the camera off the demonstrated path (roll: 81% of
            the controller's return and 10 of 16 at 0.02, 96% and 16 of 16 at 0.05).
        turbulence: fly in JSBSim's turbulence: none, light, moderate or severe (seeded per
            episode, recorded in the flight spec, so a policy is evaluated in it by default).
            A policy cloned from still-air demonstrations drifts off its target in turbulence.
        wind_kt: a steady wind from a direction drawn per episode.
        out: session folder: ``logs/`` (MCAP) and ``dataset/`` (LeRobot) inside.
        images: camera views to add to the dataset as LeRobot video features
            ``observation.images.<view>``: ``front`` (the pilot's eye) and/or ``chase``
            (``--images front`` or ``--images front chase``); drawn from the logged states
            by the headless camera (``viz.camera``). Default: none, state only.
        image_size: side of the square camera frames, in pixels.
        pilot_view: manual only: the camera the window shows beside the instruments
            (``front``, ``chase``, or ``none``), so a person can fly without FlightGear.
        task_kwargs: arguments of the task class (e.g. ``target_range``).
        device: manual only: keyboard, mouse, joystick or flightgear (fly from FlightGear's
            own cockpit: fgfs --fdm=null --native-fdm=socket,in,30,,VIEW,udp
            --native-ctrls=socket,out,30,127.0.0.1,5700,udp, with --view VIEW here).
        assist: manual only: ``controller`` or a policy folder that flies until the person
            takes over (T); the person's frames are flagged as interventions.
        view: manual only: UDP ports of FlightGear out-the-window views (repeatable; see
            gymfg_il.flightgear.launcher).
        pilot: manual only: who is at the controls: a person, or the synthetic pilot (a model
            of a person flying through the same keyboard, joystick or mouse; it runs
            headless and as fast as the machine allows; its episodes are source=synthetic).
        skill: manual only: the synthetic pilot's level, 0 (a novice) to 1 (an ace).
        keyboard: manual only: key bindings (see ``manual.bindings.KeyboardBindings``).
        mouse: manual only: mouse bindings (``MouseBindings``).
        joystick: manual only: joystick axes, dead zones, expo, buttons (``JoystickBindings``).
        flightgear: manual only: where FlightGear's controls arrive (``FlightGearBindings``:
            port, host).
    """

    kind: Literal["autopilot", "manual"] = "autopilot"
    aircraft: str = "c172p"
    task: str = "altitude"
    dynamic: bool = False
    episodes: int = 10
    episode_time_s: float | None = field(default=None, metadata={"flag": "--episode-time"})
    agent_hz: int = DEFAULT_AGENT_HZ
    seed: int = 1000
    noise: float = 0.05
    turbulence: Literal["none", "light", "moderate", "severe"] = "none"
    wind_kt: float = 0.0
    out: Path = Path("datasets/autopilot")
    images: list[str] = field(default_factory=list)
    image_size: int = 128
    pilot_view: Literal["front", "chase", "none"] = "front"
    task_kwargs: dict[str, Any] = field(default_factory=dict)
    device: Literal["keyboard", "mouse", "joystick", "flightgear"] = "keyboard"
    assist: str | None = None
    view: list[int] = field(default_factory=list, metadata={"repeat": True})
    pilot: Literal["person", "synthetic"] = "person"
    skill: float = 0.7
    keyboard: dict[str, Any] = field(default_factory=dict)
    mouse: dict[str, Any] = field(default_factory=dict)
    joystick: dict[str, Any] = field(default_factory=dict)
    flightgear: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        typed = type_problems(self)
        if typed:  # a recipe's `dynamic = "no"` must not pass as true
            raise ConfigError(join_problems("collection config", typed))
        self.out = Path(self.out)
        problems = []
        if self.kind not in ("autopilot", "manual"):
            problems.append(f"kind={self.kind!r}: choose autopilot or manual")
        if self.device not in ("keyboard", "mouse", "joystick", "flightgear"):
            problems.append(
                f"device={self.device!r}: choose keyboard, mouse, joystick or flightgear"
            )
        if self.task in ("dummy",):
            problems.append("task 'dummy' has no controller to demonstrate it")
        elif self.episode_time_s is not None and not (
            isinstance(self.episode_time_s, (int, float)) and self.episode_time_s > 0
        ):
            problems.append(f"episode_time_s={self.episode_time_s!r} must be > 0")
        else:
            try:
                self.flight()
            except ConfigError as err:
                problems.append(str(err))
        # a person may fly until they quit; the synthetic pilot flies as many as asked
        least = 0 if self.kind == "manual" and self.pilot == "person" else 1
        if not isinstance(self.episodes, int) or self.episodes < least:
            problems.append(f"episodes={self.episodes!r} must be an integer >= {least}")
        elif problem := seed_problem(self.seed, self.episodes):  # the last episode's seed
            problems.append(problem)
        if not (
            isinstance(self.noise, (int, float)) and math.isfinite(self.noise) and self.noise >= 0
        ):
            problems.append(f"noise={self.noise!r} must be a number >= 0")
        problems += [f"view port {p}: want 1..65535" for p in self.view if not 0 < p < 65536]
        self.images = [v for item in self.images for v in str(item).split(",") if v]
        try:
            check_views(self.images)
        except ConfigError as err:
            problems.append(str(err))
        if not 16 <= self.image_size <= 1024:
            problems.append(f"image_size={self.image_size}: want 16..1024 pixels")
        if not 0.0 <= self.skill <= 1.0:
            problems.append(f"skill={self.skill}: want 0 (a novice) .. 1 (an ace)")
        if problems:
            raise ConfigError(join_problems("collection config", problems))

    def flight(self) -> FlightSpec:
        """What the session flies."""
        return FlightSpec.solo(
            self.aircraft,
            self.task,
            dynamic=self.dynamic,
            task_kwargs=self.task_kwargs,
            agent_hz=self.agent_hz,
            episode_time_s=self.episode_time_s,
            turbulence=self.turbulence,
            wind_kt=self.wind_kt,
        )

    @classmethod
    def from_recipe(cls, path: Path, **overrides: Any) -> CollectConfig:
        """Read ``[collector]`` from a TOML recipe; ``overrides`` win over the file."""
        path = Path(path)
        if not path.is_file():
            raise ConfigError(f"no recipe at {path}; recipes live in collectors/*.toml")
        try:
            data = tomllib.loads(path.read_text())
        except tomllib.TOMLDecodeError as err:
            raise ConfigError(f"{path} is not valid TOML: {err}") from None
        table = data.get("collector")
        if not isinstance(table, dict):
            raise ConfigError(f"{path} has no [collector] table")
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(table) - known)
        if unknown:
            raise ConfigError(f"{path}: unknown keys {unknown}; known: {sorted(known)}")
        return cls(**{**table, **{k: v for k, v in overrides.items() if v is not None}})
