"""A browser pilot's end of the cockpit session: its input and its window.

The session loop is the same as ``collect manual``'s (``cockpit.session``), on a thread of the
server. Between it and the pilot's websocket (``web.server``) sits a ``PilotLink``:

- ``WebInput`` (the session's input stage) takes every input message that arrived since the
  last frame, in order, and hands its events to the pilot's ManualController as the pygame
  events a local device would give (so the controls move exactly as they would at this
  machine); the session commands come from the same keys. A step flies the newest input that
  arrived before it; how old that input was (its round trip and its age in frames) goes to
  the log with the step (``cockpit.timing``).
- ``WebWindow`` (the session's window stage) turns each frame's view into a ``frame``
  message: the display model's readings (not pictures), the controls, the phase, the words.
  Only the newest frame waits to be sent: a slow page skips frames, it never piles them up.

When the socket drops, the episode in flight is discarded (said in the server's output) and
the session waits, idle, for the pilot to come back with the same invite; Q or Esc on the
page discards the episode in flight and closes the page's socket, the session stays.
"""

from __future__ import annotations

import collections
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from gymfg_il.cockpit.inputs.keys import COMMAND_KEYS, help_lines
from gymfg_il.cockpit.inputs.source import Polled, Remote, Seen
from gymfg_il.cockpit.windows.view import CockpitView
from gymfg_il.display.briefing import briefing
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.manual.controller import ManualController
from gymfg_il.web.protocol import Input, encode

SENT_KEPT = 256  # frames whose send time is kept (an input answering an older one is old)
SILENT_S = 1.0  # a page that answers no frame for this long is gone, whatever its socket says


class PilotLink:
    """What a pilot's socket and session share (thread-safe).

    The socket side calls ``attach``/``detach`` and ``received``; the session's stages call
    ``take`` and ``send``. ``sender``: called with each frame's bytes, from the session's
    thread (the server hands them to its event loop).
    """

    def __init__(self, name: str, say: Callable[[str], None] = print) -> None:
        self.name, self.say = name, say
        self.inbox: collections.deque[tuple[Input, float]] = collections.deque()
        self.lock = threading.Lock()
        self.sender: Callable[[bytes], None] | None = None
        self.connected = False
        self.dropped = False  # the socket went since the session last looked
        self.quit = False  # the page asked to leave (Q or Esc)
        self.close_reason: str | None = None  # the page's socket is to close, saying why
        self.stop = False  # the server is closing: the session ends
        self.frame = 0  # frames sent (the next frame's number)
        self.heard = time.perf_counter()  # when the page last sent an input (or came)
        self.sent_at: dict[int, float] = {}
        self.welcome: dict[str, Any] | None = None  # set once the session is built
        self.ready = threading.Event()
        self.failed: str | None = None  # why the session could not be built

    # -- the socket's side --------------------------------------------------------------
    def attach(self, sender: Callable[[bytes], None]) -> None:
        with self.lock:
            self.sender, self.connected, self.quit = sender, True, False
            self.close_reason = None
            self.inbox.clear()
            self.heard = time.perf_counter()

    def detach(self) -> None:
        with self.lock:
            self.sender, self.connected, self.dropped = None, False, True

    def close_page(self, reason: str) -> None:
        """Close the page's socket with ``reason`` (the session stays, unless it ended)."""
        with self.lock:
            self.close_reason = reason
            sender = self.sender
        if sender is not None:
            sender(b"")  # wakes the socket's sender, which closes it

    def received(self, message: Input) -> None:
        self.heard = now = time.perf_counter()
        self.inbox.append((message, now))

    # -- the session's side -------------------------------------------------------------
    def take(self) -> list[tuple[Input, float]]:
        """Every input that arrived since the last call, in order."""
        out = []
        while self.inbox:
            out.append(self.inbox.popleft())
        return out

    def send(self, message: dict[str, Any]) -> None:
        """Send one frame (numbered here) if a page is there to see it."""
        with self.lock:
            n = self.frame
            self.frame += 1
            sender = self.sender
        message["n"] = n
        self.sent_at[n] = time.perf_counter()
        self.sent_at.pop(n - SENT_KEPT, None)
        if sender is not None:
            sender(encode(message))


