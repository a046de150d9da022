"""The cockpit in a real window under Xvfb: for each task, a screenshot of what X shows a few
seconds into an episode flown by the pilot who sees only the window, with the task's bugs and
guidance on it."""

import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

pytestmark = pytest.mark.display

TASKS = ("altitude", "turn", "climb-turn", "waypoints", "formation", "approach")
NEEDED = [tool for tool in ("Xvfb", "import") if shutil.which(tool) is None]
FLY = """
import subprocess, sys
from pathlib import Path
from gymfg_il.cockpit.session import ManualSession
from gymfg_il.collectors.config import ManualConfig

out = Path(sys.argv[1])
for task in sys.argv[2:]:

    def on_frame(frame, session, task=task):
        if frame == 60:  # two seconds in: what X shows, not what pygame holds
            subprocess.run(["import", "-window", "root", str(out / f"{task}.png")], check=True)

    cfg = ManualConfig(task=task, agent_hz=30, pilot="synthetic", episodes=1, seed=4,
                       out=out / task)
    ManualSession(cfg, on_frame, realtime=False, draw=True).run(max_frames=62)
"""


def test_a_screenshot_of_each_tasks_cockpit_shows_its_targets(xvfb, tmp_path):
    if NEEDED:
        pytest.skip(f"needs {', '.join(NEEDED)} (Debian: apt-get install xvfb imagemagick)")
    from PIL import Image

    with xvfb("1280x720x24") as display:
        env = {**os.environ, "DISPLAY": display, "HF_HUB_OFFLINE": "1"}
        env.pop("SDL_VIDEODRIVER", None)
        run = subprocess.run(
            [sys.executable, "-c", FLY, str(tmp_path), *TASKS],
            env=env,
            capture_output=True,
            text=True,
            timeout=600,
        )
    assert run.returncode == 0, run.stderr[-3000:]
    for task in TASKS:
        shot = np.asarray(Image.open(tmp_path / f"{task}.png").convert("RGB")).astype(int)
        assert shot.shape[:2] == (720, 1280)
        magenta = (np.abs(shot - (235, 80, 235)).sum(-1) == 0).sum()
        assert magenta > 40, f"{task}: no target bug on screen"
        sky = (np.abs(shot - (40, 110, 190)).sum(-1) == 0).sum()  # the attitude indicator
        assert sky > 2000, f"{task}: no attitude indicator on screen"
