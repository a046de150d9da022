"""A person's devices as the cockpit session's input: each frame reads pygame's event queue
once, hands the events to the ManualController (keyboard, mouse, joystick; FlightGear's
cockpit is read from its controls stream there, ``manual.controller``) and reads the session
commands off the keys (``keys.COMMAND_KEYS``), the window's close button and the joystick's
buttons."""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

from gymfg_il.cockpit.inputs.keys import COMMAND_KEYS
from gymfg_il.cockpit.inputs.source import Polled, Seen
from gymfg_il.manual.controller import ManualController


class DeviceInput:
    """pygame's queue through ``human`` (its controls move ``dt`` seconds a frame).

    Opens pygame's video system, whose queue the events arrive in (the window, where there
    is one, opens on it)."""

    def __init__(self, human: ManualController, dt: float) -> None:
        import pygame

        pygame.display.init()
        self.pg, self.human, self.dt = pygame, human, dt

    def poll(self, seen: Seen, own: Sequence[Any] = ()) -> Polled:
        """This frame's events (after them ``own``: events an input made itself), read now."""
        pg = self.pg
        events = pg.event.get()
        if own:
            events += own
        read_at = time.time()  # the input this frame flies by is read now
        commands = self.human.handle(events, self.dt)
        for event in events:
            if event.type == pg.QUIT:
                commands.append("quit")
            elif event.type == pg.KEYDOWN:
                command = COMMAND_KEYS.get(pg.key.name(event.key))
                if command:
                    commands.append(command)
        return Polled(commands, read_at)

    def close(self) -> None:
        self.human.close()
        self.pg.display.quit()
