"""A dataset as a Minari dataset (Farama's offline-RL format): ``collect export minari DIR``.

    python -m gymfg_il.collect export minari runs/roll --name gymfg/roll-c172p-v0 --root data
    MINARI_DATASETS_PATH=data python -c "import minari; d = minari.load_dataset(
        'gymfg/roll-c172p-v0'); env = d.recover_environment()"

Each dataset episode becomes a Minari episode: ``observations`` (N + 1 rows: the reset's and
the one after every step), ``actions`` (N: what the env was stepped with), ``rewards``,
``terminations`` and ``truncations`` (N), its ``seed``, and ``infos["label"]`` (the
demonstrator's action, the dataset's ``action`` column; N + 1 rows, the last repeated).

A LeRobot frame holds the observation an action was chosen from, not the one after the last
step, so the export re-flies every episode in the env it names, from its seed, and takes the
final observation, rewards and flags from that flight. The flown actions come from the
session's logs (``DIR/logs`` beside ``DIR/dataset``), and the re-flown observations must then
equal the dataset's bit for bit. Without the logs the dataset's ``action`` column is flown:
that is what was flown only without collection noise (DART's ``--noise``, the task's own,
is in the log alone, so such a dataset needs its logs), and being float32 it re-flies within
rounding (measured: at most 5e-6 relative over 90 s; ``refly.NEAR`` allows 1e-3), so the dataset's
own observations are kept and only the last comes from the flight. Actions are stored as
float32, the action space's dtype.

The Minari dataset's env spec is the registered GymFG id of the task (``GymFG/Roll-v0``) with
every keyword of the flight: aircraft, dynamic, task_kwargs, agent_hz, sim_hz,
episode_time_s, turbulence, wind_kt, wind_from_deg; ``recover_environment()`` makes it with
``gymnasium.make`` and its spaces are the dataset's. Only solo flights export (a team run's
aircraft flew beside others, which no single gymnasium env reproduces). Nothing touches the
network: Minari writes under ``root`` (its ``MINARI_DATASETS_PATH``) in its Arrow format.
Its author, author email and code permalink are the user's or GymFG-IL's package metadata's
(``export.credits``), and its requirements pin the GymFG-IL and JSBSim that flew it.
"""

from __future__ import annotations

import dataclasses
import os
import re
import shutil
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import ConfigError
from gymfg_il.export.credits import Credits, credits
from gymfg_il.export.refly import refly_all
from gymfg_il.names import BadNameError, name_problem

if TYPE_CHECKING:
    from gymfg_il.learning.frames import Frames

DATA_FORMAT = "arrow"  # Minari's Arrow storage: pyarrow is here already (LeRobot); no h5py
# each part starts with a letter, digit or underscore: no "..", ".", "/abs" or hidden parts,
# so the id names a folder inside Minari's root and nowhere else
_PART = r"\w[\w.-]*"
_ID = re.compile(rf"^({_PART}/)*{_PART}-v\d+$")


@dataclass
class MinariConfig:
    """Turn one of our LeRobot datasets into a Minari dataset (episodes with observations,
    actions, rewards, terminations, truncations) that minari.load_dataset opens and whose
    recover_environment() makes the GymFG env it was flown in; nothing touches the network.

    Attributes:
        dataset: a session folder (dataset/ and logs/ inside) or a dataset folder (meta/
            inside).
        name: the Minari dataset id, (namespace/)name-vN, e.g. gymfg/roll-c172p-v0.
        root: the folder Minari keeps its datasets in; open them with
            MINARI_DATASETS_PATH=ROOT (default: $MINARI_DATASETS_PATH, else
            ~/.minari/datasets).
        author: who made the dataset, repeatable (default: GymFG-IL's authors, from its
            package metadata).
        author_email: how to reach them, repeatable (default: the emails in GymFG-IL's
            package metadata, if any; else none is set).
        code_permalink: a link to the code that made the dataset (default: the source URL in
            GymFG-IL's package metadata, if any; else none is set).
    """

    dataset: Path = field(metadata={"positional": True})
    name: str
    root: Path | None = None
    author: list[str] = field(default_factory=list, metadata={"repeat": True})
    author_email: list[str] = field(default_factory=list, metadata={"repeat": True})
    code_permalink: str | None = None

    def __post_init__(self) -> None:
        problem = name_problem(self.name, "Minari dataset id")
        if problem is not None:
            raise BadNameError(f"--name: {problem}")
        if not _ID.match(self.name):
            raise BadNameError(
                f"--name {self.name!r}: a Minari dataset id is (namespace/)name-vN, each part "
                "starting with a letter, digit or underscore (no '..'), e.g. gymfg/roll-c172p-v0"
            )


