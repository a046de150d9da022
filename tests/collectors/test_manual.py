"""The manual collector driven headless by injected pygame events, for all three devices."""

import dataclasses
import os
import shutil

import numpy as np
import pytest

os.environ["SDL_VIDEODRIVER"] = "dummy"
import pygame

from gymfg_il.cockpit.session import ManualSession
from gymfg_il.collectors.config import ManualConfig
from gymfg_il.datasets.lerobot_api import open_metadata
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import ConfigError
from gymfg_il.learning.data import load_frames
from gymfg_il.manual.bindings import deflect, deflection

FLIGHT = {"task": "altitude", "episode_time_s": 3, "agent_hz": 30}  # 90 frames an episode


def manual_config(out, **kwargs):
    """A person's session (until they quit) of the altitude task, into ``out``."""
    return ManualConfig(**{**FLIGHT, "episodes": 0, "out": out, **kwargs})


def key(k, down=True):
    kind = pygame.KEYDOWN if down else pygame.KEYUP
    pygame.event.post(pygame.event.Event(kind, key=k, mod=0, unicode="", scancode=0))


def driven(frame, session):
    """A test drives these sessions (a session without a driver is a person's, which needs a
    real window: tests/collectors/test_manual_person.py)."""


def run(out, script, **kwargs):
    def on_frame(frame, session):
        for event in script.get(frame, []):
            event() if callable(event) else pygame.event.post(event)

    session = ManualSession(manual_config(out, **kwargs), on_frame, realtime=False)
    return session.run(max_frames=400)


@pytest.mark.slow
def test_keyboard_rates_and_centring_reach_the_dataset(tmp_path):
    script = {
        1: [lambda: key(pygame.K_SPACE)],
        3: [lambda: key(pygame.K_LEFT)],
        13: [lambda: key(pygame.K_LEFT, False)],
        40: [lambda: key(pygame.K_PAGEUP)],
        46: [lambda: key(pygame.K_PAGEUP, False)],
        200: [lambda: key(pygame.K_q)],
    }
    stats = run(tmp_path, script)
    assert stats.saved == 1
    assert stats.closing_s > 0  # the session's end is timed (benchmarks.manual reports it)
    frames = load_frames(tmp_path / "dataset")
    aileron, throttle = frames.action[:, 0], frames.action[:, 3]
    assert len(aileron) == 90
    # the stick's neutral is the trimmed start's controls: frame 0 flies them
    trim = aileron[0]
    assert 0.01 < abs(trim) < 0.1  # the c172p trims with a little aileron
    # session frame k flies dataset frame k - 1 (Space at frame 1 starts and flies frame 0);
    # left held for session frames 3..12 at 1.5/s: -0.05 per frame
    assert aileron[1] == trim and aileron[2] == pytest.approx(trim - 0.05)
    assert aileron[11] == pytest.approx(trim - 0.5, abs=1e-6)
    # released: back to the neutral at 1/s (1/30 per frame) -> there 15 frames later
    assert aileron[12] == pytest.approx(trim - 0.5 + 1 / 30, abs=1e-6)
    assert aileron[30] == trim
    # throttle up for 6 frames at 0.5/s from the trim's throttle; released, it stays
    assert throttle[38] == throttle[0]
    assert throttle[45] == pytest.approx(throttle[0] + 6 * 0.5 / 30, abs=1e-6)
    assert throttle[60] == throttle[45]
    assert not frames.episodes["gymfg/interventions"][0]
    assert frames.episodes["gymfg/source"] == ["human"]


