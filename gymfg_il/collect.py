"""``python -m gymfg_il.collect``: record demonstrations as MCAP logs and LeRobot datasets.

    python -m gymfg_il.collect autopilot --aircraft c172p --task altitude --episodes 20 --out DIR
    python -m gymfg_il.collect collectors/sample.toml        # a recipe
    python -m gymfg_il.collect recover DIR                   # rebuild DIR/dataset from DIR/logs
    python -m gymfg_il.collect repair EDITED --source ORIGINAL   # after lerobot-edit-dataset
    python -m gymfg_il.collect replay DIR                    # re-fly logged episodes, compare
    python -m gymfg_il.collect reindex DIR                   # older logs: add message indexes
    python -m gymfg_il.collect dagger --policy P --out DIR   # DAgger with the controller
    python -m gymfg_il.collect manual --device keyboard --out DIR   # a person flies
    python -m gymfg_il.collect web --out DIR --pilots 8      # people fly from their browsers
    python -m gymfg_il.collect export acmi LOG --out FLIGHT.acmi      # for Tacview
    python -m gymfg_il.collect export minari DIR --name gymfg/roll-v0 --root MINARI_DIR

A session folder holds ``logs/`` (one MCAP log per session: every step, the write-ahead log)
and ``dataset/`` (LeRobot v3.0). Collecting into an existing folder appends.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gymfg_il.collectors.config import MANUAL_HZ

if TYPE_CHECKING:
    from gymfg_il.collectors.config import ManualConfig

EPILOG = __doc__.split("\n\n", 1)[1]
# a person's session: at the manual rate, until they quit, into a folder of its own
# flight options that only a manual session takes from the command line
MANUAL_ONLY = ("gusts",)
MANUAL_DEFAULTS = {"agent_hz": MANUAL_HZ, "episodes": 0, "out": Path("datasets/manual")}


def _workers(text: str) -> int:
    n = int(text)
    if n < 1:
        raise argparse.ArgumentTypeError(f"{n} worker processes: give 1 or more")
    return n


def _running(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--workers",
        type=_workers,
        default=1,
        help="worker processes flying episodes; the log and dataset are identical to one "
        "worker's (default: 1)",
    )
    p.add_argument(
        "--ray",
        metavar="ADDRESS",
        default=None,
        help="fly the episodes as tasks on a Ray cluster: auto (the one this machine is in), "
        "local (start one in this process) or HOST:PORT; the log and dataset are written "
        "here and are identical to one worker's (pip install -e '.[ray]')",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def _recipe_parser() -> argparse.ArgumentParser:
    """``collect RECIPE.toml [options]``: the recipe's options, each overriding the file."""
    from gymfg_il import cli
    from gymfg_il.collectors.config import ManualConfig

    r = cli.parser(
        "python -m gymfg_il.collect RECIPE.toml",
        "Run a collection recipe (collectors/*.toml); options override the recipe.",
    )
    r.add_argument("recipe", type=Path)
    cli.add_fields(r, ManualConfig, overrides_only=True)
    cli.add_fields(r, ManualConfig, only=MANUAL_ONLY, overrides_only=True)
    r.add_argument(
        "--fps", dest="agent_hz", type=int, default=cli.SUPPRESS, help="the same as --agent-hz"
    )
    _running(r)
    return r


