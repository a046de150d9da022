"""The web cockpit's protocol: JSON text messages over one websocket per pilot.

A browser is hostile until checked: every message is parsed here, against fixed limits, into
typed values, and anything else is refused with a ``ProtocolError`` whose reason the server
sends as the socket's close reason (the server flies on).

Page -> server:

- ``{"type": "hello", "invite": TOKEN, "device": "keyboard" | "mouse" | "joystick"}``: the
  first message, within ``HELLO_S`` seconds;
- ``{"type": "input", "seq": N, "at": PAGE_MS, "frame": F, "events": [...]}``: what the pilot
  did since the last input (``seq`` grows by at least one each time; ``at``: the page's clock;
  ``frame``: the newest frame it had drawn), each event one of ``["down", KEY]``, ``["up",
  KEY]`` (pygame key names, ``KEYS``), ``["mouse", X, Y]`` (the pointer in the cockpit's stick
  box, ``STICK``), ``["pad", 0 | 1]`` (a gamepad connected or gone), ``["axis", I, V]`` and
  ``["button", I, 0 | 1]``.

Server -> page: ``welcome`` once (the flight, the briefing, the keys, the stick's box), then a
``frame`` after every loop of the pilot's session (``link.frame_message``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import orjson

MAX_MESSAGE_BYTES = 4096  # a message larger than this closes the socket
MAX_EVENTS = 64  # events in one input message
MAX_RATE_HZ = 240  # input messages per second (a burst of one second's worth is allowed)
HELLO_S = 3.0  # seconds a new socket has to say hello
JOINS_HZ, JOINS_BURST = 1.0, 8  # an invite opened at most once a second (after a burst)
TOKEN_CHARS = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_")
DEVICES = ("keyboard", "mouse", "joystick")
AXES = 8  # gamepad axes read
BUTTONS = 32  # gamepad buttons read
STICK = (900, 700)  # the stick box the mouse pointer moves in (the cockpit window's size)
COORD_LIMIT = 100_000.0  # a pointer further out than this is not a pointer

# the keys a page may send: the session's commands and every default binding, by pygame name
KEYS = frozenset(
    [
        "space", "e", "backspace", "p", "t", "q", "escape", "h", "f1", "g", "b",
        "left", "right", "up", "down", "page up", "page down", "home", "end", "insert",
        "delete", "enter", "return", ",", ".", "5",
        *(f"[{d}]" for d in "0123456789"),
    ]
)  # fmt: skip


class ProtocolError(ValueError):
    """A message broke the protocol; ``reason`` is what the socket is closed with."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason[:120]  # a websocket close reason holds 123 bytes


@dataclass(frozen=True, slots=True)
class Hello:
    invite: str
    device: str


@dataclass(frozen=True, slots=True)
class Input:
    """One input message: its number, the page's clock (ms), the frame it answers and its
    events (checked tuples, ``events``)."""

    seq: int
    at: float
    frame: int
    events: tuple[tuple[Any, ...], ...]


def decode(data: str | bytes) -> dict[str, Any]:
    """A message as a dict, or ``ProtocolError`` (too large, not JSON, not an object)."""
    if len(data) > MAX_MESSAGE_BYTES:
        raise ProtocolError(f"message of {len(data)} bytes; the limit is {MAX_MESSAGE_BYTES}")
    try:
        message = orjson.loads(data)
    except orjson.JSONDecodeError:
        raise ProtocolError("not JSON") from None
    if not isinstance(message, dict):
        raise ProtocolError("a message is a JSON object")
    return message


def _fields(message: dict[str, Any], known: tuple[str, ...]) -> None:
    unknown = sorted(set(message) - set(known))
    if unknown:
        raise ProtocolError(f"unknown field {str(unknown[0])[:20]!r}; want {', '.join(known)}")


