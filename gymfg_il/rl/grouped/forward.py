"""The actor-critic's sampling pass in numpy, for the env processes (``rl.grouped.sampling``).

On the few observations one env process samples at a time, torch spends a step mostly in its
per-operation overhead and stable-baselines3's distribution classes, about as long as the
envs' physics. ``NumpyActorCritic`` does the same arithmetic as ``AnchoredPolicy.forward`` on
numpy arrays (the GELU by torch's own kernel on the same memory), from the policy's current
weights: the actor's mean, stable-baselines3's gSDE noise, the log-probability of the sampled
action and the critic's value, in float32 as torch computes them.
``tests/rl/grouped/test_forward.py`` holds it to the torch policy's ``evaluate_actions``.

BLAS runs on one thread in the process that installs it: with several env processes on the
cores, a threaded matrix product waits on cores that are stepping other envs.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

Layer = Callable[[np.ndarray], np.ndarray]

_LOG_SQRT_2PI = 0.5 * math.log(2 * math.pi)


def _gelu(approximate: str) -> Layer:
    """torch's own GELU, run on the numpy array's memory (numpy has no erf; one torch call on
    a few envs' activations costs less than a numpy erf, and equals the policy's bit for bit)."""
    import torch
    from torch.nn import functional

    return lambda x: functional.gelu(torch.from_numpy(x), approximate=approximate).numpy()


def _linear(w: np.ndarray, b: np.ndarray) -> Layer:
    return lambda x: x @ w + b


def layers(net: Any) -> list[Layer]:
    """``net`` (a torch ``nn.Sequential`` of Linear, GELU, Tanh and Dropout layers) as numpy
    functions of a batch, dropout left out (it is off while sampling)."""
    from torch import nn

    out: list[Layer] = []
    for m in net:
        if isinstance(m, nn.Linear):
            out.append(_linear(m.weight.detach().numpy().T.copy(), m.bias.detach().numpy().copy()))
        elif isinstance(m, nn.GELU):
            out.append(_gelu(m.approximate))
        elif isinstance(m, nn.Tanh):
            out.append(np.tanh)
        elif not isinstance(m, nn.Dropout):
            raise TypeError(f"no numpy pass for the layer {m!r}")
    return out


def _run(net: list[Layer], x: np.ndarray) -> np.ndarray:
    for layer in net:
        x = layer(x)
    return x


class NumpyActorCritic:
    """``policy`` (an ``rl.policy.AnchoredPolicy``, on the CPU) as numpy functions, its noise
    drawn from ``rng``. ``load`` takes the policy's weights anew (call it after each update);
    ``reset_noise(n)`` draws gSDE's noise maps for ``n`` envs, as the policy's own does."""

    def __init__(self, policy: Any, rng: np.random.Generator) -> None:
        self.policy, self.rng = policy, rng
        dist = policy.action_dist
        if not policy.use_sde or dist.use_expln or not dist.full_std or dist.bijector is not None:
            raise ValueError("the numpy pass follows gSDE with full_std and no expln/squash")
        self.epsilon = float(dist.epsilon)
        self.noise: np.ndarray | None = None
        self.load(None)

    def load(self, weights: dict[str, Any] | None) -> None:
        """Take ``weights`` (the policy's ``state_dict``; None: those it has)."""
        if weights is not None:
            self.policy.load_state_dict(weights)
        actor, critic = self.policy.actor, self.policy.value_net

        def stats(norm: Any) -> tuple[np.ndarray, np.ndarray]:
            return norm.mean.numpy().copy(), norm.std.numpy().copy()

        self.actor_norm, self.critic_norm = stats(actor.obs_norm), stats(critic.obs_norm)
        self.actor, self.critic = layers(actor.net), layers(critic.net)
        # a memory's columns (the last) reach the mean through a linear layer alone
        # (``MLPPolicy.forward``)
        integral = actor.integral
        self.integral = None if integral is None else integral.weight.detach().numpy().T.copy()
        self.std = np.exp(self.policy.log_std.detach().numpy())  # (n_obs, n_act)

    def reset_noise(self, n: int) -> None:
        """A new gSDE noise map per env (``n`` of them)."""
        self.noise = (self.rng.standard_normal((n, *self.std.shape)) * self.std).astype(np.float32)

    def values(self, obs: np.ndarray) -> np.ndarray:
        """The critic's value of each observation (a batch), shape (batch,)."""
        mean, std = self.critic_norm
        return _run(self.critic, (obs - mean) / std)[:, 0]

    def sample(self, obs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A sampled action and the actor's mean for each observation of a float32 batch:
        all a step needs (``score`` values a whole rollout's steps at once, afterwards)."""
        mean, std = self.actor_norm
        z = (obs - mean) / std
        mu = self._mean(z)
        assert self.noise is not None, "reset_noise before sampling"
        action = mu + np.matmul(z[:, None, :], self.noise)[:, 0, :]
        return action.astype(np.float32), mu

    def _mean(self, z: np.ndarray) -> np.ndarray:
        """The actor's mean for the normalised observations ``z``."""
        if self.integral is None:
            return _run(self.actor, z)
        k = len(self.integral)
        return _run(self.actor, z[:, :-k]) + z[:, -k:] @ self.integral

    def score(
        self, obs: np.ndarray, actions: np.ndarray, mu: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The critic's value of each observation and the log-probability of each action,
        ``actions`` and ``mu`` as ``sample`` gave them for ``obs`` with the same weights."""
        mean, std = self.actor_norm
        z = (obs - mean) / std
        scale = np.sqrt((z * z) @ (self.std * self.std) + self.epsilon)
        d = (actions.astype(np.float64) - mu) / scale
        log_prob = (-0.5 * d * d - np.log(scale) - _LOG_SQRT_2PI).sum(axis=1)
        return self.values(obs), log_prob.astype(np.float32)

    def __call__(self, obs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """A sampled action, the value and the action's log-probability for each observation
        of a float32 batch, as the policy's ``forward`` gives them."""
        action, mu = self.sample(obs)
        return action, *self.score(obs, action, mu)
