"""The settings of a PPO run (``PPORunConfig``, ``train ppo``): the flight options
(``envs.options.FlightOptions``), what to start from and how long to train, the envs, the
evaluations, and PPO's own settings (``hyperparams.toml`` per task, ``rl.hyperparams``)."""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.envs.options import FlightOptions
from gymfg_il.errors import ConfigError, join_problems
from gymfg_il.rl import hyperparams
from gymfg_il.rl.folders import overlap_problem
from gymfg_il.rl.hyperparams import PPOSettings
from gymfg_il.typecheck import SEED_LIMIT, SEED_RULE, seed_problem, type_problems

ANCHOR_SPAN_MAX = 150_000  # the longest the anchor decays over by default (``anchor_steps``)
# the actor's default learning rate when fine-tuning (``actor_lr``); from scratch it is ``lr``
FINE_TUNE_ACTOR_LR = 1e-4
# the episodes the kept actor is chosen on by default (``select_episodes``)
SELECT_EPISODES = 64
# the default discount and GAE lambda per step at DISCOUNT_HZ, kept per second at other rates
DEFAULT_GAMMA, DEFAULT_GAE_LAMBDA, DISCOUNT_HZ = 0.99, 0.95, 10
WARMUP_MAX = 20_000  # the longest the critic warms up by default (``critic_warmup``)


