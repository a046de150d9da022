"""Training envs in as many processes as cores, each stepping its share of the envs in turn
(``train ppo``'s vector env), and sampling whole rollouts there.

stable-baselines3's ``SubprocVecEnv`` runs one process per env, so every step of N envs costs N
pipe round trips and N processes taking turns on the cores; on a 2-core machine, sampling with
8 such envs spent more time in pipes and process switches than in physics
(docs/results/rl.md). ``GroupedVecEnv`` keeps one process per group of envs: a step is one
message to each process and one reply with the group's stacked results.

It keeps ``SubprocVecEnv``'s semantics env by env: env k's first reset after ``seed(s)`` takes
seed s + k, a finished episode's last observation goes to ``info["terminal_observation"]`` and
the env resets at once, ``info["TimeLimit.truncated"]`` marks a time limit; so a run on it
repeats a run on ``SubprocVecEnv`` step for step.

Stepping in lockstep still leaves every core idle while the trainer's process runs the policy,
and costs a pipe round trip a step. ``GroupedVecEnv.rollout`` instead sends each process a copy
of the policy and its weights once per rollout: each process samples its envs' actions itself,
as stable-baselines3's ``collect_rollouts`` does, for the whole rollout, and returns the arrays
its buffer needs (``rl.run.FineTunePPO`` fills the buffer from them).
"""

from __future__ import annotations

import itertools
import multiprocessing as mp
import os
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


def _step(env: gym.Env, action: np.ndarray) -> tuple[Any, float, bool, dict[str, Any], Any]:
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
            out = [_step(env, a) for env, a in zip(envs, data, strict=True)]
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
        """Keep ``policy`` (a CPU copy) for rollouts, its sampling seeded by ``seed``; one
        thread, as ``train ppo`` runs torch (the other cores step the other groups)."""
        import torch

        torch.set_num_threads(1)
        torch.manual_seed(seed)
        # the samples are the policy's own: checking each distribution's arguments is time
        torch.distributions.Distribution.set_default_validate_args(False)
        self.policy = policy.var
        self.policy.set_training_mode(False)

    def rollout(self, weights: dict[str, Any], n_steps: int, sde_every: int) -> dict[str, Any]:
        """``n_steps`` steps of every env, each action sampled by the installed policy with
        ``weights``, as stable-baselines3's ``collect_rollouts`` samples and steps them
        (``GroupedVecEnv.rollout`` gives the arrays)."""
        import torch

        policy = self.policy
        if policy is None:
            raise RuntimeError("rollout before a policy was installed")
        policy.load_state_dict(weights)
        space = self.envs[0].action_space
        assert isinstance(space, gym.spaces.Box)
        n = len(self.envs)
        obs_seen, actions, rewards, dones, values, log_probs, bootstrap = ([] for _ in range(7))
        ends: list[tuple[int, int, dict[str, Any]]] = []  # (step, env, info) of each episode end
        resets: list[tuple[int, Any]] = []  # (env, info) of each reset, the last one counts
        if policy.use_sde:
            policy.reset_noise(n)
        obs = np.stack(self.obs)
        with torch.inference_mode():
            for t in range(n_steps):
                if policy.use_sde and sde_every > 0 and t % sde_every == 0:
                    policy.reset_noise(n)
                action, value, log_prob = policy(torch.as_tensor(obs))
                action = action.numpy()
                clipped = np.clip(action, space.low, space.high)
                out = [_step(env, a) for env, a in zip(self.envs, clipped, strict=True)]
                obs_seen.append(obs)
                actions.append(action)
                values.append(value.numpy().ravel())
                log_probs.append(log_prob.numpy().ravel())
                rewards.append(np.array([o[1] for o in out]))
                dones.append(np.array([o[2] for o in out]))
                # a time limit's cut: stable-baselines3 adds gamma x the value of where it ended
                extra = np.zeros(n, dtype=np.float32)
                cut = [i for i, o in enumerate(out) if o[2] and o[3]["TimeLimit.truncated"]]
                if cut:
                    last = np.stack([out[i][3]["terminal_observation"] for i in cut])
                    extra[cut] = policy.predict_values(torch.as_tensor(last)).numpy().ravel()
                bootstrap.append(extra)
                for i, o in enumerate(out):
                    if o[2]:
                        ends.append((t, i, o[3]))
                    if o[4] is not None:
                        resets.append((i, o[4]))
                obs = np.stack([o[0] for o in out])
            last_values = policy.predict_values(torch.as_tensor(obs)).numpy().ravel()
        self.obs = list(obs)
        return {
            "obs": np.stack(obs_seen),
            "actions": np.stack(actions),
            "rewards": np.stack(rewards),
            "dones": np.stack(dones),
            "values": np.stack(values),
            "log_probs": np.stack(log_probs),
            "bootstrap": np.stack(bootstrap),
            "last_obs": obs,
            "last_values": last_values,
            "ends": ends,
            "resets": resets,
        }


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
        process waits on another's inference (docs/results/rl.md). The first rollout of a
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
        parts = self._recv_all(self.remotes)
        out: dict[str, Any] = {
            key: np.concatenate([p[key] for p in parts], axis=1)
            for key in ("obs", "actions", "rewards", "dones", "values", "log_probs", "bootstrap")
        }
        for key in ("last_obs", "last_values"):
            out[key] = np.concatenate([p[key] for p in parts])
        out["ends"] = sorted(
            (
                (t, group.start + i, info)
                for p, group in zip(parts, self.groups, strict=True)
                for t, i, info in p["ends"]
            ),
            key=lambda end: end[:2],
        )
        for p, group in zip(parts, self.groups, strict=True):
            for i, info in p["resets"]:
                self.reset_infos[group.start + i] = info
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


def training_envs(env_fn: Callable[[], gym.Env], n: int) -> VecEnv:
    """``n`` envs built by ``env_fn``, as ``train ppo`` samples them: grouped in one process
    per core (``GroupedVecEnv``), or a single env in this process."""
    if n == 1:
        from stable_baselines3.common.vec_env import DummyVecEnv

        return DummyVecEnv([env_fn])
    return GroupedVecEnv([env_fn] * n, len(os.sched_getaffinity(0)))
