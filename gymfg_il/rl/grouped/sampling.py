"""Rollouts sampled in the env processes (``GroupedVecEnv.rollout``): each process holds a
CPU copy of the policy, run as numpy functions (``rl.grouped.forward``), receives its weights
once per rollout, and samples and steps its own envs as stable-baselines3's
``collect_rollouts`` does, for the whole rollout; the trainer's process fills
stable-baselines3's buffer from the arrays (``rl.grouped.algorithm.GroupedPPO``).

Stepping in lockstep with the trainer leaves every core idle while the trainer's process runs
the policy, and costs a pipe round trip every step.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from gymfg_il.rl.grouped.forward import NumpyActorCritic


def step_env(env: gym.Env, action: np.ndarray) -> tuple[Any, float, bool, dict[str, Any], Any]:
    """One env's step as stable-baselines3's vector envs give it (resetting a finished one;
    the reset's info, else None)."""
    obs, reward, terminated, truncated, info = env.step(action)
    done = terminated or truncated
    info["TimeLimit.truncated"] = truncated and not terminated
    reset_info = None
    if done:
        info["terminal_observation"] = obs
        obs, reset_info = env.reset()
    return obs, float(reward), done, info, reset_info


def sampling_copy(policy: Any) -> Any:
    """A CPU copy of a stable-baselines3 actor-critic to sample rollouts with: without its
    optimiser (not needed, and large) or what its last forward pass left behind (the
    distribution's tensors, which are not graph leaves and cannot be copied)."""
    import copy

    import torch

    def transient(value: Any) -> bool:
        return isinstance(value, torch.Tensor | torch.distributions.Distribution)

    dist = policy.action_dist
    kept_dist = {k: v for k, v in vars(dist).items() if transient(v)}
    kept = {k: v for k, v in vars(policy).items() if transient(v) or k == "optimizer"}
    try:
        for k in kept_dist:
            setattr(dist, k, None)
        for k in kept:
            setattr(policy, k, None)
        return copy.deepcopy(policy).to("cpu")
    finally:
        vars(dist).update(kept_dist)
        vars(policy).update(kept)


def install(policy: Any, seed: int) -> NumpyActorCritic:
    """``policy`` (a ``sampling_copy``) made ready to sample in an env process: as numpy
    functions (``rl.grouped.forward``), its samples seeded by ``seed``, BLAS and torch on one thread
    (the other cores step the other processes' envs)."""
    import torch
    from threadpoolctl import threadpool_limits

    torch.set_num_threads(1)
    threadpool_limits(1)
    policy.set_training_mode(False)
    return NumpyActorCritic(policy, np.random.default_rng(seed))


def sample_rollout(
    policy: NumpyActorCritic,
    envs: list[gym.Env],
    obs: np.ndarray,
    weights: dict[str, Any],
    n_steps: int,
    sde_every: int,
) -> dict[str, Any]:
    """``n_steps`` steps of ``envs`` from their observations ``obs``, each action sampled by
    ``policy`` with ``weights``, as stable-baselines3's ``collect_rollouts`` samples and steps
    them (the keys: ``GroupedVecEnv.rollout``; ``resets``, (env, info) of every reset). A
    step runs only the actor (``NumpyActorCritic.sample``); the values and log-probabilities
    of all the rollout's steps come in one batched pass at its end, the weights being the
    same throughout."""
    policy.load(weights)
    space = envs[0].action_space
    assert isinstance(space, gym.spaces.Box)
    n = len(envs)
    trace = _Trace()
    policy.reset_noise(n)
    for t in range(n_steps):
        if sde_every > 0 and t % sde_every == 0:
            policy.reset_noise(n)
        action, mu = policy.sample(obs)
        clipped = np.clip(action, space.low, space.high)
        out = [step_env(env, a) for env, a in zip(envs, clipped, strict=True)]
        trace.add(t, obs, action, mu, out)
        obs = np.stack([o[0] for o in out])
    # values and log-probabilities of the whole rollout in one pass (the weights held still)
    seen = np.stack(trace.obs)
    flat = (n_steps * n, -1)
    values, log_probs = policy.score(
        seen.reshape(flat),
        np.stack(trace.actions).reshape(flat),
        np.stack(trace.means).reshape(flat),
    )
    # a time limit's cut: stable-baselines3 adds gamma x the value of where it ended
    bootstrap = np.zeros((n_steps, n), dtype=np.float32)
    if trace.cuts:
        steps, at, last = zip(*trace.cuts, strict=True)
        bootstrap[list(steps), list(at)] = policy.values(np.stack(last))
    return {
        "obs": seen,
        "actions": np.stack(trace.actions),
        "rewards": np.stack(trace.rewards),
        "dones": np.stack(trace.dones),
        "values": values.reshape(n_steps, n),
        "log_probs": log_probs.reshape(n_steps, n),
        "bootstrap": bootstrap,
        "last_obs": obs,
        "last_values": policy.values(obs),
        "ends": trace.ends,
        "resets": trace.resets,
    }


class _Trace:
    """What ``sample_rollout`` keeps of each step of its envs."""

    def __init__(self) -> None:
        self.obs: list[np.ndarray] = []  # seen before each step
        self.actions: list[np.ndarray] = []
        self.means: list[np.ndarray] = []
        self.rewards: list[np.ndarray] = []
        self.dones: list[np.ndarray] = []
        self.ends: list[tuple[int, int, dict[str, Any]]] = []  # (step, env, info) of an end
        self.resets: list[tuple[int, Any]] = []  # (env, info) of each reset, the last counts
        self.cuts: list[tuple[int, int, np.ndarray]] = []  # (step, env, last obs) of a limit

    def add(
        self, t: int, obs: np.ndarray, action: np.ndarray, mu: np.ndarray, out: list[Any]
    ) -> None:
        """Step ``t``: from ``obs``, ``action`` sampled about ``mu``, the envs' ``step_env``
        answers ``out``."""
        self.obs.append(obs)
        self.actions.append(action)
        self.means.append(mu)
        self.rewards.append(np.array([o[1] for o in out]))
        self.dones.append(np.array([o[2] for o in out]))
        for i, o in enumerate(out):
            if o[2]:
                self.ends.append((t, i, o[3]))
                if o[3]["TimeLimit.truncated"]:
                    self.cuts.append((t, i, o[3]["terminal_observation"]))
            if o[4] is not None:
                self.resets.append((i, o[4]))


def merge_rollouts(parts: list[dict[str, Any]], groups: list[range]) -> dict[str, Any]:
    """The env processes' rollouts (``parts``, of the envs in ``groups``) as one, in env order."""
    out: dict[str, Any] = {
        key: np.concatenate([p[key] for p in parts], axis=1)
        for key in ("obs", "actions", "rewards", "dones", "values", "log_probs", "bootstrap")
    }
    for key in ("last_obs", "last_values"):
        out[key] = np.concatenate([p[key] for p in parts])
    paired = list(zip(parts, groups, strict=True))
    out["ends"] = sorted(
        ((t, group.start + i, info) for p, group in paired for t, i, info in p["ends"]),
        key=lambda end: end[:2],
    )
    out["resets"] = [(group.start + i, info) for p, group in paired for i, info in p["resets"]]
    return out
