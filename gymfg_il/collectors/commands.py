"""The bodies of ``collect recover`` and ``collect replay`` (``gymfg_il.collect`` parses)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from gymfg_il.datasets.from_logs import BuildReport


def report_build(report: BuildReport, root: Path) -> None:
    r = report
    note = ", rebuilt from the logs" if r.rebuilt else ""
    print(
        f"dataset {root}: {r.total_episodes} episodes (+{r.added}, {r.frames} frames in "
        f"{r.seconds:.2f} s{note})"
    )
    if r.skipped_incomplete:
        print(
            f"left out {r.skipped_incomplete} unfinished episode(s) (the session stopped "
            "mid-episode)"
        )


def replay(target: Path, episode: int | None, views: list[int] | None = None) -> int:
    from gymfg_il.collectors.autopilot import LOGS
    from gymfg_il.errors import ConfigError
    from gymfg_il.recording.reader import read_log
    from gymfg_il.recording.replay import env_from_session, replay_episode

    paths = sorted((target / LOGS).glob("*.mcap")) if target.is_dir() else [target]
    if not paths:
        raise ConfigError(f"no logs under {target}")
    failures = 0
    for path in paths:
        log = read_log(path)
        chosen = [e for e in log.complete_episodes if episode is None or e.index == episode]
        if episode is not None and not chosen:
            raise ConfigError(f"{path.name} has no completed episode {episode}")
        for ep in chosen:
            for callsign in sorted(ep.steps):
                env = env_from_session(log.session, views) if views else None
                r = replay_episode(log, ep, callsign, env=env)
                if env is not None:
                    env.close()
                verdict = (
                    "identical"
                    if r.identical
                    else (f"DIFFERS from step {r.first_mismatch} (max |diff| {r.max_abs_diff:.3g})")
                )
                print(f"{path.name} episode {ep.index} {callsign}: {r.steps} steps, {verdict}")
                failures += not r.identical
    return 1 if failures else 0


def recover(folder: Path) -> int:
    from gymfg_il.collectors.autopilot import DATASET, LOGS
    from gymfg_il.datasets.from_logs import build_from_logs
    from gymfg_il.errors import ConfigError

    logs = sorted((folder / LOGS).glob("*.mcap")) if folder.is_dir() else []
    if not logs:
        raise ConfigError(
            f"{folder} holds no {LOGS}/*.mcap: nothing to recover from (is it a "
            "collection session folder?)"
        )
    report = build_from_logs(logs, folder / DATASET)
    report_build(report, folder / DATASET)
    return 0