@dataclass
class MinariSummary:
    """What ``export_dataset`` wrote."""

    name: str
    root: Path
    episodes: int
    steps: int
    env_id: str
    credits: Credits


def env_spec(flight: FlightSpec) -> Any:
    """The gymnasium ``EnvSpec`` of a solo flight: its task's registered id with every
    keyword ``AircraftEnv`` needs to fly it again."""
    import gymnasium as gym

    from gymfg_il.envs.registration import IDS, register_envs

    register_envs()
    ego = flight.solo_aircraft
    ids = {family: env_id for env_id, family in IDS.items()}
    if ego.task not in ids:
        raise ConfigError(
            f"task {ego.task!r} has no registered GymFG id (known: {', '.join(sorted(ids))}); "
            "only the registered tasks export to Minari"
        )
    base = gym.spec(ids[ego.task])
    kwargs = {
        **base.kwargs,
        "aircraft": ego.model,
        "dynamic": ego.dynamic,
        "task_kwargs": dict(ego.task_kwargs),
        "agent_hz": flight.agent_hz,
        "sim_hz": flight.sim_hz,
        "episode_time_s": flight.episode_time_s,
        "turbulence": flight.turbulence,
        "wind_kt": flight.wind_kt,
        "wind_from_deg": flight.wind_from_deg,
        "trimmed_starts": flight.trimmed_starts,
    }
    import json

    kwargs = json.loads(json.dumps(kwargs))  # plain JSON data: Minari stores the spec as JSON
    return dataclasses.replace(base, kwargs=kwargs)


@contextmanager
def minari_root(root: Path | None) -> Iterator[Path]:
    """Minari's datasets folder set to ``root`` (it reads ``MINARI_DATASETS_PATH`` only) while
    inside, as it was afterwards."""
    before = os.environ.get("MINARI_DATASETS_PATH")
    if root is None:
        root = Path(before) if before else Path.home() / ".minari" / "datasets"
    root = Path(root).expanduser().resolve()  # Minari's Arrow storage fails on relative paths
    os.environ["MINARI_DATASETS_PATH"] = str(root)
    try:
        yield root
    finally:
        if before is None:
            os.environ.pop("MINARI_DATASETS_PATH", None)
        else:
            os.environ["MINARI_DATASETS_PATH"] = before


def _locate(path: Path) -> tuple[Path, Path | None]:
    """(the dataset folder, the session's logs folder if there is one)."""
    path = Path(path)
    root = path / "dataset" if (path / "dataset" / "meta").is_dir() else path
    if not (root / "meta" / "info.json").is_file():
        raise ConfigError(
            f"no LeRobot dataset at {path} (no meta/info.json); give a session folder from "
            "`python -m gymfg_il.collect autopilot --out DIR` or its DIR/dataset"
        )
    logs = root.parent / "logs"
    return root, logs if logs.is_dir() else None


