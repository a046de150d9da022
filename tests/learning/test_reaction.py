"""A pilot's reaction time from their demonstrations, and ``--shift``: BC pairs each
observation with the action taken that many steps later."""

import dataclasses

import numpy as np
import pytest

from gymfg_il.errors import ConfigError
from gymfg_il.learning.config import TrainConfig
from gymfg_il.learning.data import Frames
from gymfg_il.learning.reaction import reaction_steps, reactions, shifted

NAMES = ["pitch_deg", "roll_deg", "airspeed_kts"]


def answering(lags, steps=600, seed=0):
    """Episodes whose stick answers pitch and bank ``lags[e]`` steps late (the elevator
    with the pitch's change, the ailerons against the bank's), with noise of their own."""
    rng = np.random.default_rng(seed)
    obs, action, episode, frame = [], [], [], []
    for e, lag in enumerate(lags):
        moves = rng.normal(size=(steps, 2))
        attitude = np.cumsum(moves, axis=0)
        act = np.zeros((steps, 4))
        answer = np.cumsum(np.vstack([np.zeros((lag, 2)), moves[: steps - lag]]), axis=0)
        act[:, 1] = 0.01 * answer[:, 0] + 0.002 * rng.normal(size=steps).cumsum()
        act[:, 0] = -0.01 * answer[:, 1] + 0.002 * rng.normal(size=steps).cumsum()
        obs.append(np.column_stack([attitude, np.full(steps, 100.0)]))
        action.append(act)
        episode.append(np.full(steps, e))
        frame.append(np.arange(steps))
    n = len(lags)
    return Frames(
        np.vstack(obs).astype(np.float32),
        np.vstack(action).astype(np.float32),
        np.concatenate(episode),
        np.concatenate(frame),
        NAMES,
        ["aileron", "elevator", "rudder", "throttle"],
        30,
        {},
        {},
        {
            "episode_index": list(range(n)),
            "gymfg/source": ["synthetic"] * n,
            "gymfg/pilot": [f"lag{lag}" for lag in lags],
        },
    )


def test_the_estimate_finds_the_lag_at_which_the_stick_answers_the_attitude():
    frames = answering([3, 3, 9, 9, 0, 0])
    assert reactions(frames) == {"lag0": 0, "lag3": 3, "lag9": 9}
    assert reaction_steps(frames, [2, 3]) == 9
    assert reactions(frames.select(np.array([0, 1]))) == {"lag3": 3}  # the pilots selected
    # an observation without attitude, or episodes too short to tell: no estimate
    assert reaction_steps(dataclasses.replace(frames, observation_names=["a", "b", "c"])) is None
    assert (
        reaction_steps(
            frames.select(np.array([0]))._take(np.arange(len(frames.select(np.array([0])))) < 50)
        )
        is None
    )


def test_shift_pairs_each_observation_with_the_action_that_many_steps_later():
    frames = answering([3, 9], steps=300)
    out, record = shifted(frames, "5")
    assert record == {"shift": 5} and len(out) == len(frames) - 2 * 5
    first = out.episode == 0
    assert np.array_equal(out.obs[first], frames.obs[:295])
    assert np.array_equal(out.action[first], frames.action[5:300])
    auto, record = shifted(frames, "auto")
    assert record["reaction_steps"] == {"lag3": 3, "lag9": 9}
    assert len(auto) == len(frames) - 3 - 9
    assert np.array_equal(auto.action[auto.episode == 1], frames.action[300 + 9 :])
    # an autopilot's episodes are left as they are by auto
    flown = dataclasses.replace(
        frames, episodes={**frames.episodes, "gymfg/source": ["autopilot"] * 2}
    )
    assert len(shifted(flown, "auto")[0]) == len(frames)
    with pytest.raises(ConfigError, match="shift='soon': want a number of steps"):
        TrainConfig(shift="soon")
