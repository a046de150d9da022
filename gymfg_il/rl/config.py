"""The settings of a PPO fine-tuning run (``PPORunConfig``, ``train ppo``)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from gymfg_il.errors import ConfigError, join_problems
from gymfg_il.rl.folders import overlap_problem
from gymfg_il.sim.weather import Turbulence
from gymfg_il.typecheck import SEED_LIMIT, SEED_RULE, seed_problem, type_problems

ANCHOR_SPAN_MAX = 150_000  # the longest the anchor decays over by default (``anchor_steps``)
# the actor's default learning rate when fine-tuning (``actor_lr``); from scratch it is ``lr``
FINE_TUNE_ACTOR_LR = 1e-4
# the episodes the kept actor is chosen on by default (``select_episodes``)
SELECT_EPISODES = 64
# the default discount and GAE lambda per step at DISCOUNT_HZ, kept per second at other rates
DEFAULT_GAMMA, DEFAULT_GAE_LAMBDA, DISCOUNT_HZ = 0.99, 0.95, 10


@dataclass
class PPORunConfig:
    """PPO fine-tuning of a cloned MLP policy (stable-baselines3), or PPO from scratch.

    Attributes:
        init: the MLP policy to start from (a folder ``train bc --policy mlp`` wrote): the
            actor starts as its network and normalisation and flies its task and aircraft;
            left out, PPO learns from scratch (give --task and --aircraft), the comparison.
        steps: environment steps to train for (all envs together).
        out: where the policy goes (default: policies/ppo-<task>-<aircraft>).
        task: the task, from scratch; with --init it must be the policy's own.
        aircraft: the aircraft, from scratch; with --init it must be the policy's own.
        agent_hz: the agent rate (Hz), from scratch (default: 10; with --init: the policy's
            own, and another is refused).
        turbulence: the air to train in: none, light, moderate or severe (default: the
            starting policy's; a change is printed as a note).
        wind_kt: a steady wind (knots) to train in (default: the starting policy's).
        envs: environments sampled in parallel, in one process per CPU core (0: four per
            core; ``benchmarks.rl`` measures the sampling rate).
        seed: seeds the envs (env k starts from seed + k), the sampling and the networks; a
            run with the same settings and the same number of envs repeats exactly on the
            same machine and install (give --envs to repeat a run on a machine with other
            cores; on another machine a long run may part from it, docs/results/rl.md). Env
            k draws all its episodes from seed + k, so runs meant to be independent take
            seeds at least envs apart (seeds 3 and 4 share 7 of 8 envs' episodes).
        eval_every: evaluate the policy's mean action every this many env steps.
        eval_episodes: held-out episodes each evaluation flies (seeds eval_seed, eval_seed +
            1, ...), the same every time, with the controller on them once.
        eval_seed: the first held-out seed.
        select_episodes: episodes each evaluation flies to choose the kept actor (with --keep
            best): the curve's eval_episodes seeds and the next ones (seeds eval_seed ..
            eval_seed + select_episodes - 1), on two processes (default: 64, or
            eval_episodes if more). Equal to eval_episodes: chosen on the curve's seeds alone.
        keep: which actor is saved: ``best``, the evaluation with the highest success (then
            return) on the select_episodes seeds, the start included, so the result never
            flies worse than the start on these seeds; or ``last``, the actor as training
            left it. Judge the result on other seeds (``eval --seed``).
        checkpoints: keep every evaluated actor, a policy in OUT/checkpoints/step-N (about
            0.6 MB each), to fly again (``eval --policy``) or choose on other seeds.
        rollout_steps: steps each env samples between updates (PPO's n_steps).
        batch_size: samples per gradient step, a divisor of the rollout (rollout_steps x envs).
        epochs: passes over each rollout per update.
        lr: Adam learning rate of the critic.
        actor_lr: Adam learning rate of the actor (default: 1e-4 when fine-tuning, whatever
            --lr is, a third of the default critic's, so that the cloned actor moves slower
            than the critic learns and runs do not fall below their start,
            docs/results/rl.md; from scratch: lr).
        gamma: discount per step (default: 0.99 at 10 Hz, and at other agent rates the same
            decay per second, 0.99 ** (10 / Hz): 0.9967 at 30 Hz; at 30 Hz a plain 0.99 sees
            3 s ahead, and a fine-tuned turn learnt to crash; docs/results/rl.md).
        gae_lambda: GAE's lambda per step (default: 0.95 at 10 Hz, likewise per second).
        clip_range: PPO's clip on the probability ratio.
        target_kl: an update stops early when its KL divergence from the sampling policy
            passes 1.5 x this (0: never).
        action_std: the exploration noise's starting spread in the policy's normalised action
            units (1 = the demonstrations' spread of each control). PPO explores with
            stable-baselines3's generalised state-dependent exploration: the noise is a linear
            map of the normalised observation, drawn anew every rollout, so the controls
            deviate coherently for a while, which a slow aircraft's state answers.
        critic_warmup: env steps over which only the critic learns, the actor held, so the
            first actor updates follow a trained value function: every update on a rollout
            that began before this many steps (default: a tenth of the run, at most 20,000
            steps; at least one rollout).
        success_bonus: at the end of each training episode, the task judges it as eval does,
            and a success adds this share of the episode's steps to its return (a step's task
            reward is at most about 1), so what PPO maximises includes what success measures
            (0: the task's reward alone).
        anchor: weight, at the start, of the squared distance between the actor's mean action
            and the starting policy's (normalised units) added to PPO's loss; it decays
            linearly to 0 over anchor_steps (0: no anchor). Not used from scratch.
        anchor_steps: env steps over which the anchor decays (default: half the run, at most
            150k: a longer anchor holds a long run at its start; docs/results/rl.md).
        critic: hidden widths of the critic (value network).
        hidden: hidden widths of the actor, from scratch (with --init: the policy's own).
        device: cpu or cuda (the networks are small: cpu is usually faster).
        sampler: how rollouts are sampled: ``grouped``, in the env processes, one per core,
            each sampling its envs' actions from a copy of the policy (``rl.grouped``;
            ``python -m benchmarks.rl`` measures it), or ``sb3``, stable-baselines3's own
            loop (one process per env, the policy run in the trainer between steps). Both
            sample the same policy; their noise is drawn by different generators, so a seed
            flies another run on each.
    """

    init: Path | None = None
    steps: int = 1_000_000
    out: Path | None = None
    task: str | None = None
    aircraft: str | None = None
    agent_hz: int | None = None
    turbulence: Turbulence | None = None
    wind_kt: float | None = None
    envs: int = 0
    seed: int = 0
    eval_every: int = 50_000
    eval_episodes: int = 16
    eval_seed: int = 7000
    select_episodes: int | None = None
    keep: Literal["best", "last"] = "best"
    checkpoints: bool = False
    rollout_steps: int = 512
    batch_size: int = 512
    epochs: int = 10
    lr: float = 3e-4
    actor_lr: float | None = None
    gamma: float | None = None
    gae_lambda: float | None = None
    clip_range: float = 0.2
    target_kl: float = 0.02
    action_std: float = 0.2
    critic_warmup: int | None = None
    success_bonus: float = 0.2
    anchor: float = 1.0
    anchor_steps: int | None = None
    critic: list[int] = field(default_factory=lambda: [256, 256])
    hidden: list[int] = field(default_factory=lambda: [256, 256])
    device: str = "cpu"
    sampler: Literal["grouped", "sb3"] = "grouped"

    def __post_init__(self) -> None:
        typed = type_problems(self)
        if typed:
            raise ConfigError(join_problems("train ppo", typed))
        problems = []
        if self.init is None and (self.task is None or self.aircraft is None):
            problems.append(
                "give --init POLICY (a cloned MLP to fine-tune) or, from scratch, --task and "
                "--aircraft"
            )
        positive = ("steps", "eval_every", "eval_episodes", "rollout_steps", "epochs")
        for name in positive:
            if getattr(self, name) < 1:
                problems.append(f"{name}={getattr(self, name)} must be >= 1")
        if self.select_episodes is not None and self.select_episodes < self.eval_episodes:
            problems.append(
                f"select_episodes={self.select_episodes} must be >= eval_episodes="
                f"{self.eval_episodes} (the kept actor is chosen on the curve's seeds and more)"
            )
        problems += self._rollout_problems() + self._seed_problems()
        problems += filter(None, [overlap_problem(self.init, self.out)])
        problems += self._rate_problems()
        if not 0 < self.clip_range < 1:
            problems.append(f"clip_range={self.clip_range} must lie in (0, 1)")
        for name in ("target_kl", "anchor", "success_bonus"):
            value = getattr(self, name)
            if not (value >= 0 and math.isfinite(value)):
                problems.append(f"{name}={value} must be a number >= 0")
        if not (0 < self.action_std <= 10):
            problems.append(f"action_std={self.action_std} must lie in (0, 10]")
        for name in ("critic_warmup", "anchor_steps"):
            value = getattr(self, name)
            if value is not None and value < 0:
                problems.append(f"{name}={value} must be >= 0 env steps")
        if not self.critic or min(self.critic) < 1 or not self.hidden or min(self.hidden) < 1:
            problems.append("critic and hidden must be non-empty lists of widths > 0")
        if self.device not in ("cpu", "cuda", "auto") and not self.device.startswith("cuda:"):
            problems.append(f"device={self.device!r}: use cpu, cuda, cuda:N or auto")
        if problems:
            raise ConfigError(join_problems("train ppo", problems))
        self.init = None if self.init is None else Path(self.init)

    def _rate_problems(self) -> list[str]:
        """The learning rates and the discounts out of their ranges."""
        problems = []
        if not 0 < self.lr < 1:
            problems.append(f"lr={self.lr} must lie in (0, 1) (default 3e-4)")
        if self.actor_lr is not None and not 0 < self.actor_lr < 1:
            problems.append(f"actor_lr={self.actor_lr} must lie in (0, 1)")
        for name in ("gamma", "gae_lambda"):
            value = getattr(self, name)
            if value is not None and not 0 < value <= 1:
                problems.append(f"{name}={value} must lie in (0, 1]")
        return problems

    def _seed_problems(self) -> list[str]:
        """Every seed the run takes held to the one seed rule (``typecheck.seed_problem``):
        the envs' (env k starts from seed + k; stable-baselines3 seeds numpy's legacy
        generator with ``seed``) and the held-out episodes' (eval_seed + i, up to the last
        episode the kept actor is chosen on)."""
        problems = []
        if problem := seed_problem(self.seed):
            problems.append(problem)
        elif self.envs >= 0 and (last := self.seed + self.n_envs - 1) >= SEED_LIMIT:
            problems.append(
                f"seed={self.seed}: env {last - self.seed} starts from seed {last}, and a seed "
                f"is an integer {SEED_RULE}; give --seed {SEED_LIMIT - self.n_envs} or below"
            )
        if problem := seed_problem(self.eval_seed, self.chosen_on):
            problems.append(f"eval_{problem}")  # "seed=...: why" names the flag
        return problems

    def _rollout_problems(self) -> list[str]:
        """What stable-baselines3's PPO would stop on (an assertion, after the start's
        evaluation had flown) or warn of: PPO normalises the advantages of each batch, so a
        batch holds 2 samples or more, a rollout (rollout_steps x envs) too, and the batches
        divide the rollout (else each epoch ends on a truncated batch)."""
        problems = []
        if self.envs < 0:
            problems.append(f"envs={self.envs}: want 0 (four per core) or more")
        if self.batch_size < 2:
            problems.append(
                f"batch_size={self.batch_size} must be >= 2 (PPO normalises each batch's "
                "advantages)"
            )
        if problems or self.rollout_steps < 1:  # rollout_steps: refused with the other counts
            return problems
        envs = f"envs={self.envs}" if self.envs else f"{self.n_envs} envs (four a core)"
        rollout = self.rollout
        if rollout < 2:
            return [
                f"rollout_steps={self.rollout_steps} x {envs} is a rollout of {rollout} sample; "
                "PPO normalises a rollout's advantages, which takes 2 or more: give "
                "--rollout-steps 2 or more, or --envs 2 or more"
            ]
        if rollout % self.batch_size:
            fits = batch_that_fits(rollout, self.batch_size)
            return [
                f"batch_size={self.batch_size} must divide a rollout's {rollout} samples "
                f"(rollout_steps={self.rollout_steps} x {envs}), or each epoch ends on a "
                f"truncated batch: give --batch-size {fits}, or a rollout it divides"
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
        return self.rollout_steps * self.n_envs

    @property
    def actor_rate(self) -> float:
        """The actor's learning rate: ``actor_lr``, else 1e-4 when fine-tuning, else ``lr``."""
        if self.actor_lr is not None:
            return self.actor_lr
        return FINE_TUNE_ACTOR_LR if self.init is not None else self.lr

    @property
    def warmup_steps(self) -> int:
        if self.critic_warmup is not None:
            return self.critic_warmup
        return max(self.rollout, min(20_000, self.steps // 10))

    def discounts(self, agent_hz: int) -> tuple[float, float]:
        """(gamma, GAE lambda) for a flight at ``agent_hz``: as given, else the decay per
        second of 0.99 and 0.95 a step at ``DISCOUNT_HZ``."""
        k = DISCOUNT_HZ / agent_hz
        gamma = self.gamma if self.gamma is not None else DEFAULT_GAMMA**k
        lam = self.gae_lambda if self.gae_lambda is not None else DEFAULT_GAE_LAMBDA**k
        return gamma, lam

    @property
    def anchor_span(self) -> int:
        if self.anchor_steps is not None:
            return self.anchor_steps
        return min(self.steps // 2, ANCHOR_SPAN_MAX)


def batch_that_fits(rollout: int, batch: int) -> int:
    """The largest batch size of 2 or more, up to ``batch``, that divides ``rollout`` (>= 2),
    else ``rollout`` itself; of a rollout over 10**12 samples only the divisors found up to
    a million's pairs are tried (an answer in well under a second)."""
    small = [d for d in range(1, min(math.isqrt(rollout), 10**6) + 1) if rollout % d == 0]
    fitting = [d for d in small + [rollout // d for d in small] if 2 <= d <= batch]
    return max(fitting, default=rollout)
