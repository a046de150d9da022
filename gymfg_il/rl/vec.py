"""Training envs in as many processes as cores, each stepping its share of the envs in turn
(``train ppo``'s vector env).

stable-baselines3's ``SubprocVecEnv`` runs one process per env, so every step of N envs costs N
pipe round trips and N processes taking turns on the cores; on a 2-core machine, sampling with
8 such envs spent more time in pipes and process switches than in physics
(docs/results/rl.md). ``GroupedVecEnv`` keeps one process per group of envs: a step is one
message to each process and one reply with the group's stacked results.

It keeps ``SubprocVecEnv``'s semantics env by env: env k's first reset after ``seed(s)`` takes
seed s + k, a finished episode's last observation goes to ``info["terminal_observation"]`` and
the env resets at once, ``info["TimeLimit.truncated"]`` marks a time limit; so a run on it
repeats a run on ``SubprocVecEnv`` step for step.
"""

from __future__ import annotations

import itertools
import multiprocessing as mp
from collections.abc import Callable, Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from stable_baselines3.common.vec_env.base_vec_env import (
    CloudpickleWrapper,
    VecEnv,
    VecEnvIndices,
    VecEnvObs,
    VecEnvStepReturn,
)


def _step(env: gym.Env, action: np.ndarray) -> tuple[Any, float, bool, dict[str, Any], Any]:
    """One env's step as stable-baselines3's vector envs give it (resetting a finished one)."""
    obs, reward, terminated, truncated, info = env.step(action)
    done = terminated or truncated
    info["TimeLimit.truncated"] = truncated and not terminated
    reset_info: dict[str, Any] = {}
    if done:
        info["terminal_observation"] = obs
        obs, reset_info = env.reset()
    return obs, float(reward), done, info, reset_info


def _worker(remote: Any, parent: Any, fns: CloudpickleWrapper) -> None:
    """A group's process: builds its envs, then answers commands for all of them at once."""
    from stable_baselines3.common.env_util import is_wrapped

    parent.close()
    envs: list[gym.Env] = [fn() for fn in fns.var]
    try:
        while True:
            try:
                cmd, data = remote.recv()
            except (EOFError, KeyboardInterrupt):
                return
            if cmd == "step":
                out = [_step(env, a) for env, a in zip(envs, data, strict=True)]
                obs, rewards, dones, infos, resets = zip(*out, strict=True)
                remote.send((np.stack(obs), np.array(rewards), np.array(dones), infos, resets))
            elif cmd == "reset":
                done = [
                    env.reset(seed=seed, **({"options": opt} if opt else {}))
                    for env, (seed, opt) in zip(envs, data, strict=True)
                ]
                obs, infos = zip(*done, strict=True)
                remote.send((np.stack(obs), infos))
            elif cmd == "close":
                remote.close()
                return
            elif cmd == "spaces":
                remote.send((envs[0].observation_space, envs[0].action_space))
            elif cmd == "get_attr":
                remote.send([envs[i].get_wrapper_attr(data[1]) for i in data[0]])
            elif cmd == "set_attr":
                for i in data[0]:
                    setattr(envs[i], data[1], data[2])
                remote.send(None)
            elif cmd == "env_method":
                at, name, args, kwargs = data
                remote.send([envs[i].get_wrapper_attr(name)(*args, **kwargs) for i in at])
            elif cmd == "is_wrapped":
                remote.send([is_wrapped(envs[i], data[1]) for i in data[0]])
            elif cmd == "render":
                remote.send([env.render() for env in envs])
            else:
                raise NotImplementedError(f"{cmd!r} is no command of a GroupedVecEnv worker")
    finally:
        for env in envs:
            env.close()


def groups_of(n_envs: int, processes: int) -> list[range]:
    """``n_envs`` envs in ``min(n_envs, processes)`` consecutive groups of near-equal size."""
    k = max(1, min(n_envs, processes))
    size, extra = divmod(n_envs, k)
    bounds = [0]
    for g in range(k):
        bounds.append(bounds[-1] + size + (g < extra))
    return [range(a, b) for a, b in itertools.pairwise(bounds)]