@pytest.mark.slow
def test_mouse_is_the_stick(tmp_path):
    move = pygame.event.Event(
        pygame.MOUSEMOTION, pos=(625 + 100, 350 - 50), rel=(0, 0), buttons=(0, 0, 0)
    )  # the window (1,250 x 700 with the pilot's view) centres the stick
    script = {1: [lambda: key(pygame.K_SPACE)], 5: [move], 200: [lambda: key(pygame.K_q)]}
    run(tmp_path, script, device="mouse")
    frames = load_frames(tmp_path / "dataset")
    # 100 px right of centre, 50 px up, span 200 px: aileron 0.5, elevator +0.25 (nose down)
    # of the travel from the stick's neutral (the trim the episode starts with, flown at
    # frame 0) to full deflection
    trim = frames.action[0]
    assert frames.action[4, 0] == pytest.approx(trim[0] + 0.5 * (1 - trim[0]))
    assert frames.action[4, 1] == pytest.approx(trim[1] + 0.25 * (1 - trim[1]))
    assert frames.action[2, 0] == trim[0] and trim[1] > 0.1  # the c172p's trimmed elevator


@pytest.mark.slow
def test_joystick_axes_buttons_and_unplugging(tmp_path):
    added = pygame.event.Event(pygame.JOYDEVICEADDED, device_index=0, instance_id=0)
    axis = pygame.event.Event(pygame.JOYAXISMOTION, instance_id=0, axis=0, value=0.6)
    pitch = pygame.event.Event(pygame.JOYAXISMOTION, instance_id=0, axis=1, value=0.02)
    removed = pygame.event.Event(pygame.JOYDEVICEREMOVED, instance_id=0)
    button_end = pygame.event.Event(pygame.JOYBUTTONDOWN, instance_id=0, button=2)
    script = {
        0: [added],
        1: [lambda: key(pygame.K_SPACE)],
        5: [axis, pitch],
        30: [removed],
        40: [added, axis],
        60: [button_end],
        200: [lambda: key(pygame.K_q)],
    }
    stats = run(tmp_path, script, device="joystick", joystick={"buttons": {2: "end"}})
    assert stats.saved == 1
    frames = load_frames(tmp_path / "dataset")
    a = frames.action
    shaped = ((0.6 - 0.05) / 0.95) * 0.7 + 0.3 * ((0.6 - 0.05) / 0.95) ** 3
    trim = a[0]  # the stick deflects from its neutral, the trim flown at frame 0
    assert a[4, 0] == pytest.approx(deflect(trim[0], shaped), rel=1e-6)
    assert a[4, 1] == trim[1]  # inside the dead zone
    assert a[29, 0] == trim[0]  # unplugged: centred, and the session went on
    assert a[39, 0] == pytest.approx(deflect(trim[0], shaped), rel=1e-6)  # plugged back in
    assert len(a) == 59  # the button ended and saved the episode


@pytest.mark.slow
def test_takeover_from_the_controller_is_flagged_and_handed_back(tmp_path):
    script = {
        1: [lambda: key(pygame.K_SPACE)],
        20: [lambda: key(pygame.K_t)],
        21: [lambda: key(pygame.K_UP)],
        30: [lambda: key(pygame.K_UP, False)],
        40: [lambda: key(pygame.K_t)],
        200: [lambda: key(pygame.K_q)],
    }
    run(tmp_path, script, assist="controller")
    frames = load_frames(tmp_path / "dataset")
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    ds = LeRobotDataset("x/y", root=tmp_path / "dataset", video_backend="pyav")
    intervention = np.array([bool(ds[i]["intervention"]) for i in range(len(ds))])
    assert intervention[:19].sum() == 0 and intervention[19:39].all()
    assert intervention[39:].sum() == 0
    assert frames.episodes["gymfg/interventions"] == [20]
    assert frames.episodes["gymfg/source"] == ["controller+human"]
    # the human pushed the nose down while flying; the controller's hand-back is bumpless
    assert frames.action[25, 1] > frames.action[18, 1]
    assert abs(frames.action[39, 1] - frames.action[38, 1]) < 0.1


