"""The synthetic pilot as the cockpit session's input (``collect manual --pilot synthetic``):
it presses Space to start each episode and, while one is flown, looks at what the window
shows (the display model) and gives the key, joystick or mouse events a person would make
(``manual.synthetic.SyntheticPilot``). They reach the ManualController after pygame's own
events of the frame, as a person's keys would: the controller cannot tell them apart.

With an assistant (``--assist POLICY``) it is a human-gated DAgger teacher: it takes over (T)
when the task's error grows past ``gate`` times the task's tolerance and hands back once the
error has stayed within the tolerance for ``settle_s``; its frames are the interventions.
"""

from __future__ import annotations

from typing import Any

from gymfg_il.cockpit.inputs.devices import DeviceInput
from gymfg_il.cockpit.inputs.source import Polled, Seen
from gymfg_il.manual.synthetic import SyntheticPilot, key_codes
from gymfg_il.tasks.verdicts import TrackedError


def tap(key: str) -> list[Any]:
    """A key pressed and let go within one frame."""
    import pygame

    code = key_codes()[key]
    return [
        pygame.event.Event(kind, key=code, mod=0, unicode="", scancode=0)
        for kind in (pygame.KEYDOWN, pygame.KEYUP)
    ]


class SyntheticInput:
    """The synthetic ``pilot``'s hands on ``devices``' controller (module docstring).

    Args:
        devices: the session's devices (pygame's queue still reads a person's Q).
        pilot: the model of a person (``manual.synthetic``).
        assisted: an assistant flies until the pilot takes over.
        tracked: the task's tracked error, as every verdict reads it
            (``tasks.verdicts.TrackedError``), for the gate (None: a task without a target,
            never gated).
        gate: with an assistant, take over when |error| exceeds this many tolerances.
        settle_s: hand back after the error has stayed within the tolerance this long.
    """

    def __init__(
        self,
        devices: DeviceInput,
        pilot: SyntheticPilot,
        *,
        assisted: bool,
        tracked: TrackedError | None,
        gate: float = 3.0,
        settle_s: float = 3.0,
    ) -> None:
        self.devices, self.pilot, self.assisted, self.tracked = devices, pilot, assisted, tracked
        self.gate, self.settle_s = gate, settle_s
        self._settled = 0.0
        self._started = 0
        self.sent: list[list[Any]] = []  # per recorded frame: the device events it made

    def poll(self, seen: Seen) -> Polled:
        return self.devices.poll(seen, self._events(seen))

    def _events(self, seen: Seen) -> list[Any]:
        if seen.phase == "idle":
            return tap("space")  # the next episode
        if seen.phase != "recording":
            return []
        human = self.devices.human
        if seen.started != self._started:  # a new episode: a fresh pilot, its own seed
            self._started = seen.started
            self.pilot.reset(seen.seed)
            self.pilot.start_from(human.start_controls)
            self._settled = 0.0
        events = self._gated(seen) if self.assisted else []
        if not seen.human_flies:
            self.sent.append([])
            return events
        events += self.pilot.events(seen.display, human.values)
        self.sent.append(list(self.pilot.sent))
        return events

    def _gated(self, seen: Seen) -> list[Any]:
        """T when the error grows too large; T again once it has settled."""
        if self.tracked is None or seen.observation is None:
            return []
        tolerance = self.tracked.tolerance
        error = abs(self.tracked(seen.observation))
        if not seen.human_flies:
            if error > self.gate * tolerance:
                self._settled = 0.0
                return tap("t")
            return []
        self._settled = self._settled + self.pilot.dt if error <= tolerance else 0.0
        return tap("t") if self._settled >= self.settle_s else []

    def close(self) -> None:
        self.devices.close()
