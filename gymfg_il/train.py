"""``python -m gymfg_il.train bc``: behaviour cloning on a LeRobot dataset.

With no options it trains an MLP on the bundled sample dataset and saves it under policies/.
The policy keeps the dataset's flight spec (aircraft, task, rate, episode time) in its
config.json, so ``eval --policy`` and ``collect dagger --policy`` fly it as it was recorded.
"""

from __future__ import annotations

import sys


def main(argv: list[str] | None = None) -> int:
    from gymfg_il import cli
    from gymfg_il.learning.bc import TrainConfig

    p = cli.parser("python -m gymfg_il.train", __doc__)
    sub = p.add_subparsers(dest="algorithm", metavar="{bc}")
    bc = sub.add_parser(
        "bc",
        help="behaviour cloning (MLP or GRU) on a LeRobot dataset",
        description="Train a behaviour-cloning policy on a LeRobot dataset; "
        "saves config.json, model.safetensors and loss.png.",
    )
    cli.add_fields(bc, TrainConfig)
    bc.add_argument("--no-progress", action="store_true", help="no progress bar")
    args = p.parse_args(list(sys.argv[1:] if argv is None else argv))
    if args.algorithm is None:
        p.print_help()
        return 2
    return cli.run(lambda: _bc(cli.build(TrainConfig, args), not args.no_progress))


def _bc(cfg: object, show_progress: bool) -> int:
    from gymfg_il import cli
    from gymfg_il.datasets.lerobot_api import hub_offline
    from gymfg_il.learning.bc import TrainConfig, epochs_for, train_bc
    from gymfg_il.learning.data import load_frames

    assert isinstance(cfg, TrainConfig)
    hub_offline()
    frames = load_frames(cfg.dataset, cfg.camera if cfg.policy == "vision" else None)
    epochs = epochs_for(cfg, frames)
    bar = cli.progress_bar(epochs, "epochs", "ep", show_progress)

    def on_epoch(epoch: int, train: float, val: float) -> None:
        bar.update(1)
        bar.set_postfix(loss=f"{train:.4f}", val=f"{val:.4f}")

    result = train_bc(cfg, on_epoch, frames)
    bar.close()
    print(
        f"trained {result.meta['name']} on {result.meta['train']['train_frames']} frames "
        f"({result.frames / result.seconds:,.0f} frames/s): loss {result.train_loss[0]:.4f} "
        f"-> {result.train_loss[-1]:.4f}, validation {result.val_loss[-1]:.4f}"
    )
    print(f"policy saved to {result.out} (loss curve: {result.out / 'loss.png'})")
    if result.overfit:
        print(f"warning: {result.overfit}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
