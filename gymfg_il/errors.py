"""The project's exceptions: every one names the bad value and the fix."""

from __future__ import annotations


class GymFGError(Exception):
    """Base class of every error GymFG-IL raises on purpose."""


class ConfigError(GymFGError, ValueError):
    """A configuration value breaks a rule; the message says which and how to fix it."""


class RateError(ConfigError):
    """An agent rate that does not divide the simulation rate exactly."""


class UnknownAircraftError(ConfigError, LookupError):
    """An aircraft model name that JSBSim does not ship."""


class DuplicateNameError(ConfigError):
    """Two teams with one name, or two aircraft with one callsign."""


class ActionError(GymFGError, ValueError):
    """An action of the wrong shape or with NaN/inf values; never passed to JSBSim."""


class EnvStateError(GymFGError, RuntimeError):
    """An environment used out of order (step before reset, step after the episode ended)."""


def join_problems(what: str, problems: list[str]) -> str:
    """One message for all problems of one input (LeRobot's validate_frame style): ``what``
    names the input ("TrainConfig") or says what is wrong with it ("the dataset at X is
    damaged")."""
    if len(problems) == 1:
        return f"{what}: {problems[0]}"
    return f"{what} ({len(problems)} problems):\n" + "\n".join(f"  - {p}" for p in problems)


class MixedTasksError(ConfigError):
    """A dataset whose episodes were flown in different tasks, trained as if they were one."""


class UntrustedTaskError(ConfigError):
    """A record read from a file names a task by import path whose module nobody imported:
    building it would run code the file chose."""


# what the libraries under GymFG say when the disk is full: OSError's errno (ENOSPC, EDQUOT),
# or only in their text (safetensors' SafetensorError, pyarrow's and torch's messages)
_FULL_ERRNOS = (28, 122)
_FULL_TEXTS = ("No space left on device", "StorageFull", "os error 28", "Disk quota exceeded")


def disk_full(err: BaseException) -> str | None:
    """Where ``err`` (or what caused it) says the disk is full: the file or the message;
    None when it says nothing of the kind."""
    seen: set[int] = set()
    found: BaseException | None = err
    while found is not None and id(found) not in seen:
        seen.add(id(found))
        if isinstance(found, OSError) and found.errno in _FULL_ERRNOS:
            return str(found.filename or found.strerror)
        if any(text in str(found) for text in _FULL_TEXTS):
            return str(found).splitlines()[0][:200] if str(found) else type(found).__name__
        found = found.__cause__ or found.__context__
    return None
