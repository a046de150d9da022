"""GymFG-IL's commands start quietly: pygame's import of setuptools' deprecated pkg_resources
no longer prints its warning (importing gymfg_il silences that one warning, from pygame)."""

import os
import subprocess
import sys

import pytest

ENV = {**os.environ, "HF_HUB_OFFLINE": "1", "SDL_VIDEODRIVER": "dummy"}


def run(*argv: str) -> subprocess.CompletedProcess[str]:
    done = subprocess.run(
        [sys.executable, "-m", *argv], env=ENV, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr[-2000:]
    return done


@pytest.mark.slow
def test_a_manual_run_prints_no_pkg_resources_warning(tmp_path):
    argv = ["manual", "--pilot", "synthetic", "--device", "keyboard", "--episodes", "1"]
    argv += ["--episode-time", "2", "--out", str(tmp_path / "run"), "--no-progress"]
    done = run("gymfg_il.collect", *argv)
    assert "saved 1 episode(s)" in done.stdout
    assert "pkg_resources" not in done.stderr, done.stderr


def test_the_gui_screenshot_prints_no_pkg_resources_warning(tmp_path):
    done = run("gymfg_il.cockpit.screenshot", str(tmp_path / "gui.png"))
    assert (tmp_path / "gui.png").is_file()
    assert "pkg_resources" not in done.stderr, done.stderr
