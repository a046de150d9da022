"""Where a PPO run writes: its policy folder (``--out``), which never lies in, over or
around the starting policy's (``--init``), and its scratch folder in the temp directory (the
TensorBoard log and the evaluated actors until the policy is saved).

A run removes its scratch folder when it ends; a killed one (``kill -9``, a lost machine)
cannot, so the folder is named for the run's process (``gymfg-ppo-PID-XXXXXXXX``) and the
next run clears the folders whose process is gone, as ``staged`` saves clear the staging
folders of killed saves (the same liveness test, ``checkpoint_folder._alive``)."""

from __future__ import annotations

import logging
import os
import shutil
import stat
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

from gymfg_il.errors import ConfigError
from gymfg_il.policies.checkpoint_folder import _alive

if TYPE_CHECKING:
    from gymfg_il.envs.flight import FlightSpec

log = logging.getLogger(__name__)
SCRATCH = "gymfg-ppo-"  # a scratch folder's name: SCRATCH + the run's pid + "-" + a random tail


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


def scratch_folder() -> Path:
    """A new scratch folder in the temp directory, named for this process, once the folders
    of killed runs are cleared (``clear_killed_runs``)."""
    clear_killed_runs()
    return Path(tempfile.mkdtemp(prefix=f"{SCRATCH}{os.getpid()}-"))


def clear_killed_runs(where: Path | None = None) -> list[Path]:
    """Remove the scratch folders in ``where`` (default: the temp directory) of runs whose
    process is gone; those of live processes, of this one (its runs remove their own), of
    other users and anything not named as a scratch folder stay. The folders removed."""
    cleared = []
    for path in sorted(Path(where or tempfile.gettempdir()).glob(f"{SCRATCH}*-*")):
        pid, dash, _ = path.name.removeprefix(SCRATCH).partition("-")
        if not (dash and pid.isdigit()) or int(pid) == os.getpid() or _alive(int(pid)):
            continue
        try:
            info = path.lstat()
            if not stat.S_ISDIR(info.st_mode) or info.st_uid != os.getuid():
                continue  # a link or a file, or another user's
            shutil.rmtree(path)
        except FileNotFoundError:  # another run starting now cleared it first
            continue
        except OSError as err:
            log.warning("cannot remove %s, a killed PPO run's scratch folder: %s", path, err)
            continue
        cleared.append(path)
    return cleared
