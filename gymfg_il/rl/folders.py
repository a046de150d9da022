"""Where a PPO run writes: its policy folder (``--out``), which never lies in, over or
around the starting policy's (``--init``)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from gymfg_il.errors import ConfigError

if TYPE_CHECKING:
    from gymfg_il.envs.flight import FlightSpec


def overlap_problem(init: Path | None, out: Path | None) -> str | None:
    """Why ``out`` may not take the policy of a run that starts from ``init``, or None: the
    same folder (links followed), or one inside the other (saving replaces ``out`` whole)."""
    if init is None or out is None:
        return None
    try:
        start, into = Path(init).resolve(), Path(out).resolve()
    except (OSError, RuntimeError) as err:  # a loop of links
        return f"--out {out}, --init {init}: cannot follow the path ({err}); give plain folders"
    if into == start:
        return (
            f"--out {out} is the starting policy's folder (--init {init}): saving would replace "
            "it; give an --out of its own"
        )
    if start in into.parents:
        return (
            f"--out {out} lies inside --init {init}: the policy would be saved into the "
            "starting policy's folder; give an --out outside it"
        )
    if into in start.parents:
        return (
            f"--init {init} lies inside --out {out}, and saving replaces --out whole, the "
            "starting policy with it: give an --out that does not hold it"
        )
    return None


def out_folder(out: Path | None, init: Path | None, flight: FlightSpec) -> Path:
    """Where the run saves its policy: ``out``, by default policies/ppo-<task>-<aircraft>,
    checked before anything is trained: apart from ``init`` and writable (``check_out``)."""
    from gymfg_il.policies.checkpoint_folder import check_out

    folder = Path(out or f"policies/ppo-{flight.task}-{flight.aircraft}")
    if problem := overlap_problem(init, folder):
        raise ConfigError(problem)
    check_out(folder)
    return folder
