"""The online protocol: msgpack maps over ZeroMQ (DEALER clients, a ROUTER server), each
checked on receipt against the schema of its type. Version 1.

Client -> server:

| type | fields |
| --- | --- |
| join | team, token, aircraft {callsign: model} |
| report | team, token, states {callsign: [catalogue values]}, done |
| leave | team, token |

Server -> client:

| type | fields |
| --- | --- |
| welcome | team, mode, opponent_view [names], simulation |
| central | tick, opponents [[callsign, team, [opponent_view values]]], done, reason |
| wait | reason |
| error | code, message |
"""

from __future__ import annotations

import math
from typing import Any

import msgpack

from gymfg_il.errors import GymFGError
from gymfg_il.sim.properties import NAMES

VERSION = 1
MAX_MESSAGE_BYTES = 64 * 1024
_NAME_MAX = 64
_NUMBERS = {float, int}  # exact types: msgpack gives bool for booleans, never a subclass


class ProtocolError(GymFGError, ValueError):
    """A message that does not follow the protocol; ``code`` is sent back to its sender."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(message)
        self.code = code


class ServerError(GymFGError, RuntimeError):
    """The server refused a request (full, unauthorised, ...) or stopped answering."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(f"{message} [{code}]")
        self.code = code


def encode(msg: dict[str, Any]) -> bytes:
    return msgpack.packb({"v": VERSION, **msg}, use_bin_type=True)


def _name(value: object, what: str) -> str:
    if not isinstance(value, str) or not 0 < len(value) <= _NAME_MAX:
        raise ProtocolError("malformed", f"{what} must be a string of 1..{_NAME_MAX} chars")
    return value


def decode(data: bytes, sender: str = "client") -> dict[str, Any]:
    """Parse and check one message; ProtocolError says what is wrong with it."""
    if len(data) > MAX_MESSAGE_BYTES:
        raise ProtocolError(
            "oversized", f"message of {len(data)} bytes; at most {MAX_MESSAGE_BYTES} are accepted"
        )
    try:
        msg = msgpack.unpackb(data, raw=False, strict_map_key=True)
    except Exception as err:  # msgpack raises many types for garbage
        raise ProtocolError("malformed", f"not msgpack ({type(err).__name__})") from None
    if not isinstance(msg, dict):
        raise ProtocolError("malformed", "a message must be a map")
    if msg.get("v") != VERSION:
        raise ProtocolError(
            "version", f"protocol version {msg.get('v')!r}; this end speaks {VERSION}"
        )
    kind = msg.get("type")
    check = (_CLIENT if sender == "client" else _SERVER).get(kind)  # type: ignore[arg-type]
    if check is None:
        raise ProtocolError("malformed", f"unknown message type {kind!r}")
    check(msg)
    return msg


def _join(msg: dict[str, Any]) -> None:
    _name(msg.get("team"), "team")
    if not isinstance(msg.get("token", ""), str):
        raise ProtocolError("malformed", "token must be a string")
    aircraft = msg.get("aircraft")
    if not isinstance(aircraft, dict) or not 0 < len(aircraft) <= 64:
        raise ProtocolError("malformed", "aircraft must map 1..64 callsigns to models")
    for callsign, model in aircraft.items():
        _name(callsign, "callsign")
        _name(model, "aircraft model")


def _report(msg: dict[str, Any]) -> None:
    _name(msg.get("team"), "team")
    states = msg.get("states")
    if not isinstance(states, dict) or not 0 < len(states) <= 64:
        raise ProtocolError("malformed", "states must map 1..64 callsigns to state vectors")
    for callsign, values in states.items():
        _name(callsign, "callsign")
        if not isinstance(values, list) or len(values) != len(NAMES):
            raise ProtocolError(
                "malformed",
                f"the state of {callsign!r} must be a list of {len(NAMES)} numbers (the catalogue)",
            )
        # checked in C (map), as this runs for every aircraft at every step
        if not (set(map(type, values)) <= _NUMBERS and all(map(math.isfinite, values))):
            bad = next(v for v in values if type(v) not in _NUMBERS or not math.isfinite(v))
            raise ProtocolError("malformed", f"the state of {callsign!r} holds {bad!r}")
    if not isinstance(msg.get("done", False), bool):
        raise ProtocolError("malformed", "done must be a boolean")


def _leave(msg: dict[str, Any]) -> None:
    _name(msg.get("team"), "team")


def _any(msg: dict[str, Any]) -> None:
    pass


_CLIENT = {"join": _join, "report": _report, "leave": _leave}
_SERVER = {"welcome": _any, "central": _any, "wait": _any, "error": _any}
