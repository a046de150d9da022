"""The bodies of ``collect recover``, ``repair``, ``replay`` and ``reindex``
(``gymfg_il.collect`` parses)."""

from __future__ import annotations

import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from gymfg_il.collectors.session import DATASET, LOGS
from gymfg_il.datasets.episode_logs import EpisodeRef, base_refs, dataset_refs, unrebuildable
from gymfg_il.datasets.from_logs import BuildReport, build_from_logs
from gymfg_il.datasets.gather import read_logs, set_aside
from gymfg_il.datasets.health import check_files
from gymfg_il.errors import ConfigError
from gymfg_il.names import check_name
from gymfg_il.recording.reader import EmptyLog, Log, read_log
from gymfg_il.recording.replay import replay_episode, world_for


@dataclass
class RecoverConfig:
    """Rebuild a session's dataset from its logs (after a crash or kill: keeps every
    completed episode). The logs are the truth: a dataset that differs from them is kept
    beside as dataset.broken-<time> and rebuilt; a file under logs/ that is no readable log
    is renamed <name>.set-aside. Every episode the dataset holds, or held, that no log under
    logs/ can rebuild (its log deleted, or a DAgger session's base episodes without their
    linked logs) is named, and the exit status is 1.

    Attributes:
        dir: the session folder (logs/ inside).
        callsign: only this aircraft's episodes (repeatable; default: every aircraft, all of
            one observation layout).
    """

    dir: Path = field(metadata={"positional": True})
    callsign: list[str] = field(default_factory=list, metadata={"repeat": True})

    def __post_init__(self) -> None:
        for callsign in self.callsign:
            check_name(callsign, "callsign")


@dataclass
class RepairConfig:
    """Write back the GymFG episode metadata (the gymfg/* columns: aircraft, task, seed,
    source, flight spec, ...) that LeRobot's own editing (lerobot-edit-dataset delete_episodes,
    split, merge, remove_feature) drops: each episode's is taken from the dataset it came
    from, found by its frames. The dataset card (README.md) is written again from them; a
    dataset whose episodes kept their columns (a merge) gets its card written when it has
    none or an outdated one.

    Attributes:
        dir: the edited dataset (meta/ inside), or a session folder (dataset/ inside).
        source: a dataset (or session folder) the edited one was made from; repeatable (a
            merge has several).
    """

    dir: Path = field(metadata={"positional": True})
    source: list[Path] = field(default_factory=list, metadata={"repeat": True})


@dataclass
class ReplayConfig:
    """Re-fly logged episodes through JSBSim from their seeds and actions, and check every
    state of every aircraft matches the log bit for bit.

    Attributes:
        log: an .mcap log, or a session folder (all its logs).
        episode: only this episode (default: all completed).
        view: also show the replay in FlightGear listening on this UDP port (repeatable;
            real time; see gymfg_il.flightgear.launcher).
    """

    log: Path = field(metadata={"positional": True})
    episode: int | None = None
    view: list[int] = field(default_factory=list, metadata={"repeat": True})

    def __post_init__(self) -> None:
        bad = [p for p in self.view if not 0 < p < 65536]
        if bad:
            raise ConfigError(f"--view {bad[0]}: a UDP port is 1..65535")


@dataclass
class ReindexConfig:
    """Give older logs the message indexes Foxglove's reader needs, in place and crash-safely
    (a verified copy replaces each file atomically); logs that have them are left untouched,
    damaged or unfinished ones are refused and left as they were.

    Attributes:
        logs: .mcap logs or folders (every .mcap under them).
    """

    logs: list[Path] = field(metadata={"positional": True})


def report_build(report: BuildReport, root: Path, moved: dict[Path, Path] | None = None) -> None:
    """Print what a build did: the dataset, why an old one was set aside, what each log
    gave and what it left out (``moved``: logs set aside, to where)."""
    r = report
    note = ", rebuilt from the logs" if r.rebuilt else ""
    print(
        f"dataset {root}: {r.total_episodes} episodes (+{r.added}, {r.frames} frames in "
        f"{r.seconds:.2f} s{note})"
    )
    if r.differences:
        print(f"the old dataset was set aside as {r.aside} (not deleted) and rebuilt, because:")
        for line in r.differences[:20]:
            print(f"  {line}")
        if len(r.differences) > 20:
            print(f"  ... and {len(r.differences) - 20} more")
    if r.logs:
        print("what each log gave:")
    for outcome in r.logs:
        print(f"  {outcome}")
    if r.skipped_incomplete:
        print(
            f"left out {r.skipped_incomplete} unfinished episode(s) (the session stopped "
            "mid-episode)"
        )
    for name in r.skipped_empty:
        print(f"skipped {name}: a session stopped before writing anything to it")
    if r.damage:
        print("damaged logs: what could not be read is left out:", file=sys.stderr)
        for line in r.damage:
            print(f"  {line}", file=sys.stderr)
    for path, target in (moved or {}).items():
        print(f"set aside {path.name} as {target.name} (not deleted)", file=sys.stderr)


