"""A team's client process for the online tests: flies the paper's loop against a server and
saves its states per step (``python run_team.py ADDRESS TOKEN TEAM SEED SECONDS OUT [SPIN_US
[rejoin]]``; with ``rejoin``, it keeps trying to join while the server says the team is
connected: a team coming back as soon as the server has dropped its killed self)."""

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from gymfg_il import Team
from gymfg_il.aircraft import c172p, f15
from gymfg_il.controllers.autopilot import controller_for
from gymfg_il.tasks import (
    DummyTask,
    ReachStaticTargetAltitudeTask,
    ReachStaticTargetHeadingTask,
    ReachStaticTargetRollTask,
    geometry,
)


class ChaseTask(DummyTask):
    """Rewarded for closing on blue-1, an opponent seen only through the server."""

    def task_reward(self, ctx):
        blue = ctx.targets.get("blue-1")  # absent until blue joins, and after it leaves
        return -1.0 if blue is None else -geometry.distance_ft(ctx.state, blue) / 1e4


def teams(seconds: float) -> dict[str, Team]:
    return {
        "red": Team(
            "red",
            [
                (c172p("red-1"), ReachStaticTargetAltitudeTask),
                (c172p("red-2"), ReachStaticTargetRollTask),
            ],
            episode_time_s=seconds,
        ),
        "blue": Team(
            "blue", [(f15("blue-1"), ReachStaticTargetHeadingTask)], episode_time_s=seconds
        ),
    }


def start(address, token, team, seed, seconds, out, spin_us=1000, rejoin=False):
    """This script as a team's client process, its output piped; with ``rejoin``, it keeps
    trying to join while the server says the team is connected."""
    return subprocess.Popen(
        [
            sys.executable,
            str(Path(__file__)),
            address,
            token,
            team,
            str(seed),
            str(seconds),
            str(out),
            str(spin_us),
            *(["rejoin"] if rejoin else []),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )


def pilots(env, team):
    return [
        controller_for(s.task, s.aircraft.model, env.dt, s.aircraft.profile.cruise_throttle)
        for s in env.world.team_slots[team.name]
    ]


def fly(env, team, seed, on_step=None, rejoin=False):
    from gymfg_il.online.protocol import ServerError

    refusals = 0
    while True:
        try:
            team_state, opponents = env.reset(team, seed=seed)
            break
        except ServerError as err:
            if not (rejoin and err.code == "duplicate"):
                raise
            refusals += 1
            if refusals == 1:
                print(f"refused: {err}", flush=True)
            time.sleep(0.01)  # (a client's retry interval; the test waits on its output)
    agents = pilots(env, team)
    for agent in agents:
        agent.reset(seed)
    states, done, info = [], False, {}
    while not done:
        actions = [a.act(s, opponents) for s, a in zip(team_state, agents, strict=True)]
        team_state, opponents, _, terminated, truncated, info = env.step(np.hstack(actions))
        states.append(np.stack([s.state for s in env.world.team_slots[team.name]]))
        done = terminated or truncated
        if on_step is not None:
            on_step(len(states))
    return np.array(states), info


if __name__ == "__main__":
    from gymfg_il.online.client import OnlineEnv

    address, token, name, seed, seconds, out, *rest = sys.argv[1:9]
    team = teams(float(seconds))[name]
    env = OnlineEnv(address, token=token, timeout_s=20, spin_us=float(rest[0]) if rest else 1000)
    rejoin = rest[1:] == ["rejoin"]
    states, info = fly(env, team, int(seed), lambda n: print(f"step {n}", flush=True), rejoin)
    np.save(out, states)
    print(f"done {len(states)} {info['server_reason']}", flush=True)
    env.close()
