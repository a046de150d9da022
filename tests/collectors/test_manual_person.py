"""A person's session that could never get input says what is missing and exits, instead of
waiting silently (red-team finding: with no display pygame drew nowhere and the session waited
for keys nobody could press; with no joystick it read nothing, both until killed)."""

import os
import subprocess
import sys

import pytest

DEADLINE_S = 300  # only a hang reaches it: the refusal comes before anything is built


def collect_manual(tmp_path, env_changes, *extra):
    """``collect manual``'s stderr, where it refuses; a variable of ``env_changes`` that is
    None, and the display's variables not given, are unset."""
    env = {**os.environ, "HF_HUB_OFFLINE": "1"}
    env.update({name: value for name, value in env_changes.items() if value is not None})
    for name in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER", *env_changes):
        if env_changes.get(name) is None:
            env.pop(name, None)
    out = tmp_path / "session"
    argv = ["manual", "--episodes", "1", "--out", str(out), *extra]
    try:
        done = subprocess.run(
            [sys.executable, "-m", "gymfg_il.collect", *argv],
            env=env,
            capture_output=True,
            text=True,
            timeout=DEADLINE_S,
        )
    except subprocess.TimeoutExpired as hung:
        pytest.fail(f"collect manual {' '.join(extra)} waited silently: {hung.stderr!r}")
    assert done.returncode == 2, done.stdout + done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    assert not out.exists()  # refused before anything was made
    # the project's error is the first thing said, and the only one
    assert done.stderr.startswith("error: ") and done.stderr.count("error:") == 1, done.stderr
    return done.stderr


def test_no_display_says_so_and_exits(tmp_path):
    err = collect_manual(tmp_path, {})
    assert "error: collect manual: no display to open the window on" in err
    assert "DISPLAY unset" in err and "--pilot synthetic" in err


def test_no_display_is_one_line_with_no_error_of_sdl_before_it(tmp_path):
    """#53: with XDG_RUNTIME_DIR unset too (a bare ssh session, a container), SDL's Wayland
    probe wrote "error: XDG_RUNTIME_DIR is invalid or not set in the environment." before
    the project's own line, which read as a second error."""
    err = collect_manual(tmp_path, {"XDG_RUNTIME_DIR": None})
    (line,) = err.splitlines()
    assert line.startswith("error: collect manual: no display to open the window on")
    err = collect_manual(tmp_path, {"XDG_RUNTIME_DIR": None, "WAYLAND_DISPLAY": "wayland-0"})
    assert "WAYLAND_DISPLAY=wayland-0, XDG_RUNTIME_DIR unset" in err  # the probe's hint kept


def test_a_display_that_is_not_there_says_so_and_exits(tmp_path):
    err = collect_manual(tmp_path, {"DISPLAY": ":97"})  # no X server on :97
    assert "no display to open the window on (DISPLAY=:97" in err


def test_no_joystick_says_so_and_exits(tmp_path):
    err = collect_manual(tmp_path, {"SDL_VIDEODRIVER": "dummy"}, "--device", "joystick")
    assert "--device joystick: no joystick is connected" in err
    # the dummy driver draws nowhere: a person could not see the window either
    assert "SDL_VIDEODRIVER=dummy draws the window nowhere" in err


@pytest.mark.slow
def test_a_person_is_refused_the_dummy_window_but_the_synthetic_pilot_flies_there(tmp_path):
    err = collect_manual(tmp_path, {"SDL_VIDEODRIVER": "dummy"}, "--device", "keyboard")
    assert "error: collect manual: SDL_VIDEODRIVER=dummy draws the window nowhere" in err
    from gymfg_il import collect

    out = tmp_path / "synthetic"
    argv = ["manual", "--pilot", "synthetic", "--episodes", "1", "--episode-time", "2"]
    assert collect.main([*argv, "--out", str(out), "--no-progress"]) == 0
    assert (out / "dataset" / "meta" / "info.json").is_file()
