"""Training envs in as many processes as cores, each stepping its share of the envs in turn
(the grouped sampler's vector env), and sampling whole rollouts there.

stable-baselines3's ``SubprocVecEnv`` runs one process per env, so every step of N envs costs N
pipe round trips and N processes taking turns on the cores; with a few cores that costs more
than the physics. ``GroupedVecEnv`` keeps one process per group of envs: a step is one
message to each process and one reply with the group's stacked results.

It keeps ``SubprocVecEnv``'s semantics env by env: env k's first reset after ``seed(s)`` takes
seed s + k, a finished episode's last observation goes to ``info["terminal_observation"]`` and
the env resets at once, ``info["TimeLimit.truncated"]`` marks a time limit; so a run on it
repeats a run on ``SubprocVecEnv`` step for step.

``GroupedVecEnv.rollout`` has each process sample its envs' actions itself for a whole
rollout (``rl.grouped.sampling``).
"""

from __future__ import annotations

import itertools
import multiprocessing as mp
import warnings
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

from gymfg_il.rl.grouped.sampling import (
    install,
    merge_rollouts,
    sample_rollout,
    sampling_copy,
    step_env,
)


class _Group:
    """A group's envs in their process, each one's current observation, and (for
    ``GroupedVecEnv.rollout``) a copy of the policy that samples them."""

    def __init__(self, envs: list[gym.Env]) -> None:
        self.envs = envs
        self.obs: list[Any] = [None] * len(envs)
        self.policy: Any = None

    def answer(self, cmd: str, data: Any) -> Any:
        """What the process answers to ``cmd`` (``data``: the command's arguments)."""
        from stable_baselines3.common.env_util import is_wrapped

        envs = self.envs
        if cmd == "step":
            out = [step_env(env, a) for env, a in zip(envs, data, strict=True)]
            obs, rewards, dones, infos, resets = zip(*out, strict=True)
            self.obs = list(obs)
            return np.stack(obs), np.array(rewards), np.array(dones), infos, resets
        if cmd == "reset":
            done = [
                env.reset(seed=seed, **({"options": opt} if opt else {}))
                for env, (seed, opt) in zip(envs, data, strict=True)
            ]
            obs, infos = zip(*done, strict=True)
            self.obs = list(obs)
            return np.stack(obs), infos
        if cmd == "rollout":
            return self.rollout(*data)
        if cmd == "policy":
            return self.install(*data)
        if cmd == "spaces":
            return envs[0].observation_space, envs[0].action_space
        if cmd == "render":
            return [env.render() for env in envs]
        at, *rest = data
        if cmd == "get_attr":
            return [envs[i].get_wrapper_attr(rest[0]) for i in at]
        if cmd == "has_attr":
            return [envs[i].has_wrapper_attr(rest[0]) for i in at]
        if cmd == "set_attr":
            for i in at:
                setattr(envs[i], rest[0], rest[1])
            return [None] * len(at)
        if cmd == "env_method":
            name, args, kwargs = rest
            return [envs[i].get_wrapper_attr(name)(*args, **kwargs) for i in at]
        if cmd == "is_wrapped":
            return [is_wrapped(envs[i], rest[0]) for i in at]
        raise NotImplementedError(f"{cmd!r} is no command of a GroupedVecEnv worker")

    def install(self, policy: CloudpickleWrapper, seed: int) -> None:
        """Keep ``policy`` (``sampling.sampling_copy``) for rollouts, seeded by ``seed``."""
        self.policy = install(policy.var, seed)

    def rollout(self, weights: dict[str, Any], n_steps: int, sde_every: int) -> dict[str, Any]:
        """``sampling.sample_rollout`` of this group's envs with the installed policy."""
        if self.policy is None:
            raise RuntimeError("rollout before a policy was installed")
        out = sample_rollout(
            self.policy, self.envs, np.stack(self.obs), weights, n_steps, sde_every
        )
        self.obs = list(out["last_obs"])
        return out


