"""A manual run starts quietly: pygame's import of setuptools' deprecated pkg_resources no
longer prints its warning (gymfg_il.manual silences that one warning, from pygame alone)."""

import os
import subprocess
import sys


def test_a_manual_run_prints_no_pkg_resources_warning(tmp_path):
    env = {**os.environ, "HF_HUB_OFFLINE": "1", "SDL_VIDEODRIVER": "dummy"}
    argv = ["manual", "--pilot", "synthetic", "--device", "keyboard", "--episodes", "1"]
    argv += ["--episode-time", "2", "--out", str(tmp_path / "run"), "--no-progress"]
    done = subprocess.run(
        [sys.executable, "-m", "gymfg_il.collect", *argv],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert "saved 1 episode(s)" in done.stdout
    assert "pkg_resources" not in done.stderr, done.stderr
