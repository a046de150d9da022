"""The headless web pilot: the display-bound synthetic pilot (``manual.synthetic``) flying a
web cockpit through the same protocol as a browser (``web.protocol``), so the whole path,
from the server's frames to the recorded actions, is tested without a browser.

Each frame it gets, it reads the display model the page would draw, and answers with the
events a person's keyboard, mouse or gamepad would make (keys by name, the pointer in the
stick box, the gamepad's axes); Space starts each episode. A pilot that always answers
before the next frame flies exactly as ``collect manual --pilot synthetic`` does.

    python -m gymfg_il.web.headless ws://127.0.0.1:8080/ws --invite TOKEN --episodes 3
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import orjson

from gymfg_il.display.readings import Display, Reading


@dataclass
class Flown:
    """What a headless pilot did: episodes saved, frames seen, inputs sent, how each input
    answered (the frames between the one it answered and the next it saw), and the reason
    the server closed the socket with ("" if the pilot left)."""

    saved: int = 0
    frames: int = 0
    inputs: int = 0
    closed: str = ""
    welcome: dict[str, Any] = field(default_factory=dict)


def _pilot(welcome: dict[str, Any], skill: float) -> tuple[Any, Any]:
    """The synthetic pilot for the welcomed flight (its own copy of the task reads the same
    display model), and the env it was built from (to close)."""
    from gymfg_il.envs.options import FlightOptions
    from gymfg_il.manual.bindings import JoystickBindings, KeyboardBindings, MouseBindings
    from gymfg_il.manual.perception import DisplayIntent
    from gymfg_il.manual.synthetic import SyntheticPilot

    options = {k: v for k, v in welcome["flight"].items() if k != "gusts" or v != "none"}
    flight = FlightOptions(**options).flight()
    env = flight.make_env()
    throttle = env.aircraft.profile.cruise_throttle
    intent = DisplayIntent(env.task, env.aircraft.model, env.dt, throttle)
    size = tuple(welcome["stick"]["size"])
    pilot = SyntheticPilot(
        welcome["device"],
        intent,
        env.dt,
        skill,
        KeyboardBindings(),
        MouseBindings(),
        JoystickBindings(),
        size,
    )
    # its first answer costs tens of ms (first calls through the controller's code): make it
    # here, so that the first frame of a flight is answered in time like every other
    from gymfg_il.display.readings import display_of

    env.reset(seed=0)
    controls = np.array([0.0, 0.0, 0.0, throttle])
    pilot.reset(0)
    pilot.start_from(controls)
    for step in range(3):
        pilot.events(display_of(env.task, env.world.slots[0].state, step), controls)
    return pilot, env


def wire(events: list[Any]) -> list[list[Any]]:
    """pygame events as the protocol's events."""
    import pygame

    out: list[list[Any]] = []
    for e in events:
        if e.type in (pygame.KEYDOWN, pygame.KEYUP):
            out.append(["down" if e.type == pygame.KEYDOWN else "up", pygame.key.name(e.key)])
        elif e.type == pygame.MOUSEMOTION:
            out.append(["mouse", e.pos[0], e.pos[1]])
        elif e.type == pygame.JOYDEVICEADDED:
            out.append(["pad", 1])
        elif e.type == pygame.JOYAXISMOTION:
            out.append(["axis", e.axis, float(e.value)])
        elif e.type in (pygame.JOYBUTTONDOWN, pygame.JOYBUTTONUP):
            out.append(["button", e.button, int(e.type == pygame.JOYBUTTONDOWN)])
    return out


SPACE = [["down", "space"], ["up", "space"]]