def _worker(remote: Any, parent: Any, fns: CloudpickleWrapper) -> None:
    """A group's process: builds its envs, then answers commands for all of them at once. An
    error goes back to the parent, which raises it; the process goes on."""
    parent.close()
    group = _Group([])
    try:
        group.envs = [fn() for fn in fns.var]
        while True:
            cmd, data = remote.recv()
            if cmd == "close":
                return
            try:
                reply: tuple[bool, Any] = (True, group.answer(cmd, data))
            except Exception as err:  # the parent raises it
                reply = (False, err)
            try:
                remote.send(reply)
            except Exception as err:  # an answer or an error that cannot be pickled
                remote.send((False, RuntimeError(f"{cmd}: {err!r}")))
    except (EOFError, KeyboardInterrupt, BrokenPipeError):
        return
    finally:
        for env in group.envs:
            env.close()
        remote.close()


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
    docstring), for envs with a Box observation. The processes start by forkserver (or
    spawn), so a script that builds one runs under ``if __name__ == "__main__":``. An error
    in an env is raised here, with the env's own message."""

    def __init__(self, env_fns: Sequence[Callable[[], gym.Env]], processes: int) -> None:
        method = "forkserver" if "forkserver" in mp.get_all_start_methods() else "spawn"
        ctx: Any = mp.get_context(method)
        self.groups = groups_of(len(env_fns), processes)
        self.remotes: list[Any] = []
        self.processes: list[Any] = []
        self.waiting, self.closed = False, False
        try:
            for group in self.groups:
                remote, work = ctx.Pipe()
                fns = CloudpickleWrapper([env_fns[i] for i in group])
                process = ctx.Process(target=_worker, args=(work, remote, fns), daemon=True)
                process.start()
                work.close()
                self.remotes.append(remote)
                self.processes.append(process)
            self.remotes[0].send(("spaces", None))
            ((observation_space, action_space),) = self._recv_all(self.remotes[:1])
        except BaseException:
            self.close()
            raise
        if not isinstance(observation_space, gym.spaces.Box):
            self.close()
            raise TypeError(f"GroupedVecEnv stacks Box observations, not {observation_space}")
        super().__init__(len(env_fns), observation_space, action_space)
        self.reset_infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        self._policy: Any = None  # the policy whose copy the processes hold

    @staticmethod
    def _recv_all(remotes: Sequence[Any]) -> list[Any]:
        """Every group's answer, all read before the first error there is raised here (an
        unread answer would answer the next command)."""
        replies = []
        for remote in remotes:
            try:
                replies.append(remote.recv())
            except EOFError:
                replies.append((False, RuntimeError("an env process of GroupedVecEnv ended")))
        for ok, answer in replies:
            if not ok:
                raise answer
        return [answer for _, answer in replies]

    def step_async(self, actions: np.ndarray) -> None:
        for remote, group in zip(self.remotes, self.groups, strict=True):
            remote.send(("step", actions[group.start : group.stop]))
        self.waiting = True

    def step_wait(self) -> VecEnvStepReturn:
        try:
            results = self._recv_all(self.remotes)
        finally:
            self.waiting = False
        obs, rewards, dones, infos, resets = zip(*results, strict=True)
        # as stable-baselines3's envs: each env's last reset info, until it resets again
        for i, reset_info in enumerate(r for group in resets for r in group):
            if reset_info is not None:
                self.reset_infos[i] = reset_info
        flat = [info for group in infos for info in group]
        return np.concatenate(obs), np.concatenate(rewards), np.concatenate(dones), flat

    def reset(self) -> VecEnvObs:
        for remote, group in zip(self.remotes, self.groups, strict=True):
            remote.send(("reset", [(self._seeds[i], self._options[i]) for i in group]))
        results = self._recv_all(self.remotes)
        obs, infos = zip(*results, strict=True)
        self.reset_infos = [info for group in infos for info in group]
        self._reset_seeds()
        self._reset_options()
        return np.concatenate(obs)

    def rollout(self, policy: Any, n_steps: int, seed: int, sde_every: int = -1) -> dict[str, Any]:
        """``n_steps`` steps of every env, each action sampled by ``policy`` (a
        stable-baselines3 actor-critic) in the envs' own processes, exactly as its
        ``collect_rollouts`` samples and steps them: actions clipped to the box, a time limit's
        value bootstrapped, finished envs reset. A step then costs no pipe round trip, and no
        process waits on another's inference. The first rollout of a
        policy sends each process a copy, its sampling seeded by ``seed`` and the group;
        every rollout sends the current weights.

        Returns arrays of shape (n_steps, num_envs, ...): ``obs`` (seen before each step),
        ``actions`` (unclipped), ``rewards`` (the envs' own), ``dones``, ``values``,
        ``log_probs``, ``bootstrap`` (the value where a time limit cut an episode, else 0);
        ``last_obs`` and ``last_values`` after the last step; ``ends``, (step, env, info) of
        every episode's end."""
        if self._policy is not policy:
            clone = sampling_copy(policy)
            for g, remote in enumerate(self.remotes):
                state = int(np.random.SeedSequence([seed, g]).generate_state(1)[0])
                remote.send(("policy", (CloudpickleWrapper(clone), state)))
            self._recv_all(self.remotes)
            self._policy = policy
        weights = {k: v.detach().cpu() for k, v in policy.state_dict().items()}
        for remote in self.remotes:
            remote.send(("rollout", (weights, n_steps, sde_every)))
        out = merge_rollouts(self._recv_all(self.remotes), self.groups)
        for i, info in out.pop("resets"):
            self.reset_infos[i] = info
        return out

    def close(self) -> None:
        """Ends the env processes (those that no longer answer too) and closes the pipes."""
        if self.closed:
            return
        self.closed = True
        for remote in self.remotes:
            try:
                if self.waiting:
                    remote.recv()
                remote.send(("close", None))
            except (EOFError, OSError):
                pass  # that process has ended already
        for process in self.processes:
            process.join(timeout=10)
            if process.is_alive():
                process.terminate()
                process.join()
        for remote in self.remotes:
            remote.close()

    def _ask(self, cmd: str, indices: VecEnvIndices, *data: Any) -> list[Any]:
        """``cmd`` on the envs at ``indices``, each group asked once; the answers in env order."""
        wanted = [range(self.num_envs)[i] for i in self._get_indices(indices)]
        asked = []
        for remote, group in zip(self.remotes, self.groups, strict=True):
            mine = [i - group.start for i in wanted if i in group]
            if mine:
                remote.send((cmd, (mine, *data)))
                asked.append((remote, [group.start + i for i in mine]))
        answers: dict[int, Any] = {}
        replies = self._recv_all([remote for remote, _ in asked])
        for (_, at), reply in zip(asked, replies, strict=True):
            answers.update(zip(at, reply, strict=True))
        return [answers[i] for i in wanted]

    def has_attr(self, attr_name: str) -> bool:
        return all(self._ask("has_attr", None, attr_name))

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
        if self.render_mode != "rgb_array":
            warnings.warn(
                f"the render mode is {self.render_mode}; images need rgb_array", stacklevel=2
            )
            return [None] * self.num_envs
        for remote in self.remotes:
            remote.send(("render", None))
        return [image for group in self._recv_all(self.remotes) for image in group]
