"""stable-baselines3 callbacks of a PPO run: ``EvaluationCallback`` counts the sampled steps
and evaluates the actor every ``eval_every`` env steps (``rl.judge``)."""

from __future__ import annotations

from collections.abc import Callable

from stable_baselines3.common.callbacks import BaseCallback

from gymfg_il.rl.judge import EvalPoint, Judge
from gymfg_il.rl.policy import AnchoredPolicy


class EvaluationCallback(BaseCallback):
    """Calls ``on_steps(n)`` for every n env steps sampled, and evaluates the actor with
    ``judge`` after the first update at or past every multiple of ``eval_every`` env steps
    (the point is appended to ``curve``, logged as ``eval/*`` and passed to ``on_eval``); on
    ``more`` seeds too when ``more`` (the kept actor is chosen on them)."""

    def __init__(
        self,
        judge: Judge,
        curve: list[EvalPoint],
        eval_every: int,
        more: bool,
        on_steps: Callable[[int], None] | None = None,
        on_eval: Callable[[EvalPoint], None] | None = None,
    ) -> None:
        super().__init__()
        self.judge, self.curve, self.eval_every, self.more = judge, curve, eval_every, more
        self.on_steps, self.on_eval = on_steps, on_eval
        self.next_eval = eval_every

    def _on_step(self) -> bool:
        if self.on_steps is not None:
            self.on_steps(self.training_env.num_envs)
        return True

    def _on_rollout_start(self) -> None:
        # after the update on the rollout that ended here (the last update is evaluated by
        # train_ppo, after learn)
        if self.num_timesteps < self.next_eval:
            return
        while self.next_eval <= self.num_timesteps:
            self.next_eval += self.eval_every
        policy = self.model.policy
        assert isinstance(policy, AnchoredPolicy)
        point = self.judge(policy.actor, self.num_timesteps, more=self.more)
        self.curve.append(point)
        self.logger.record("eval/success", point.success)
        self.logger.record("eval/mean_return", point.mean_return)
        self.logger.record("eval/crashed", point.crashed)
        if self.on_eval is not None:
            self.on_eval(point)
