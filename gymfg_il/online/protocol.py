"""The online protocol: msgpack maps over ZeroMQ (DEALER clients, a ROUTER server), each
checked on receipt against the schema of its type, in both directions: a server checks what
clients send and a client checks what servers send. Version 2.

Client -> server:

| type | fields |
| --- | --- |
| join | team, token, aircraft {callsign: model} |
| report | team, token, states {callsign: [catalogue values]}, done |
| alive | team, token (the answer to a ``wait``: the team is still there) |
| leave | team, token |

Server -> client:

| type | fields |
| --- | --- |
| welcome | team, mode, opponent_view [names], simulation |
| central | tick, opponents [[callsign, team, [opponent_view values]]], done, reason |
| wait | reason |
| error | code, message |

Names (teams, callsigns, aircraft models) follow ``gymfg_il.names``: printable, 1 to 64
characters. Numbers are finite floats or integers (never booleans); a message is at most
``MAX_MESSAGE_BYTES``.
"""

from __future__ import annotations

import math
from typing import Any

import msgpack

from gymfg_il.errors import GymFGError
from gymfg_il.names import name_problem
from gymfg_il.sim.properties import INDEX, NAMES

VERSION = 2
MAX_MESSAGE_BYTES = 64 * 1024
MAX_AIRCRAFT = 64  # per team
MAX_TEXT = 4096  # characters of a reason or an error message
MODES = ("fixed", "open")
_NUMBERS = {float, int}  # exact types: msgpack gives bool for booleans, never a subclass


class ProtocolError(GymFGError, ValueError):
    """A message that does not follow the protocol; ``code`` is sent back to its sender."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(message)
        self.code = code


class ServerError(GymFGError, RuntimeError):
    """The server refused a request (full, unauthorised, ...), sent a malformed reply or
    stopped answering."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(f"{message} [{code}]")
        self.code = code


def encode(msg: dict[str, Any]) -> bytes:
    return msgpack.packb({"v": VERSION, **msg}, use_bin_type=True)


def printable(text: str) -> str:
    """``text`` with every character that is not printable escaped (``\\n``, ``\\x1b``,
    ``\\u202e``), so that text from the other end cannot forge log lines or drive a
    terminal."""
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def _malformed(message: str) -> ProtocolError:
    return ProtocolError("malformed", message)


def _short(value: object) -> str:
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _name(value: object, what: str) -> str:
    problem = name_problem(value, what)
    if problem is not None:
        raise _malformed(problem)
    assert isinstance(value, str)
    return value


def _count(value: object, what: str) -> int:
    if type(value) is not int or value < 0:
        raise _malformed(f"{what} must be a whole number >= 0, got {_short(value)}")
    return value


def _flag(value: object, what: str) -> bool:
    if type(value) is not bool:
        raise _malformed(f"{what} must be a boolean, got {_short(value)}")
    return value


def _text(value: object, what: str) -> str:
    if type(value) is not str or len(value) > MAX_TEXT:
        raise _malformed(f"{what} must be a string of at most {MAX_TEXT} characters")
    return value


def _numbers(values: object, width: int | None, what: str) -> None:
    """A list of ``width`` finite numbers (any width from 1 to the catalogue's if None)."""
    if type(values) is not list or not (
        len(values) == width if width is not None else 0 < len(values) <= len(NAMES)
    ):
        size = f"{width}" if width is not None else f"1..{len(NAMES)}"
        raise _malformed(f"{what} must be a list of {size} numbers, got {_short(values)}")
    # checked in C (map), as this runs for every aircraft at every step
    if not (set(map(type, values)) <= _NUMBERS and all(map(math.isfinite, values))):
        bad = next(v for v in values if type(v) not in _NUMBERS or not math.isfinite(v))
        raise _malformed(f"{what} holds {bad!r}; every value must be a finite number")


