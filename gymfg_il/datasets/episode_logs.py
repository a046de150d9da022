"""Which log each dataset episode is rebuilt from, and keeping those logs beside the dataset.

Every episode built from a log records the log file, the episode in it and the aircraft
(``gymfg/log``, ``gymfg/log_episode``, ``gymfg/callsign``). A session's dataset is rebuilt
from the logs in the session's ``logs/`` folder (``collect recover``), so each of its
episodes needs its log there. A DAgger session starts from a copy of the policy's dataset:
``link_base_logs`` hard-links (or, across file systems, copies) the logs of those base
episodes into the session's ``logs/`` and writes ``logs/base-episodes.json``, which names
each base episode with the log it came from. A rebuild takes from a linked log only the
episodes listed there (the base dataset may hold fewer than its logs: one aircraft of a team
run, or episodes deleted since), in the base dataset's order, before the session's own.
``unrebuildable`` names the episodes a dataset should hold that its logs cannot give.

A log name read from a dataset or ``base-episodes.json`` becomes a path only through
``log_path``: a plain file name inside the folder (no separator, not ``..``), or refused.
"""

from __future__ import annotations

import filecmp
import json
import logging
import os
import shutil
import stat
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gymfg_il.errors import ConfigError
from gymfg_il.files import JSON_LIMIT, PARQUET_LIMIT, read_regular, regular_problem

BASE_EPISODES = "base-episodes.json"
BASE_FIX = (
    "it names the base episodes of a DAgger session: restore it, or delete it to rebuild "
    "every episode of the linked logs"
)
log = logging.getLogger(__name__)
_NAME_MAX = 255  # a file name's length on common file systems


def log_name_problem(name: object) -> str | None:
    """Why ``name`` (read from a dataset or a record) is not a log's file name, or None."""
    rule = "a log is named by its file name alone, inside the session's logs/ folder"
    if not isinstance(name, str) or not 0 < len(name) <= _NAME_MAX:
        return f"{str(name)[:80]!r} is not a log file name ({rule})"
    if name in (".", "..") or "/" in name or "\\" in name or not name.isprintable():
        return f"{name[:80]!r} is not a log file name ({rule})"
    return None


def log_path(folder: Path, name: str) -> Path:
    """``folder / name`` for a plain file name; ConfigError (naming it) for any other."""
    problem = log_name_problem(name)
    if problem is not None:
        raise ConfigError(problem)
    return Path(folder) / name


@dataclass(frozen=True, order=True)
class EpisodeRef:
    """One aircraft's episode of one log file."""

    log: str
    episode: int
    callsign: str

    def __str__(self) -> str:
        return f"{self.log} episode {self.episode} ({self.callsign})"


def dataset_refs(root: Path) -> list[tuple[int, EpisodeRef | None]]:
    """(dataset episode index, its log episode) of every episode of the dataset at ``root``,
    read straight from ``meta/episodes`` (so also of a dataset LeRobot cannot load); None
    for an episode that records no log. [] when there is no readable episode table."""
    import pyarrow.parquet as pq

    wanted = ["episode_index", "gymfg/log", "gymfg/log_episode", "gymfg/callsign"]
    rows: list[tuple[int, EpisodeRef | None]] = []
    for path in sorted((Path(root) / "meta" / "episodes").rglob("*.parquet")):
        if problem := regular_problem(path, PARQUET_LIMIT):  # a FIFO's open would hang
            log.warning("could not read %s: it %s; its episodes are not checked", path, problem)
            continue
        try:
            names = pq.read_schema(path).names
            table = pq.read_table(path, columns=[c for c in wanted if c in names])
        except Exception:  # a torn file: what it held is unknown
            log.warning("could not read %s; its episodes are not checked", path)
            continue
        columns: dict[str, list[Any]] = {c: table[c].to_pylist() for c in table.column_names}
        for i, index in enumerate(columns.get("episode_index", [])):
            ref = None
            if all(c in columns for c in wanted[1:]):
                ref = EpisodeRef(
                    str(columns["gymfg/log"][i]),
                    int(columns["gymfg/log_episode"][i]),
                    str(columns["gymfg/callsign"][i]),
                )
            rows.append((int(index), ref))
    return sorted(rows, key=lambda r: r[0])