class WebInput:
    """The session's input from a browser (module docstring).

    Args:
        link: the pilot's link.
        human: the pilot's controller, which the events move.
        dt: seconds per frame (keys move the controls this long each frame).
    """

    def __init__(self, link: PilotLink, human: ManualController, dt: float) -> None:
        import pygame

        from gymfg_il.manual.synthetic import key_codes

        self.link, self.human, self.dt, self.pg = link, human, dt, pygame
        self.codes = key_codes()  # every name web.protocol.KEYS allows is here (a test says)
        # the newest input: (the frame it answered, its round trip s, its arrival, Unix s)
        self._newest: tuple[int, float, float] | None = None

    def poll(self, seen: Seen) -> Polled:
        pg, link = self.pg, self.link
        events: list[Any] = []
        commands: list[str] = []
        for message, arrived in link.take():
            events += self._events(message)
            sent = link.sent_at.get(message.frame)
            if sent is not None:  # (perf_counter: the round trip; the wall clock: the log's)
                wall = time.time() - (time.perf_counter() - arrived)
                self._newest = (message.frame, arrived - sent, wall)
        read_at = time.time()
        silent = time.perf_counter() - link.heard > SILENT_S
        if seen.phase != "idle" and link.connected and silent:  # a line that died unclosed
            link.dropped, link.heard = True, time.perf_counter()
            link.say(f"pilot {link.name}: no input for {SILENT_S:g} s")
        if link.dropped or link.quit or link.stop:
            link.dropped = False
            self.human.held.clear()  # keys held when the page went are let go
            events = []
            if seen.phase != "idle":
                commands.append("discard")
                why = "the server stops" if link.stop else "the connection dropped"
                link.say(f"pilot {link.name}: {why}; the episode in flight was discarded")
        commands += self.human.handle(events, self.dt)
        for event in events:
            if event.type == pg.KEYDOWN:
                command = COMMAND_KEYS.get(pg.key.name(event.key))
                if command == "quit":  # the page leaves; the session waits for its return
                    link.quit = True
                    if seen.phase != "idle":
                        commands.append("discard")
                        link.say(
                            f"pilot {link.name}: the page quit; the episode in flight was discarded"
                        )
                    link.close_page(
                        "you quit (an episode in flight was discarded); open your "
                        "invite again to fly on"
                    )
                elif command:
                    commands.append(command)
        if link.stop:
            commands.append("quit")
        remote = None
        if self._newest is not None:
            frame, trip, wall = self._newest
            remote = Remote(wall, trip, link.frame - frame)
        return Polled(commands, read_at, remote)

    def _events(self, message: Input) -> list[Any]:
        """The pygame events of one input message (checked by ``web.protocol``)."""
        pg = self.pg
        out = []
        for event in message.events:
            kind = event[0]
            if kind in ("down", "up"):
                kind_of = pg.KEYDOWN if kind == "down" else pg.KEYUP
                code = self.codes[event[1]]
                out.append(pg.event.Event(kind_of, key=code, mod=0, unicode="", scancode=0))
            elif kind == "mouse":
                pos = (event[1], event[2])
                out.append(pg.event.Event(pg.MOUSEMOTION, pos=pos, rel=(0, 0), buttons=(0, 0, 0)))
            elif kind == "pad":
                if event[1]:
                    out.append(pg.event.Event(pg.JOYDEVICEADDED, device_index=0, instance_id=0))
                else:
                    out.append(pg.event.Event(pg.JOYDEVICEREMOVED, instance_id=0))
            elif kind == "axis":
                out.append(
                    pg.event.Event(pg.JOYAXISMOTION, instance_id=0, axis=event[1], value=event[2])
                )
            else:  # button
                kind_of = pg.JOYBUTTONDOWN if event[2] else pg.JOYBUTTONUP
                out.append(pg.event.Event(kind_of, instance_id=0, button=event[1]))
        return out

    def close(self) -> None:
        self.human.close()


def _floats(values: np.ndarray) -> list[float]:
    return [float(v) for v in values]


class WebWindow:
    """The session's window in a browser: each view becomes a ``frame`` message (module
    docstring); the ``welcome`` the page gets first is made here, from the flight."""

    shown = True

    def __init__(
        self,
        link: PilotLink,
        human: ManualController,
        env: AircraftEnv,
        flight: FlightSpec,
        flight_options: dict[str, Any],
        say: Callable[[str], None] = print,
    ) -> None:
        self.link, self.human, self.say = link, human, say
        self._saved, self._discarded = 0, 0
        self.max_steps, self.dt = env.world.max_steps, env.dt
        link.welcome = {
            "type": "welcome",
            "pilot": link.name,
            "device": human.device,
            "flight": flight_options,
            "label": f"{flight.task_label} on {env.aircraft.model}",
            "briefing": briefing(env.task, env.world.max_steps * env.dt),
            "help": help_lines(human.device, human.keys),
            "dt": env.dt,
            "max_steps": env.world.max_steps,
            "stick": {"size": list(human.window_size), "span": human.mouse.span_px},
            "axes": dict(human.joy.axes),
        }

    def draw(self, view: CockpitView) -> None:
        debrief = view.debrief
        if view.episode > self._saved:  # the server's output says what each pilot saved
            self._saved = view.episode
            verdict = "" if debrief is None else f": {debrief.lines[0]}"
            self.say(f"pilot {self.link.name} saved episode {view.episode}{verdict}")
        self.link.send(
            {
                "type": "frame",
                "status": view.status,
                "episode": view.episode,
                "started": view.started,
                "seed": view.seed,
                "steps": view.steps,
                "readings": [
                    [r.name, r.value, r.unit, r.instrument, r.role, r.label]
                    for r in view.display.readings
                ],
                "controls": _floats(view.controls),
                "start": _floats(self.human.start_controls),
                "trim": _floats(view.trim),
                "flown": _floats(view.flown),
                "human": view.human_flies,
                "message": view.message,
                "late": view.late,
                "help": view.show_help,
                "debrief": None
                if debrief is None
                else {"success": debrief.success, "grade": debrief.grade, "lines": debrief.lines},
            }
        )

    def close(self) -> None:
        """Nothing to close: the socket is the server's."""