def _say_unfinished(lg: Log) -> None:
    """A log without its footer ends where its writer stopped: a session killed mid-write,
    or a file cut short. Say so, and what of it is left out."""
    if lg.finished:
        return
    cut = [e.index for e in lg.episodes if not e.complete and not e.discarded]
    print(
        f"{lg.path.name}: the file ends before its footer (a session killed mid-write, or "
        f"the file cut short); {len(lg.complete_episodes)} completed episode(s) in it"
        + (f", episode {cut[-1]} incomplete and left out" if cut else ""),
        file=sys.stderr,
    )


def replay(target: Path, episode: int | None, views: Sequence[int] = ()) -> int:
    """Re-fly every completed episode of the log(s) at ``target``; 1 if any differs."""
    paths = sorted((target / LOGS).glob("*.mcap")) if target.is_dir() else [target]
    if not paths:
        raise ConfigError(f"no logs under {target}")
    failures = 0
    logs: list[Log] = []
    if target.is_dir():  # a folder's unreadable files (a FIFO, a link, junk) are named
        logs, empty, unreadable = read_logs(paths)
        for name in empty:
            print(f"skipped {name}: a session stopped before writing anything to it")
        for u in unreadable:
            print(f"could not read {u.path.name}: {u.why}", file=sys.stderr)
        failures += len(unreadable)
    else:
        try:
            logs.append(read_log(target))
        except EmptyLog:
            print(f"skipped {target.name}: a session stopped before writing anything to it")
    for lg in logs:
        for note in lg.damage:
            print(f"{lg.path.name}: could not read {note}", file=sys.stderr)
            failures += 1
        _say_unfinished(lg)
    if not any(lg.complete_episodes for lg in logs):
        raise ConfigError(f"nothing to replay: no log at {target} holds a completed episode")
    if episode is not None and not any(
        e.index == episode for lg in logs for e in lg.complete_episodes
    ):
        raise ConfigError(f"no log under {target} has a completed episode {episode}")
    for log in logs:
        path = log.path
        chosen = [e for e in log.complete_episodes if episode is None or e.index == episode]
        for ep in chosen:
            world = world_for(log, views) if views else None
            try:
                r = replay_episode(log, ep, world=world)
            finally:
                if world is not None:
                    world.close()
                    world.pool.close()
            for callsign, (same, first) in r.per_aircraft.items():
                steps = len(ep.steps[callsign])
                verdict = "identical" if same else f"DIFFERS from step {first}"
                print(f"{path.name} episode {ep.index} {callsign}: {steps} steps, {verdict}")
            if not r.identical:
                print(f"  largest |difference| {r.max_abs_diff:.3g}")
            failures += not r.identical
    return 1 if failures else 0


def _report_matched(report: BuildReport, root: Path) -> None:
    """Say which dataset episodes had lost their records but are logged episodes by their
    frames (a dataset edited with LeRobot's tools), and what recover added back to it."""
    if not report.matched:
        return
    print(
        f"{len(report.matched)} dataset episode(s) record no log (LeRobot's dataset editing "
        "drops the gymfg/* records) but hold the frames of logged episodes, so they are "
        "kept as those episodes; give them their records back with python -m "
        f"gymfg_il.collect repair {root} --source ORIGINAL"
    )
    if report.added:
        print(
            f"the {report.added} logged episode(s) the dataset lacked were added back (recover "
            "keeps every completed episode of the logs; to train without some, use train bc "
            "--select, or mark them when you fly)"
        )