def _link(source: Path, target: Path) -> None:
    """``target`` the same file as ``source``: a hard link, else a copy (atomically)."""
    if target.exists():
        if os.path.samefile(source, target) or filecmp.cmp(source, target, shallow=False):
            return
        raise ConfigError(
            f"{target} exists and differs from {source}, a log of the dataset DAgger starts "
            "from; give DAgger a new --out folder"
        )
    try:
        os.link(source, target)
    except OSError:  # another file system, or links not allowed
        tmp = target.with_name(f".{target.name}.tmp-{os.getpid()}")
        shutil.copy2(source, tmp)
        os.replace(tmp, target)


def link_base_logs(base: Path, logs: Path) -> list[str]:
    """Link the logs of every episode of the dataset at ``base`` (a session's ``dataset/``:
    its logs are in the session's ``logs/``) into ``logs`` and record them in
    ``logs/base-episodes.json``; what could not be linked, one line per episode. A log name
    that is no plain file name (``log_name_problem``) links nothing."""
    source = Path(base).parent / "logs"
    logs.mkdir(parents=True, exist_ok=True)
    problems, episodes = [], []
    for index, ref in dataset_refs(base):
        entry: dict[str, Any] = {"index": index, "log": None}
        bad = None if ref is None else log_name_problem(ref.log)
        if ref is None:
            problems.append(f"base episode {index}: records no log")
        elif bad is not None:
            problems.append(f"base episode {index}: {bad}; not linked")
        elif not _regular(source / ref.log):
            problems.append(f"base episode {index} ({ref}): no log file {source / ref.log}")
            entry |= {"log": ref.log, "log_episode": ref.episode, "callsign": ref.callsign}
        else:
            _link(source / ref.log, logs / ref.log)
            entry |= {
                "log": ref.log,
                "log_episode": ref.episode,
                "callsign": ref.callsign,
                "from": str((source / ref.log).resolve()),
            }
        episodes.append(entry)
    record = {"dataset": str(Path(base).resolve()), "episodes": episodes}
    tmp = logs / f".{BASE_EPISODES}.tmp-{os.getpid()}"
    tmp.write_text(json.dumps(record, indent=1))
    os.replace(tmp, logs / BASE_EPISODES)
    return problems


def _regular(path: Path) -> bool:
    """A regular file itself, not a link to one (a link may lead out of the folder)."""
    try:
        return stat.S_ISREG(path.lstat().st_mode)
    except OSError:
        return False


def base_refs(folders: Iterable[Path]) -> list[tuple[int, EpisodeRef | None]]:
    """The base episodes ``base-episodes.json`` in ``folders`` name, in the base order."""
    out: list[tuple[int, EpisodeRef | None]] = []
    for folder in folders:
        path = Path(folder) / BASE_EPISODES
        try:
            raw = read_regular(path, JSON_LIMIT, BASE_FIX)
        except FileNotFoundError:
            continue
        try:
            record = json.loads(raw)
            for e in record["episodes"]:
                ref = None
                if e.get("log") is not None:
                    log_path(path.parent, e["log"])  # a file name in this folder, or refused
                    ref = EpisodeRef(e["log"], int(e["log_episode"]), e["callsign"])
                out.append((int(e["index"]), ref))
        except (ValueError, KeyError, TypeError) as err:
            raise ConfigError(f"{path} is malformed ({err}); {BASE_FIX}") from None
    return out


def unrebuildable(
    wanted: Iterable[tuple[int, EpisodeRef | None]],
    logged: set[EpisodeRef],
    logs: Path,
) -> list[str]:
    """One line per episode of ``wanted`` (dataset index, log episode) that is not among
    the ``logged`` complete episodes of the logs in ``logs``, saying why."""
    lines = []
    for index, ref in wanted:
        if ref is None:
            lines.append(f"dataset episode {index}: records no log")
        elif log_name_problem(ref.log) is not None:
            lines.append(f"dataset episode {index}: {log_name_problem(ref.log)}")
        elif ref not in logged:
            why = "not a completed episode of it" if (logs / ref.log).is_file() else "log missing"
            lines.append(f"dataset episode {index}: {ref}: {why}")
    return lines
