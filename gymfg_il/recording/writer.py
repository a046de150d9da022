"""The MCAP trajectory log: every step of every aircraft, written as it happens.

The log is the write-ahead log of a collection session: the chunk in progress is finished,
flushed and fsynced at every episode boundary, so ``kill -9`` at any moment loses at most the
episode in progress; ``recording.reader`` reads what an unfinished file holds.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np
from mcap.writer import CompressionType, IndexType, Writer

from gymfg_il.recording import schemas
from gymfg_il.sim.properties import ACTION_NAMES, NAMES

SESSION_METADATA = "gymfg.session"
EPISODE_TOPIC = "/gymfg/episode"
_FT_TO_M = 0.3048


def step_topic(callsign: str) -> str:
    return f"/gymfg/{callsign}/step"


def state_topic(callsign: str) -> str:
    return f"/gymfg/{callsign}/state"


def location_topic(callsign: str) -> str:
    return f"/gymfg/{callsign}/location"


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


class TrajectoryWriter:
    """Write one session's MCAP log at ``path`` (an existing file is never overwritten).

    Args:
        path: the ``.mcap`` file to create.
        session: what the session is (env spec, aircraft, task, rates, source); stored as the
            ``gymfg.session`` metadata record, values JSON-encoded.
        callsigns: the aircraft whose steps will be logged.
        dt: seconds per agent step (the log's clock advances by it per step).
        chunk_size: bytes per MCAP chunk; small chunks bound what a crash can lose.
    """

    def __init__(
        self,
        path: Path,
        session: Mapping[str, Any],
        callsigns: list[str],
        dt: float,
        chunk_size: int = 256 * 1024,
    ) -> None:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        self.path = path
        self._file: BinaryIO = open(path, "xb")  # noqa: SIM115 (closed in close())
        # Chunk indexes only: per-message indexes would double the records a reader walks,
        # and chunk indexes are what viewers use to seek.
        self._writer = Writer(
            self._file,
            chunk_size=chunk_size,
            compression=CompressionType.ZSTD,
            index_types=IndexType.CHUNK | IndexType.ATTACHMENT | IndexType.METADATA,
        )
        self._writer.start(profile="", library="gymfg-il")
        step_schema = self._writer.register_schema(
            "gymfg.Step", "jsonschema", schemas.encoded(schemas.STEP)
        )
        event_schema = self._writer.register_schema(
            "gymfg.EpisodeEvent", "jsonschema", schemas.encoded(schemas.EPISODE_EVENT)
        )
        state_schema = self._writer.register_schema(
            "gymfg.State", "jsonschema", schemas.encoded(schemas.STATE)
        )
        fix_schema = self._writer.register_schema(
            "foxglove.LocationFix", "jsonschema", schemas.encoded(schemas.LOCATION_FIX)
        )
        self._events = self._writer.register_channel(EPISODE_TOPIC, "json", event_schema)
        self._steps = {
            c: self._writer.register_channel(step_topic(c), "json", step_schema) for c in callsigns
        }
        self._states = {
            c: self._writer.register_channel(state_topic(c), "json", state_schema)
            for c in callsigns
        }
        self._fixes = {
            c: self._writer.register_channel(location_topic(c), "json", fix_schema)
            for c in callsigns
        }
        meta = {
            "schema_version": schemas.SCHEMA_VERSION,
            "versions": package_versions(),
            "callsigns": callsigns,
            "dt": dt,
            **session,
        }
        self._writer.add_metadata(SESSION_METADATA, {k: json.dumps(v) for k, v in meta.items()})
        self._dt_ns = round(dt * 1e9)
        self._clock_ns = time.time_ns()
        self._sequence = 0
        self.episode = -1
        self._in_episode = False
        self._sync()

    def _sync(self) -> None:
        self._writer.flush()
        os.fsync(self._file.fileno())

    def _emit(self, channel: int, message: Mapping[str, Any]) -> None:
        self._sequence += 1
        self._writer.add_message(
            channel,
            log_time=self._clock_ns,
            data=json.dumps(message).encode(),
            publish_time=self._clock_ns,
            sequence=self._sequence,
        )

    def start_episode(self, **info: Any) -> int:
        """Open the next episode; ``info`` holds seed, task, target, initial state, source."""
        if self._in_episode:
            raise RuntimeError("end or discard the current episode before starting another")
        self.episode += 1
        self._in_episode = True
        self._emit(self._events, {"event": "start", "episode": self.episode, **info})
        return self.episode

    def log_step(
        self,
        callsign: str,
        step: int,
        state: np.ndarray,
        observation: np.ndarray,
        action: tuple[float, ...] | np.ndarray,
        label: tuple[float, ...] | np.ndarray,
        reward: float,
        terminated: bool = False,
        truncated: bool = False,
        intervention: bool = False,
    ) -> None:
        """Log one agent step of ``callsign`` (state after the step, action that led to it)."""
        self._clock_ns += self._dt_ns
        values = state.tolist()
        self._emit(
            self._steps[callsign],
            {
                "episode": self.episode,
                "step": step,
                "time_s": step * self._dt_ns / 1e9,
                "observation": np.asarray(observation, dtype=np.float64).tolist(),
                "action": dict(zip(ACTION_NAMES, map(float, action), strict=True)),
                "label": dict(zip(ACTION_NAMES, map(float, label), strict=True)),
                "reward": float(reward),
                "terminated": bool(terminated),
                "truncated": bool(truncated),
                "intervention": bool(intervention),
            },
        )
        self._emit(
            self._states[callsign],
            {"episode": self.episode, "step": step, **dict(zip(NAMES, values, strict=True))},
        )
        sec, nsec = divmod(self._clock_ns, 1_000_000_000)
        self._emit(
            self._fixes[callsign],
            {
                "timestamp": {"sec": sec, "nsec": nsec},
                "frame_id": callsign,
                "latitude": values[0],
                "longitude": values[1],
                "altitude": values[2] * _FT_TO_M,
                "position_covariance": [0.0] * 9,
                "position_covariance_type": 0,
            },
        )

    def end_episode(self, **info: Any) -> None:
        """Close the episode (``outcome``, ``steps``, ...) and make it durable."""
        self._emit(self._events, {"event": "end", "episode": self.episode, **info})
        self._in_episode = False
        self._sync()

    def discard_episode(self, reason: str = "discarded") -> None:
        """Drop the episode in progress: it is logged as discarded and never becomes data."""
        self._emit(self._events, {"event": "discard", "episode": self.episode, "outcome": reason})
        self._in_episode = False
        self._sync()

    def close(self) -> None:
        if self._file.closed:
            return
        if self._in_episode:
            self.discard_episode("session closed mid-episode")
        self._writer.finish()
        self._file.flush()
        os.fsync(self._file.fileno())
        self._file.close()

    def __enter__(self) -> TrajectoryWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
