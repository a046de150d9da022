"""``python -m gymfg_il.train bc``: behaviour cloning on a LeRobot dataset.

With no options it trains an MLP on the bundled sample dataset and saves it under policies/.
"""

from __future__ import annotations

import argparse
import sys


def parse_args(argv: list[str]) -> argparse.Namespace:
    from gymfg_il.cli import add_dataclass_args
    from gymfg_il.learning.bc import TrainConfig

    p = argparse.ArgumentParser(
        prog="python -m gymfg_il.train",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="algorithm", metavar="{bc}")
    bc = sub.add_parser(
        "bc",
        help="behaviour cloning (MLP or GRU) on a LeRobot dataset",
        description="Train a behaviour-cloning policy on a LeRobot dataset; "
        "saves config.json, model.safetensors and loss.png.",
    )
    add_dataclass_args(bc, TrainConfig)
    bc.add_argument("--no-progress", action="store_true", help="no progress bar")
    args = p.parse_args(argv)
    if args.algorithm is None:
        p.print_help()
        p.exit(2)
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(list(sys.argv[1:] if argv is None else argv))
    from gymfg_il.cli import dataclass_from_args
    from gymfg_il.errors import GymFGError
    from gymfg_il.learning.bc import TrainConfig, train_bc

    try:
        cfg = dataclass_from_args(TrainConfig, args)
        from tqdm import tqdm

        bar = tqdm(
            total=cfg.epochs, desc="epochs", unit="ep", disable=args.no_progress, file=sys.stderr
        )

        def on_epoch(epoch: int, train: float, val: float) -> None:
            bar.update(1)
            bar.set_postfix(loss=f"{train:.4f}", val=f"{val:.4f}")

        result = train_bc(cfg, on_epoch)
        bar.close()
    except GymFGError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print(
        f"trained {result.meta['name']} on {result.meta['train']['frames']} frames "
        f"({result.frames / result.seconds:,.0f} frames/s): loss {result.train_loss[0]:.4f} "
        f"-> {result.train_loss[-1]:.4f}, validation {result.val_loss[-1]:.4f}"
    )
    print(f"policy saved to {result.out} (loss curve: {result.out / 'loss.png'})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
