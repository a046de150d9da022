"""``python -m gymfg_il.train bc``: behaviour cloning on a LeRobot dataset.

With no options it trains an MLP on the bundled sample dataset and saves it under policies/.
The policy keeps the dataset's flight spec (aircraft, task, rate, episode time) in its
config.json, so ``eval --policy`` and ``collect dagger --policy`` fly it as it was recorded.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
import typing
from importlib.util import find_spec
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from gymfg_il.envs.flight import FlightSpec
    from gymfg_il.rl.config import PPORunConfig
    from gymfg_il.rl.saving import PPOResult


def build_parser() -> argparse.ArgumentParser:
    """The command line: ``bc`` takes ``TrainConfig``'s flags, ``--policy`` (the type) and
    the settings of every registered policy type (``policy_settings``)."""
    from gymfg_il import cli
    from gymfg_il.learning.config import TrainConfig
    from gymfg_il.policies.factory import bc_types

    p = cli.parser("python -m gymfg_il.train", __doc__)
    sub = p.add_subparsers(dest="algorithm", metavar="{bc,ppo}")
    bc = sub.add_parser(
        "bc",
        help="behaviour cloning (MLP, GRU, action chunks or vision) on a LeRobot dataset",
        description="Train a behaviour-cloning policy on a LeRobot dataset; "
        "saves config.json, model.safetensors and loss.png.",
    )
    cli.add_fields(bc, TrainConfig, only=("dataset", "out"))
    types = bc_types()
    listed = "; ".join(f"{name}: {_first_sentence(t.config)}" for name, t in types.items())
    bc.add_argument(
        "--policy",
        choices=list(types),
        default="mlp",
        help=f"policy type (default: mlp); {listed}".replace("%", "%%"),
    )
    cli.add_fields(bc, TrainConfig, skip=("dataset", "out"))
    cli.add_fields(bc, policy_settings(), overrides_only=True)
    bc.add_argument("--no-progress", action="store_true", help="no progress bar")
    _ppo_parser(sub)
    return p


def _ppo_parser(sub: Any) -> None:
    """``ppo``'s flags in groups: the run, the flight, the evaluations, PPO's own (their
    defaults per task from ``rl/hyperparams.toml``)."""
    from gymfg_il import cli
    from gymfg_il.envs.options import TASK_OWN_TIME, FlightOptions, unset_values
    from gymfg_il.rl import hyperparams
    from gymfg_il.rl.config import PPORunConfig

    ppo = sub.add_parser(
        "ppo",
        help="fine-tune a cloned MLP policy by RL (PPO, stable-baselines3), or train from scratch",
        description="Fine-tune a cloned MLP policy with PPO (stable-baselines3) in its own "
        "flight, or learn one from scratch: the actor starts as the policy, the critic is "
        "warmed up first, and a decaying anchor keeps the first updates near the start. "
        "Evaluates on held-out seeds every --eval-every steps (the start and the controller "
        "too) and saves a ppo policy (config.json, model.safetensors) that eval, collect "
        "dagger and --assist fly, with curve.png, curve.json and a TensorBoard log. Needs the "
        "rl extra: pip install -e '.[rl]'.",
    )
    run = ("init", "steps", "out", "envs", "seed", "sampler", "device", "hidden")
    cli.add_fields(ppo, PPORunConfig, only=run)
    ppo.add_argument("--no-progress", action="store_true", help="no progress bar")
    flight = ppo.add_argument_group("the flight (with --init, left out: the policy's own)")
    unset = {**unset_values(), "episode_time_s": TASK_OWN_TIME}
    options = tuple(f.name for f in dataclasses.fields(FlightOptions))
    shown = {k: f"the policy's; from scratch {v}" for k, v in unset.items()}
    shown |= dict.fromkeys(("task", "aircraft"), "the policy's; from scratch, give it")
    cli.add_fields(typing.cast(Any, flight), PPORunConfig, only=options, shown=shown)
    evaluation = ppo.add_argument_group("evaluations")
    judged = ("eval_every", "eval_episodes", "eval_seed", "select_episodes", "keep", "checkpoints")
    cli.add_fields(typing.cast(Any, evaluation), PPORunConfig, only=judged)
    own = ppo.add_argument_group("PPO's own (defaults per task: gymfg_il/rl/hyperparams.toml)")
    table = hyperparams.table(None)
    shown = {k: f"{v}, or the task's in hyperparams.toml" for k, v in table.items()}
    cli.add_fields(typing.cast(Any, own), PPORunConfig, only=hyperparams.NAMES, shown=shown)


def main(argv: list[str] | None = None) -> int:
    from gymfg_il import cli

    p = build_parser()
    args = p.parse_args(list(sys.argv[1:] if argv is None else argv))
    if args.algorithm is None:
        p.print_help()
        return 2
    return cli.run(lambda: _ppo(args) if args.algorithm == "ppo" else _bc(args))


def _ppo(args: argparse.Namespace) -> int:
    from gymfg_il import cli
    from gymfg_il.rl.config import PPORunConfig

    cfg = cli.build(PPORunConfig, args)
    missing = [m for m in ("stable_baselines3", "tensorboard") if not find_spec(m)]
    if missing:
        from gymfg_il.errors import ConfigError

        raise ConfigError(
            f"train ppo needs the rl extra ({', '.join(missing)} not installed): "
            "pip install -e '.[rl]'"
        )
    from gymfg_il.rl.run import train_ppo
    from gymfg_il.rl.start import starting_policy

    start = starting_policy(cfg)
    for note in start.notes:
        print(note, file=sys.stderr)
    print(ppo_plan(cfg, start.flight), file=sys.stderr)
    bar = cli.progress_bar(cfg.steps, "env steps", "step", not args.no_progress)

    def on_eval(point: Any) -> None:
        text = f"{100 * point.success:.0f}% success, return {point.mean_return:.1f}"
        if args.no_progress:
            print(f"step {point.step:,}: {text}", file=sys.stderr)
        else:
            bar.set_postfix_str(text)

    result = train_ppo(cfg, on_steps=bar.update, on_eval=on_eval, start=start)
    bar.close()
    print(ppo_outcome(result))
    kept = result.kept
    which = "the actor of " + ("the start" if kept.step == 0 else f"step {kept.step:,}")
    print(
        f"policy saved to {result.out}: {which} ({100 * kept.select_success:.0f}% success on "
        f"{kept.chosen_on} evaluation seeds; curve: {result.out / 'curve.png'})"
    )
    return 0


def ppo_outcome(result: PPOResult) -> str:
    """What a ``train ppo`` run reached, in a line: the curve's seeds at the start and for
    the actor it saved (the kept one, not necessarily the last evaluated), beside the
    controller on the same seeds; the last evaluation too where it is another actor."""
    first, last, expert = result.curve[0], result.curve[-1], result.controller
    saved = result.kept  # a point of the curve (``rl.judge.choose``)
    tail = ""
    if saved is not last:
        tail = (
            f"; the last evaluation, step {last.step:,}: {100 * last.success:.0f}%, "
            f"return {last.mean_return:.1f}"
        )
    return (
        f"trained {result.out.name} for {result.steps:,} env steps in {duration(result.seconds)}"
        f": success {100 * first.success:.0f}% -> {100 * saved.success:.0f}% (the saved actor; "
        f"controller {100 * expert.success:.0f}%), return {first.mean_return:.1f} -> "
        f"{saved.mean_return:.1f} (controller {expert.mean_return:.1f}){tail}"
    )


def ppo_plan(cfg: PPORunConfig, flight: FlightSpec) -> str:
    """What a ``train ppo`` run will do, in a line: the flight and its air, the steps and
    envs, how many of them the actor learns from, the evaluations and the kept actor."""
    air = "still air" if flight.turbulence == "none" else f"{flight.turbulence} turbulence"
    if flight.wind_kt:
        air += f" and a {flight.wind_kt:g} kt wind"
    last = cfg.eval_seed + cfg.eval_episodes - 1
    when = f"every {cfg.eval_every:,} env steps" if cfg.eval_every < cfg.steps else "at the start"
    kept_on = f"{cfg.eval_seed}..{cfg.eval_seed + cfg.chosen_on - 1}"
    sampled = -(-cfg.steps // cfg.rollout) * cfg.rollout  # whole rollouts
    keep = "the last actor kept"
    if cfg.keep == "best":
        keep = f"the kept actor the best on seeds {kept_on}"
    return (
        f"PPO on {flight.task_label} on {flight.aircraft} in {air}: {cfg.steps:,} env steps on "
        f"{cfg.n_envs} env(s); the critic alone learns from the first "
        f"{sampled - cfg.actor_steps:,}, the actor too from the next {cfg.actor_steps:,}; "
        f"evaluated {when} and at the end on "
        f"seeds {cfg.eval_seed}..{last} (the curve), {keep}"
    )


def _bc(args: argparse.Namespace) -> int:
    from gymfg_il import cli
    from gymfg_il.datasets.lerobot_api import hub_offline
    from gymfg_il.learning.bc import train_bc
    from gymfg_il.learning.config import TrainConfig, validation_words
    from gymfg_il.learning.data import load_frames
    from gymfg_il.learning.fit import Estimate

    cfg = cli.build(TrainConfig, args, policy=policy_config(args))
    hub_offline()
    frames = load_frames(cfg.dataset, cfg.policy.window.camera)
    show = not args.no_progress
    bar: Any = None

    def on_start(estimate: Estimate) -> None:
        nonlocal bar
        samples = f"{cfg.batch_size} samples ({cfg.policy.window.describe()})"
        print(
            f"training {estimate.epochs} epoch(s) x {estimate.batches} batches of {samples}: "
            f"{duration(estimate.seconds)} ({estimate.batch_s:.3g} s a batch, timed here)",
            file=sys.stderr,
        )
        bar = cli.progress_bar(estimate.epochs, "epochs", "ep", show)

    def on_epoch(epoch: int, train: float, val: float) -> None:
        bar.update(1)
        bar.set_postfix(loss=f"{train:.4f}", **({} if math.isnan(val) else {"val": f"{val:.4f}"}))

    result = train_bc(cfg, on_epoch, frames, on_start)
    bar.close()
    held = validation_words(result.val_loss[-1], result.meta["train"]["val_frames"])
    print(
        f"trained {result.meta['name']} on {result.meta['train']['train_frames']} frames "
        f"({result.frames / result.seconds:,.0f} frames/s): loss {result.train_loss[0]:.4f} "
        f"-> {result.train_loss[-1]:.4f}, {held}"
    )
    print(f"policy saved to {result.out} (loss curve: {result.out / 'loss.png'})")
    if result.overfit:
        print(f"warning: {result.overfit}", file=sys.stderr)
    return 0


def policy_settings() -> type:
    """The settings of every registered policy type as one dataclass of optional fields, one
    per name (a setting several types share is one flag; given a list where a type's setting
    is one value, that type takes the first), each documented for every type it belongs to."""
    from gymfg_il import cli
    from gymfg_il.learning.config import TrainConfig
    from gymfg_il.policies.factory import bc_types

    kinds: dict[str, Any] = {}
    uses: dict[str, dict[str, list[str]]] = {}  # name -> its text -> the types it is theirs
    for name, ptype in bc_types().items():
        docs, hints = cli.field_docs(ptype.config), typing.get_type_hints(ptype.config)
        for f in dataclasses.fields(ptype.config):
            if not f.metadata.get("cli", True):
                continue
            kind, known = hints[f.name], kinds.get(f.name)
            if known is not None and _element(known) != _element(kind):
                raise TypeError(f"policy {name}: setting {f.name}: {kind} clashes with {known}")
            if known is None or typing.get_origin(kind) is list:
                kinds[f.name] = kind
            text = f"{docs.get(f.name, '')} (default: {_default(f)})"
            uses.setdefault(f.name, {}).setdefault(text, []).append(name)
    taken = {f.name for f in dataclasses.fields(TrainConfig)} & set(kinds)
    if taken:
        raise TypeError(f"policy settings {sorted(taken)} clash with train bc's own flags")
    doc = "Attributes:\n" + "".join(
        f"    {setting}: "
        + "; ".join(f"{', '.join(names)}: {text}" for text, names in texts.items())
        + "\n"
        for setting, texts in uses.items()
    )
    fields = [(n, kinds[n] | None, dataclasses.field(default=None)) for n in kinds]
    settings = dataclasses.make_dataclass("PolicySettings", fields)
    settings.__doc__ = doc
    return settings


def policy_config(args: argparse.Namespace) -> Any:
    """The configuration of ``args.policy`` with the settings given on the command line (the
    rest at its defaults); a setting given that the type does not have is named on stderr."""
    from gymfg_il.policies.factory import policy_type

    ptype = policy_type(args.policy)
    own = {f.name: f for f in dataclasses.fields(ptype.config) if f.metadata.get("cli", True)}
    hints = typing.get_type_hints(ptype.config)
    values = {}
    for name in (f.name for f in dataclasses.fields(policy_settings())):
        if not hasattr(args, name):
            continue
        value = getattr(args, name)
        if name not in own:
            flag = "--" + name.replace("_", "-")
            print(
                f"warning: {flag} is no setting of a {ptype.name} policy: ignored", file=sys.stderr
            )
            continue
        if isinstance(value, list) and typing.get_origin(hints[name]) is not list:
            value = value[0]
        values[name] = value
    return ptype.config(**values)


def _default(f: dataclasses.Field[Any]) -> Any:
    if f.default_factory is not dataclasses.MISSING:
        return f.default_factory()
    return f.default


def _element(kind: Any) -> Any:
    """The type of one value of ``kind`` (``int`` for ``list[int]`` and ``int``)."""
    return typing.get_args(kind)[0] if typing.get_origin(kind) is list else kind


def _first_sentence(cls: type) -> str:
    from gymfg_il import cli

    text = cli.summary(cls).split(". ")[0].rstrip(".").replace("``", "")
    return text[:1].lower() + text[1:]


def duration(seconds: float) -> str:
    """An estimate of ``seconds`` as a person reads a wait: "about 40 s", "about 3 min 20 s",
    "about 1 h 05 min"."""
    s = round(seconds)
    if s < 1:
        return "under a second"
    if s < 60:
        return f"about {s} s"
    if s < 3600:
        return f"about {s // 60} min {s % 60:02d} s"
    return f"about {s // 3600} h {s % 3600 // 60:02d} min"


if __name__ == "__main__":
    raise SystemExit(main())