def decode(data: bytes, sender: str = "client", width: int | None = None) -> dict[str, Any]:
    """Parse and check one message from ``sender`` (client or server); ProtocolError says
    what is wrong with it. ``width``: the values in each opponent row of a central state
    (the length of the opponent view the server announced)."""
    if len(data) > MAX_MESSAGE_BYTES:
        raise ProtocolError(
            "oversized", f"message of {len(data)} bytes; at most {MAX_MESSAGE_BYTES} are accepted"
        )
    try:
        msg = msgpack.unpackb(data, raw=False, strict_map_key=True)
    except Exception as err:  # msgpack raises many types for garbage
        raise _malformed(f"not msgpack ({type(err).__name__})") from None
    if not isinstance(msg, dict):
        raise _malformed("a message must be a map")
    if msg.get("v") != VERSION:
        raise ProtocolError(
            "version", f"protocol version {_short(msg.get('v'))}; this end speaks {VERSION}"
        )
    kind = msg.get("type")
    if sender == "client":
        check = _CLIENT.get(kind) if isinstance(kind, str) else None
        if check is None:
            raise _malformed(f"unknown message type {_short(kind)}")
        check(msg)
    else:
        if kind == "central":
            _central(msg, width)
        elif kind in _SERVER and isinstance(kind, str):
            _SERVER[kind](msg)
        else:
            raise _malformed(f"unknown message type {_short(kind)}")
    return msg


# -- client -> server ------------------------------------------------------------------------
def _team(msg: dict[str, Any]) -> None:
    _name(msg.get("team"), "team")
    if not isinstance(msg.get("token", ""), str):
        raise _malformed("token must be a string")


def _join(msg: dict[str, Any]) -> None:
    _team(msg)
    aircraft = msg.get("aircraft")
    if not isinstance(aircraft, dict) or not 0 < len(aircraft) <= MAX_AIRCRAFT:
        raise _malformed(f"aircraft must map 1..{MAX_AIRCRAFT} callsigns to models")
    for callsign, model in aircraft.items():
        _name(callsign, "callsign")
        _name(model, "aircraft model")


def _report(msg: dict[str, Any]) -> None:
    _team(msg)
    states = msg.get("states")
    if not isinstance(states, dict) or not 0 < len(states) <= MAX_AIRCRAFT:
        raise _malformed(f"states must map 1..{MAX_AIRCRAFT} callsigns to state vectors")
    for callsign, values in states.items():
        _name(callsign, "callsign")
        _numbers(values, len(NAMES), f"the state of {callsign!r} (the catalogue's values)")
    _flag(msg.get("done", False), "done")


_CLIENT = {"join": _join, "report": _report, "alive": _team, "leave": _team}


# -- server -> client ------------------------------------------------------------------------
def _welcome(msg: dict[str, Any]) -> None:
    _name(msg.get("team"), "team")
    if msg.get("mode") not in MODES:
        raise _malformed(f"mode {_short(msg.get('mode'))} is not one of {MODES}")
    view = msg.get("opponent_view")
    if type(view) is not list or not 0 < len(view) <= len(NAMES):
        raise _malformed(f"opponent_view must list 1..{len(NAMES)} state variables")
    unknown = [n for n in view if not isinstance(n, str) or n not in INDEX]
    if unknown or len(set(view)) != len(view):
        raise _malformed(
            f"opponent_view {_short(view)} names unknown or repeated state variables "
            f"{_short(unknown)}"
        )
    _count(msg.get("simulation"), "simulation")


def _central(msg: dict[str, Any], width: int | None) -> None:
    _count(msg.get("tick"), "tick")
    rows = msg.get("opponents")
    if type(rows) is not list:
        raise _malformed(f"opponents must be a list of rows, got {_short(rows)}")
    seen: set[str] = set()
    flat: list[Any] = []  # every row's values, checked at once in C (this runs every step)
    sizes = range(1, len(NAMES) + 1) if width is None else (width,)
    for row in rows:
        if type(row) is not list or len(row) != 3:
            raise _malformed(f"an opponent row is [callsign, team, values], got {_short(row)}")
        callsign, team, values = row
        _name(callsign, "callsign")
        _name(team, "team")
        if callsign in seen:
            raise _malformed(f"callsign {callsign!r} is shown twice among the opponents")
        seen.add(callsign)
        if type(values) is not list or len(values) not in sizes:
            _numbers(values, width, f"the row of {callsign!r}")  # (raises, saying why)
        flat += values
    if not (set(map(type, flat)) <= _NUMBERS and all(map(math.isfinite, flat))):
        for callsign, _, values in rows:
            _numbers(values, width, f"the row of {callsign!r} (the opponent view's values)")
        raise AssertionError("unreachable: _numbers names the row at fault")
    _flag(msg.get("done"), "done")
    _text(msg.get("reason"), "reason")


def _wait(msg: dict[str, Any]) -> None:
    _text(msg.get("reason"), "reason")


def _error(msg: dict[str, Any]) -> None:
    _name(msg.get("code"), "error code")
    _text(msg.get("message"), "error message")


_SERVER = {"welcome": _welcome, "wait": _wait, "error": _error}
