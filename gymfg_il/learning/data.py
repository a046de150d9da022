"""A LeRobot dataset in memory (``Frames``): opened with LeRobot's own ``LeRobotDataset``,
its columns taken from the Arrow table underneath in one piece each; which flight its
episodes were flown in; and the split into training and validation episodes. The training
samples are gathered from it in ``learning.batches``."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.datasets import lerobot_api as lr
from gymfg_il.datasets.health import check_files, dataset_problems, stats_problems
from gymfg_il.datasets.provenance import metadata_columns
from gymfg_il.datasets.verify import page_problems
from gymfg_il.datasets.videos import decode_camera, image_key
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import ConfigError, MixedTasksError, join_problems
from gymfg_il.learning.data_checks import (
    FEATURES,
    column_problems,
    meta_problems,
    opened,
    rebuild_hint,
)


@dataclass
class Frames:
    """Every frame of a dataset: observations, actions, and where each frame sits."""

    obs: np.ndarray  # (N, n_obs) float32
    action: np.ndarray  # (N, 4) float32
    episode: np.ndarray  # (N,) int64
    frame: np.ndarray  # (N,) int64
    observation_names: list[str]
    action_names: list[str]
    fps: int
    obs_stats: dict[str, np.ndarray]
    action_stats: dict[str, np.ndarray]
    episodes: dict[str, list[Any]] = field(default_factory=dict)  # per-episode metadata
    intervention: np.ndarray | None = None  # (N,) bool: a person took over from a policy
    images: np.ndarray | None = None  # (N, H, W, 3) uint8: one camera, when asked for
    camera: str | None = None  # which (``front``, ``chase``)

    def __len__(self) -> int:
        return len(self.action)

    def flight(self) -> tuple[FlightSpec | None, str]:
        """The solo flight every episode was flown as (``flight_of``)."""
        return flight_of(self.episodes)

    def demonstrated(self) -> Frames:
        """The frames a demonstrator flew: every frame of a demonstration, and of an episode a
        policy flew with a person (or the synthetic pilot) watching (source ``policy+...``),
        only the frames they took over (human-gated DAgger learns from the takeovers alone;
        the policy's own frames would teach it what it already does)."""
        sources = self.episodes.get("gymfg/source")
        if self.intervention is None or not sources:
            return self
        ids = self.episodes.get("episode_index", list(range(len(sources))))
        assisted = [i for i, src in zip(ids, sources, strict=True) if src.startswith("policy+")]
        keep = ~np.isin(self.episode, assisted) | self.intervention
        return self if keep.all() else self._take(keep)

    def from_first_input(self) -> Frames:
        """Each episode a person or the synthetic pilot flew (source ``human`` or
        ``synthetic``) from its first input on: the frame whose action first differs from the
        episode's first. The frames before it show hands at rest whatever the state (a person
        reading the briefing, or not yet reacting). An episode never touched is kept whole."""
        sources = self.episodes.get("gymfg/source")
        if not sources or not len(self):
            return self
        ids = self.episodes.get("episode_index", list(range(len(sources))))
        person = [i for i, src in zip(ids, sources, strict=True) if src in ("human", "synthetic")]
        first, end = episode_runs(self.episode)
        moved = np.any(self.action != self.action[first], axis=1)
        count = np.cumsum(moved)
        before = count[first] - moved[first]  # inputs before each frame's episode
        touched = count[end - 1] > before
        keep = (count > before) | ~touched | ~np.isin(self.episode, person)
        return self if keep.all() else self._take(keep)

    def later_actions(self, steps: np.ndarray) -> Frames:
        """Each observation paired with the action taken ``steps`` (one per frame) steps later
        in its episode; the frames with no such action are left out."""
        _, end = episode_runs(self.episode)
        keep = np.arange(len(self)) + steps < end
        out = self._take(keep)
        out.action = self.action[np.flatnonzero(keep) + steps[keep]]
        return out

    def select(self, episodes: np.ndarray) -> Frames:
        return self._take(np.isin(self.episode, episodes))

    def _take(self, keep: np.ndarray) -> Frames:
        return Frames(
            self.obs[keep],
            self.action[keep],
            self.episode[keep],
            self.frame[keep],
            self.observation_names,
            self.action_names,
            self.fps,
            self.obs_stats,
            self.action_stats,
            self.episodes,
            None if self.intervention is None else self.intervention[keep],
            None if self.images is None else self.images[keep],
            self.camera,
        )


def episode_runs(episode: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each frame of frames that run episode by episode: the index of its episode's first
    frame, and one past its last."""
    n = len(episode)
    starts = np.r_[True, episode[1:] != episode[:-1]] if n else np.zeros(0, dtype=bool)
    first = np.maximum.accumulate(np.where(starts, np.arange(n), 0))
    end = np.r_[np.flatnonzero(starts)[1:], n][np.cumsum(starts) - 1]
    return first, end


def flight_of(episodes: dict[str, list[Any]]) -> tuple[FlightSpec | None, str]:
    """The solo flight every episode (``gymfg/*`` columns) was flown as (a team run's
    aircraft on its own; the longest episode time where only that differs), and why there is
    none when the episodes disagree on more or predate flight specs."""
    specs = episodes.get("gymfg/spec")
    if not specs:
        return None, (
            "its episodes record no flight spec (its dataset predates them, or LeRobot's "
            "editing dropped them: `python -m gymfg_il.collect repair DIR --source ORIGINAL`)"
        )
    callsigns = episodes.get("gymfg/callsign") or ["ego"] * len(specs)
    found = {
        FlightSpec.from_json(text).for_callsign(c)
        for text, c in set(zip(specs, callsigns, strict=True))
    }
    longest = max(s.episode_time_s for s in found)
    alike = {s.replace(episode_time_s=longest) for s in found}
    if len(alike) > 1:
        return None, (
            f"its episodes were flown in {len(alike)} different flights (aircraft, task, "
            "options or rate)"
        )
    return alike.pop(), ""


def _observed(spec: str, callsign: str) -> tuple[str, ...] | None:
    """The observation names of ``callsign``'s task in the flight ``spec`` (JSON)."""
    try:
        aircraft = FlightSpec.from_json(spec).for_callsign(callsign).solo_aircraft
        return tuple(aircraft.task_factory()().observation_names)
    except (ConfigError, ValueError, KeyError, TypeError):
        return None  # a spec this version cannot build: its names are unknown


def check_tasks(episodes: dict[str, list[Any]], mixed_tasks: bool = False) -> None:
    """Refuse (``MixedTasksError``, naming the episodes of each task) a dataset whose episodes
    (``gymfg/*`` columns) were flown in different tasks: ``observation.state[k]`` would mean
    one variable in some episodes and another in the rest, or the same inputs would ask for
    different behaviours. ``mixed_tasks`` trains one policy across tasks on purpose, allowed
    only where every task observes the same names (altitude with altitude-dynamic, say).
    Datasets without the columns (older, or edited by LeRobot's tools) are not checked."""
    tasks = episodes.get("gymfg/task")
    if not tasks:
        return
    ids = episodes.get("episode_index") or list(range(len(tasks)))
    specs = episodes.get("gymfg/spec") or [None] * len(tasks)
    callsigns = episodes.get("gymfg/callsign") or ["ego"] * len(tasks)
    cache: dict[tuple[str, str], tuple[str, ...] | None] = {}
    groups: dict[tuple[str, tuple[str, ...] | None], list[int]] = {}
    for index, task, spec, callsign in zip(ids, tasks, specs, callsigns, strict=True):
        key = (str(spec), str(callsign))
        if key not in cache:
            cache[key] = _observed(spec, callsign) if spec else None
        groups.setdefault((str(task), cache[key]), []).append(int(index))
    names = {n for _, n in groups if n is not None}
    if len({t for t, _ in groups}) <= 1 and len(names) <= 1:
        return
    if len(names) <= 1 and mixed_tasks:
        return

    def episodes_text(ids: list[int]) -> str:
        shown = ", ".join(str(i) for i in ids[:10])
        return shown + (f", ... ({len(ids)} in all)" if len(ids) > 10 else "")

    lines = []
    for (task, observed), members in sorted(groups.items(), key=lambda g: g[1][0]):
        what = "observation unknown" if observed is None else f"observes {', '.join(observed)}"
        lines.append(f"task {task!r} ({what}): episodes {episodes_text(members)}")
    if len(names) > 1:
        raise MixedTasksError(
            join_problems(
                "the dataset's episodes come from tasks that observe different variables "
                "(the same observation.state column means another variable in each group); "
                "train on one task's episodes: collect or rebuild one dataset per task "
                "(--mixed-tasks cannot help: it needs the same observation names)",
                lines,
            )
        )
    raise MixedTasksError(
        join_problems(
            "the dataset's episodes come from different tasks; pass --mixed-tasks to train "
            "one policy across them on purpose (they observe the same variables), or train "
            "on one task's episodes",
            lines,
        )
    )


def dataset_flight(root: Path) -> tuple[FlightSpec | None, str, dict[str, Any]]:
    """The flight of the dataset at ``root`` (``flight_of``), without loading its frames;
    also its ``fps`` and ``observation_names``."""
    meta = opened(Path(root), lr.open_metadata)
    spec, why = flight_of(metadata_columns(meta))
    found = {
        "fps": int(meta.fps),
        "observation_names": list(meta.features["observation.state"]["names"]),
    }
    return spec, why, found


def _column(table: Any, name: str) -> np.ndarray:
    import pyarrow as pa

    col = table.column(name).combine_chunks()
    if pa.types.is_fixed_size_list(col.type):
        flat = col.flatten().to_numpy(zero_copy_only=False)
        return flat.reshape(len(col), col.type.list_size)
    if pa.types.is_list(col.type) or pa.types.is_large_list(col.type):
        return np.stack(col.to_numpy(zero_copy_only=False))
    return col.to_numpy(zero_copy_only=False)


def load_frames(root: Path, camera: str | None = None) -> Frames:
    """Open the LeRobot dataset at ``root`` and take its frames into memory (``camera``:
    with that view's frames, decoded, ``observation.images.<camera>``)."""
    root = Path(root)
    if not (root / "meta").is_dir() and (root / "dataset" / "meta").is_dir():
        root = root / "dataset"  # a session folder: its dataset is inside
    check_files(root)  # a FIFO or a device in a file's place is named, not read
    if not (root / "meta" / "info.json").is_file():
        session = next((f for f in (root, root.parent) if any(f.glob("logs/*.mcap"))), None)
        raise ConfigError(
            f"no LeRobot dataset at {root} (no meta/info.json); "
            + (
                f"its session's logs are in {session / 'logs'} (a session killed before its "
                f"dataset was written?): build it with python -m gymfg_il.collect recover "
                f"{session}"
                if session is not None
                else "collect one with `python -m gymfg_il.collect autopilot --out DIR` and "
                "pass DIR/dataset"
            )
        )
    problems = meta_problems(root) or dataset_problems(root)
    if problems:
        raise ConfigError(
            join_problems(f"the dataset at {root} is incomplete", problems) + rebuild_hint(root)
        )
    ds = opened(root, lr.open_dataset)
    features = ds.meta.features
    table = ds.hf_dataset.data.table
    stats = ds.meta.stats
    problems = column_problems(table, ds.meta.episodes, features)
    problems += page_problems(root, features)  # damage LeRobot's reader takes as numbers
    problems += stats_problems(stats, {k: list(features[k]["names"]) for k in FEATURES})
    if problems:
        raise ConfigError(
            join_problems(f"the dataset at {root} is damaged", problems) + rebuild_hint(root)
        )
    episodes = metadata_columns(ds.meta)
    if ds.meta.episodes is not None:
        for name in ("episode_index", "length"):
            episodes[name] = list(ds.meta.episodes[name])
        _check_episode_index(table, episodes["episode_index"], root)
    return Frames(
        obs=_column(table, "observation.state").astype(np.float32),
        action=_column(table, "action").astype(np.float32),
        episode=_column(table, "episode_index").astype(np.int64),
        frame=_column(table, "frame_index").astype(np.int64),
        observation_names=list(features["observation.state"]["names"]),
        action_names=list(features["action"]["names"]),
        fps=int(ds.meta.fps),
        obs_stats={k: np.asarray(stats["observation.state"][k]) for k in ("mean", "std")},
        action_stats={k: np.asarray(stats["action"][k]) for k in ("mean", "std")},
        episodes=episodes,
        intervention=(
            _column(table, "intervention").astype(bool).reshape(-1)
            if "intervention" in features
            else None
        ),
        images=None if camera is None else decode_camera(root, image_key(camera), ds.meta),
        camera=camera,
    )


def _check_episode_index(table: Any, listed: list[Any], root: Path) -> None:
    """The episode table lists each episode of the data files once, in order (a rewritten
    ``episode_index`` would attach one episode's record to another's frames)."""
    held = np.unique(_column(table, "episode_index"))
    if [int(i) for i in listed] != list(range(len(listed))) or not np.isin(held, listed).all():
        raise ConfigError(
            f"the dataset at {root} is damaged: meta/episodes lists episode_index "
            f"{[int(i) for i in listed][:8]}..., the data files hold episodes "
            f"{held[:8].tolist()}...; want 0, 1, 2, ... in both" + rebuild_hint(root)
        )


def split_by_episode(
    frames: Frames, val_fraction: float, seed: int
) -> tuple[Frames, Frames | None]:
    """Hold out whole episodes for validation (never frames of a training episode)."""
    if not 0.0 <= val_fraction < 1.0:
        raise ConfigError(f"val_fraction={val_fraction} must lie in [0, 1)")
    ids = np.unique(frames.episode)
    n_val = round(len(ids) * val_fraction)
    if val_fraction > 0 and len(ids) > 1:
        n_val = max(1, min(n_val, len(ids) - 1))
    if n_val == 0:
        return frames, None
    rng = np.random.default_rng(seed)
    val = rng.choice(ids, n_val, replace=False)
    return frames.select(np.setdiff1d(ids, val)), frames.select(val)
