"""``python -m gymfg_il.serve``: the central state server of online GymFG simulations.

python -m gymfg_il.serve --mode fixed --teams 2 --port 5555 --secret s3cret
python -m gymfg_il.serve --mode open --team red:r3d --team blue:blu3 --curve
"""

from __future__ import annotations

import argparse
import logging
import signal
import sys


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="python -m gymfg_il.serve",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--mode",
        choices=["fixed", "open"],
        default="fixed",
        help="fixed: k teams, starts when all joined, ends when one completes; "
        "open: teams join and leave at step boundaries (default: fixed)",
    )
    p.add_argument("--teams", type=int, default=2, help="k, for --mode fixed (default: 2)")
    p.add_argument(
        "--bind", default="127.0.0.1", help="address to listen on (default: loopback only)"
    )
    p.add_argument("--port", type=int, default=5555, help="TCP port (default: 5555; 0 = any)")
    p.add_argument("--secret", default="", help="shared secret every team must present")
    p.add_argument(
        "--team",
        action="append",
        default=[],
        metavar="NAME:SECRET",
        help="a per-team secret (repeatable); wins over --secret for that team",
    )
    p.add_argument(
        "--timeout",
        type=float,
        default=5.0,
        help="seconds of silence after which a team counts as stalled (default: 5)",
    )
    p.add_argument(
        "--on-stall",
        choices=["drop", "pause", "end"],
        default="drop",
        help="what a stalled team does to the others (default: drop it; it may rejoin)",
    )
    p.add_argument(
        "--view",
        nargs="+",
        help="state variables teams see of each other (default: position and orientation)",
    )
    p.add_argument(
        "--curve",
        action="store_true",
        help="encrypt with ZeroMQ CURVE; prints the public key clients need",
    )
    p.add_argument(
        "--batch-io",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="run ZeroMQ's I/O thread under SCHED_BATCH (Linux), so a tick's replies go out "
        "together instead of the thread preempting the server after each (default: on)",
    )
    p.add_argument(
        "--seconds", type=float, help="stop after this long (default: run until interrupted)"
    )
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    from gymfg_il.errors import GymFGError
    from gymfg_il.online.server import ServerConfig, StateServer

    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(levelname)s %(message)s")
    try:
        secrets = dict(item.split(":", 1) for item in args.team)
    except ValueError:
        print("error: --team takes NAME:SECRET", file=sys.stderr)
        return 2
    try:
        config = ServerConfig(
            mode=args.mode,
            teams=args.teams,
            bind=args.bind,
            port=args.port,
            secrets=secrets,
            shared_secret=args.secret,
            timeout_s=args.timeout,
            on_stall=args.on_stall,
            curve=args.curve,
            batch_io=args.batch_io,
            **({"opponent_view": tuple(args.view)} if args.view else {}),
        )
        server = StateServer(config)
    except GymFGError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    if not (secrets or args.secret):
        logging.warning("no secrets given: any client may join as any team")
    print(f"serving {args.mode} simulation on {server.address}", flush=True)
    if server.public_key is not None:
        print(f"CURVE public key: {server.public_key.decode()}", flush=True)
    signal.signal(signal.SIGTERM, lambda *_: server.stop())
    try:
        server.run(args.seconds)
    except KeyboardInterrupt:
        pass
    finally:
        server.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
