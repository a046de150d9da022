"""Running an evaluation (``evaluation.runner``): a recurrent policy flies every episode with
its state carried from step to step and fresh at each episode's start."""

import numpy as np

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.evaluation.runner import evaluate
from gymfg_il.policies.agent import PolicyAgent
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.rollout.seeded import fly_many


def test_eval_flies_a_recurrent_policy_with_its_state_carried_and_reset(tiny_gru, carried_state):
    spec = AgentSpec.policy(tiny_gru)
    flight = FlightSpec.from_dict(spec.meta()["spec"]).replace(episode_time_s=5)
    agents = {"controller": AgentSpec.controller(), "policy:gru": spec}
    _, traces = evaluate(flight, agents, [0, 1])  # one kept agent flies both episodes
    _, alone = evaluate(flight, agents, [1])
    assert np.array_equal(traces["policy:gru"][1].actions, alone["policy:gru"][0].actions)
    policy = PolicyAgent.load(tiny_gru).policy
    for seed, trace in zip([0, 1], traces["policy:gru"], strict=True):
        (episode,) = fly_many(flight, spec, [seed])  # what eval flew, with its observations
        assert np.array_equal(episode.solo.actions, trace.actions)
        carried_state(policy, episode.solo.observations, episode.solo.actions)
