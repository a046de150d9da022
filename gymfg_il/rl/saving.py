"""What a PPO run leaves (``save_run``): its policy folder, a ``ppo`` policy
(config.json and model.safetensors) that ``eval``, ``collect dagger`` and ``--assist`` fly,
with the run's settings and curve in config.json's ``rl`` entry and curve.json, the curve's
plot (curve.png), stable-baselines3's TensorBoard log and, if asked, every evaluated actor."""

from __future__ import annotations

import json
import shutil
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from gymfg_il.errors import ConfigError
from gymfg_il.rl.config import PPORunConfig
from gymfg_il.rl.judge import EvalPoint, plot_curve
from gymfg_il.rl.start import Start, as_ppo, meta_of, stats_of


@dataclass
class PPOResult:
    """A finished run: where its policy went, its env steps and wall time, its curve (the
    start first, the actor after the last update last), the controller on the curve's
    seeds, the notes on its flight, and the kept actor's evaluation."""

    out: Path
    steps: int
    seconds: float
    curve: list[EvalPoint]
    controller: EvalPoint
    notes: list[str]
    kept: EvalPoint  # the saved actor's evaluation (``PPORunConfig.keep``)

    @property
    def kept_step(self) -> int:
        """The step of the saved actor's evaluation."""
        return self.kept.step


def save_run(cfg: PPORunConfig, result: PPOResult, start: Start, actor: Any, scratch: Path) -> None:
    """The policy folder: config.json and model.safetensors (a ``ppo`` policy), the curve
    (curve.json, curve.png), the TensorBoard log and, if asked, every evaluated actor
    (checkpoints/), saved whole or not at all."""
    from gymfg_il.learning.saving import check_diverged
    from gymfg_il.policies.checkpoint import save_policy
    from gymfg_il.policies.checkpoint_folder import staged

    module = as_ppo(actor)
    check_diverged(module, f"lr={cfg.ppo.lr}", fix="lower --lr (default 3e-4)")
    flight = start.flight
    name = Path(result.out).name
    settings = {k: str(v) if isinstance(v, Path) else v for k, v in asdict(cfg).items()}
    settings |= asdict(cfg.ppo)  # PPO's settings as applied: given, else hyperparams.toml's
    settings["gamma"], settings["gae_lambda"] = cfg.discounts(flight.agent_hz)
    settings["actor_lr"] = cfg.actor_rate
    settings["critic_warmup"], settings["anchor_steps"] = cfg.warmup_steps, cfg.anchor_span
    rl = {
        "algorithm": "ppo (stable-baselines3)",
        "init": str(cfg.init) if cfg.init else None,
        "steps": result.steps,
        "kept": {
            "which": cfg.keep,
            "step": result.kept_step,
            "chosen_on": result.kept.chosen_on,
            "select_success": result.kept.select_success,
        },
        "wall_s": round(result.seconds, 1),
        "envs": cfg.n_envs,
        "settings": settings,
        "curve": [asdict(p) for p in result.curve],
        "controller": asdict(result.controller),
    }
    meta = {
        **meta_of(start),
        "name": name,
        "spec": flight.to_dict(),
        "spec_note": "",
        "task": flight.task,
        "dynamic": flight.dynamic,
        "aircraft": flight.aircraft,
        "rl": rl,
    }
    try:
        with staged(result.out) as folder:
            save_policy(
                module, folder, meta, stats_of(module, "obs_norm"), stats_of(module, "action_norm")
            )
            (folder / "curve.json").write_text(json.dumps(rl, indent=1))
            title = f"{name}: {flight.task_label} on {flight.aircraft}"
            plot_curve(result.curve, result.controller, title, folder / "curve.png", result.kept)
            for part in ("tensorboard", "checkpoints"):
                if (scratch / part).is_dir():
                    shutil.copytree(scratch / part, folder / part)
    except OSError as err:
        raise ConfigError(
            f"cannot save the policy to {result.out} ({err}); free some space or give another --out"
        ) from None
