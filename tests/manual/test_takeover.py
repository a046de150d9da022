"""A person and an assistant sharing the controls (``manual.takeover``): while the person
flies, a recurrent assistant is still called at every step, so its state follows the flight."""

import numpy as np

from gymfg_il.envs.single import AircraftEnv
from gymfg_il.manual.controller import ManualController
from gymfg_il.manual.takeover import Takeover
from gymfg_il.policies.agent import PolicyAgent
from gymfg_il.rollout import Rollout


def test_a_recurrent_assistant_takes_back_as_if_it_had_watched_every_step(tiny_gru, carried_state):
    env = AircraftEnv("altitude", "c172p", episode_time_s=6)
    assistant = PolicyAgent.load(tiny_gru)
    takeover = Takeover(ManualController("keyboard"), assistant)
    rollout = Rollout(env, [takeover])
    rollout.reset(0)
    steps = []
    while not rollout.done:
        if len(steps) in (20, 40):  # the person takes over, then hands back
            takeover.toggle(steps[-1].action)
            takeover.human.values[1] += 0.1 * takeover.human_flies  # and pulls a little
        (step,) = rollout.step().steps
        steps.append(step)
    env.close()
    person = np.array([s.intervention for s in steps])
    assert len(steps) == 60 and person.tolist() == [False] * 20 + [True] * 20 + [False] * 20
    actions = np.array([s.action for s in steps])
    assert np.array_equal(actions[20:40], np.tile(takeover.human.values, (20, 1)))
    # the assistant's actions before and after: its state ran through every observation
    observations = np.array([s.observation for s in steps])
    carried_state(assistant.policy, observations, actions, flown=~person)