class _Answers:
    """The headless pilot's answer to each frame (module docstring)."""

    def __init__(self, episodes: int, skill: float) -> None:
        self.episodes, self.skill = episodes, skill
        self.pilot: Any = None
        self.env: Any = None
        self.started = 0

    def welcome(self, message: dict[str, Any]) -> None:
        self.pilot, self.env = _pilot(message, self.skill)

    def events(self, message: dict[str, Any]) -> list[list[Any]] | None:
        """This frame's events; None once the episodes asked for are saved."""
        status, pilot = message["status"], self.pilot
        if status == "idle":
            return None if message["episode"] >= self.episodes else SPACE
        if status != "recording":
            return []
        if message["started"] != self.started:  # a new episode: its own seed
            self.started = message["started"]
            pilot.reset(message["seed"])
            pilot.start_from(np.array(message["start"]))
        if not message["human"]:
            return []
        display = Display(tuple(Reading(*r) for r in message["readings"]))
        return wire(pilot.events(display, np.array(message["controls"])))

    def close(self) -> None:
        if self.env is not None:
            self.env.close()


async def fly(
    url: str,
    invite: str,
    episodes: int,
    *,
    skill: float = 0.7,
    device: str = "keyboard",
    ready: asyncio.Barrier | None = None,
) -> Flown:
    """Fly ``episodes`` episodes through the web cockpit at ``url`` (its ``/ws``) with
    ``invite``; returns what was done once the last is saved or the server closes. With
    ``ready``, wait there once set up, before the first answer (pilots sharing one process
    start together: none is still setting up, holding the others' answers up)."""
    from websockets.asyncio.client import connect
    from websockets.exceptions import ConnectionClosed

    flown, answers, seq = Flown(), _Answers(episodes, skill), 0
    try:
        async with connect(url, max_size=2**22, open_timeout=30) as ws:
            await ws.send(orjson.dumps({"type": "hello", "invite": invite, "device": device}))
            try:
                async for data in ws:
                    message = orjson.loads(data)
                    if message.get("type") == "welcome":
                        flown.welcome = message
                        answers.welcome(message)
                        if ready is not None:
                            with contextlib.suppress(asyncio.BrokenBarrierError):
                                await ready.wait()
                            ready = None
                        continue
                    if message.get("type") != "frame" or answers.pilot is None:
                        continue
                    flown.frames += 1
                    flown.saved = message["episode"]
                    events = answers.events(message)
                    if events is None:
                        break
                    seq += 1
                    flown.inputs += 1
                    answer = {"type": "input", "seq": seq, "at": time.monotonic() * 1000.0,
                              "frame": message["n"], "events": events}  # fmt: skip
                    await ws.send(orjson.dumps(answer))
            except ConnectionClosed as closed:
                flown.closed = closed.rcvd.reason if closed.rcvd is not None else "dropped"
            else:
                flown.closed = ws.close_reason or ""
    finally:
        if ready is not None:  # never welcomed: the others start without this one
            await ready.abort()
        answers.close()
    return flown


async def fly_many(url: str, invites: list[str], episodes: int, **kwargs: Any) -> list[Flown]:
    """Several headless pilots at once, one invite each, starting together."""
    ready = asyncio.Barrier(len(invites))
    flights = (fly(url, i, episodes, ready=ready, **kwargs) for i in invites)
    return list(await asyncio.gather(*flights))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m gymfg_il.web.headless",
        description="Fly a web cockpit with the synthetic pilot, through the web protocol.",
    )
    p.add_argument("url", help="the server's websocket, e.g. ws://127.0.0.1:8080/ws")
    p.add_argument("--invite", required=True, action="append", help="a token (repeatable)")
    p.add_argument("--episodes", type=int, default=1, help="episodes each pilot saves")
    p.add_argument("--skill", type=float, default=0.7, help="0 (a novice) .. 1 (an ace)")
    p.add_argument("--device", default="keyboard", choices=("keyboard", "mouse", "joystick"))
    args = p.parse_args(argv)
    flown = asyncio.run(
        fly_many(args.url, args.invite, args.episodes, skill=args.skill, device=args.device)
    )
    for f in flown:
        print(f"saved {f.saved}, frames {f.frames}, inputs {f.inputs}, closed: {f.closed!r}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