class GroupedVecEnv(VecEnv):
    """stable-baselines3's vector env over ``env_fns`` in ``processes`` processes (module
    docstring). The processes start by forkserver (or spawn), so a script that builds one
    runs under ``if __name__ == "__main__":``."""

    def __init__(self, env_fns: Sequence[Callable[[], gym.Env]], processes: int) -> None:
        method = "forkserver" if "forkserver" in mp.get_all_start_methods() else "spawn"
        ctx: Any = mp.get_context(method)
        self.groups = groups_of(len(env_fns), processes)
        self.remotes: list[Any] = []
        self.processes: list[Any] = []
        for group in self.groups:
            remote, work = ctx.Pipe()
            fns = CloudpickleWrapper([env_fns[i] for i in group])
            process = ctx.Process(target=_worker, args=(work, remote, fns), daemon=True)
            process.start()
            work.close()
            self.remotes.append(remote)
            self.processes.append(process)
        self.waiting, self.closed = False, False
        self.remotes[0].send(("spaces", None))
        observation_space, action_space = self.remotes[0].recv()
        super().__init__(len(env_fns), observation_space, action_space)

    def step_async(self, actions: np.ndarray) -> None:
        for remote, group in zip(self.remotes, self.groups, strict=True):
            remote.send(("step", actions[group.start : group.stop]))
        self.waiting = True

    def step_wait(self) -> VecEnvStepReturn:
        results = [remote.recv() for remote in self.remotes]
        self.waiting = False
        obs, rewards, dones, infos, resets = zip(*results, strict=True)
        self.reset_infos = [info for group in resets for info in group]
        flat = [info for group in infos for info in group]
        return np.concatenate(obs), np.concatenate(rewards), np.concatenate(dones), flat

    def reset(self) -> VecEnvObs:
        for remote, group in zip(self.remotes, self.groups, strict=True):
            remote.send(("reset", [(self._seeds[i], self._options[i]) for i in group]))
        results = [remote.recv() for remote in self.remotes]
        obs, infos = zip(*results, strict=True)
        self.reset_infos = [info for group in infos for info in group]
        self._reset_seeds()
        self._reset_options()
        return np.concatenate(obs)

    def close(self) -> None:
        if self.closed:
            return
        if self.waiting:
            for remote in self.remotes:
                remote.recv()
        for remote in self.remotes:
            remote.send(("close", None))
        for process in self.processes:
            process.join()
        for remote in self.remotes:
            remote.close()
        self.closed = True

    def _ask(self, cmd: str, indices: VecEnvIndices, *data: Any) -> list[Any]:
        """``cmd`` on the envs at ``indices``, each group asked once; the answers in env order."""
        wanted = list(self._get_indices(indices))
        asked = []
        for remote, group in zip(self.remotes, self.groups, strict=True):
            mine = [i - group.start for i in wanted if i in group]
            if mine:
                remote.send((cmd, (mine, *data)))
                asked.append((remote, [group.start + i for i in mine]))
        answers: dict[int, Any] = {}
        for remote, at in asked:
            answers.update(zip(at, remote.recv() or [None] * len(at), strict=True))
        return [answers[i] for i in wanted]

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        return self._ask("get_attr", indices, attr_name)

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        self._ask("set_attr", indices, attr_name, value)

    def env_method(
        self,
        method_name: str,
        *method_args: Any,
        indices: VecEnvIndices = None,
        **method_kwargs: Any,
    ) -> list[Any]:
        return self._ask("env_method", indices, method_name, method_args, method_kwargs)

    def env_is_wrapped(
        self, wrapper_class: type[gym.Wrapper], indices: VecEnvIndices = None
    ) -> list[bool]:
        return self._ask("is_wrapped", indices, wrapper_class)

    def get_images(self) -> Sequence[np.ndarray | None]:
        for remote in self.remotes:
            remote.send(("render", None))
        return [image for remote in self.remotes for image in remote.recv()]
