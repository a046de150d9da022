"""What an input of the cockpit session is: a source, read once a frame, of the session's
commands (start, end, quit, take over, ...) and of the controls, which it moves on the
ManualController it drives (``manual.controller``: the Agent that flies them, so the flown
controls are the input's as they stand when the aircraft steps).

The inputs: a person's pygame devices (``devices``: keyboard, mouse, joystick, or FlightGear's
cockpit through its controls stream), and the synthetic pilot (``synthetic_pilot``), which
reads what the window shows and gives the keys a person would press.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from gymfg_il.display.readings import Display


@dataclass(frozen=True, slots=True)
class Seen:
    """What an input may look at before it is read each frame.

    Attributes:
        phase: the session's phase (``idle``, ``recording``, ``paused``: ``cockpit.phases``).
        started: episodes started so far (a new number: a new episode).
        seed: the seed of the episode in flight (or of the next one).
        display: what the window shows now (``display.readings``).
        human_flies: the pilot has the controls (not the assistant).
        observation: the aircraft's observation now (None before the first episode); the
            synthetic pilot's DAgger gate reads the task's tracked error from it.
    """

    phase: str
    started: int
    seed: int
    display: Display
    human_flies: bool
    observation: np.ndarray | None


@dataclass(frozen=True, slots=True)
class Polled:
    """One frame's input: the session commands read (in order) and the wall clock at which the
    input was read (what a real-time session records with the frame).

    ``remote``: for an input from afar (``collect web``), when the newest input arrived,
    its round trip and its age (``Remote``); None for a local input."""

    commands: list[str]
    read_at: float
    remote: Remote | None = None


@dataclass(frozen=True, slots=True)
class Remote:
    """The input a frame flies by, from afar: the wall clock (Unix s) it arrived at, its
    round trip (s, from sending the frame it answered to its arrival) and its age in frames
    (this frame's number less the answered one's; 1: the next frame)."""

    arrived_s: float
    trip_s: float
    age_frames: int


class Input(Protocol):
    """A source of commands and controls (module docstring)."""

    def poll(self, seen: Seen) -> Polled:
        """Read this frame's input: move the controls, return the commands."""
        ...

    def close(self) -> None: ...
