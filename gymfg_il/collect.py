"""``python -m gymfg_il.collect``: record demonstrations as MCAP logs and LeRobot datasets.

    python -m gymfg_il.collect autopilot --aircraft c172p --task altitude --episodes 20 --out DIR
    python -m gymfg_il.collect collectors/sample.toml        # a recipe
    python -m gymfg_il.collect recover DIR                   # rebuild DIR/dataset from DIR/logs
    python -m gymfg_il.collect replay DIR                    # re-fly logged episodes, compare
    python -m gymfg_il.collect dagger --policy P --out DIR   # DAgger with the controller
    python -m gymfg_il.collect manual --device keyboard --out DIR   # a person flies

A session folder holds ``logs/`` (one MCAP log per session: every step, the write-ahead log)
and ``dataset/`` (LeRobot v3.0). Collecting into an existing folder appends.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

EPILOG = __doc__.split("\n\n", 1)[1]


def _autopilot_args(p: argparse.ArgumentParser, recipe: bool) -> None:
    d = None if recipe else argparse.SUPPRESS
    p.add_argument("--aircraft", default=d, help="JSBSim model (default: c172p)")
    p.add_argument(
        "--task",
        default=d,
        help="task family: altitude, roll, pitch, heading, airspeed, level (default: altitude)",
    )
    p.add_argument(
        "--dynamic",
        action="store_const",
        const=True,
        default=d,
        help="moving targets instead of fixed ones",
    )
    p.add_argument("--episodes", type=int, default=d, help="episodes to record (default: 10)")
    p.add_argument(
        "--episode-time",
        dest="episode_time_s",
        type=float,
        default=d,
        help="seconds per episode (default: 90)",
    )
    p.add_argument(
        "--agent-hz",
        type=int,
        default=d,
        help="agent rate = dataset fps, a divisor of 120 (default: 10)",
    )
    p.add_argument("--seed", type=int, default=d, help="seed of the first episode (default: 0)")
    p.add_argument(
        "--noise",
        type=float,
        default=d,
        help="DART noise: std of Gaussian noise on the executed surfaces; the "
        "dataset keeps the clean label (default: 0)",
    )
    p.add_argument(
        "--out", type=Path, default=d, help="session folder (default: datasets/autopilot)"
    )
    p.add_argument(
        "--workers",
        type=_workers,
        default=1,
        help="worker processes flying episodes; the log and dataset are identical "
        "to one worker's (default: 1)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def _workers(text: str) -> int:
    n = int(text)
    if n < 1:
        raise argparse.ArgumentTypeError(f"{n} worker processes: give 1 or more")
    return n


def parse_args(argv: list[str]) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="python -m gymfg_il.collect",
        description="Record demonstrations: every step to an MCAP log, every completed episode "
        "to a LeRobot dataset.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(
        dest="command", metavar="{autopilot,manual,dagger,recover,replay,RECIPE.toml}"
    )
    auto = sub.add_parser("autopilot", help="the task's PID controller flies seeded episodes")
    _autopilot_args(auto, recipe=False)
    rec = sub.add_parser(
        "recover",
        help="rebuild DIR/dataset from the logs in DIR/logs "
        "(after a crash or kill: keeps every completed episode)",
    )
    rec.add_argument("dir", type=Path, help="session folder")
    man = sub.add_parser(
        "manual",
        help="a person flies (keyboard, mouse or joystick) in a "
        "pygame window; every completed episode is saved at once",
    )
    man.add_argument(
        "--device",
        default="keyboard",
        choices=["keyboard", "mouse", "joystick"],
        help="input device (default: keyboard)",
    )
    man.add_argument("--aircraft", default="c172p", help="JSBSim model (default: c172p)")
    man.add_argument("--task", default="altitude", help="task family (default: altitude)")
    man.add_argument("--dynamic", action="store_true", help="moving targets")
    man.add_argument(
        "--episode-time", type=float, default=90.0, help="seconds per episode (default: 90)"
    )
    man.add_argument(
        "--fps",
        type=int,
        default=30,
        help="real-time loop and dataset rate, a divisor of 120 (default: 30)",
    )
    man.add_argument("--seed", type=int, default=0, help="seed of the first episode")
    man.add_argument(
        "--episodes",
        type=int,
        default=0,
        help="stop after this many saved episodes (default: 0 = until Q)",
    )
    man.add_argument(
        "--assist",
        help="'controller' or a policy folder: it flies until you "
        "take over with T (your frames are flagged as interventions)",
    )
    man.add_argument(
        "--out",
        type=Path,
        default=Path("datasets/manual"),
        help="session folder (default: datasets/manual)",
    )
    man.add_argument(
        "--view",
        type=int,
        action="append",
        default=[],
        metavar="PORT",
        help="FlightGear out-the-window view on this UDP port (repeatable)",
    )
    dag = sub.add_parser(
        "dagger",
        help="the policy flies, the controller labels what it "
        "visits, the data is aggregated and the policy retrained",
    )
    dag.add_argument("--policy", type=Path, required=True, help="checkpoint to start from")
    dag.add_argument(
        "--expert",
        default="controller",
        choices=["controller"],
        help="who labels the visited states (default: the task's controller)",
    )
    dag.add_argument("--iterations", type=int, default=3, help="rounds (default: 3)")
    dag.add_argument("--episodes", type=int, default=10, help="episodes per round (default: 10)")
    dag.add_argument("--seed", type=int, default=2000, help="first seed (default: 2000)")
    dag.add_argument("--epochs", type=int, help="training epochs per round (default: the policy's)")
    dag.add_argument(
        "--out",
        type=Path,
        required=True,
        help="session folder: logs/, dataset/ (the aggregate), policy-<k>/",
    )
    dag.add_argument("--workers", type=_workers, default=1, help="worker processes (default: 1)")
    rep = sub.add_parser(
        "replay",
        help="re-fly logged episodes through JSBSim from their seeds "
        "and actions, and check every state matches the log bit for bit",
    )
    rep.add_argument("log", type=Path, help="an .mcap log, or a session folder (all its logs)")
    rep.add_argument("--episode", type=int, help="only this episode (default: all completed)")
    rep.add_argument(
        "--view",
        type=int,
        action="append",
        default=[],
        metavar="PORT",
        help="also show the replay in FlightGear listening on this UDP port "
        "(real time; see gymfg_il.viz.flightgear)",
    )
    if argv and argv[0].endswith(".toml"):
        r = argparse.ArgumentParser(
            prog="python -m gymfg_il.collect RECIPE.toml",
            description="Run a collection recipe (collectors/*.toml); options override the recipe.",
        )
        r.add_argument("recipe", type=Path)
        _autopilot_args(r, recipe=True)
        args = r.parse_args(argv)
        args.command = "recipe"
        return args
    args = p.parse_args(argv)
    if args.command is None:
        p.print_help()
        p.exit(2)
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(list(sys.argv[1:] if argv is None else argv))
    from gymfg_il.errors import GymFGError

    try:
        if args.command == "recover":
            from gymfg_il.collectors.commands import recover

            return recover(args.dir)
        if args.command == "replay":
            from gymfg_il.collectors.commands import replay

            return replay(args.log, args.episode, args.view)
        if args.command == "dagger":
            return dagger(args)
        if args.command == "manual":
            return manual_from_args(args)
        from gymfg_il.collectors.config import CollectConfig

        options = {
            k: v
            for k, v in vars(args).items()
            if k not in ("command", "recipe", "no_progress", "workers") and v is not None
        }
        if args.command == "recipe":
            from gymfg_il.collectors.config import CollectConfig as _C

            recipe = _C.from_recipe(args.recipe, **options)
            if recipe.kind == "manual":
                return manual(recipe)
        cfg = (
            CollectConfig.from_recipe(args.recipe, **options)
            if args.command == "recipe"
            else CollectConfig(**options)
        )
        return collect(cfg, progress=not args.no_progress, workers=args.workers)
    except GymFGError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2


def collect(cfg: object, progress: bool = True, workers: int = 1) -> int:
    from tqdm import tqdm

    from gymfg_il.collectors.autopilot import DATASET, LOGS, record_autopilot
    from gymfg_il.collectors.commands import report_build
    from gymfg_il.collectors.config import CollectConfig
    from gymfg_il.datasets.from_logs import build_from_logs
    from gymfg_il.parallel import Workers

    assert isinstance(cfg, CollectConfig)
    # the pool starts before the bar's monitor thread, which would rule out a fork start
    with Workers(min(workers, cfg.episodes)) as pool:
        bar = tqdm(
            total=cfg.episodes, desc="episodes", unit="ep", disable=not progress, file=sys.stderr
        )

        def tick(i: int, ret: float) -> None:
            bar.update(1)
            bar.set_postfix(ret=f"{ret:.1f}")
            if not progress:  # a line per durable episode, for logs and supervising scripts
                print(f"episode {i} saved (return {ret:.1f})", flush=True)

        result = record_autopilot(cfg, workers=pool, progress=tick)
        bar.close()
    print(f"logged {len(result.episodes)} episodes ({result.steps} steps) to {result.log}")
    report = build_from_logs(sorted((cfg.out / LOGS).glob("*.mcap")), cfg.out / DATASET)
    report_build(report, cfg.out / DATASET)
    return 0


def manual_from_args(args: argparse.Namespace) -> int:
    from gymfg_il.collectors.config import CollectConfig

    cfg = CollectConfig(
        kind="manual",
        aircraft=args.aircraft,
        task=args.task,
        dynamic=args.dynamic,
        episodes=max(args.episodes, 1),
        episode_time_s=args.episode_time,
        agent_hz=args.fps,
        seed=args.seed,
        out=args.out,
        device=args.device,
        assist=args.assist,
    )
    if args.episodes == 0:
        cfg.episodes = 0
    return manual(cfg, tuple(args.view))


def manual(cfg: object, views: tuple[int, ...] = ()) -> int:
    from gymfg_il.collectors.config import CollectConfig
    from gymfg_il.manual.session import ManualSession
    from gymfg_il.parallel import EnvSpec

    assert isinstance(cfg, CollectConfig)
    spec = EnvSpec(
        cfg.task,
        cfg.aircraft,
        cfg.dynamic,
        cfg.agent_hz,
        cfg.episode_time_s,
        dict(cfg.task_kwargs),
        views,
    )
    session = ManualSession(
        spec,
        cfg.out,
        cfg.device,
        {"keyboard": cfg.keyboard, "mouse": cfg.mouse, "joystick": cfg.joystick},
        cfg.assist,
        cfg.seed,
        cfg.episodes,
    )
    stats = session.run()
    print(
        f"saved {stats.saved} episode(s), discarded {stats.discarded}; dataset: "
        f"{stats.dataset or 'none yet'}"
    )
    return 0


def dagger(args: argparse.Namespace) -> int:
    from gymfg_il.collectors.dagger import DaggerIteration, run_dagger

    def report(step: DaggerIteration) -> None:
        print(
            f"iteration {step.iteration}: policy return {step.policy_return:.1f} over "
            f"{step.episodes} episodes; dataset {step.dataset_episodes} episodes; retrained "
            f"-> {step.policy} (validation loss {step.val_loss:.4f})",
            flush=True,
        )

    overrides = {"epochs": args.epochs} if args.epochs else {}
    history = run_dagger(
        args.policy,
        args.out,
        args.iterations,
        args.episodes,
        args.seed,
        args.workers,
        overrides,
        report,
    )
    print(
        f"final policy: {history[-1].policy} (evaluate it: python -m gymfg_il.eval "
        f"--policy {history[-1].policy})"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
