"""Reading MCAP trajectory logs, finished or not (a killed session leaves no footer)."""

from __future__ import annotations

import gc
import json
import struct
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import orjson
import zstandard
from mcap.exceptions import McapError
from mcap.records import Channel, Chunk, Message, Metadata
from mcap.stream_reader import StreamReader

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import GymFGError
from gymfg_il.recording.session import SESSION_METADATA, spec_of, upgrade
from gymfg_il.recording.writer import EPISODE_TOPIC
from gymfg_il.rollout.records import OpponentView
from gymfg_il.sim.properties import ACTION_NAMES, NAMES


class LogError(GymFGError, ValueError):
    """A file that is not a GymFG trajectory log, or is damaged beyond its first bytes."""


@dataclass
class AircraftSteps:
    """One aircraft's steps in one episode, as arrays (one row per step).

    ``state`` (the full catalogue state after each step) is decoded on first use: building a
    dataset does not need it, replay does.
    """

    observation: np.ndarray
    action: np.ndarray
    label: np.ndarray
    reward: np.ndarray
    terminated: np.ndarray
    truncated: np.ndarray
    intervention: np.ndarray
    raw_states: list[bytes] = field(default_factory=list, repr=False)
    _state: np.ndarray | None = field(default=None, repr=False)

    @property
    def state(self) -> np.ndarray:
        if self._state is None:
            rows = [orjson.loads(b) for b in self.raw_states]
            self._state = np.array([[r[n] for n in NAMES] for r in rows], dtype=np.float64)
        return self._state

    def __len__(self) -> int:
        return len(self.reward)


@dataclass
class LoggedEpisode:
    index: int
    start: dict[str, Any]
    end: dict[str, Any] | None = None
    discarded: bool = False
    steps: dict[str, AircraftSteps] = field(default_factory=dict)
    raw_views: dict[str, list[bytes]] = field(default_factory=dict, repr=False)

    @property
    def complete(self) -> bool:
        return self.end is not None and not self.discarded

    def start_of(self, callsign: str) -> dict[str, Any]:
        """``callsign``'s start: ``target`` and ``initial_state`` (older logs: the episode's)."""
        aircraft = self.start.get("aircraft")
        if isinstance(aircraft, dict) and callsign in aircraft:
            return dict(aircraft[callsign])
        return {k: self.start[k] for k in ("target", "initial_state") if k in self.start}

    def views(self, team: str) -> list[OpponentView]:
        """What ``team`` saw of the other teams after each step (team runs)."""
        rows = [orjson.loads(b) for b in self.raw_views.get(team, [])]
        return [
            OpponentView(r["callsigns"], tuple(r["names"]), np.array(r["values"], np.float64))
            for r in rows
        ]


@dataclass
class Log:
    path: Path
    session: dict[str, Any]
    episodes: list[LoggedEpisode]
    finished: bool  # the file has its footer (the session closed cleanly)

    @property
    def complete_episodes(self) -> list[LoggedEpisode]:
        return [e for e in self.episodes if e.complete]

    @property
    def spec(self) -> FlightSpec:
        """The flight spec the log was recorded with."""
        return spec_of(self.session)

    def aircraft(self, callsign: str) -> dict[str, Any]:
        """What the session record says of ``callsign``: team, model, task, observation
        names, task description."""
        try:
            return dict(self.session["aircraft"][callsign])
        except (KeyError, TypeError):
            raise LogError(f"{self.path.name} records no aircraft {callsign!r}") from None


def _steps(rows: list[dict[str, Any]], states: list[bytes]) -> AircraftSteps:
    # The writer keeps the contract's action order; read values in bulk when the keys say so.
    if list(rows[0]["action"]) == list(ACTION_NAMES):
        action = [list(r["action"].values()) for r in rows]
        label = [list(r["label"].values()) for r in rows]
    else:
        action = [[r["action"][n] for n in ACTION_NAMES] for r in rows]
        label = [[r["label"][n] for n in ACTION_NAMES] for r in rows]
    return AircraftSteps(
        observation=np.array([r["observation"] for r in rows], dtype=np.float64),
        action=np.array(action, dtype=np.float64),
        label=np.array(label, dtype=np.float64),
        reward=np.array([r["reward"] for r in rows], dtype=np.float64),
        terminated=np.array([r.get("terminated", False) for r in rows], dtype=bool),
        truncated=np.array([r.get("truncated", False) for r in rows], dtype=bool),
        intervention=np.array([r.get("intervention", False) for r in rows], dtype=bool),
        raw_states=states,
    )


_RECORD = struct.Struct("<BQ")
_CHANNEL_HEAD = struct.Struct("<HHI")
_MESSAGE_HEAD = struct.Struct("<H")


