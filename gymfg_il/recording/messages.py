"""Sorting a log's messages by kind as they stream past: episode events, each aircraft's step
rows and full states, each team's opponent views (only what a dataset needs is decoded; full
states and views stay bytes until asked for)."""

from __future__ import annotations

import json
import struct
from typing import Any

import orjson

from gymfg_il.recording.mcap_walk import (
    CHANNEL,
    CHUNK,
    FOOTER,
    MESSAGE,
    METADATA,
    Damage,
    chunk_data,
    records,
    string,
    string_map,
)
from gymfg_il.recording.session import SESSION_METADATA
from gymfg_il.recording.writer import EPISODE_TOPIC

_U16 = struct.Struct("<H")
_RECORD = struct.Struct("<BQ")
_CHANNEL_HEAD = struct.Struct("<HHI")


class Sorter:
    """Sorts a log's records (see the module docstring)."""

    def __init__(self) -> None:
        self.kinds: dict[int, tuple[str, str]] = {}
        self.events: list[dict[str, Any]] = []
        self.rows: dict[tuple[int, str], list[dict[str, Any]]] = {}
        self.states: dict[tuple[int, str], list[bytes | memoryview]] = {}
        self.views: dict[tuple[int, str], list[bytes | memoryview]] = {}
        self._last: dict[str, tuple[int, str]] = {}
        self._episode = -1

    def chunk(self, data: bytes) -> None:
        """Every record of a decompressed, checked chunk (a tight loop: a log holds tens of
        thousands of messages)."""
        pos, end = 0, len(data)
        kinds, message = self.kinds, self.message
        while pos < end:
            opcode, length = _RECORD.unpack_from(data, pos)
            body = pos + 9
            if opcode == MESSAGE:  # channel_id u16, sequence u32, log/publish time u64
                (channel_id,) = _U16.unpack_from(data, body)
                if channel_id in kinds:
                    message(channel_id, data[body + 22 : body + length])
            elif opcode == CHANNEL:  # id u16, schema_id u16, topic (u32 length + bytes)
                channel_id, _, size = _CHANNEL_HEAD.unpack_from(data, body)
                self.channel(channel_id, data[body + 8 : body + 8 + size].decode())
            pos = body + length

    def record(self, opcode: int, body: memoryview) -> None:
        if opcode == MESSAGE:  # channel_id u16, sequence u32, log and publish time u64
            (channel_id,) = _U16.unpack_from(body, 0)
            if channel_id in self.kinds:
                self.message(channel_id, body[22:])
        elif opcode == CHANNEL:  # id u16, schema_id u16, topic string, ...
            (channel_id,) = _U16.unpack_from(body, 0)
            topic, _ = string(body, 4)
            self.channel(channel_id, topic)

    def channel(self, channel_id: int, topic: str) -> None:
        if topic == EPISODE_TOPIC:
            self.kinds[channel_id] = ("episode", "")
            return
        parts = topic.split("/")
        if len(parts) == 4 and parts[1] == "gymfg" and parts[3] in ("step", "state"):
            self.kinds[channel_id] = (parts[3], parts[2])
        elif len(parts) == 5 and parts[1:3] == ["gymfg", "team"] and parts[4] == "opponents":
            self.kinds[channel_id] = ("view", parts[3])

    def message(self, channel_id: int, data: bytes | memoryview) -> None:
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


def stream(data: bytes, seen: Sorter, damage: list[Damage]) -> tuple[dict[str, Any] | None, bool]:
    """Feed a log's records to ``seen``; (session record, finished?). Damaged chunks and
    records are skipped and described in ``damage``."""
    session: dict[str, Any] | None = None
    finished = False
    for pos, opcode, body in records(data, damage):
        end = pos + 9 + len(body)
        if opcode == CHUNK:
            try:
                seen.chunk(chunk_data(body))
            except (ValueError, struct.error) as err:
                damage.append(Damage(pos, end, str(err)))
        elif opcode in (CHANNEL, MESSAGE):
            seen.record(opcode, body)
        elif opcode == METADATA:
            try:
                name, at = string(body, 0)
                if name == SESSION_METADATA:
                    session = {k: json.loads(v) for k, v in string_map(body, at).items()}
            except (ValueError, struct.error) as err:
                damage.append(Damage(pos, end, f"a damaged metadata record ({err})"))
        elif opcode == FOOTER:
            finished = True
    return session, finished