def hello(message: dict[str, Any]) -> Hello:
    """The first message: an invite and a device."""
    if message.get("type") != "hello":
        raise ProtocolError("say hello first: {type: hello, invite, device}")
    _fields(message, ("type", "invite", "device"))
    invite, device = message.get("invite"), message.get("device", "keyboard")
    if not isinstance(invite, str) or not 8 <= len(invite) <= 64 or set(invite) - TOKEN_CHARS:
        raise ProtocolError("no such invite")
    if device not in DEVICES:
        raise ProtocolError(f"device: choose one of {', '.join(DEVICES)}")
    return Hello(invite, device)


def _int(value: Any, low: int, high: int, what: str) -> int:
    if type(value) is not int or not low <= value <= high:
        raise ProtocolError(f"{what}: want an integer in {low}..{high}")
    return value


def _number(value: Any, low: float, high: float, what: str) -> float:
    if type(value) not in (int, float) or not math.isfinite(value) or not low <= value <= high:
        raise ProtocolError(f"{what}: want a number in {low:g}..{high:g}")
    return float(value)


def _event(event: Any) -> tuple[Any, ...]:
    if not isinstance(event, list) or not event or not isinstance(event[0], str):
        raise ProtocolError("an event is a list: [kind, ...]")
    kind, args = event[0], event[1:]
    arity = {"down": 1, "up": 1, "mouse": 2, "pad": 1, "axis": 2, "button": 2}.get(kind)
    if arity is None:
        raise ProtocolError(f"event kind {kind[:20]!r}: want down, up, mouse, pad, axis, button")
    if len(args) != arity:
        raise ProtocolError(f"a {kind} event takes {arity} value(s)")
    if kind in ("down", "up"):
        if not isinstance(args[0], str) or args[0] not in KEYS:
            raise ProtocolError(f"key {str(args[0])[:20]!r} is not a cockpit key")
        return (kind, args[0])
    if kind == "mouse":
        x = _number(args[0], -COORD_LIMIT, COORD_LIMIT, "mouse x")
        y = _number(args[1], -COORD_LIMIT, COORD_LIMIT, "mouse y")
        return (kind, x, y)
    if kind == "pad":
        return (kind, _int(args[0], 0, 1, "pad"))
    if kind == "axis":
        return (kind, _int(args[0], 0, AXES - 1, "axis"), _number(args[1], -1, 1, "axis value"))
    return (kind, _int(args[0], 0, BUTTONS - 1, "button"), _int(args[1], 0, 1, "button state"))


def inputs(message: dict[str, Any], last_seq: int) -> Input:
    """An input message after the one numbered ``last_seq``."""
    if message.get("type") != "input":
        raise ProtocolError(f"message type {str(message.get('type'))[:20]!r}: want input")
    _fields(message, ("type", "seq", "at", "frame", "events"))
    seq = _int(message.get("seq"), last_seq + 1, 2**53, "seq (it must grow)")
    at = _number(message.get("at"), 0.0, 1e15, "at")
    frame = _int(message.get("frame"), -1, 2**53, "frame")
    events = message.get("events")
    if not isinstance(events, list) or len(events) > MAX_EVENTS:
        raise ProtocolError(f"events: want a list of at most {MAX_EVENTS}")
    return Input(seq, at, frame, tuple(_event(e) for e in events))


class RateLimit:
    """At most ``hz`` a second on average, a burst of ``burst`` (default: one second's worth)
    allowed (a token bucket on the caller's clock); ``what`` is counted."""

    def __init__(
        self, hz: float = MAX_RATE_HZ, burst: float | None = None, what: str = "messages"
    ) -> None:
        self.hz, self.burst, self.what = hz, hz if burst is None else burst, what
        self.tokens = self.burst
        self.at: float | None = None

    def take(self, now: float) -> None:
        if self.at is not None:
            self.tokens = min(self.burst, self.tokens + (now - self.at) * self.hz)
        self.at = now
        if self.tokens < 1.0:
            raise ProtocolError(f"more than {self.hz:g} {self.what} a second")
        self.tokens -= 1.0


def encode(message: dict[str, Any]) -> bytes:
    """A message for the page (numpy arrays as lists)."""
    return orjson.dumps(message, option=orjson.OPT_SERIALIZE_NUMPY)
