"""The frame strip of the README, the docs' front page and the camera guide: an approach
flown by the task's expert, seen by the headless camera (front view above, chase view below)
at six moments.

    python docs/experiments/camera_strip.py [OUT.png]   (default docs/images/camera_strip.png)
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from gymfg_il.envs.single import AircraftEnv
from gymfg_il.rollout.agents import AgentSpec

TIMES_S = (0, 60, 100, 130, 155, 175)


def main(out: Path, seed: int = 3, size: int = 160) -> None:
    env = AircraftEnv("approach", "c172p")
    pilot = AgentSpec.controller().make(env)
    obs, _ = env.reset(seed=seed)
    pilot.reset(seed)
    shots = []
    wanted = {round(t / env.dt) for t in TIMES_S}
    for step in range(env.world.max_steps + 1):
        if step in wanted:
            shots.append(
                (step * env.dt, env.camera_frame("front", size), env.camera_frame("chase", size))
            )
        obs, _, terminated, truncated, _ = env.step(pilot.act(obs))
        if terminated or truncated:
            break
    gap = 6
    strip = Image.new("RGB", (len(shots) * (size + gap), 2 * size + gap + 18), "white")
    draw = ImageDraw.Draw(strip)
    for i, (t, front, chase) in enumerate(shots):
        x = i * (size + gap)
        strip.paste(Image.fromarray(front), (x, 18))
        strip.paste(Image.fromarray(chase), (x, 18 + size + gap))
        draw.text((x + 4, 3), f"t = {t:.0f} s", fill=(0, 0, 0))
    out.parent.mkdir(parents=True, exist_ok=True)
    strip.save(out)
    print(f"wrote {out}: {len(shots)} moments, front above, chase below")
    env.close()
    assert np.isfinite(obs).all()


if __name__ == "__main__":
    main(Path(sys.argv[1] if len(sys.argv) > 1 else "docs/images/camera_strip.png"))
