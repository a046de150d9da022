"""Sorting a log's messages by kind as they stream past: episode events, each aircraft's step
rows and full states, each team's opponent views (only what a dataset needs is decoded; full
states and views stay bytes until asked for).

The channel records sit in the first chunk; the writer keeps a copy of them outside every
chunk (the ``gymfg.channels`` metadata record) and a finished file another in its summary, so
a damaged first chunk costs only its own episodes. The session record is written twice, each
copy with its CRC (``recording.session.checked``)."""

from __future__ import annotations

import hashlib
import json
import struct
from typing import Any

import orjson

from gymfg_il.recording.mcap_walk import (
    CHANNEL,
    CHUNK,
    DATA_END,
    FOOTER,
    MAGIC,
    MESSAGE,
    METADATA,
    Damage,
    chunk_data,
    data_intact,
    records,
    string,
    string_map,
    summary_intact,
)
from gymfg_il.recording.schemas import EPISODE_TOPIC
from gymfg_il.recording.session import (
    CHANNELS_METADATA,
    CRC_KEY,
    SESSION_COPY,
    SESSION_METADATA,
    crc_state,
)

_U16 = struct.Struct("<H")
_U32 = struct.Struct("<I")
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
        self.kinds.pop(channel_id, None)  # a chunk's record overrides a copy's
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
    found = list(records(data, damage))
    maps: list[tuple[int, int, str, dict[str, str]]] = []  # (offset, end, name, entries)
    finished, summary_ok, data_ok, data_end = False, None, None, len(data)
    for pos, opcode, body in found:
        end = pos + 9 + len(body)
        if opcode == METADATA:
            try:
                name, at = string(body, 0)
                maps.append((pos, end, name, string_map(body, at)))
            except (ValueError, struct.error) as err:
                damage.append(Damage(pos, end, f"a damaged metadata record ({err})"))
        elif opcode == DATA_END:
            data_ok, data_end = data_intact(data, pos, body), pos
        elif opcode == FOOTER:
            finished, summary_ok = True, summary_intact(data, pos, body)
            if data[end:] != MAGIC:
                damage.append(Damage(end, len(data), "the closing MCAP magic is damaged"))
    session = _session(maps, damage)
    # channels the first chunk declares, should it be lost: the summary's (unless its CRC
    # fails) over the writer's table
    for pos, end, name, entries in maps:
        if name == CHANNELS_METADATA:
            if crc_state(entries) is False:
                damage.append(Damage(pos, end, "the channel table fails its CRC check"))
                continue
            for key, topic in entries.items():
                if key != CRC_KEY and key.isdigit():
                    seen.channel(int(key), topic)
    if summary_ok is False:
        damage.append(Damage(data_end, len(data), "the summary fails its CRC check"))
    for pos, opcode, body in found:
        if opcode == CHANNEL and (pos < data_end or summary_ok is not False):
            seen.record(opcode, body)
    for opcode, body in _in_written_order([f for f in found if f[0] < data_end], damage):
        if opcode == CHUNK:
            seen.chunk(body)
        else:
            seen.record(opcode, body)
    if data_ok is False and not any(d.start < data_end for d in damage):
        damage.append(
            Damage(
                0,
                data_end,
                "the data section fails its CRC outside every chunk (a record header or "
                "index; every chunk read passed its own CRC)",
            )
        )
    return session, finished


def _in_written_order(
    found: list[tuple[int, int, memoryview]], damage: list[Damage]
) -> list[tuple[int, Any]]:
    """The data section's chunks (decompressed and checked) and loose channel and message
    records, in the order they were written: by the sequence number of their first message
    (a chunk copied twice is read once; chunks moved out of order are put back)."""
    items: list[tuple[int, int, int, Any]] = []  # (sequence, position, opcode, body)
    copies: set[bytes] = set()
    last = -1
    for pos, opcode, body in found:
        end = pos + 9 + len(body)
        if opcode == CHUNK:
            try:
                inner = chunk_data(body)
            except (ValueError, struct.error) as err:
                damage.append(Damage(pos, end, str(err)))
                continue
            fingerprint = hashlib.blake2b(inner, digest_size=16).digest()
            if fingerprint in copies:
                damage.append(Damage(pos, end, "a copy of an earlier chunk; read once"))
                continue
            copies.add(fingerprint)
            last = _first_sequence(inner, last)
            items.append((last, pos, opcode, inner))
        elif opcode in (CHANNEL, MESSAGE):  # a channel stays after what precedes it
            last = _U32.unpack_from(body, 2)[0] if opcode == MESSAGE else last
            items.append((last, pos, opcode, body))
    ordered = sorted(items, key=lambda item: item[:2])
    moved = [a[1] for a, b in zip(ordered, items, strict=True) if a[1] != b[1]]
    if moved:
        damage.append(
            Damage(min(moved), max(moved), "chunks out of the order they were written; reordered")
        )
    return [(opcode, body) for _, _, opcode, body in ordered]


def _first_sequence(records: bytes, default: int) -> int:
    """The sequence number of the first message among a chunk's ``records`` (``default``
    where it holds none)."""
    pos = 0
    while pos + 9 <= len(records):
        opcode, length = _RECORD.unpack_from(records, pos)
        if opcode == MESSAGE:
            return int(_U32.unpack_from(records, pos + 9 + 2)[0])
        pos += 9 + length
    return default


def _session(maps: list[tuple[int, int, str, dict[str, str]]], damage: list[Damage]) -> Any:
    """The session record: the first copy that passes its CRC (logs before the CRC: the
    first that decodes); damaged copies go to ``damage``."""
    chosen = None
    for pos, end, name, entries in maps:
        if name not in (SESSION_METADATA, SESSION_COPY):
            continue
        state = crc_state(entries)
        try:
            record = {k: json.loads(v) for k, v in entries.items() if k != CRC_KEY}
        except ValueError as err:
            damage.append(Damage(pos, end, f"a damaged session record ({err})"))
            continue
        if state is False:
            damage.append(Damage(pos, end, "a session record fails its CRC check"))
        elif chosen is None:
            chosen = record
    return chosen
