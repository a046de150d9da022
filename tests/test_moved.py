"""The old import paths users write keep working, each with a DeprecationWarning that names
the new home; the old ``python -m`` command runs the new one and says so."""

import importlib
import subprocess
import sys

import pytest

MOVED = {  # old module -> (new module, a name users import from it)
    "gymfg_il.controllers.agent": ("gymfg_il.agent", "ConstantAgent"),
    "gymfg_il.viz.flightgear": ("gymfg_il.flightgear.launcher", "FlightGear"),
    "gymfg_il.viz.netfdm": ("gymfg_il.flightgear.netfdm", "FlightGearSender"),
    "gymfg_il.viz.peers": ("gymfg_il.flightgear.peers", "MultiplayerConfig"),
    "gymfg_il.viz.multiplayer": ("gymfg_il.flightgear.multiplayer", "TrafficSender"),
    "gymfg_il.manual.cockpit": ("gymfg_il.flightgear.cockpit", "CockpitReceiver"),
    "gymfg_il.rl.env": ("gymfg_il.rl.envs", "make_env"),
    "gymfg_il.rl.vec": ("gymfg_il.rl.grouped.vec", "GroupedVecEnv"),
    "gymfg_il.rl.forward": ("gymfg_il.rl.grouped.forward", "NumpyActorCritic"),
    "gymfg_il.rl.sampling": ("gymfg_il.rl.grouped.sampling", "sample_rollout"),
    "gymfg_il.manual.gui": ("gymfg_il.cockpit.windows.gui", "ControlsGUI"),
    "gymfg_il.manual.pfd": ("gymfg_il.cockpit.windows.pfd", "PrimaryFlightDisplay"),
    "gymfg_il.collectors.manual": ("gymfg_il.cockpit.session", "ManualSession"),
    "gymfg_il.collectors.manual_view": ("gymfg_il.cockpit.windows.pygame_window", "SHOWN"),
    "gymfg_il.collectors.synthetic": ("gymfg_il.cockpit.inputs.synthetic_pilot", "SyntheticInput"),
    "gymfg_il.collectors.screenshot": ("gymfg_il.cockpit.screenshot", "main"),
    "gymfg_il.collectors.manual_keys": ("gymfg_il.cockpit.inputs.keys", "help_lines"),
    "gymfg_il.collectors.timing": ("gymfg_il.cockpit.timing", "EpisodeTiming"),
    "gymfg_il.collectors.updater": ("gymfg_il.cockpit.updater", "DatasetUpdater"),
    "gymfg_il.display.guidance": ("gymfg_il.tasks.guidance", "reading_names"),
    "gymfg_il.display.instruments": ("gymfg_il.tasks.guidance", "PRIMARY"),
}


@pytest.mark.parametrize("old", sorted(MOVED))
def test_an_old_path_gives_the_new_object_and_names_its_home(old):
    new, name = MOVED[old]
    with pytest.warns(DeprecationWarning, match=f"{old} has moved to {new}") as caught:
        value = getattr(importlib.import_module(old), name)
    assert value is getattr(importlib.import_module(new), name)
    assert caught[0].filename == __file__  # it points at the line that used the old path


NAMES = {  # (module that lives on, a name that moved out of it) -> its new home
    ("gymfg_il.tasks.courses", "ApproachTask"): "gymfg_il.tasks.approach",
    ("gymfg_il.tasks.scenery", "task_landmarks"): "gymfg_il.tasks.library",
}


@pytest.mark.parametrize(("old", "name"), sorted(NAMES))
def test_a_name_that_moved_out_of_a_living_module_gives_the_new_object(old, name):
    new = NAMES[old, name]
    with pytest.warns(DeprecationWarning, match=f"{old}.{name} has moved to {new}") as caught:
        value = getattr(importlib.import_module(old), name)
    assert value is getattr(importlib.import_module(new), name)
    assert caught[0].filename == __file__
    with pytest.raises(AttributeError, match=f"module '{old}' has no attribute 'Nothing'"):
        importlib.import_module(old).Nothing  # noqa: B018


GONE = {  # (module that lives on, a table each task now declares itself) -> what says it
    ("gymfg_il.controllers.autopilot", "MANEUVER_TARGETS"): "expert_targets",
    ("gymfg_il.controllers.autopilot", "scaled_for"): r"ManeuverTask\.expert\(\)",
    ("gymfg_il.manual.perception", "DISPLAY_SOURCES"): r"Task\.expert\(\)\.on_display",
}


@pytest.mark.parametrize(("old", "name"), sorted(GONE))
def test_a_table_a_task_now_declares_says_where_its_knowledge_went(old, name):
    with pytest.raises(AttributeError, match=f"{old}.{name} is gone: .*{GONE[old, name]}"):
        getattr(importlib.import_module(old), name)


def test_a_name_the_new_home_lacks_is_an_attribute_error_naming_both():
    old = importlib.import_module("gymfg_il.viz.peers")
    with pytest.raises(AttributeError, match=r"gymfg_il\.viz\.peers.*gymfg_il\.flightgear\.peers"):
        old.NoSuchThing  # noqa: B018


def test_a_name_with_no_new_home_says_what_replaced_it():
    old = importlib.import_module("gymfg_il.collectors.synthetic")
    with pytest.raises(AttributeError, match=r"SyntheticDriver is gone: .*pilot='synthetic'"):
        old.SyntheticDriver  # noqa: B018


def test_a_task_table_that_became_the_tasks_own_says_where_it_went():
    old = importlib.import_module("gymfg_il.display.guidance")
    with pytest.raises(AttributeError, match=r"APPROACH is gone: ApproachTask\.guidance"):
        old.APPROACH  # noqa: B018


def test_the_old_screenshot_command_runs_the_new_one_and_says_so():
    proc = subprocess.run(
        [sys.executable, "-m", "gymfg_il.collectors.screenshot", "--help"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 0, proc.stderr
    assert "python -m gymfg_il.cockpit.screenshot" in proc.stdout
    assert "use python -m gymfg_il.cockpit.screenshot" in proc.stderr


def test_the_old_multiplayer_command_runs_the_new_one_and_says_so():
    proc = subprocess.run(
        [sys.executable, "-m", "gymfg_il.viz.multiplayer", "listen", "--help"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 0, proc.stderr
    assert "python -m gymfg_il.flightgear.multiplayer listen" in proc.stdout
    assert "use python -m gymfg_il.flightgear.multiplayer" in proc.stderr