@pytest.mark.slow
def test_discarded_episode_is_flown_again_with_its_seed(tmp_path):
    script = {
        1: [lambda: key(pygame.K_SPACE)],
        10: [lambda: key(pygame.K_BACKSPACE)],
        12: [lambda: key(pygame.K_SPACE)],
        300: [lambda: key(pygame.K_q)],
    }
    stats = run(tmp_path, script, seed=7)
    assert (stats.saved, stats.discarded) == (1, 1)
    frames = load_frames(tmp_path / "dataset")
    assert frames.episodes["gymfg/seed"] == [7] and len(frames) == 90


@pytest.mark.slow
def test_appending_another_task_is_refused(tmp_path):
    run(tmp_path, {1: [lambda: key(pygame.K_SPACE)], 200: [lambda: key(pygame.K_q)]})
    with pytest.raises(ConfigError, match="features differ"):
        ManualSession(manual_config(tmp_path, task="roll"), driven, realtime=False)


def test_the_gui_shows_the_tasks_target_while_flying(tmp_path):
    drawn = []

    def spy(session):
        gui = session.stages.window.gui
        draw = gui.draw
        gui.draw = lambda frame: (drawn.append(frame), draw(frame))

    def on_frame(frame, session):
        if frame == 1:
            spy(session)
            key(pygame.K_SPACE)
        if frame == 20:
            key(pygame.K_q)

    ManualSession(manual_config(tmp_path), on_frame, realtime=False).run(max_frames=40)
    flying = [f for f in drawn if f.status != "idle"]
    assert flying and all("altitude_ft_target" in f.display.names for f in flying)
    assert all(
        abs(f.display["altitude_ft_target"] - f.display["altitude_ft"]) <= 1000 for f in flying
    )
    idle = [f for f in drawn if f.status == "idle"]
    assert idle and "altitude_ft_target" not in idle[0].display.names  # no target before
    assert any("Success" in line for line in idle[0].notes)  # the briefing, before it


@pytest.mark.slow
def test_the_window_says_how_an_episode_went(tmp_path):
    def on_frame(frame, session):
        if frame == 1:
            key(pygame.K_SPACE)
        if frame == 100:
            key(pygame.K_q)

    session = ManualSession(manual_config(tmp_path, episode_time_s=2), on_frame, realtime=False)
    session.run(max_frames=120)
    said = session.stages.log.debrief
    assert said is not None and not said.success  # 2 s: not held yet
    assert said.lines[0].startswith("FAILED: over the last 10 s")


def test_the_window_shows_the_pilots_view_beside_the_instruments(tmp_path):
    shots = {}

    def on_frame(frame, session):
        if frame == 1:
            key(pygame.K_SPACE)
        if frame in (2, 25):
            shots[frame] = pygame.surfarray.array3d(session.stages.window.gui.screen).transpose(
                1, 0, 2
            )
        if frame < 25:
            key(pygame.K_RIGHT)  # roll right: the horizon in the view turns
        if frame == 30:
            key(pygame.K_q)

    session = ManualSession(manual_config(tmp_path), on_frame, realtime=False)
    window = session.stages.window
    assert window.gui.size == (1250, 700) and window.camera is not None
    session.run(max_frames=40)
    # the view's box right of the instruments: sky on top (blue), ground below (green)
    for shot in shots.values():
        view = shot[100:420, 1250 - 340 : 1250 - 20].astype(int)
        assert (view[20:60, :, 2] > view[20:60, :, 1]).mean() > 0.9
    # after rolling, the view changed
    assert np.abs(shots[2][100:420, 910:1230].astype(int) - shots[25][100:420, 910:1230]).mean() > 3
    headless = ManualSession(
        manual_config(tmp_path / "b", pilot_view="none"), driven, realtime=False
    )
    window = headless.stages.window
    assert window.gui.size == (900, 700) and window.camera is None