def _flying(sub: Any) -> None:
    """The subcommands that fly: autopilot, manual, dagger."""
    import textwrap

    from gymfg_il import cli
    from gymfg_il.cockpit.inputs.keys import keys_help
    from gymfg_il.collectors.config import CollectConfig, ManualConfig
    from gymfg_il.envs.options import TASK_OWN_TIME, unset_values
    from gymfg_il.learning.dagger import DaggerConfig

    # a flight option left out is the flight's default, shown as such
    unset, shown = unset_values(), {"episode_time_s": TASK_OWN_TIME}
    auto = sub.add_parser("autopilot", help="the task's PID controller flies seeded episodes")
    cli.add_fields(auto, CollectConfig, defaults=unset, shown=shown)
    _running(auto)
    manual = sub.add_parser(
        "manual",
        help="a person flies (keyboard, mouse, joystick or FlightGear's cockpit) in a pygame "
        "window; every completed episode is saved at once",
        description=textwrap.fill(
            "A person flies in real time; Space starts an episode, E saves it, Backspace "
            "discards it, T takes over from --assist, Q quits. Every key is listed below.",
            79,
        ),
        epilog=keys_help(),  # built from the bindings, as the manual guide's table
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    cli.add_fields(
        manual,
        ManualConfig,
        defaults={**unset, **MANUAL_DEFAULTS},
        shown=shown,
        flags={"agent_hz": "--fps"},
    )
    cli.add_fields(manual, ManualConfig, only=MANUAL_ONLY, shown={"gusts": "none"})
    manual.add_argument(
        "--no-progress", action="store_true", help="no progress bar (--pilot synthetic)"
    )
    _web_parser(sub, unset, shown)
    dagger = sub.add_parser(
        "dagger",
        help="the policy flies, the controller labels what it visits, the data is aggregated "
        "and the policy retrained",
    )
    cli.add_fields(dagger, DaggerConfig)


def _web_parser(sub: Any, unset: dict[str, Any], shown: dict[str, str]) -> None:
    """``collect web``: the flight's options as ``collect manual``'s, and the server's."""
    import textwrap

    from gymfg_il import cli
    from gymfg_il.cockpit.inputs.keys import keys_help
    from gymfg_il.web.config import WebConfig

    web = sub.add_parser(
        "web",
        help="people fly from their browsers; every saved episode goes to one dataset",
        description=textwrap.fill(
            "Serve a web cockpit: each pilot opens their invite link and flies in a browser "
            "(keyboard, mouse stick or gamepad) an aircraft simulated here in real time; every "
            "saved episode goes to one dataset, OUT/dataset. Ctrl-C stops it. The keys are "
            "collect manual's (below). Guide: docs/guides/web.md.",
            79,
        ),
        epilog=keys_help(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    cli.add_fields(
        web,
        WebConfig,
        defaults={**unset, "agent_hz": MANUAL_HZ},
        shown=shown,
        flags={"agent_hz": "--fps"},
    )
    cli.add_fields(web, WebConfig, only=MANUAL_ONLY, shown={"gusts": "none"})


def _tools(sub: Any) -> None:
    """The subcommands that work on a session's files: recover, repair, replay, reindex."""
    from gymfg_il import cli
    from gymfg_il.collectors.commands import (
        RecoverConfig,
        ReindexConfig,
        RepairConfig,
        ReplayConfig,
    )

    for name, config in (
        ("recover", RecoverConfig),
        ("repair", RepairConfig),
        ("replay", ReplayConfig),
        ("reindex", ReindexConfig),
    ):
        cli.add_fields(sub.add_parser(name, help=cli.summary(config)), config)


def parse_args(argv: list[str]) -> argparse.Namespace:
    from gymfg_il import cli

    if argv and argv[0].endswith(".toml"):
        r = _recipe_parser()
        args = r.parse_args(argv)
        args.command = "recipe"
        return args
    p = cli.parser(
        "python -m gymfg_il.collect",
        "Record demonstrations: every step to an MCAP log, every completed episode to a "
        "LeRobot dataset.",
        EPILOG,
    )
    sub = p.add_subparsers(
        dest="command",
        metavar="{autopilot,manual,web,dagger,recover,repair,replay,reindex,export,RECIPE.toml}",
    )
    _flying(sub)
    _tools(sub)
    _exports(sub)
    args = p.parse_args(argv)
    if args.command is None:
        p.print_help()
        p.exit(2)
    return args


def _exports(sub: argparse._SubParsersAction) -> None:
    from gymfg_il import cli
    from gymfg_il.export.acmi import AcmiConfig
    from gymfg_il.export.minari import MinariConfig

    what = "a log or dataset in another tool's format: Tacview (acmi), Minari (minari)"
    export = sub.add_parser("export", help=what, description=what[0].upper() + what[1:] + ".")
    formats = export.add_subparsers(dest="format", metavar="{acmi,minari}", required=True)
    cli.add_fields(formats.add_parser("acmi", help=cli.summary(AcmiConfig)), AcmiConfig)
    cli.add_fields(formats.add_parser("minari", help=cli.summary(MinariConfig)), MinariConfig)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(list(sys.argv[1:] if argv is None else argv))
    from gymfg_il import cli
    from gymfg_il.datasets.lerobot_api import hub_offline

    hub_offline()
    return cli.run(lambda: COMMANDS[args.command](args))


def _autopilot(args: argparse.Namespace) -> int:
    from gymfg_il import cli
    from gymfg_il.collectors.autopilot import collect_autopilot
    from gymfg_il.collectors.commands import report_build
    from gymfg_il.collectors.config import CollectConfig, ManualConfig
    from gymfg_il.errors import ConfigError

    if args.command == "recipe":
        known = {f.name for f in dataclasses.fields(ManualConfig)}
        options = {k: v for k, v in vars(args).items() if k in known}
        cfg = CollectConfig.from_recipe(args.recipe, **options)
        if isinstance(cfg, ManualConfig):
            if args.workers != 1 or args.ray:  # (its --noise is the synthetic pilot's)
                raise ConfigError("--workers and --ray apply to autopilot recipes, not manual")
            return _fly_by_hand(cfg, not args.no_progress)
    else:
        cfg = cli.build(CollectConfig, args)
    show = not args.no_progress

    def progress(total: int) -> Callable[[int, float], None]:
        bar = cli.progress_bar(total, "episodes", "ep", show)

        def tick(i: int, ret: float) -> None:
            bar.update(1)
            bar.set_postfix(ret=f"{ret:.1f}")
            if not show:  # a line per durable episode, for logs and supervising scripts
                print(f"episode {i} saved (return {ret:.1f})", flush=True)
            if bar.n == total:
                bar.close()

        return tick

    result, report = collect_autopilot(cfg, args.workers, progress, ray=args.ray)
    if result.log is None:
        print(f"nothing to fly: the dataset at {cfg.out / 'dataset'} holds these episodes")
    else:
        print(f"logged {len(result.episodes)} episodes ({result.steps} steps) to {result.log}")
    if report is not None:
        report_build(report, cfg.out / "dataset")
        return 1 if report.damage else 0
    return 0


def _manual(args: argparse.Namespace) -> int:
    from gymfg_il import cli
    from gymfg_il.collectors.config import ManualConfig

    return _fly_by_hand(cli.build(ManualConfig, args), not args.no_progress)


def _fly_by_hand(cfg: ManualConfig, show_progress: bool = True) -> int:
    import os

    from gymfg_il import cli
    from gymfg_il.cockpit.session import ManualSession

    if cfg.pilot == "person":
        session = ManualSession(cfg)
        print(  # say in the terminal too what the session waits for
            "the window is open: Space in it starts an episode, E saves it, Backspace "
            "discards it, Q quits (H: help)",
            flush=True,
        )
        stats = session.run()
    else:  # the synthetic pilot: headless, as fast as the machine allows
        os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
        bar = cli.progress_bar(cfg.episodes, "episodes", "ep", show_progress)

        def progress(frame: int, session: ManualSession) -> None:
            bar.update(session.stats.saved - bar.n)

        session = ManualSession(cfg, progress)
        try:
            stats = session.run()
        finally:
            bar.update(session.stats.saved - bar.n)
            bar.close()
    print(
        f"saved {stats.saved} episode(s), discarded {stats.discarded}; dataset: "
        f"{stats.dataset or 'none yet'}"
    )
    return 0


def _web(args: argparse.Namespace) -> int:
    from gymfg_il import cli
    from gymfg_il.web.config import WebConfig
    from gymfg_il.web.server import WebServer

    return WebServer(cli.build(WebConfig, args)).run()


def _dagger(args: argparse.Namespace) -> int:
    from gymfg_il import cli
    from gymfg_il.learning.dagger import DaggerConfig, DaggerIteration

    def report(step: DaggerIteration) -> None:
        print(
            f"iteration {step.iteration}: policy return {step.policy_return:.1f} over "
            f"{step.episodes} episodes; dataset {step.dataset_episodes} episodes; retrained "
            f"-> {step.policy} ({step.validation})",
            flush=True,
        )

    history = cli.build(DaggerConfig, args).run(report)
    print(
        f"final policy: {history[-1].policy} (evaluate it: python -m gymfg_il.eval "
        f"--policy {history[-1].policy})"
    )
    return 0


def _recover(args: argparse.Namespace) -> int:
    from gymfg_il import cli
    from gymfg_il.collectors.commands import RecoverConfig, recover

    cfg = cli.build(RecoverConfig, args)
    return recover(cfg.dir, cfg.callsign)


def _repair(args: argparse.Namespace) -> int:
    from gymfg_il import cli
    from gymfg_il.collectors.commands import RepairConfig, repair

    cfg = cli.build(RepairConfig, args)
    return repair(cfg.dir, cfg.source)


def _replay(args: argparse.Namespace) -> int:
    from gymfg_il import cli
    from gymfg_il.collectors.commands import ReplayConfig, replay

    cfg = cli.build(ReplayConfig, args)
    return replay(cfg.log, cfg.episode, cfg.view)


def _reindex(args: argparse.Namespace) -> int:
    from gymfg_il import cli
    from gymfg_il.collectors.commands import ReindexConfig, reindex

    return reindex(cli.build(ReindexConfig, args).logs)


def _export(args: argparse.Namespace) -> int:
    from gymfg_il import cli

    if args.format == "acmi":
        from gymfg_il.export.acmi import AcmiConfig, export_acmi

        return export_acmi(cli.build(AcmiConfig, args))
    from gymfg_il.export.minari import MinariConfig, export_minari

    return export_minari(cli.build(MinariConfig, args))


COMMANDS: dict[str, Callable[[argparse.Namespace], int]] = {
    "autopilot": _autopilot,
    "recipe": _autopilot,
    "manual": _manual,
    "web": _web,
    "dagger": _dagger,
    "recover": _recover,
    "repair": _repair,
    "replay": _replay,
    "reindex": _reindex,
    "export": _export,
}

if __name__ == "__main__":
    raise SystemExit(main())
