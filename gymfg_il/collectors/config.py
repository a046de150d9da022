"""What a collection session flies and where it writes, from the command line or a recipe.

``CollectConfig`` holds what every collection has: the flight (``envs.options.FlightOptions``),
the episodes and their seeds, the session folder, the dataset's camera views, and the
autopilot's DART noise; ``collect autopilot`` is built from it. ``ManualConfig`` adds what a
session flown through a device needs (``collect manual``, ``cockpit.session.ManualSession``):
who is at the controls, the device and its bindings, an assistant, what the window shows.

A recipe is a TOML file with a ``[collector]`` table holding these fields (``kind = "manual"``
makes it a ``ManualConfig``), e.g. ``collectors/sample.toml``;
``python -m gymfg_il.collect collectors/NAME.toml`` runs it.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, ClassVar, Literal

from gymfg_il.datasets.videos import DEFAULT_IMAGE_SIZE, check_views
from gymfg_il.envs.options import FlightOptions, unset_values
from gymfg_il.errors import ConfigError, join_problems
from gymfg_il.names import name_problem
from gymfg_il.tasks.base import Task
from gymfg_il.tasks.library import TASK_FAMILIES, TRACKED_TASKS, task_class
from gymfg_il.typecheck import seed_problem, type_problems


@dataclass
class CollectConfig(FlightOptions):
    """A collection session: the flight (its options above), the episodes, where they go.

    Attributes:
        episodes: episodes to record (manual: 0 = until you quit).
        seed: seed of the first episode (episode i uses seed + i); from 1000, so that `eval`,
            whose seeds start at 0, flies cases the demonstrations never showed.
        noise: autopilot only: DART-style noise: std of Gaussian noise added to each executed
            control, throttle included (the dataset keeps the demonstrator's clean action as
            the label), so the demonstrations show how to recover from small deviations,
            which behaviour cloning from a controller's demonstrations needs; 0 = none.
            Default: the task's own (``Task.demonstration_noise``): 0.1; the fixed heading's
            and the turn's 0.2.
        out: session folder: ``logs/`` (MCAP) and ``dataset/`` (LeRobot) inside.
        images: camera views to add to the dataset as LeRobot video features
            ``observation.images.<view>``: ``front`` (the pilot's eye) and/or ``chase``
            (``--images front`` or ``--images front chase``); drawn from the logged states
            by the headless camera (``viz.camera``). Default: none, state only.
        image_size: side of the square camera frames, in pixels.
    """

    episodes: int = 10
    seed: int = 1000
    noise: float | None = None
    out: Path = Path("datasets/autopilot")
    images: list[str] = field(default_factory=list)
    image_size: int = DEFAULT_IMAGE_SIZE
    logs_gusts: ClassVar[bool] = False  # each episode's gust events go to its log

    def __post_init__(self) -> None:
        typed = type_problems(self)
        if typed:  # a recipe's `dynamic = "no"` must not pass as true
            raise ConfigError(join_problems("collection config", typed))
        self.out = Path(self.out)
        self.images = [v for item in self.images for v in str(item).split(",") if v]
        problems = self.problems()
        if problems:
            raise ConfigError(join_problems("collection config", problems))

    def fewest_episodes(self) -> int:
        """The fewest episodes a session may be asked for."""
        return 1

    def dart_noise(self) -> float:
        """The DART noise the autopilot's episodes fly with: ``noise``, or unset, the task's
        own (``Task.demonstration_noise``; for a task that cannot be built the common one,
        and ``problems`` names the task)."""
        if self.noise is not None:
            return self.noise
        try:
            task = task_class(self.task or unset_values()["task"], bool(self.dynamic))
        except ConfigError:
            task = Task
        return task.demonstration_noise

    def problems(self) -> list[str]:
        """What is wrong with these values, each with its fix (empty: nothing)."""
        problems = []
        if self.task in TASK_FAMILIES and self.task not in TRACKED_TASKS:
            problems.append(f"task {self.task!r} has no controller to demonstrate it")
        elif self.episode_time_s is not None and not self.episode_time_s > 0:
            problems.append(f"episode_time_s={self.episode_time_s!r} must be > 0")
        else:
            try:
                self.flight()
            except ConfigError as err:
                problems.append(str(err))
        least = self.fewest_episodes()
        if self.episodes < least:
            problems.append(f"episodes={self.episodes!r} must be an integer >= {least}")
        elif problem := seed_problem(self.seed, self.episodes):  # the last episode's seed
            problems.append(problem)
        if self.noise is not None and not (math.isfinite(self.noise) and self.noise >= 0):
            problems.append(f"noise={self.noise!r} must be a number >= 0")
        if self.gusts not in (None, "none") and not self.logs_gusts:
            problems.append(
                f"gusts={self.gusts!r}: gust events are flown and logged in manual sessions "
                "(collect manual --gusts); an autopilot's data shows recoveries with --noise"
            )
        try:
            check_views(self.images)
        except ConfigError as err:
            problems.append(str(err))
        if not 16 <= self.image_size <= 1024:
            problems.append(f"image_size={self.image_size}: want 16..1024 pixels")
        return problems

    @classmethod
    def from_recipe(cls, path: Path, **overrides: Any) -> CollectConfig:
        """Read ``[collector]`` from a TOML recipe (a ``ManualConfig`` for ``kind =
        "manual"``); ``overrides`` (options given beside the recipe) win over the file."""
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
        table = dict(table)
        kind = table.pop("kind", "autopilot")
        chosen = KINDS.get(kind)
        if chosen is None:
            raise ConfigError(f"{path}: kind={kind!r}: choose {' or '.join(KINDS)}")
        known = {f.name for f in fields(chosen)}
        overrides = {k: v for k, v in overrides.items() if v is not None}
        manual = sorted(manual_only(overrides)) if chosen is not ManualConfig else []
        if manual:
            flags = ", ".join("--" + k.replace("_", "-") for k in manual)
            raise ConfigError(f"{flags} apply to manual recipes; {path} is an autopilot one")
        unknown = sorted(set(table) - known)
        if unknown:
            why = " (manual sessions only: kind = 'manual')" if manual_only(unknown) else ""
            raise ConfigError(f"{path}: unknown keys {unknown}{why}; known: {sorted(known)}")
        return chosen(**{**table, **overrides})


# a person's session flies at this rate unless told otherwise (what a person can follow
# smoothly, and what the synthetic pilot, who stands in for one, is evaluated at)
MANUAL_HZ = 30


@dataclass
class ManualConfig(CollectConfig):
    """A collection session flown through a device in a window, by a person or the synthetic
    pilot (``cockpit.session.ManualSession``).

    Attributes:
        device: keyboard, mouse, joystick or flightgear (fly from FlightGear's own cockpit:
            fgfs --fdm=null --native-fdm=socket,in,30,,VIEW,udp
            --native-ctrls=socket,out,30,127.0.0.1,5700,udp, with --view VIEW here).
        assist: ``controller`` or a policy folder that flies until the person takes over
            (T); the person's frames are flagged as interventions.
        view: UDP ports of FlightGear out-the-window views (repeatable; see
            gymfg_il.flightgear.launcher).
        pilot: who is at the controls: a person, or the synthetic pilot (a model of a person
            flying through the same keyboard, joystick or mouse; it runs headless and as fast
            as the machine allows; its episodes are source=synthetic).
        skill: the synthetic pilot's level, 0 (a novice) to 1 (an ace).
        noise: the synthetic pilot only: DART-style noise, the std of Gaussian noise added
            to every control it flies, drawn from each episode's seed; the dataset keeps the
            pilot's own action as the label, so its episodes show recoveries from the
            deviations; 0 = none. A person shows recoveries with --gusts instead.
        pilot_name: who flies this session, stored with each episode (the card lists pilots,
            ``train bc --select pilot=NAME`` picks theirs); default: ``synthetic-<skill>``
            for the synthetic pilot, none for a person.
        pilot_view: the camera the window shows beside the instruments (``front``,
            ``chase``, or ``none``), so a person can fly without FlightGear.
        keyboard: key bindings (see ``manual.bindings.KeyboardBindings``).
        mouse: mouse bindings (``MouseBindings``).
        joystick: joystick axes, dead zones, expo, buttons (``JoystickBindings``).
        flightgear: where FlightGear's controls arrive (``FlightGearBindings``: port, host).
    """

    device: Literal["keyboard", "mouse", "joystick", "flightgear"] = "keyboard"
    assist: str | None = None
    view: list[int] = field(default_factory=list, metadata={"repeat": True})
    pilot: Literal["person", "synthetic"] = "person"
    skill: float = 0.7
    noise: float = 0.0  # a person's flight is not perturbed
    pilot_name: str | None = None
    pilot_view: Literal["front", "chase", "none"] = "front"
    keyboard: dict[str, Any] = field(default_factory=dict)
    mouse: dict[str, Any] = field(default_factory=dict)
    joystick: dict[str, Any] = field(default_factory=dict)
    flightgear: dict[str, Any] = field(default_factory=dict)
    logs_gusts: ClassVar[bool] = True

    def fewest_episodes(self) -> int:
        """A person may fly until they quit (0); the synthetic pilot flies as many as asked."""
        return 0 if self.pilot == "person" else 1

    def problems(self) -> list[str]:
        problems = super().problems()
        problems += [f"view port {p}: want 1..65535" for p in self.view if not 0 < p < 65536]
        if not 0.0 <= self.skill <= 1.0:
            problems.append(f"skill={self.skill}: want 0 (a novice) .. 1 (an ace)")
        if self.noise and self.pilot != "synthetic":
            problems.append(
                f"noise={self.noise!r} perturbs the synthetic pilot's controls, not a "
                "person's; add --pilot synthetic, or drop --noise and fly --gusts LEVEL to "
                "show recoveries"
            )
        name = self.pilot_name
        problem = None if name is None else name_problem(name, "pilot name")
        if problem is None and name is not None and "|" in name:
            problem = f"pilot name {name!r} holds '|', which tables of pilots use to separate"
        if problem is not None:
            problems.append(f"pilot_name: {problem}")
        return problems


KINDS: dict[str, type[CollectConfig]] = {"autopilot": CollectConfig, "manual": ManualConfig}


def manual_only(names: Any) -> set[str]:
    """Which of ``names`` are options of manual sessions only."""
    common = {f.name for f in fields(CollectConfig)}
    return ({f.name for f in fields(ManualConfig)} - common) & set(names)