def test_a_policy_assists_only_at_the_rate_it_was_trained_at(tmp_path):
    import json

    policy = tmp_path / "policy"
    policy.mkdir()
    (policy / "model.safetensors").write_bytes(b"not read")
    spec = FlightSpec.solo("c172p", "altitude", agent_hz=10)
    stats = {"mean": [0.0], "std": [1.0]}
    config = {"type": "mlp", "policy": {}, "obs_stats": stats, "action_stats": stats}
    (policy / "config.json").write_text(json.dumps({**config, "spec": spec.to_dict(), "fps": 10}))
    with pytest.raises(ConfigError, match=r"trained at 10 Hz.*at 30 Hz"):
        ManualSession(manual_config(tmp_path / "out", assist=str(policy)), driven, realtime=False)


@pytest.mark.slow
def test_the_dataset_helper_builds_on_request_and_outlives_a_crash(tmp_path, caplog):
    from gymfg_il import collect
    from gymfg_il.cockpit.updater import DatasetUpdater

    argv = ["autopilot", "--episodes", "2", "--episode-time", "2", "--out", str(tmp_path)]
    assert collect.main([*argv, "--no-progress"]) == 0
    shutil.rmtree(tmp_path / "dataset")
    updater = DatasetUpdater(tmp_path)
    updater.warm()
    assert updater.proc is not None
    updater.proc.kill()  # the helper dies before its first build: another takes over
    updater.proc.wait()
    updater.request()
    updater.request()  # while one builds: one more after it
    assert updater.pending and updater.close() and updater.failures == 0
    assert len(load_frames(tmp_path / "dataset").episodes["gymfg/seed"]) == 2
    (tmp_path / "logs" / "zz-broken.mcap").write_bytes(os.urandom(4000))
    updater = DatasetUpdater(tmp_path)
    updater.request()
    updater.request()  # queued behind a build that reports damage: still run
    # the first build sets the broken file aside (and the session hears it); the next is clean
    assert updater.close() and updater.failures == 1
    assert "could not be read" in caplog.text and "collect recover" in caplog.text
    assert (tmp_path / "logs" / "zz-broken.mcap.set-aside").is_file()
    assert len(load_frames(tmp_path / "dataset").episodes["gymfg/seed"]) == 2  # nothing lost


def test_a_trimmed_stick_keeps_its_full_travel():
    """Full stick either way is the full command whatever the trim; a pilot aiming at a
    command finds the deflection that gives it."""
    for trim in (0.18, -0.3, 0.0):
        assert deflect(trim, 0.0) == trim
        assert deflect(trim, 1.0) == 1.0 and deflect(trim, -1.0) == -1.0
        for command in (-1.0, -0.5, trim, 0.4, 1.0):
            v = deflection(trim, command)
            assert -1.0 <= v <= 1.0 and deflect(trim, v) == pytest.approx(command)
    assert deflect(0.18, 0.5) == pytest.approx(0.59) and deflect(0.18, -0.5) == -0.41


@pytest.mark.slow
def test_trim_keys_move_the_neutral_the_surface_stays_on(tmp_path):
    script = {
        1: [lambda: key(pygame.K_SPACE)],
        3: [lambda: key(pygame.K_END)],  # elevator trim nose up, 30 frames at 0.1/s
        33: [lambda: key(pygame.K_END, False)],
        40: [lambda: key(pygame.K_DELETE)],  # rudder trim right, 15 frames
        55: [lambda: key(pygame.K_DELETE, False)],
        60: [lambda: key(pygame.K_UP)],  # nose down 6 frames, then released: back to the trim
        66: [lambda: key(pygame.K_UP, False)],
        200: [lambda: key(pygame.K_q)],
    }
    stats = run(tmp_path, script)
    assert stats.saved == 1
    frames = load_frames(tmp_path / "dataset")
    elevator, rudder = frames.action[:, 1], frames.action[:, 2]
    start_elevator, start_rudder = elevator[0], rudder[0]
    # session frame k flies dataset frame k - 1: trim held for session frames 3..32
    assert elevator[31] == pytest.approx(start_elevator - 30 * 0.1 / 30, abs=1e-6)
    assert elevator[50] == elevator[31]  # released, the surface stays on the new trim
    assert rudder[54] == pytest.approx(start_rudder + 15 * 0.1 / 30, abs=1e-6)
    # a surface key's deflection centres back on the new trim, not on the start's
    assert elevator[64] > elevator[31] + 0.2
    assert elevator[89] == pytest.approx(elevator[31], abs=1e-6)
    assert rudder[89] == pytest.approx(rudder[54], abs=1e-6)


