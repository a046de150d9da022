"""``python -m gymfg_il.flightgear.multiplayer listen``: is my FlightGear reaching the agents?"""

from __future__ import annotations

import argparse
import contextlib
import json
import signal
import sys
import threading
import time
from collections.abc import Sequence
from typing import TextIO

from gymfg_il.errors import ConfigError
from gymfg_il.flightgear.peers import MultiplayerConfig, MultiplayerLink

LISTEN_HELP = """Is my FlightGear reaching the agents? Listen for FlightGear multiplayer position
messages on a UDP port and print each aircraft heard, about once a second, as one JSON line:
callsign, model, latitude_deg, longitude_deg, altitude_ft, roll_deg, pitch_deg, heading_deg.

Point FlightGear at it (peer to peer, no server needed; its --multiplay=in port must differ):
  fgfs --callsign=me --multiplay=out,10,127.0.0.1,5002 --multiplay=in,10,127.0.0.1,5003
  python -m gymfg_il.flightgear.multiplayer listen --port 5002 --seconds 30
"""


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m gymfg_il.flightgear.multiplayer listen``: the multiplayer diagnostic."""
    top = argparse.ArgumentParser(
        prog="python -m gymfg_il.flightgear.multiplayer",
        description="FlightGear multiplayer tools.",
    )
    sub = top.add_subparsers(dest="command", required=True)
    p = sub.add_parser(
        "listen",
        help="print the FlightGear aircraft heard on a port",
        description=LISTEN_HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--port", type=int, default=5002, help="UDP port to listen on (default 5002)")
    p.add_argument(
        "--host",
        default="127.0.0.1",
        help="address to bind (default 127.0.0.1, this machine only; 0.0.0.0 for all)",
    )
    p.add_argument(
        "--seconds",
        type=float,
        default=10.0,
        help="how long to listen (default 10; ctrl-C stops sooner)",
    )
    p.add_argument("--json", metavar="OUT", help="also write the lines to this file")
    args = top.parse_args(argv)
    if not args.seconds > 0:  # NaN too
        print(f"error: --seconds {args.seconds:g}: listen for a positive time", file=sys.stderr)
        return 2
    try:
        link = MultiplayerLink(MultiplayerConfig(listen_port=args.port, host=args.host))
    except ConfigError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    heard: set[str] = set()
    stop = threading.Event()
    try:
        with contextlib.ExitStack() as files:
            if threading.current_thread() is threading.main_thread():
                # ctrl-C ends the listening between two polls, as --seconds would
                previous = signal.signal(signal.SIGINT, lambda *_: stop.set())
                files.callback(signal.signal, signal.SIGINT, previous)
            out = files.enter_context(open(args.json, "w")) if args.json else None
            _listen(link, args.seconds, out, heard, stop)
    except OSError as err:  # opening or writing --json (stdout is not a file of ours)
        print(f"error: --json {args.json}: cannot write there ({err})", file=sys.stderr)
        return 2
    finally:
        link.close()
    if not heard:
        print(
            f"heard nobody on {args.host}:{args.port} in {args.seconds:g} s "
            f"({link.rejected} datagrams rejected: not a position message, or not an aircraft)",
            file=sys.stderr,
        )
    return 0


def _listen(
    link: MultiplayerLink,
    seconds: float,
    out: TextIO | None,
    heard: set[str],
    stop: threading.Event,
) -> None:
    """Print the aircraft heard about once a second for ``seconds`` or until ``stop`` (and
    write them to ``out``); the callsigns go into ``heard``."""
    end = time.monotonic() + seconds
    next_print = time.monotonic() + 1.0
    while time.monotonic() < end and not stop.is_set():
        time.sleep(0.02)
        peers = link.poll()
        if time.monotonic() < next_print:
            continue
        next_print += 1.0
        for peer in sorted(peers.values(), key=lambda p: p.callsign):
            heard.add(peer.callsign)
            line = json.dumps(peer.summary())
            print(line, flush=True)
            if out:
                out.write(line + "\n")
                out.flush()


if __name__ == "__main__":
    raise SystemExit(main())