def _chunk_messages(chunk: Chunk, seen: _Collector) -> None:
    """Feed every channel and message of a chunk to ``seen``.

    The mcap library's ``breakup_chunk`` builds a record object per message; a log holds
    tens of thousands of them, so this walks the chunk's records with ``struct`` instead and
    checks the chunk's CRC itself.
    """
    if chunk.compression == "zstd":
        data = zstandard.decompress(chunk.data, max_output_size=chunk.uncompressed_size)
    elif chunk.compression == "":
        data = chunk.data
    else:
        raise LogError(f"unsupported chunk compression {chunk.compression!r}")
    if chunk.uncompressed_crc and zlib.crc32(data) != chunk.uncompressed_crc:
        raise LogError("a chunk fails its CRC check")
    pos, end = 0, len(data)
    kinds, message = seen.kinds, seen.message
    while pos < end:
        opcode, length = _RECORD.unpack_from(data, pos)
        body = pos + 9
        if opcode == 0x05:  # Message: channel_id u16, sequence u32, log/publish time u64
            (channel_id,) = _MESSAGE_HEAD.unpack_from(data, body)
            if channel_id in kinds:
                message(channel_id, data[body + 22 : body + length])
        elif opcode == 0x04:  # Channel: id u16, schema_id u16, topic (u32 length + bytes)
            channel_id, _, size = _CHANNEL_HEAD.unpack_from(data, body)
            seen.channel(channel_id, data[body + 8 : body + 8 + size].decode())
        pos = body + length


class _Collector:
    """Sorts a log's messages by kind as they stream past (only what a dataset needs is
    decoded; full states are kept as bytes until asked for)."""

    def __init__(self) -> None:
        self.kinds: dict[int, tuple[str, str]] = {}
        self.events: list[dict[str, Any]] = []
        self.rows: dict[tuple[int, str], list[dict[str, Any]]] = {}
        self.states: dict[tuple[int, str], list[bytes]] = {}
        self.views: dict[tuple[int, str], list[bytes]] = {}
        self._last: dict[str, tuple[int, str]] = {}
        self._episode = -1

    def channel(self, channel_id: int, topic: str) -> None:
        if topic == EPISODE_TOPIC:
            self.kinds[channel_id] = ("episode", "")
            return
        parts = topic.split("/")
        if len(parts) == 4 and parts[1] == "gymfg" and parts[3] in ("step", "state"):
            self.kinds[channel_id] = (parts[3], parts[2])
        elif len(parts) == 5 and parts[1:3] == ["gymfg", "team"] and parts[4] == "opponents":
            self.kinds[channel_id] = ("view", parts[3])

    def message(self, channel_id: int, data: bytes) -> None:
        kind = self.kinds.get(channel_id)
        if kind is None:
            return
        what, callsign = kind
        if what == "step":
            msg = orjson.loads(data)
            key = (int(msg["episode"]), callsign)
            self.rows.setdefault(key, []).append(msg)
            self._last[callsign] = key
        elif what == "state":
            # written right after its step message: same episode
            last = self._last.get(callsign)
            if last is not None:
                self.states.setdefault(last, []).append(data)
        elif what == "view":  # written after the steps of its tick: same episode
            self.views.setdefault((self._episode, callsign), []).append(data)
        else:
            event = orjson.loads(data)
            self._episode = int(event.get("episode", -1))
            self.events.append(event)


def _stream(path: Path, seen: _Collector) -> tuple[dict[str, Any] | None, bool]:
    """Stream the log's records into ``seen``; return (session record, file finished?)."""
    session: dict[str, Any] | None = None
    with open(path, "rb") as f:
        reader = StreamReader(f, validate_crcs=True, emit_chunks=True)
        try:
            for record in reader.records:
                if isinstance(record, Chunk):
                    _chunk_messages(record, seen)
                elif isinstance(record, Channel):
                    seen.channel(record.id, record.topic)
                elif isinstance(record, Metadata) and record.name == SESSION_METADATA:
                    session = {k: json.loads(v) for k, v in record.metadata.items()}
                elif isinstance(record, Message):
                    seen.message(record.channel_id, record.data)
        except (McapError, EOFError, ValueError, OSError, KeyError, struct.error) as err:
            if session is None:
                raise LogError(
                    f"{path} is not a readable GymFG trajectory log ({type(err).__name__}: "
                    f"{err}); it holds no session record"
                ) from None
            return session, False
    return session, True


def read_log(path: Path) -> Log:
    """Everything readable in ``path``; an unfinished file yields its durable part."""
    path = Path(path)
    if not path.is_file():
        raise LogError(f"no trajectory log at {path}")
    seen = _Collector()
    # Tens of thousands of small decoded messages would trigger the cyclic GC many times
    # over; none of them form cycles.
    gc_was_enabled = gc.isenabled()
    gc.disable()
    try:
        session, finished = _stream(path, seen)
    finally:
        if gc_was_enabled:
            gc.enable()
    if session is None:
        raise LogError(f"{path} has no {SESSION_METADATA} record: not a GymFG trajectory log")
    session = upgrade(session)
    events, rows, states = seen.events, seen.rows, seen.states
    episodes: dict[int, LoggedEpisode] = {}
    for ev in events:
        k = ev["episode"]
        if ev["event"] == "start":
            episodes[k] = LoggedEpisode(k, ev)
        elif k in episodes and ev["event"] == "end":
            episodes[k].end = ev
        elif k in episodes and ev["event"] == "discard":
            episodes[k].discarded = True
    for (k, callsign), msgs in rows.items():
        if k in episodes:
            episodes[k].steps[callsign] = _steps(msgs, states.get((k, callsign), []))
    for (k, team), views in seen.views.items():
        if k in episodes:
            episodes[k].raw_views[team] = views
    return Log(path, session, [episodes[k] for k in sorted(episodes)], finished)