def test_the_help_names_the_trim_keys():
    from gymfg_il.cockpit.inputs.keys import help_lines
    from gymfg_il.manual.bindings import KeyboardBindings

    text = "\n".join(help_lines("keyboard", KeyboardBindings()))
    assert "TRIM" in text and "home" in text and "end" in text and "delete" in text
    assert "TRIM" not in "\n".join(help_lines("joystick", KeyboardBindings()))


@pytest.mark.slow
def test_verdicts_marks_and_the_pilot_reach_the_dataset_and_its_card(tmp_path):
    script = {
        1: [lambda: key(pygame.K_SPACE)],
        100: [lambda: key(pygame.K_b), lambda: key(pygame.K_g)],  # the last mark counts
        110: [lambda: key(pygame.K_SPACE)],
        230: [lambda: key(pygame.K_q)],
    }
    stats = run(tmp_path, script, pilot_name="ann")
    assert stats.saved == 2
    frames = load_frames(tmp_path / "dataset")
    eps = frames.episodes
    assert eps["gymfg/pilot"] == ["ann", "ann"]
    assert eps["gymfg/mark"] == ["success", ""]  # the second was never marked
    # 3 s of altitude cannot hold the target for the last 10 s: the task's judge says so
    assert eps["gymfg/success"] == [0, 0]
    assert all(v.startswith("over the last") for v in eps["gymfg/verdict"])
    assert eps["gymfg/grade"] == ["unsatisfactory"] * 2  # a failure's grade
    card = (tmp_path / "dataset" / "README.md").read_text()
    assert "| verdicts | 0 of 2 succeeded by the task's own judge |" in card
    assert "| grades | 2 unsatisfactory |" in card
    assert "| pilots | ann: 2 episodes, 0 succeeded (2 unsatisfactory) |" in card
    assert "success (1 episode)" in card


@pytest.mark.slow
def test_a_mark_needs_an_ended_episode(tmp_path):
    # before any episode, and while one is flown, G and B mark nothing
    script = {
        0: [lambda: key(pygame.K_g)],
        1: [lambda: key(pygame.K_SPACE)],
        20: [lambda: key(pygame.K_b)],
        150: [lambda: key(pygame.K_q)],
    }
    run(tmp_path, script)
    eps = load_frames(tmp_path / "dataset").episodes
    assert eps["gymfg/mark"] == [""] and eps["gymfg/pilot"] == [""]


@pytest.mark.slow
def test_train_selects_episodes_by_pilot_mark_and_verdict(tmp_path):
    from gymfg_il.learning.config import TrainConfig
    from gymfg_il.learning.selection import selected

    fly = {1: [lambda: key(pygame.K_SPACE)], 100: [lambda: key(pygame.K_q)]}
    run(tmp_path, {**fly, 95: [lambda: key(pygame.K_g)]}, pilot_name="ann")
    run(tmp_path, fly, pilot_name="bob", seed=50)  # appended (another case: not a twin)
    frames = load_frames(tmp_path / "dataset")
    assert frames.episodes["gymfg/pilot"] == ["ann", "bob"]
    bob = selected(frames, ["pilot=bob"], "here")
    assert set(bob.episode) == {1} and len(bob) == 90
    assert set(selected(frames, ["mark=success"], "here").episode) == {0}
    assert set(selected(frames, ["failure", "pilot=ann"], "here").episode) == {0}
    with pytest.raises(ConfigError, match="no episode"):
        selected(frames, ["success"], "here")
    # a dataset built before the column existed
    older = dataclasses.replace(
        frames, episodes={k: v for k, v in frames.episodes.items() if k != "gymfg/pilot"}
    )
    with pytest.raises(ConfigError, match=r"records no gymfg/pilot.*collect recover"):
        selected(older, ["pilot=ann"], "an older dataset")
    with pytest.raises(ConfigError, match="mark= takes success or failure"):
        TrainConfig(select=["mark=good"])