@dataclass
class PPORunConfig(FlightOptions):
    """PPO (stable-baselines3) on a solo flight: fine-tuning a cloned MLP policy, or learning
    from scratch. With --init the run flies the policy's own flight (its task, aircraft and
    rate, which may not change), with the flight options that are given in place of its own
    (each change is printed); from scratch the options name the flight (--task and
    --aircraft at least).

    Attributes:
        init: the MLP policy to start from (a folder ``train bc --policy mlp`` or ``train
            ppo`` wrote): the actor starts as its network and normalisation; left out, PPO
            learns from scratch (give --task and --aircraft).
        steps: environment steps to train for (all envs together); the actor learns after
            the critic's warm-up (--critic-warmup), so a run must be longer than that.
        out: where the policy goes (default: policies/ppo-<task>-<aircraft>).
        envs: environments sampled in parallel (0: four per CPU core).
        seed: seeds the envs (env k draws all its episodes from seed + k), the sampling and
            the networks: the same settings and number of envs repeat a run exactly on the
            same machine and install. Runs meant to be independent take seeds at least envs
            apart, or they share most of their episodes.
        sampler: how rollouts are sampled: ``grouped``, in the env processes, one per core,
            each sampling its envs' actions from a copy of the policy (``rl.grouped``), or
            ``sb3``, stable-baselines3's own loop (one process per env, the policy run in
            the trainer between steps). Both sample the same policy; their noise comes from
            different generators, so a seed flies another run on each.
        device: cpu or cuda (the networks are small: cpu is usually faster).
        hidden: hidden widths of the actor, from scratch (with --init: the policy's own).
        eval_every: evaluate the policy's mean action every this many env steps (and at the
            start and the end).
        eval_episodes: held-out episodes each evaluation flies (seeds eval_seed, eval_seed +
            1, ...), the same every time, with the controller on them once: the curve.
        eval_seed: the first held-out seed.
        select_episodes: episodes each evaluation flies to choose the kept actor (with --keep
            best): the curve's seeds and the next ones (eval_seed .. eval_seed +
            select_episodes - 1), on two processes (default: 64, or eval_episodes if more).
        keep: which actor is saved: ``best``, the evaluation with the highest success (then
            return) on the select_episodes seeds, the start included, so the result never
            flies worse than the start on these seeds; or ``last``, the actor as training
            left it. Judge the result on other seeds (``eval --seed``).
        checkpoints: keep every evaluated actor, a policy in OUT/checkpoints/step-N (about
            0.6 MB each), to fly again (``eval --policy``).
        rollout_steps: steps each env samples between updates (PPO's n_steps).
        batch_size: samples per gradient step, a divisor of the rollout (rollout_steps x envs).
        epochs: passes over each rollout per update.
        lr: Adam learning rate of the critic.
        actor_lr: Adam learning rate of the actor (default: 1e-4 when fine-tuning, so that the
            cloned actor moves slower than the critic learns; from scratch: lr).
        gamma: discount per step (default: 0.99 at 10 Hz, and at other agent rates the same
            decay per second, 0.99 ** (10 / Hz)).
        gae_lambda: GAE's lambda per step (default: 0.95 at 10 Hz, likewise per second).
        clip_range: PPO's clip on the probability ratio.
        target_kl: an update stops early when its KL divergence from the sampling policy
            passes 1.5 x this (0: never).
        action_std: the exploration noise's starting spread in the policy's normalised action
            units (1 = the demonstrations' spread of each control). PPO explores with
            stable-baselines3's generalised state-dependent exploration (gSDE): the noise is
            a linear map of the normalised observation, drawn anew every rollout, so the
            controls deviate coherently for a while.
        critic_warmup: env steps over which only the critic learns, the actor held, so that
            the first actor updates follow a trained value function: every update on a
            rollout that began before this many steps (default: a tenth of the run, at most
            20,000 steps, at least one rollout); then the actor's rate ramps up from 0 over
            as many steps when fine-tuning.
        success_bonus: at the end of each training episode, the task judges it as eval does,
            and a success adds this share of the episode's steps to its return (a step's task
            reward is at most about 1; 0: the task's reward alone; ``rl.reward``).
        anchor: weight, at the start, of the squared distance between the actor's mean action
            and the starting policy's (normalised units) added to PPO's loss; it decays
            linearly to 0 over anchor_steps (0: no anchor). Not used from scratch.
        anchor_steps: env steps over which the anchor decays (default: half the run, at most
            150,000).
        critic: hidden widths of the critic (value network).
    """

    init: Path | None = None
    steps: int = 1_000_000
    out: Path | None = None
    envs: int = 0
    seed: int = 0
    sampler: Literal["grouped", "sb3"] = "grouped"
    device: str = "cpu"
    hidden: list[int] = field(default_factory=lambda: [256, 256])
    eval_every: int = 50_000
    eval_episodes: int = 16
    eval_seed: int = 7000
    select_episodes: int | None = None
    keep: Literal["best", "last"] = "best"
    checkpoints: bool = False
    # PPO's own: None takes the task's value in hyperparams.toml (``ppo``)
    rollout_steps: int | None = None
    batch_size: int | None = None
    epochs: int | None = None
    lr: float | None = None
    actor_lr: float | None = None
    gamma: float | None = None
    gae_lambda: float | None = None
    clip_range: float | None = None
    target_kl: float | None = None
    action_std: float | None = None
    critic_warmup: int | None = None
    success_bonus: float | None = None
    anchor: float | None = None
    anchor_steps: int | None = None
    critic: list[int] | None = None

    def __post_init__(self) -> None:
        typed = type_problems(self)
        if typed:
            raise ConfigError(join_problems("train ppo", typed))
        self.init = None if self.init is None else Path(self.init)
        given = {n: getattr(self, n) for n in hyperparams.NAMES if getattr(self, n) is not None}
        self._ppo = hyperparams.resolve(self.ppo_task, given)
        problems = self._run_problems() + self.ppo.problems()
        if self.envs >= 0:
            problems += self._seed_problems()
        if not problems:  # the counts a rollout is made of are sound
            problems += self._rollout_problems()
        if problems:
            raise ConfigError(join_problems("train ppo", problems))

    @property
    def ppo(self) -> PPOSettings:
        """PPO's settings for this run: those given, else the task's in hyperparams.toml."""
        return self._ppo

    @property
    def ppo_task(self) -> str | None:
        """The task whose PPO settings the run takes: ``task``, else the starting policy's
        (from its config.json; None where that cannot be read, and the start says why)."""
        if self.task is not None or self.init is None:
            return self.task
        try:
            spec = json.loads((self.init / "config.json").read_text())["spec"]
            return FlightSpec.from_dict(spec).task
        except (OSError, ValueError, KeyError, TypeError, AttributeError, ConfigError):
            return None

    def _run_problems(self) -> list[str]:
        """What is wrong with the run's own settings (not PPO's)."""
        problems = []
        if self.init is None and (self.task is None or self.aircraft is None):
            problems.append(
                "give --init POLICY (a cloned MLP to fine-tune) or, from scratch, --task and "
                "--aircraft"
            )
        if self.episode_time_s is not None and not self.episode_time_s > 0:
            problems.append(f"episode_time_s={self.episode_time_s} must be > 0")
        for name in ("steps", "eval_every", "eval_episodes"):
            if getattr(self, name) < 1:
                problems.append(f"{name}={getattr(self, name)} must be >= 1")
        if self.envs < 0:
            problems.append(f"envs={self.envs}: want 0 (four per core) or more")
        if self.select_episodes is not None and self.select_episodes < self.eval_episodes:
            problems.append(
                f"select_episodes={self.select_episodes} must be >= eval_episodes="
                f"{self.eval_episodes} (the kept actor is chosen on the curve's seeds and more)"
            )
        problems += filter(None, [overlap_problem(self.init, self.out)])
        if not self.hidden or min(self.hidden) < 1:
            problems.append(f"hidden={self.hidden}: want a non-empty list of widths > 0")
        if self.device not in ("cpu", "cuda", "auto") and not self.device.startswith("cuda:"):
            problems.append(f"device={self.device!r}: use cpu, cuda, cuda:N or auto")
        return problems

    def _seed_problems(self) -> list[str]:
        """Every seed the run takes held to the one seed rule (``typecheck.seed_problem``):
        the envs' (env k starts from seed + k; stable-baselines3 seeds numpy's legacy
        generator with ``seed``) and the held-out episodes' (eval_seed + i, up to the last
        episode the kept actor is chosen on)."""
        problems = []
        if problem := seed_problem(self.seed):
            problems.append(problem)
        elif (last := self.seed + self.n_envs - 1) >= SEED_LIMIT:
            problems.append(
                f"seed={self.seed}: env {last - self.seed} starts from seed {last}, and a seed "
                f"is an integer {SEED_RULE}; give --seed {SEED_LIMIT - self.n_envs} or below"
            )
        if problem := seed_problem(self.eval_seed, self.chosen_on):
            problems.append(f"eval_{problem}")  # "seed=...: why" names the flag
        return problems

    def _rollout_problems(self) -> list[str]:
        """What stable-baselines3's PPO would stop on (an assertion, after the start's
        evaluation had flown) or warn of, and a run whose actor would never learn: PPO
        normalises the advantages of each batch, so a rollout (rollout_steps x envs) holds 2
        samples or more, and the batches divide it (else each epoch ends on a truncated
        batch); the actor learns only after the critic's warm-up."""
        envs = f"envs={self.envs}" if self.envs else f"{self.n_envs} envs (four a core)"
        rollout, batch = self.rollout, self.ppo.batch_size
        if rollout < 2:
            return [
                f"rollout_steps={self.ppo.rollout_steps} x {envs} is a rollout of {rollout} "
                "sample; PPO normalises a rollout's advantages, which takes 2 or more: give "
                "--rollout-steps 2 or more, or --envs 2 or more"
            ]
        if rollout % batch:
            return [
                f"batch_size={batch} must divide a rollout's {rollout} samples "
                f"(rollout_steps={self.ppo.rollout_steps} x {envs}), or each epoch ends on a "
                f"truncated batch: give --batch-size {batch_that_fits(rollout, batch)}, or a "
                "rollout it divides"
            ]
        if self.actor_steps == 0:
            return [
                f"steps={self.steps:,}: the actor would never learn: the critic warms up over "
                f"the first {self.warmup_steps:,} env steps (--critic-warmup; a rollout is "
                f"{rollout:,}: rollout_steps={self.ppo.rollout_steps} x {envs}) and the run "
                f"ends there; give --steps {self.least_steps():,} or more, or a shorter "
                "--critic-warmup"
            ]
        return []

    @property
    def n_envs(self) -> int:
        """The envs sampled in parallel: ``envs``, else four per CPU core."""
        return self.envs or 4 * len(os.sched_getaffinity(0))

    @property
    def chosen_on(self) -> int:
        """Episodes each evaluation flies: those the kept actor is chosen on (``keep`` best),
        else the curve's."""
        if self.keep == "last":
            return self.eval_episodes
        if self.select_episodes is not None:
            return self.select_episodes
        return max(SELECT_EPISODES, self.eval_episodes)

    @property
    def rollout(self) -> int:
        """Env steps per update, all envs together."""
        return self.ppo.rollout_steps * self.n_envs

    @property
    def actor_rate(self) -> float:
        """The actor's learning rate: ``actor_lr``, else 1e-4 when fine-tuning, else ``lr``."""
        if self.ppo.actor_lr is not None:
            return self.ppo.actor_lr
        return FINE_TUNE_ACTOR_LR if self.init is not None else self.ppo.lr

    @property
    def warmup_steps(self) -> int:
        """The env steps over which only the critic learns."""
        return self._warmup(self.steps)

    def _warmup(self, steps: int) -> int:
        if self.ppo.critic_warmup is not None:
            return self.ppo.critic_warmup
        return max(self.rollout, min(WARMUP_MAX, steps // 10))

    @property
    def actor_steps(self) -> int:
        """The env steps of the rollouts the actor learns from: every update's rollout after
        the warm-up (a run samples whole rollouts, ``steps`` or more)."""
        return _actor_steps(self.steps, self.rollout, self.warmup_steps)

    def least_steps(self) -> int:
        """The fewest ``steps`` whose run has the actor learn from one rollout."""
        rollout, k = self.rollout, 1
        while _actor_steps(k * rollout, rollout, self._warmup(k * rollout)) == 0:
            k += 1
        return k * rollout

    def discounts(self, agent_hz: int) -> tuple[float, float]:
        """(gamma, GAE lambda) for a flight at ``agent_hz``: as given, else the decay per
        second of 0.99 and 0.95 a step at ``DISCOUNT_HZ``."""
        k = DISCOUNT_HZ / agent_hz
        gamma = self.ppo.gamma if self.ppo.gamma is not None else DEFAULT_GAMMA**k
        lam = self.ppo.gae_lambda if self.ppo.gae_lambda is not None else DEFAULT_GAE_LAMBDA**k
        return gamma, lam

    @property
    def anchor_span(self) -> int:
        """The env steps over which the anchor decays."""
        if self.ppo.anchor_steps is not None:
            return self.ppo.anchor_steps
        return min(self.steps // 2, ANCHOR_SPAN_MAX)


def _actor_steps(steps: int, rollout: int, warmup: int) -> int:
    """The env steps the actor learns from in a run of ``steps`` (whole rollouts of
    ``rollout``) whose critic warms up over ``warmup``: the updates whose rollout began at
    or after the warm-up's end."""
    updates, held = -(-steps // rollout), -(-warmup // rollout)
    return max(0, updates - held) * rollout


def batch_that_fits(rollout: int, batch: int) -> int:
    """The largest batch size of 2 or more, up to ``batch``, that divides ``rollout`` (>= 2),
    else ``rollout`` itself; of a rollout over 10**12 samples only the divisors found up to
    a million's pairs are tried (an answer in well under a second)."""
    small = [d for d in range(1, min(math.isqrt(rollout), 10**6) + 1) if rollout % d == 0]
    fitting = [d for d in small + [rollout // d for d in small] if 2 <= d <= batch]
    return max(fitting, default=rollout)
