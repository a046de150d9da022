"""``python -m gymfg_il.serve``: the central state server of online GymFG simulations.

python -m gymfg_il.serve --mode fixed --teams 2 --port 5555 --secret s3cret
python -m gymfg_il.serve --mode open --team red:r3d --team blue:blu3 --curve
"""

from __future__ import annotations

import argparse
import logging
import signal


def _team_secret(text: str) -> tuple[str, str]:
    name, sep, secret = text.partition(":")
    if not (sep and name and secret):
        raise argparse.ArgumentTypeError(f"--team takes NAME:SECRET, got {text!r}")
    return name, secret


def main(argv: list[str] | None = None) -> int:
    from gymfg_il import cli
    from gymfg_il.online.server import ServerConfig

    p = cli.parser("python -m gymfg_il.serve", __doc__)
    cli.add_fields(p, ServerConfig)
    p.add_argument(
        "--team",
        type=_team_secret,
        action="append",
        default=[],
        metavar="NAME:SECRET",
        help="a per-team secret (repeatable); wins over --secret for that team, whose "
        "callsigns are then its own: NAME, or NAME then anything but a letter (NAME-1)",
    )
    p.add_argument(
        "--seconds", type=float, help="stop after this long (default: run until interrupted)"
    )
    args = p.parse_args(argv)
    return cli.run(lambda: _serve(cli.build(ServerConfig, args, secrets=dict(args.team)), args))


def _serve(config: object, args: argparse.Namespace) -> int:
    from gymfg_il.online.server import ServerConfig, StateServer

    assert isinstance(config, ServerConfig)
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(levelname)s %(message)s")
    server = StateServer(config)
    print(f"serving {config.mode} simulation on {server.address}", flush=True)
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
