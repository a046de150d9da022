"""Which episodes of a dataset train, and how much each weighs: by their records (``train bc
--select``, ``--weight grade``), and each episode once however often the dataset holds it.

The records (the ``gymfg/*`` columns) come from files: a value of the wrong kind is one
``ConfigError`` naming the episode and the way back to the truth (``collect recover``
rebuilds them from the logs), never a traceback or a silent choice.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gymfg_il.datasets.verify import digest
from gymfg_il.errors import ConfigError
from gymfg_il.learning.config import GRADE_WEIGHTS
from gymfg_il.learning.frames import episode_runs
from gymfg_il.tasks.grades import rank

if TYPE_CHECKING:
    from gymfg_il.learning.frames import Frames

log = logging.getLogger(__name__)

REBUILD = (
    "build it afresh from its logs (python -m gymfg_il.collect recover FOLDER, which sets a "
    "dataset whose records differ from its logs aside)"
)


def _verdicts(ids: list[Any], values: list[Any], where: Path | str) -> list[int]:
    """The ``gymfg/success`` values (1, 0, -1 for not judged); ConfigError naming the
    episodes whose value is anything else."""
    bad = [(i, v) for i, v in zip(ids, values, strict=True) if not _verdict(v)]
    if bad:
        shown = ", ".join(f"episode {i}: {v!r}"[:80] for i, v in bad[:5])
        raise ConfigError(
            f"{where}: gymfg/success must be 1, 0 or -1 (not judged), but {len(bad)} "
            f"episode(s) hold something else ({shown}): {REBUILD}"
        )
    return [int(v) for v in values]


def _verdict(value: Any) -> bool:
    return type(value) is int and value in (-1, 0, 1)


def selected(frames: Frames, terms: list[str], where: Path | str) -> Frames:
    """The episodes of ``frames`` that meet every ``terms`` (``TrainConfig.select``)."""
    if not terms:
        return frames
    eps = frames.episodes
    ids = eps.get("episode_index", list(range(len(eps.get("gymfg/seed", [])))))
    keep = np.ones(len(ids), dtype=bool)
    for term in terms:
        key, _, value = term.partition("=")
        column = "success" if key in ("success", "failure") else key
        values = eps.get(f"gymfg/{column}")
        if values is None or len(values) != len(ids):
            raise ConfigError(
                f"{where} records no gymfg/{column} per episode (built before it was "
                f"stored), so --select {term} cannot choose: {REBUILD}, or drop --select"
            )
        if key in ("success", "failure"):
            wanted = int(key == "success")
            keep &= np.array([v == wanted for v in _verdicts(ids, values, where)])
        elif key == "grade":  # that grade or a better one
            keep &= np.array([0 <= rank(v) <= rank(value) for v in values])
        else:
            keep &= np.array([str(v) == value for v in values])
    if not keep.any():
        raise ConfigError(f"--select {' '.join(terms)}: no episode of {where} meets it")
    return frames.select(np.asarray(ids)[keep])


def grade_weights(frames: Frames, where: Path | str) -> np.ndarray:
    """Each frame's sampling weight from its episode's grade (``TrainConfig.weight``)."""
    eps = frames.episodes
    grades = eps.get("gymfg/grade")
    ids = eps.get("episode_index", list(range(len(grades or []))))
    if grades is None or len(grades) != len(ids) or min(map(rank, grades), default=-1) < 0:
        raise ConfigError(
            f"{where}: not every episode records a grade (gymfg/grade; a dataset built before "
            f"grades were stored, or of a source nobody graded), so --weight grade cannot "
            f"weigh them: {REBUILD}, or drop --weight"
        )
    by_episode = {int(i): GRADE_WEIGHTS[str(g)] for i, g in zip(ids, grades, strict=True)}
    return np.array([by_episode[int(e)] for e in frames.episode], dtype=np.float64)


def once_each(frames: Frames, where: Path | str) -> Frames:
    """``frames`` with each episode once: an episode whose frames repeat an earlier one's (a
    dataset merged with itself, a log taken twice) is left out, with a warning that says
    which."""
    first, end = episode_runs(frames.episode)
    starts = np.unique(first)
    seen: dict[str, int] = {}
    repeats: list[tuple[int, int]] = []
    for s in starts:
        rows = slice(int(s), int(end[s]))
        e = int(frames.episode[s])
        twin = seen.setdefault(digest(frames.obs[rows], frames.action[rows]), e)
        if twin != e:
            repeats.append((e, twin))
    if not repeats:
        return frames
    said = ", ".join(f"{e} (= {twin})" for e, twin in repeats[:10])
    more = f" and {len(repeats) - 10} more" if len(repeats) > 10 else ""
    log.warning(
        "%s holds %d episode(s) twice, frame for frame (a dataset merged with itself?): "
        "episodes %s%s are left out, so each is trained on once",
        where,
        len(repeats),
        said,
        more,
    )
    kept = np.setdiff1d(frames.episode[starts], [e for e, _ in repeats])
    return frames.select(kept)