@pytest.mark.slow
def test_a_slow_loop_counts_its_late_frames_and_the_window_warns(tmp_path):
    """In real time, frames made late by a slow loop are counted (the episode is kept), the
    window warns while it happens, and the dataset and card give the rate and jitter."""
    import time

    seen = []

    def late_warning(session):
        return session.stages.log.late_warning(session.stages.phases.state == "recording")

    def on_frame(frame, session):
        if frame == 1:
            key(pygame.K_SPACE)
        if frame in range(20, 26):
            time.sleep(0.1)  # 3 periods at 30 Hz: late by any measure
        if frame == 27:
            seen.append(late_warning(session))
        if frame == 95:  # the episode (90 frames from frame 1) has ended
            seen.append(late_warning(session))
            key(pygame.K_q)

    session = ManualSession(manual_config(tmp_path), on_frame, realtime=True)
    assert session.run(max_frames=200).saved == 1
    assert seen[0].startswith("LATE: ") and seen[1] == ""  # warned while flying, not after
    eps = load_frames(tmp_path / "dataset").episodes
    late = eps["gymfg/late_frames"][0]
    assert 6 <= late == session.stages.log.timing.late  # a busy machine may make more late
    # 6 frames of 133 ms among 90 of 33 ms: at most 27 Hz, the spread tens of ms
    assert 5 < eps["gymfg/rate_hz"][0] < 27.5 and eps["gymfg/jitter_ms"][0] > 10
    card = (tmp_path / "dataset" / "README.md").read_text()
    assert f"| timing | {late} late frame(s) in 1 of 1 real-time episodes; episode 0: " in card
    # each frame keeps the wall clock its input was read at, from the episode's first
    # frame (its Unix time in gymfg/wall_start): the slow frames show there, beside the
    # simulation's timestamp, which stays frame / fps
    clock, timestamp = frame_columns(tmp_path / "dataset", "wall_time", "timestamp")
    gaps = np.diff(clock)
    assert len(clock) == 90 and clock[0] == 0 and (gaps > 0).all()
    assert abs(eps["gymfg/wall_start"][0] - time.time()) < 60
    assert sum(gaps > 0.09) >= 6 and sum(gaps > 1.5 / 30) == pytest.approx(late, abs=1)
    assert np.median(gaps) == pytest.approx(1 / 30, abs=0.01)  # paced at 30 Hz otherwise
    assert clock[-1] - timestamp[-1] > 0.4  # the flight ran 0.6 s slower than its simulation
    np.testing.assert_allclose(timestamp, np.arange(90) / 30, atol=1e-6)


def frame_columns(root, *names):
    """Per-frame columns of a dataset, as stock LeRobot loads them."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    dataset = LeRobotDataset("gymfg/test", root=root)
    frames = [dataset[i] for i in range(dataset.num_frames)]
    return [np.array([float(f[n]) for f in frames]) for n in names]


@pytest.mark.slow
def test_a_session_run_as_fast_as_it_can_records_no_timing(tmp_path):
    run(tmp_path, {1: [lambda: key(pygame.K_SPACE)], 100: [lambda: key(pygame.K_q)]})
    eps = load_frames(tmp_path / "dataset").episodes
    assert eps["gymfg/late_frames"] == [-1] and eps["gymfg/rate_hz"] == [-1.0]
    card = (tmp_path / "dataset" / "README.md").read_text()
    assert "| timing | not recorded (no episode was flown in real time) |" in card
    assert "wall_time" not in open_metadata(tmp_path / "dataset").features  # no clock to keep
