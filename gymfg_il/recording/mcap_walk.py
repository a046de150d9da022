"""Walking an MCAP file's records by hand, so that damage costs only what it touches.

Chunks decode independently: a chunk that fails to decompress or fails its CRC is skipped and
reported, and the walk goes on with the next record. A record whose header is garbage (a bad
opcode or a length that cannot be) is skipped by searching forward for the next record that
parses as a whole chunk or a whole metadata record. A record cut off by the end of the file is
where a killed session stopped writing (not damage), unless a whole record follows it. The mcap
library's readers stop at the first bad byte; this one keeps every episode the damage does not
reach. ``summary_intact`` and ``data_intact`` check the CRCs a finished file carries of its
summary and of everything before it.

Layout (little endian): magic, then records of ``opcode u8, length u64, body``; a chunk body
is ``start u64, end u64, uncompressed_size u64, uncompressed_crc u32, compression (u32 length
+ bytes), records (u64 length + bytes)``.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Iterator
from dataclasses import dataclass

import zstandard

MAGIC = b"\x89MCAP0\r\n"
HEADER, FOOTER, SCHEMA, CHANNEL, MESSAGE, CHUNK = 0x01, 0x02, 0x03, 0x04, 0x05, 0x06
METADATA, DATA_END = 0x0C, 0x0F
_FOOTER_HEAD = struct.Struct("<BQQQ")  # opcode, length, summary start, summary offset start
KNOWN = set(range(0x01, 0x10))
_RECORD = struct.Struct("<BQ")
_CHUNK = struct.Struct("<QQQII")  # start, end, uncompressed size, crc, compression length
_U32 = struct.Struct("<I")
_U64 = struct.Struct("<Q")
_MAX_CHUNK = 1 << 30


@dataclass
class Damage:
    """A part of a file that could not be read: where, and why."""

    start: int
    end: int
    why: str

    def __str__(self) -> str:
        return f"bytes {self.start}-{self.end}: {self.why}"


def _chunk_at(data: bytes, pos: int) -> int | None:
    """The end of the chunk record at ``pos``, if a whole, self-consistent one is there."""
    if pos + 9 + _CHUNK.size > len(data) or data[pos] != CHUNK:
        return None
    (length,) = _U64.unpack_from(data, pos + 1)
    end = pos + 9 + length
    if end > len(data) or length > _MAX_CHUNK:
        return None
    _, _, size, _, clen = _CHUNK.unpack_from(data, pos + 9)
    head = pos + 9 + _CHUNK.size
    if clen not in (0, 4) or size > _MAX_CHUNK or head + clen + 8 > end:
        return None
    if data[head : head + clen] not in (b"", b"zstd"):
        return None
    (records,) = _U64.unpack_from(data, head + clen)
    return end if head + clen + 8 + records == end else None


# the layout of each record whose body the walk checks: fixed-size integers ("B", "H", "I",
# "Q"), "s" a u32-prefixed string, byte array or map; the fields fill the body exactly
# ("+": a message, whose data runs to the end of its body)
_LAYOUTS = {
    HEADER: "ss",
    FOOTER: "QQI",
    SCHEMA: "Hsss",
    CHANNEL: "HHsss",
    MESSAGE: "HIQQ+",
    0x07: "Hs",  # message index
    0x08: "QQQQsQsQQ",  # chunk index
    0x0B: "QHIIIIQQs",  # statistics
    METADATA: "ss",
    0x0D: "QQs",  # metadata index
    0x0E: "BQQ",  # summary offset
    DATA_END: "I",
}
_SIZES = {"B": 1, "H": 2, "I": 4, "Q": 8}


def _fills(data: bytes, start: int, end: int, layout: str) -> bool:
    """Whether ``layout`` exactly fills ``data[start:end]``."""
    at = start
    for kind in layout:
        if kind == "+":
            return at <= end
        if kind == "s":
            if at + 4 > end:
                return False
            at += 4 + _U32.unpack_from(data, at)[0]
        else:
            at += _SIZES[kind]
        if at > end:
            return False
    return at == end


def _whole(data: bytes, pos: int) -> int | None:
    """The end of the record at ``pos`` when it is whole: a chunk self-consistent, a record
    of a known layout filled exactly, any other followed by a sane record header."""
    if pos + 9 > len(data) or data[pos] not in KNOWN:
        return None
    if data[pos] == CHUNK:
        return _chunk_at(data, pos)
    (length,) = _U64.unpack_from(data, pos + 1)
    end = pos + 9 + length
    if end > len(data) or length > _MAX_CHUNK:
        return None
    layout = _LAYOUTS.get(data[pos])
    if layout is not None:
        return end if _fills(data, pos + 9, end, layout) else None
    if end + 9 > len(data):
        return end
    opcode, following = _RECORD.unpack_from(data, end)
    return end if opcode in KNOWN and following <= len(data) else None


def _next_record(data: bytes, start: int) -> int | None:
    """The offset of the next whole chunk or metadata record at or after ``start``."""
    found = []
    for opcode in (CHUNK, METADATA):
        pos = data.find(bytes([opcode]), start)
        while pos != -1:
            if _whole(data, pos) is not None:
                found.append(pos)
                break
            pos = data.find(bytes([opcode]), pos + 1)
    return min(found, default=None)


def records(data: bytes, damage: list[Damage]) -> Iterator[tuple[int, int, memoryview]]:
    """(offset, opcode, body) of every readable top-level record; what cannot be read goes
    to ``damage``. Stops at the footer, or where the file ends (a session killed mid-write:
    the last record runs past the end of a file that does not end in the closing magic)."""
    view = memoryview(data)
    closed = len(data) > 2 * len(MAGIC) and data.endswith(MAGIC)
    pos = len(MAGIC)
    while pos + 9 <= len(data):
        opcode, length = _RECORD.unpack_from(data, pos)
        end = _whole(data, pos)
        if end is not None:
            yield pos, opcode, view[pos + 9 : end]
            if opcode == FOOTER:
                return
            pos = end
            continue
        resume = _next_record(data, pos + 1)
        if resume is None:
            cut = opcode in KNOWN and pos + 9 + length > len(data) and not closed
            if not cut:
                damage.append(Damage(pos, len(data), "unreadable records to the end of the file"))
            return
        damage.append(Damage(pos, resume, f"a damaged record (opcode {opcode:#04x})"))
        pos = resume


def magic_damage(data: bytes) -> Damage | None:
    """What is wrong with the file's opening magic: None when intact (or cut short inside
    it), a Damage when one byte differs; ValueError when it is not an MCAP file."""
    head = data[: len(MAGIC)]
    if MAGIC.startswith(head):
        return None
    if len(head) == len(MAGIC) and sum(a != b for a, b in zip(head, MAGIC, strict=True)) == 1:
        return Damage(0, len(MAGIC), "the MCAP magic is damaged")
    raise ValueError("not an MCAP file")


def summary_intact(data: bytes, footer: int, body: memoryview) -> bool | None:
    """Whether the summary section passes the CRC in the footer record at ``footer``
    (None: the file records no CRC)."""
    start, offsets, crc = struct.unpack_from("<QQI", body, 0)
    if not crc:
        return None
    if not 0 < start <= footer:
        return False
    head = _FOOTER_HEAD.pack(FOOTER, len(body), start, offsets)
    return zlib.crc32(head, zlib.crc32(data[start:footer])) == crc


def data_intact(data: bytes, data_end: int, body: memoryview) -> bool | None:
    """Whether everything before the data end record at ``data_end`` passes the CRC it
    carries (None: the file records none)."""
    (crc,) = _U32.unpack_from(body, 0)
    return None if not crc else zlib.crc32(data[:data_end]) == crc


def chunk_data(body: memoryview) -> bytes:
    """The records of a chunk, decompressed and checked; ValueError when they cannot be read
    (it does not decompress, fails its CRC, or, without a CRC, a record runs past its end)."""
    _, _, size, crc, clen = _CHUNK.unpack_from(body, 0)
    head = _CHUNK.size
    compression = bytes(body[head : head + clen])
    raw = body[head + clen + 8 :]
    if compression == b"zstd":
        try:
            inner = zstandard.decompress(raw, max_output_size=size)
        except zstandard.ZstdError as err:
            raise ValueError(f"a chunk does not decompress ({err})") from None
    elif compression == b"":
        inner = bytes(raw)
    else:
        raise ValueError(f"unsupported chunk compression {compression!r}")
    if crc:
        if zlib.crc32(inner) != crc:
            raise ValueError("a chunk fails its CRC check")
        return inner  # the CRC vouches for every record length inside
    pos, end = 0, len(inner)
    while pos < end:
        if pos + 9 > end:
            raise ValueError("a chunk ends inside a record header")
        pos += 9 + _RECORD.unpack_from(inner, pos)[1]
    if pos != end:
        raise ValueError("a record runs past the end of its chunk")
    return inner


def string_map(body: memoryview, pos: int) -> dict[str, str]:
    """An MCAP map<string, string> at ``pos``."""
    (size,) = _U32.unpack_from(body, pos)
    pos, end, out = pos + 4, pos + 4 + size, {}
    while pos < end:
        key, pos = string(body, pos)
        value, pos = string(body, pos)
        out[key] = value
    return out


def string(body: memoryview, pos: int) -> tuple[str, int]:
    """An MCAP string (u32 length + UTF-8) at ``pos``, and the position after it."""
    (size,) = _U32.unpack_from(body, pos)
    return bytes(body[pos + 4 : pos + 4 + size]).decode(), pos + 4 + size
