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
    """One message for all problems of one input (LeRobot's validate_frame style)."""
    if len(problems) == 1:
        return f"{what}: {problems[0]}"
    return f"{what} has {len(problems)} problems:\n" + "\n".join(f"  - {p}" for p in problems)


class MixedTasksError(ConfigError):
    """A dataset whose episodes were flown in different tasks, trained as if they were one."""


class UntrustedTaskError(ConfigError):
    """A record read from a file names a task by import path whose module nobody imported:
    building it would run code the file chose."""
