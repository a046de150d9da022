"""What a training run leaves on disk: the policy folder (``config.json``,
``model.safetensors``), its loss curve (``loss.png``) and log (``train_log.json``), saved
whole or not at all (``policies.checkpoint_folder.staged``), and never from a run whose loss
or weights stopped being finite numbers (``--lr 1e308`` saved a policy of NaN weights with
exit status 0)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.errors import ConfigError, disk_full


class DivergedError(ConfigError):
    """Training whose loss or weights stopped being finite numbers; nothing is saved."""


def check_diverged(
    policy: Any, settings: str, epoch: int | None = None, fix: str = "lower --lr (default 1e-3)"
) -> None:
    """Refuse (``DivergedError``) a run at ``epoch``, whose loss was not finite, or (no
    ``epoch``) a policy whose weights are not all finite; ``settings`` names the run's step
    sizes for the message, ``fix`` what to change."""
    import torch

    if epoch is None and all(bool(torch.isfinite(t).all()) for t in policy.state_dict().values()):
        return
    when = f"in epoch {epoch + 1} (the loss is not finite)" if epoch is not None else ""
    raise DivergedError(
        f"training diverged {when or '(its weights are not finite)'} with {settings}; "
        f"nothing was saved: {fix}"
    )


def finite_or_null(losses: list[float]) -> list[float | None]:
    """``losses`` for a JSON file: null where there is none (NaN: no episode held out), so
    that the file is JSON every reader parses, not Python's ``NaN``."""
    return [None if math.isnan(v) else v for v in losses]


def save_run(
    out: Path,
    policy: Any,
    meta: dict[str, Any],
    stats: tuple[dict[str, np.ndarray], dict[str, np.ndarray]],
    losses: tuple[list[float], list[float]],
) -> None:
    """Save the policy, its loss curve and log as the folder ``out``, replacing any older
    policy there in one step."""
    from gymfg_il.policies.checkpoint import save_policy
    from gymfg_il.policies.checkpoint_folder import staged

    train, val = losses
    try:
        with staged(out) as folder:
            save_policy(policy, folder, meta, *stats)
            label = getattr(policy, "loss_label", "loss")
            plot_losses(train, val, folder / "loss.png", str(meta["name"]), label)
            text = json.dumps({"train_loss": train, "val_loss": finite_or_null(val)}, indent=1)
            (folder / "train_log.json").write_text(text)
    except OSError as err:
        if disk_full(err):
            raise  # the entry point says so in one line
        raise ConfigError(
            f"cannot save the policy to {out} ({err.strerror or err}); give another --out"
        ) from None


def plot_losses(
    train: list[float], val: list[float], path: Path, title: str, label: str = "loss"
) -> None:
    """Save ``loss_figure`` to ``path``."""
    import matplotlib.pyplot as plt

    fig = loss_figure(train, val, title, label)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def loss_figure(train: list[float], val: list[float], title: str, label: str) -> Any:
    """The loss of every epoch, training and validation, on a log scale over whole epochs;
    ``label`` says what the loss is (the policy's ``loss_label``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    fig, ax = plt.subplots(figsize=(6, 3.5))
    epochs = np.arange(1, len(train) + 1)
    ax.semilogy(epochs, train, label="train")
    if not all(math.isnan(v) for v in val):
        ax.semilogy(epochs, val, label="validation (held-out episodes)")
    ax.set_xlabel("epoch")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_ylabel(label)
    ax.set_title(title)
    ax.legend()
    fig.tight_layout()
    return fig
