"""What the manual session's window shows each frame: the display model of the moment (the
session's ``display``: instruments, bugs, guidance), the state variables (``SHOWN``), the
stick, the briefing before an episode and the debrief after it, the session's state and,
beside them, the pilot's camera."""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

from gymfg_il.cockpit.windows.gui import GuiFrame
from gymfg_il.display.readings import Display
from gymfg_il.sim.properties import BY_NAME, INDEX
from gymfg_il.tasks.scenery import Landmark, landmarks_of

if TYPE_CHECKING:
    from gymfg_il.collectors.manual import ManualSession

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


def window_frame(session: ManualSession) -> GuiFrame:
    """The window's frame of the session as it is now."""
    env = session.env
    world = env.world
    state = world.slots[0].state
    flying = session.state != "idle"
    steps_left = world.max_steps - world.steps if flying else world.max_steps
    human = session.human_flies or not flying
    view = None
    if session.camera is not None:
        marks = landmarks_of(env.task, getattr(env.task, "plan", None), world.steps)
        view = session.camera.frame(state, next_gate_marked(marks, session.display))
    if flying:
        notes = session.briefing[:2]
    elif session.debrief is not None:
        notes = list(session.debrief.lines)
    else:
        notes = session.briefing
    return GuiFrame(
        action=session.human.values if human else session.last_action,
        trim=session.human.neutral if human else None,
        variables={n: (float(state[INDEX[n]]), BY_NAME[n].unit) for n in SHOWN},
        display=session.display,
        notes=notes,
        episode=session.episode,
        time_left_s=max(0.0, steps_left * env.dt),
        status=session.state,
        pilot=session.person if session.human_flies else str(session.assist_name),
        message=session.late_warning or session.message or session.human.status,
        help_lines=session.help,
        show_help=session.show_help,
        view=view,
    )


def next_gate_marked(marks: list[Landmark], display: Display) -> list[Landmark]:
    """``marks`` with the next gate to fly through highlighted (the display's gates left)."""
    gates = [i for i, mark in enumerate(marks) if mark.kind == "gate"]
    left = [r.value for r in display if r.name == "gates_left"]
    if not gates or not left or not 0 < left[0] <= len(gates):
        return marks
    at = gates[len(gates) - round(left[0])]
    return [dataclasses.replace(m, highlight=True) if i == at else m for i, m in enumerate(marks)]
