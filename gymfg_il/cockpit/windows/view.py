"""What a window of the cockpit session is: a sink that draws each frame's ``CockpitView``
(the display model, the controls, the session's phase and words), gathered by the session
from its stages. The windows: pygame's (``pygame_window``), and none (``NoWindow``: a
headless session draws nothing, and no view is gathered for it)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from gymfg_il.display.briefing import Debrief
from gymfg_il.display.readings import Display


@dataclass(frozen=True, slots=True)
class CockpitView:
    """One frame as a window draws it.

    Attributes:
        status: the session's phase (``idle``, ``recording``, ``paused``).
        episode: the number of the episode flown (or next).
        steps: agent steps flown this episode.
        state: the aircraft's state (catalogue order).
        display: the display model of the moment (``display.readings``).
        controls: the controls a person holds (the ManualController's).
        trim: their neutral (aileron, elevator, rudder).
        flown: what was flown last (shown while the assistant flies).
        human_flies: the person (not the assistant) has the controls.
        debrief: the last episode's verdict (None before the first ends, and while flying).
        message: the session's line (what to do next), or a device's status.
        late: the warning while frames come late ("" when none).
        show_help: show the keys.
        seed: the seed of the episode in flight (or of the next one).
        started: episodes started so far (a new number: a new episode).
    """

    status: str
    episode: int
    steps: int
    state: np.ndarray
    display: Display
    controls: np.ndarray
    trim: np.ndarray
    flown: np.ndarray
    human_flies: bool
    debrief: Debrief | None
    message: str
    late: str
    show_help: bool
    seed: int = 0
    started: int = 0


class Window(Protocol):
    """A sink of frames (module docstring); ``shown``: it draws (else no view is gathered)."""

    shown: bool

    def draw(self, view: CockpitView) -> None: ...

    def close(self) -> None: ...


class NoWindow:
    """No window: a headless session (the synthetic pilot, a test) draws nothing."""

    shown = False

    def draw(self, view: CockpitView) -> None:
        """Nothing to draw."""

    def close(self) -> None:
        """Nothing to close."""
