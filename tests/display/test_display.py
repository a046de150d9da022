"""The display model: every task's readings, drawn by the window, and the only thing the
synthetic pilot reads."""

import math

import numpy as np
import pytest

from gymfg_il.cockpit.windows.gui import ControlsGUI, GuiFrame, spoken
from gymfg_il.display.briefing import briefing, debrief
from gymfg_il.display.readings import PRIMARY, display_of
from gymfg_il.manual.perception import MOTION, DisplayIntent
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.tasks.guidance import Line, reading_names
from gymfg_il.tasks.library import TASK_FAMILIES, DummyTask

MANEUVERS = ("turn", "climb-turn", "waypoints", "formation", "approach")
TARGETS = ("altitude", "roll", "pitch", "heading", "airspeed", "sideslip")
EVERY_TASK = (*TARGETS, "level", "dummy", *MANEUVERS)


def started(make_env, task, seed=5, aircraft="c172p"):
    env = make_env(task, aircraft, agent_hz=30)
    env.reset(seed=seed)
    return env, display_of(env.task, env.world.slots[0].state, env.world.steps)


@pytest.fixture(scope="module")
def gui():
    window = ControlsGUI()
    yield window
    window.close()


@pytest.mark.parametrize("task", EVERY_TASK)
def test_the_window_draws_every_reading_of_the_display_model(make_env, gui, task):
    env, display = started(make_env, task)
    assert display.names == reading_names(env.task)
    assert len(set(display.names)) == len(display.names)  # one reading, one name
    gui.draw(GuiFrame(action=np.zeros(4), display=display))
    assert gui.drawn == set(display.names)
    if any(r.role == "bug" for r in display):  # a target shows as a magenta bug
        import pygame

        pixels = pygame.surfarray.array3d(gui.screen).reshape(-1, 3)
        assert (np.abs(pixels - (235, 80, 235)).sum(1) == 0).sum() > 20


@pytest.mark.parametrize("task", EVERY_TASK)
def test_the_pilot_reads_only_what_the_window_draws(make_env, task):
    env, display = started(make_env, task)
    intent = DisplayIntent(env.task, "c172p", env.dt, 0.6)
    assert intent.used <= set(display.names)
    assert set(MOTION.values()) <= set(PRIMARY)  # the rates come from the drawn attitude


def test_the_targets_are_the_tasks_own(make_env):
    env, display = started(make_env, "altitude")
    assert display["altitude_ft_target"] == pytest.approx(env.task.target_value(0), abs=0.01)
    env, display = started(make_env, "turn")
    plan = env.task.plan
    assert display["altitude_ft_target"] == plan["altitude_ft"]
    new = (plan["start_heading_deg"] + plan["turn_deg"]) % 360
    assert display["heading_deg_target"] == pytest.approx(new)
    assert display["turn_remaining_deg"] == pytest.approx(plan["turn_deg"], abs=0.01)


def test_the_approach_shows_an_ils(make_env):
    env, display = started(make_env, "approach")
    observed = env.task.observe(env.world.slots[0].state, 0)
    obs = dict(zip(env.observation_names, observed, strict=True))
    assert display["approach_kts"] == pytest.approx(env.task.plan["approach_kts"], abs=0.01)
    # the needles agree with the offsets: right of the centre line reads positive dots
    assert math.copysign(1, display["localizer_dots"]) == math.copysign(
        1, obs["centerline_offset_ft"]
    )
    assert math.copysign(1, display["glideslope_dots"]) == math.copysign(
        1, obs["glidepath_error_ft"]
    )
    assert 18000 < display["distance_ft"] < 25000  # 3.5-4 NM out


def test_a_reading_is_said_as_a_pilot_says_it(make_env):
    _, display = started(make_env, "formation")
    said = {r.name: spoken(r) for r in display}
    assert said["behind_slot_ft"].endswith(("behind", "ahead"))
    assert said["lead_heading_deg"].isdigit() and len(said["lead_heading_deg"]) == 3
    _, display = started(make_env, "approach")
    assert {r.name: spoken(r) for r in display}["distance_ft"].endswith("NM")


def test_the_pilot_flies_without_the_observation(make_env):
    env, _ = started(make_env, "turn")
    agent = AgentSpec.synthetic("keyboard", 0.7).make(env)
    agent.reset(5)
    blind = np.full(len(env.observation_names), np.nan)
    for _ in range(30):
        action = agent.act(blind)
        env.step(action)
    assert np.isfinite(action).all()


def test_the_briefing_is_the_tasks_docstring_and_the_debrief_its_verdict(make_env):
    env, _ = started(make_env, "turn")
    words = " ".join(briefing(env.task, 90))
    assert "Turn by 60-180 degrees" in words and "within 5 deg" in words
    states = np.array([env.world.slots[0].state] * 3)
    crashed = debrief(env.task, states, np.zeros(2), env.dt, "crashed", -5.0)
    assert not crashed.success and crashed.lines[0] == "FAILED: crashed"
    env, _ = started(make_env, "altitude")
    assert "within 50 ft of the target" in " ".join(briefing(env.task, 90))
    held = debrief(env.task, states, np.full(400, 10.0), env.dt, "time limit", 600.0)
    assert held.success and held.lines[0].startswith("SUCCESS")
    missed = debrief(env.task, states, np.full(400, 80.0), env.dt, "time limit", 400.0)
    assert not missed.success


def test_a_task_of_your_own_declares_what_the_window_shows(make_env):
    """#53: a task owns its guidance; the display reads the declaration, no table."""

    class Glide(DummyTask):
        name = "glide"
        guidance = (Line("sink_fpm", "ft/min", "panel", "guidance", "sink rate"),)

        def guidance_values(self, observed):
            return [-60.0 * observed["vertical_speed_fps"]]

    env, _ = started(make_env, "dummy")
    state = env.world.slots[0].state
    task = Glide()
    task.bind(env.aircraft, env.dt, 900)
    display = display_of(task, state, 0)
    assert display.names == reading_names(task) == (*PRIMARY, "sink_fpm")
    assert display["sink_fpm"] == pytest.approx(-60.0 * display["vertical_speed_fps"], rel=1e-6)


def test_every_library_task_is_checked_here():
    assert set(EVERY_TASK) == set(TASK_FAMILIES)


def test_the_next_gate_is_highlighted_in_the_view(make_env):
    from gymfg_il.cockpit.windows.pygame_window import next_gate_marked
    from gymfg_il.tasks.scenery import landmarks_of

    env, display = started(make_env, "waypoints")
    marks = next_gate_marked(landmarks_of(env.task, env.task.plan, 0), display)
    assert [m.highlight for m in marks] == [True, False, False]  # 3 gates left: the first