def recover(folder: Path, callsigns: Sequence[str] | None = None) -> int:
    """Rebuild ``folder/dataset`` from ``folder/logs`` (``callsigns``: only these aircraft);
    1 when a log is damaged or an episode the dataset holds (or, of a DAgger session, its
    base dataset held) cannot be rebuilt from the logs: each such episode is named."""
    logs = sorted((folder / LOGS).glob("*.mcap")) if folder.is_dir() else []
    if not logs:
        raise ConfigError(
            f"{folder} holds no {LOGS}/*.mcap: nothing to recover from (is it a "
            "collection session folder?)"
        )
    root = folder / DATASET
    check_files(root)  # a FIFO in a file's place would hang every reader below
    # what the dataset should hold: its episodes as its table lists them (also when LeRobot
    # cannot load it) and a DAgger session's base episodes
    before = dataset_refs(root)
    wanted = {ref: i for i, ref in [*base_refs([folder / LOGS]), *before] if ref is not None}
    unnamed = [i for i, ref in before if ref is None]  # episodes that record no log
    report = build_from_logs(logs, root, callsigns=callsigns or None)
    moved = {u.path: set_aside(u.path) for u in report.unreadable}
    report_build(report, root, moved)
    after = dataset_refs(root)
    held = {ref for _, ref in after}
    lost: list[tuple[int, EpisodeRef | None]] = [
        (i, ref) for ref, i in wanted.items() if ref not in held
    ]
    if report.rebuilt:  # set aside: what it held that no log names is gone
        lost += [(i, None) for i in unnamed]
    # what no log holds: by the record it names, else by its frames (what this build added
    # came from the logs, also where the dataset keeps no records)
    logged = {*report.matched, *range(report.total_episodes - report.added, report.total_episodes)}
    kept = [(i, ref) for i, ref in after if ref not in report.logged and i not in logged]
    _report_matched(report, root)
    named = []
    for title, rows in (
        ("are lost: no log under {logs} holds them", lost),
        ("are kept from the dataset as it was, but no log under {logs} holds them", kept),
    ):
        lines = unrebuildable(sorted(rows, key=lambda r: r[0]), report.logged, folder / LOGS)
        if lines:
            print(
                f"{len(lines)} episode(s) " + title.format(logs=folder / LOGS) + ":",
                file=sys.stderr,
            )
            for line in lines:
                print(f"  {line}", file=sys.stderr)
        named += lines
    bad = bool(report.damage or named)
    return 1 if bad else 0  # the dataset holds all that could be read


def repair(folder: Path, sources: Sequence[Path]) -> int:
    """Restore the ``gymfg/*`` episode columns of the dataset at ``folder`` from ``sources``
    (``datasets.provenance.restore``)."""
    from gymfg_il.datasets import lerobot_api as lr
    from gymfg_il.datasets.card import CARD, card_text, write_card
    from gymfg_il.datasets.provenance import metadata_columns, restore

    def dataset(path: Path) -> Path:
        root = path / DATASET if (path / DATASET / "meta").is_dir() else path
        if not (root / "meta" / "info.json").is_file():
            raise ConfigError(f"no LeRobot dataset at {path} (no meta/info.json)")
        return root

    root = dataset(folder)
    meta = lr.open_metadata(root)
    if metadata_columns(meta):  # a merge keeps them, but writes no card
        card = root / CARD
        old = card.read_text(encoding="utf-8") if card.is_file() else None
        state = f"dataset {root}: its episodes have their gymfg/* columns"
        if old == card_text(root, str(meta.repo_id), meta=meta):
            print(f"{state} and its card is current; nothing to repair")
            return 0
        write_card(root, str(meta.repo_id), meta=meta)
        print(
            f"{state}; wrote its card {card} ({'none' if old is None else 'an outdated one'} "
            "was there)"
        )
        return 0
    if not sources:
        raise ConfigError(
            f"the episodes of {root} have lost their gymfg/* columns (LeRobot's dataset "
            "editing drops them): give the dataset it was made from, --source ORIGINAL"
        )
    restored = restore(root, meta, [dataset(s) for s in sources])
    write_card(root, str(meta.repo_id))  # the card reads them: tasks, sources, noise
    print(f"dataset {root}: restored the gymfg/* columns of {restored} episodes")
    return 0


def reindex(targets: Sequence[Path]) -> int:
    """Re-index every log at ``targets`` (files or folders); 1 if any was refused."""
    from gymfg_il.recording.indexes import reindex as reindex_log
    from gymfg_il.recording.reader import LogError

    paths = []
    for target in targets:
        if target.is_dir():
            paths += sorted(target.rglob("*.mcap"))
        elif target.is_file():
            paths.append(target)
        else:
            raise ConfigError(f"{target}: no such log or folder")
    if not paths:
        raise ConfigError(f"no .mcap logs under {', '.join(map(str, targets))}")
    refused = 0
    for path in paths:
        try:
            r = reindex_log(path)
        except LogError as err:
            print(f"refused {path}: {err}", file=sys.stderr)
            refused += 1
            continue
        if r.changed:
            print(
                f"reindexed {path}: {r.messages} messages ({'; '.join(r.problems)} before); "
                f"{r.size_before:,} -> {r.size_after:,} bytes"
            )
        else:
            print(f"{path}: already has message indexes; left untouched")
    return 1 if refused else 0
