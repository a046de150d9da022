"""The session record: what a log's flight was, written once at the top of every MCAP log
(metadata record ``gymfg.session``) and read back whole.

    {"schema_version": 2, "spec": FlightSpec.to_dict(), "source": "autopilot",
     "aircraft": {callsign: {"team", "model", "task", "observation_names", "task_description"}},
     "callsigns": [...], "dt": 0.1, "versions": {...}, ...extra (noise, iteration, device)}

Logs written before the flight spec existed (``schema_version`` 1) are read as if they had one
(``upgrade``), so nothing recorded then is lost.
"""

from __future__ import annotations

import json
import zlib
from collections.abc import Mapping
from typing import Any

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import ConfigError
from gymfg_il.sim.timing import DEFAULT_SIM_HZ
from gymfg_il.tasks.base import Task

SCHEMA_VERSION = 2
SESSION_METADATA = "gymfg.session"
SESSION_COPY = "gymfg.session.copy"  # the same record again: a flipped bit costs one of two
CHANNELS_METADATA = "gymfg.channels"  # channel id -> topic, outside every chunk
CRC_KEY = "gymfg.crc32"


def _crc(entries: Mapping[str, str]) -> str:
    body = sorted((k, v) for k, v in entries.items() if k != CRC_KEY)
    return str(zlib.crc32(json.dumps(body).encode()))


def checked(entries: Mapping[str, str]) -> dict[str, str]:
    """A metadata map with its CRC-32 under ``CRC_KEY`` (MCAP checks no metadata record)."""
    return {**entries, CRC_KEY: _crc(entries)}


def crc_state(entries: Mapping[str, str]) -> bool | None:
    """Whether a metadata map passes its CRC; None when it has none (logs before it)."""
    if CRC_KEY not in entries:
        return None
    return entries[CRC_KEY] == _crc(entries)


def package_versions() -> dict[str, str]:
    """Versions of the packages a log's contents depend on."""
    from importlib.metadata import PackageNotFoundError, version

    out = {}
    for name in ("gymfg-il", "jsbsim", "gymnasium", "mcap", "numpy", "lerobot"):
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "absent"
    return out


def task_description(task: Task, model: str) -> str:
    """The dataset's per-frame task string: the first line of the task's docstring, and the
    aircraft."""
    doc = (type(task).__doc__ or task.name).strip().splitlines()[0]
    return f"{doc} ({model})"


def session_record(
    spec: FlightSpec,
    source: str,
    tasks: Mapping[str, Task] | None = None,
    **extra: Any,
) -> dict[str, Any]:
    """The session record of a flight; ``tasks`` (callsign -> the task flown) where the spec
    cannot rebuild them, else they are built from the spec."""
    aircraft = {}
    for team in spec.teams:
        for a in team.roster:
            task = tasks[a.callsign] if tasks is not None else a.task_factory()()
            aircraft[a.callsign] = {
                "team": team.name,
                "model": a.model,
                "task": task.describe(),
                "observation_names": list(task.observation_names),
                "task_description": task_description(task, a.model),
            }
    return {
        "schema_version": SCHEMA_VERSION,
        "versions": package_versions(),
        "spec": spec.to_dict(),
        "source": source,
        "aircraft": aircraft,
        "callsigns": list(aircraft),
        "dt": 1.0 / spec.agent_hz,
        **extra,
    }


def spec_of(session: Mapping[str, Any]) -> FlightSpec:
    """The flight spec a session record holds."""
    if "spec" not in session:
        raise ConfigError("the log's session record has no flight spec; it cannot be replayed")
    return FlightSpec.from_dict(session["spec"])


def upgrade(session: dict[str, Any]) -> dict[str, Any]:
    """A session record of any schema version as the current one."""
    if session.get("schema_version", 1) >= SCHEMA_VERSION:
        return session
    env = session.get("env")
    if not isinstance(env, dict):
        return session  # not ours to fix; readers say what is missing
    spec = FlightSpec.solo(
        env["aircraft"],
        env["task"],
        dynamic=bool(env.get("dynamic")),
        task_kwargs=env.get("task_kwargs") or {},
        agent_hz=int(env["agent_hz"]),
        sim_hz=int(env.get("sim_hz", DEFAULT_SIM_HZ)),
        episode_time_s=float(env["episode_time_s"]),
    )
    task = spec.solo_aircraft.task_factory()()
    old = {k: v for k, v in session.items() if k not in ("env", "aircraft", "task")}
    return {
        **old,
        "schema_version": SCHEMA_VERSION,
        "spec": spec.to_dict(),
        "aircraft": {
            "ego": {
                "team": "ego",
                "model": spec.aircraft,
                "task": task.describe(),
                "observation_names": session.get("observation_names")
                or list(task.observation_names),
                "task_description": session.get("task_description")
                or task_description(task, spec.aircraft),
            }
        },
        "callsigns": ["ego"],
    }
