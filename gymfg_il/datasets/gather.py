"""The logs a dataset build reads, what it takes of each, and setting aside what it cannot read.

A build reads every log it is given that is a regular file (not a link, which may lead out
of the folder, nor a FIFO or device, which would block or never end) and an MCAP trajectory
log; the others are ``Unreadable`` and ``collect recover`` renames each to
``<name>.set-aside`` beside it (never deleting it). ``LogOutcome`` is what became of each
read log: the episodes added, those the dataset already held, and those left out and why.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from gymfg_il.datasets.episode_logs import EpisodeRef
from gymfg_il.errors import ConfigError
from gymfg_il.recording.reader import EmptyLog, Log, LogError, read_log

log = logging.getLogger(__name__)
SET_ASIDE = ".set-aside"


@dataclass(frozen=True)
class Unreadable:
    """A log file a build could not read, and why."""

    path: Path
    why: str


@dataclass
class LogOutcome:
    """What a build did with one log (episodes of its own numbering)."""

    name: str
    added: list[EpisodeRef] = field(default_factory=list)
    held: list[EpisodeRef] = field(default_factory=list)  # already in the dataset
    left_out: list[str] = field(default_factory=list)  # "what: why"
    damaged: bool = False  # the log's damage is listed with the other logs'
    seeds: list[int] = field(default_factory=list)  # of the episodes taken

    def __str__(self) -> str:
        took = f"{self.name}: took {len(self.added) + len(self.held)} episode(s)"
        if self.added or self.held:
            seeds = f", seeds {ranges(self.seeds)}" if self.seeds else ""
            took += (
                f" (log episodes {episodes_text(self.added + self.held)}{seeds}; "
                f"{len(self.added)} new)"
            )
        if self.left_out:
            took += f"; left out: {'; '.join(self.left_out)}"
        if self.damaged:
            took += "; damaged: what it lost is listed under 'damaged logs'"
        return took


def episodes_text(refs: Iterable[EpisodeRef]) -> str:
    """Episode numbers as ranges ("0-3, 7"), per aircraft when there are several."""
    by: dict[str, list[int]] = {}
    for ref in refs:
        by.setdefault(ref.callsign, []).append(ref.episode)
    parts = []
    for callsign, numbers in by.items():
        text = ranges(numbers)
        parts.append(text if len(by) == 1 else f"{text} ({callsign})")
    return "; ".join(parts)


def ranges(numbers: Iterable[int]) -> str:
    """Numbers as ranges: "0-3, 7"."""
    runs: list[list[int]] = []
    for k in sorted(set(numbers)):
        if runs and k == runs[-1][-1] + 1:
            runs[-1].append(k)
        else:
            runs.append([k])
    return ", ".join(f"{r[0]}-{r[-1]}" if len(r) > 1 else str(r[0]) for r in runs)


def read_logs(paths: Sequence[Path]) -> tuple[list[Log], list[str], list[Unreadable]]:
    """(the logs read, in name order; the names of logs never written to; the files that
    are no readable log)."""
    logs: list[Log] = []
    empty: list[str] = []
    unreadable: list[Unreadable] = []
    for path in sorted(paths):
        if path.is_symlink():
            unreadable.append(
                Unreadable(
                    path,
                    f"a symbolic link (to {os.readlink(path)}); a build reads the log files "
                    "themselves, never a link that may lead out of the folder",
                )
            )
            continue
        try:
            logs.append(read_log(path))
        except EmptyLog:
            log.warning("skipped %s: a session stopped before writing anything to it", path)
            empty.append(path.name)
        except LogError as err:
            unreadable.append(Unreadable(path, str(err)))
    return logs, empty, unreadable


def no_logs(root: Path, unreadable: Sequence[Unreadable]) -> ConfigError:
    """The error of a build that has no log to read."""
    why = "; ".join(f"{u.path.name}: {u.why}" for u in unreadable)
    return ConfigError(
        f"no readable trajectory log to build {root} from" + (f" ({why})" if why else "")
    )


def set_aside(path: Path) -> Path:
    """Rename ``path`` (a file, link or FIFO; never followed) to ``<name>.set-aside`` beside
    it (``.set-aside-2``, ... when taken); the new path."""
    target = path.with_name(path.name + SET_ASIDE)
    k = 1
    while os.path.lexists(target):
        k += 1
        target = path.with_name(f"{path.name}{SET_ASIDE}-{k}")
    os.rename(path, target)
    return target


def chosen_aircraft(logs: list[Log], callsigns: Sequence[str] | None) -> list[tuple[Log, str]]:
    """(log, callsign) of every aircraft to take, checked to share one layout and rate."""
    chosen = [
        (lg, c) for lg in logs for c in lg.session.get("callsigns", [])
        if callsigns is None or c in callsigns
    ]  # fmt: skip
    if not chosen:
        raise ConfigError(f"the logs hold no aircraft {list(callsigns or [])}")
    first_log, first = chosen[0]
    names = first_log.aircraft(first)["observation_names"]
    fps = first_log.spec.agent_hz
    for lg, c in chosen[1:]:
        if lg.aircraft(c)["observation_names"] != names:
            raise ConfigError(
                f"{c!r} in {lg.path.name} observes other variables than {first!r} in "
                f"{first_log.path.name}; one dataset holds one observation layout: build one "
                "per task (choose the aircraft with callsigns=, `collect recover --callsign`)"
            )
        if lg.spec.agent_hz != fps:
            raise ConfigError(
                f"{lg.path.name} records another rate ({lg.spec.agent_hz} Hz) than "
                f"{first_log.path.name} ({fps} Hz); one dataset holds one fps"
            )
    return chosen