def export_dataset(
    dataset: Path, name: str, root: Path | None = None, made_by: Credits | None = None
) -> MinariSummary:
    """Write the LeRobot dataset at ``dataset`` as the Minari dataset ``name`` under
    ``root`` (see the module docstring; ``made_by``: its author, email and code permalink,
    default ``credits()``: the package's); what was written."""
    import gymnasium as gym
    import minari

    from gymfg_il.learning.data import load_frames

    MinariConfig(dataset, name, root)  # the id's rule
    folder, logs = _locate(dataset)
    frames = load_frames(folder)
    flight = _solo_flight(frames, folder)
    spec = env_spec(flight)
    env = gym.make(spec)
    try:
        buffers = refly_all(env, spec.id, frames, logs)
    finally:
        env.close()
    sources = sorted(set(frames.episodes.get("gymfg/source", [])))
    made_by = made_by if made_by is not None else credits()
    with minari_root(root) as where, _writing(where, name):
        minari.create_dataset_from_buffers(
            dataset_id=name,
            buffer=buffers,
            env=spec,
            algorithm_name=", ".join(sources) or None,
            author=set(made_by.author) or None,
            author_email=set(made_by.author_email) or None,
            code_permalink=made_by.code_permalink,
            requirements=list(made_by.requirements) or None,
            description=(
                f"GymFG-IL demonstrations exported from the LeRobot dataset {folder.name}: "
                f"{flight.aircraft} flying {flight.task_label} at {flight.agent_hz} Hz "
                f"(JSBSim); observation names {', '.join(frames.observation_names)}; "
                "infos['label'] is the demonstrator's action"
            ),
            observation_space=env.observation_space,
            action_space=env.action_space,
            data_format=DATA_FORMAT,
        )
    steps = int(sum(len(b.rewards) for b in buffers))
    return MinariSummary(name, where, len(buffers), steps, str(spec.id), made_by)


def _solo_flight(frames: Frames, folder: Path) -> FlightSpec:
    """The one solo flight every episode of the dataset at ``folder`` was flown as, or an
    error saying why there is none."""
    flight, why = frames.flight()
    if flight is None or why:  # a note: the episodes' weather differs (``flight_of``)
        raise ConfigError(
            f"the dataset at {folder} names no one flight: {why}"
            + ("; a Minari dataset names one env: export the episodes of one air" if flight else "")
        )
    team_runs = {
        c for c, s in zip(frames.episodes["gymfg/callsign"], frames.episodes["gymfg/spec"],
                          strict=True) if not FlightSpec.from_json(s).is_solo
    }  # fmt: skip
    if team_runs:
        raise ConfigError(
            f"the dataset at {folder} holds team-run episodes ({', '.join(sorted(team_runs))} "
            "flew beside other aircraft); a Minari dataset names one gymnasium env, which "
            "flies one aircraft: export a solo dataset"
        )
    return flight


@contextmanager
def _writing(where: Path, name: str) -> Iterator[None]:
    """Minari writing the dataset ``name`` under ``where``: without its warnings about
    settings left unset, and leaving no half-written dataset behind; one that exists already
    is a ConfigError."""
    with warnings.catch_warnings():
        assert (where / name).resolve().is_relative_to(where), name  # the id's rule keeps it in
        for what in ("code_permalink", "author", "author_email", "eval_env"):
            warnings.filterwarnings("ignore", message=f"`{what}` is set to None")
        try:
            yield
        except ValueError as err:
            if "already exists" in str(err):
                raise ConfigError(
                    f"a Minari dataset {name} already exists under {where}: give another "
                    "--name (or version) or delete it (minari.delete_dataset)"
                ) from None
            shutil.rmtree(where / name, ignore_errors=True)  # never half a dataset
            raise
        except BaseException:
            shutil.rmtree(where / name, ignore_errors=True)
            raise


def export_minari(cfg: MinariConfig) -> int:
    """``collect export minari``: write the dataset and say how to open it."""
    made_by = credits(cfg.author, cfg.author_email, cfg.code_permalink)
    s = export_dataset(cfg.dataset, cfg.name, cfg.root, made_by)
    unset = made_by.unset()
    print(
        f"wrote Minari dataset {s.name} under {s.root}: {s.episodes} episodes, {s.steps} "
        f"steps, env {s.env_id}; author {', '.join(made_by.author) or 'not set'}"
        + (f" (not set: {', '.join(unset)})" if unset else "")
        + f"\nopen it: MINARI_DATASETS_PATH={s.root} python -c "
        f"\"import minari; print(minari.load_dataset('{s.name}'))\""
    )
    return 0
