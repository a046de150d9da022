"""An online team flown by a recurrent policy: as offline, the rollout resets it at every
episode the client starts and carries its state through every step in lockstep."""

import pytest

from gymfg_il import Team
from gymfg_il.aircraft import c172p
from gymfg_il.online.client import OnlineEnv
from gymfg_il.policies.agent import PolicyAgent
from gymfg_il.rollout import Rollout
from gymfg_il.tasks import ReachStaticTargetAltitudeTask

pytestmark = pytest.mark.network


def test_an_online_recurrent_pilot_carries_its_state_and_starts_afresh(
    server, tiny_gru, carried_state
):
    address, _ = server("--mode", "open")
    red = Team("red", [(c172p("red-1"), ReachStaticTargetAltitudeTask)], episode_time_s=3)
    gru = PolicyAgent.load(tiny_gru)
    env = OnlineEnv(address, timeout_s=20)
    rollout = Rollout(env, [gru], team=red)
    try:
        for seed in (0, 1):
            flown = rollout.episode(seed).trajectories["red-1"]
            assert len(flown) == 30
            carried_state(gru.policy, flown.observations, flown.actions)
    finally:
        env.close()
