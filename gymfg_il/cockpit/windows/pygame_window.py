"""The cockpit's pygame window: each frame's view (``windows.view.CockpitView``) drawn by the
controls GUI (``windows.gui``): the display model (instruments, bugs, guidance), the state
variables (``SHOWN``), the stick and its trim, the briefing before an episode and the debrief
after it, the session's phase and, beside them, the pilot's camera."""

from __future__ import annotations

import dataclasses
from typing import Any

from gymfg_il.cockpit.windows.gui import ControlsGUI, GuiFrame
from gymfg_il.cockpit.windows.view import CockpitView
from gymfg_il.display.readings import Display
from gymfg_il.sim.properties import BY_NAME, INDEX
from gymfg_il.tasks.scenery import Landmark, landmarks_of
from gymfg_il.viz.camera import Camera

SHOWN = (
    "altitude_ft",
    "airspeed_kts",
    "vertical_speed_fps",
    "heading_deg",
    "roll_deg",
    "pitch_deg",
    "alpha_deg",
    "beta_deg",
    "thrust_lbs",
)


def window_size(camera: bool) -> tuple[int, int]:
    """The window's size, with the pilot's camera beside the instruments or without (the
    mouse stick is centred in it, so a headless session keeps the size it would have)."""
    return (1250, 700) if camera else (900, 700)


class PygameWindow:
    """Draws each view into a pygame window (module docstring).

    Args:
        gui: the window.
        camera: the pilot's view beside the instruments (None: none).
        task: the bound task (its landmarks are drawn in the camera's view).
        max_steps, dt: the episode's length in agent steps, and a step's seconds.
        briefing: the task in words (``display.briefing``).
        help_lines: the keys (``inputs.keys.help_lines``).
        pilot: who flies when the person does (``human``, ``synthetic``).
        assistant: who flies when the person lets it (``controller``, ``policy``, or None).
    """

    shown = True

    def __init__(
        self,
        gui: ControlsGUI,
        camera: Camera | None,
        task: Any,
        max_steps: int,
        dt: float,
        *,
        briefing: list[str],
        help_lines: list[str],
        pilot: str,
        assistant: str | None,
    ) -> None:
        self.gui, self.camera, self.task = gui, camera, task
        self.max_steps, self.dt = max_steps, dt
        self.briefing, self.help_lines = briefing, help_lines
        self.pilot, self.assistant = pilot, assistant

    def draw(self, view: CockpitView) -> None:
        self.gui.draw(self.frame(view))

    def frame(self, view: CockpitView) -> GuiFrame:
        """What the GUI draws of ``view``."""
        flying = view.status != "idle"
        steps_left = self.max_steps - view.steps if flying else self.max_steps
        human = view.human_flies or not flying
        if flying:
            notes = self.briefing[:2]
        elif view.debrief is not None:
            notes = list(view.debrief.lines)
        else:
            notes = self.briefing
        return GuiFrame(
            action=view.controls if human else view.flown,
            trim=view.trim if human else None,
            variables={n: (float(view.state[INDEX[n]]), BY_NAME[n].unit) for n in SHOWN},
            display=view.display,
            notes=notes,
            episode=view.episode,
            time_left_s=max(0.0, steps_left * self.dt),
            status=view.status,
            pilot=self.pilot if view.human_flies else str(self.assistant),
            message=view.late or view.message,
            help_lines=self.help_lines,
            show_help=view.show_help,
            view=self._camera(view),
        )

    def _camera(self, view: CockpitView) -> Any:
        if self.camera is None:
            return None
        marks = landmarks_of(self.task, getattr(self.task, "plan", None), view.steps)
        return self.camera.frame(view.state, next_gate_marked(marks, view.display))

    def close(self) -> None:
        self.gui.close()


def next_gate_marked(marks: list[Landmark], display: Display) -> list[Landmark]:
    """``marks`` with the next gate to fly through highlighted (the display's gates left)."""
    gates = [i for i, mark in enumerate(marks) if mark.kind == "gate"]
    left = [r.value for r in display if r.name == "gates_left"]
    if not gates or not left or not 0 < left[0] <= len(gates):
        return marks
    at = gates[len(gates) - round(left[0])]
    return [dataclasses.replace(m, highlight=True) if i == at else m for i, m in enumerate(marks)]
