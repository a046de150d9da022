"""A finished log's indexes, read the way Foxglove reads them, and re-indexing older logs.

Foxglove's indexed reader (``McapIndexedReader`` of ``@mcap/core``) finds every message
through the summary: the chunk indexes, each chunk's message index records, then the message at
its offset inside the decompressed chunk. Logs written before the writer asked for message
indexes have chunk indexes without them (Foxglove then fails on every read) and an empty
attachment index group. ``reindex`` rewrites such a log with the same records in the same
order and every index, into a temporary file beside it; the copy is read back through its
message indexes and compared with the original before it atomically replaces it, so a crash at
any moment leaves either the old file or the new one, both whole.
"""

from __future__ import annotations

import hashlib
import io
import os
import struct
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

import zstandard
from mcap.data_stream import ReadDataStream
from mcap.exceptions import McapError
from mcap.reader import SeekingReader
from mcap.records import (
    Attachment,
    Channel,
    Chunk,
    Header,
    Message,
    MessageIndex,
    Metadata,
    Schema,
)
from mcap.stream_reader import StreamReader, get_chunk_data_stream
from mcap.summary import Summary
from mcap.writer import CompressionType, IndexType, Writer

from gymfg_il.recording.mcap_walk import MAGIC, MESSAGE
from gymfg_il.recording.reader import LogError, read_log

_FOOTER = 1 + 8 + 20 + len(MAGIC)  # footer record (opcode, length, body) and closing magic
_SUMMARY_OFFSET, _ATTACHMENT_INDEX = 0x0E, 0x0A
_RECORD = struct.Struct("<BQ")
_SUMMARY_OFFSET_BODY = struct.Struct("<BQQ")
_FOOTER_BODY = struct.Struct("<QQ")
# mcap's readers raise these on damaged or cut files (a bad record, CRC, end of file)
_UNREADABLE = (McapError, struct.error, ValueError, EOFError, zstandard.ZstdError)


@dataclass(frozen=True)
class IndexedMessage:
    topic: str
    sequence: int
    log_time: int
    publish_time: int
    data: bytes


def _finished(f: BinaryIO, path: Path) -> None:
    f.seek(0, io.SEEK_END)
    size = f.tell()
    f.seek(0)
    if f.read(len(MAGIC)) != MAGIC:
        raise LogError(f"{path} is not an MCAP file (no MCAP magic at its start)")
    closed = size >= _FOOTER + len(MAGIC) and f.seek(size - len(MAGIC)) >= 0
    if not closed or f.read(len(MAGIC)) != MAGIC:
        raise LogError(
            f"{path} has no footer: its session was killed or the file was cut, so it has no "
            "summary to index; `collect recover` reads what it holds"
        )


def _summary(f: BinaryIO, path: Path) -> Summary:
    _finished(f, path)
    f.seek(0)
    try:
        summary = SeekingReader(f, validate_crcs=True).get_summary()
    except _UNREADABLE as err:
        raise LogError(f"{path}: its summary cannot be read ({err}); the file is damaged") from None
    if summary is None:
        raise LogError(f"{path} has no summary section: nothing indexes its messages")
    return summary


def _empty_groups(f: BinaryIO) -> list[int]:
    """Opcodes of the summary offset records that point at empty groups."""
    f.seek(-(_FOOTER), io.SEEK_END)
    opcode, _ = _RECORD.unpack(f.read(_RECORD.size))
    _, offsets_start = _FOOTER_BODY.unpack(f.read(_FOOTER_BODY.size))
    if opcode != 0x02 or not offsets_start:
        return []
    f.seek(offsets_start)
    end = f.seek(0, io.SEEK_END) - _FOOTER
    f.seek(offsets_start)
    empty = []
    while f.tell() < end:
        opcode, length = _RECORD.unpack(f.read(_RECORD.size))
        body = f.read(length)
        if opcode == _SUMMARY_OFFSET and len(body) >= _SUMMARY_OFFSET_BODY.size:
            group, _, group_length = _SUMMARY_OFFSET_BODY.unpack_from(body)
            if group_length == 0:
                empty.append(group)
    return empty


def index_problems(path: Path) -> list[str]:
    """What keeps an indexed reader from using the finished log at ``path`` ([] = none).
    LogError when it is no finished MCAP file."""
    path = Path(path)
    with open(path, "rb") as f:
        summary = _summary(f, path)
        problems = []
        empty = summary.statistics is not None and summary.statistics.message_count == 0
        if not summary.chunk_indexes and not empty:  # a log with no message has no chunk
            problems.append("no chunk indexes")
        bare = sum(1 for ci in summary.chunk_indexes if not ci.message_index_offsets)
        if bare:
            problems.append(f"{bare} of {len(summary.chunk_indexes)} chunks have no message index")
        if _ATTACHMENT_INDEX in _empty_groups(f):
            problems.append("an empty attachment index group")
    return problems


def indexed_messages(path: Path) -> Iterator[IndexedMessage]:
    """Every message of the finished log at ``path``, found as Foxglove finds it: chunk index
    -> the chunk's message index records -> the message at each indexed offset (file order).
    LogError when a chunk has no message index or an index points at no message."""
    path = Path(path)
    with open(path, "rb") as f:
        summary = _summary(f, path)
        for ci in summary.chunk_indexes:
            if not ci.message_index_offsets:
                raise LogError(
                    f"{path}: the chunk at byte {ci.chunk_start_offset} has no message index "
                    "(an older log: `python -m gymfg_il.collect reindex` rewrites it)"
                )
            entries: list[tuple[int, int]] = []  # (offset in the chunk, channel)
            for channel_id, offset in ci.message_index_offsets.items():
                f.seek(offset + _RECORD.size)
                index = MessageIndex.read(ReadDataStream(f))
                entries += [(at, channel_id) for _, at in index.records]
            f.seek(ci.chunk_start_offset + _RECORD.size)
            try:
                stream, _ = get_chunk_data_stream(Chunk.read(ReadDataStream(f)), validate_crc=True)
            except _UNREADABLE as err:
                raise LogError(f"{path}: a chunk cannot be read ({err})") from None
            data = stream.read(ci.uncompressed_size)
            for at, channel_id in sorted(entries):
                opcode, length = _RECORD.unpack_from(data, at)
                if opcode != MESSAGE:
                    raise LogError(f"{path}: a message index points at no message (byte {at})")
                body = ReadDataStream(io.BytesIO(data[at + 9 : at + 9 + length]))
                m = Message.read(body, length)
                if m.channel_id != channel_id:
                    raise LogError(f"{path}: a message index names the wrong channel")
                topic = summary.channels[channel_id].topic
                yield IndexedMessage(topic, m.sequence, m.log_time, m.publish_time, m.data)


def _digest(digest: hashlib.blake2b, topic: str, m: IndexedMessage | Message) -> None:
    digest.update(topic.encode())
    digest.update(struct.pack("<IQQQ", m.sequence, m.log_time, m.publish_time, len(m.data)))
    digest.update(m.data)


@dataclass(frozen=True)
class Reindexed:
    path: Path
    changed: bool
    messages: int
    problems: tuple[str, ...]  # what the old file lacked ([] when it was already fine)
    size_before: int
    size_after: int


def reindex(path: Path, chunk_size: int = 256 * 1024) -> Reindexed:
    """Give the finished log at ``path`` message indexes (and no empty attachment index), in
    place and crash-safely (see the module docstring). A log that has them is left untouched;
    a damaged (any CRC it carries fails) or unfinished one raises LogError and is left as it
    was."""
    path = Path(path)
    if not path.is_file():
        raise LogError(f"no log at {path}")
    problems = index_problems(path)
    damage = read_log(path).damage  # every chunk's CRC, the session record's, the data's
    if damage:
        raise LogError(
            f"{path} is damaged and was left as it was: {'; '.join(damage)} "
            "(`python -m gymfg_il.collect recover` keeps what can be read)"
        )
    size = path.stat().st_size
    if not problems:
        return Reindexed(path, False, 0, (), size, size)
    tmp = path.with_name(f".{path.name}.reindex-{os.getpid()}.tmp")
    tmp.unlink(missing_ok=True)
    try:
        count, digest = _rewrite(path, tmp, chunk_size)
        _verify(path, tmp, count, digest)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    _sync_dir(path.parent)
    return Reindexed(path, True, count, tuple(problems), size, path.stat().st_size)


def _rewrite(path: Path, tmp: Path, chunk_size: int) -> tuple[int, str]:
    """Copy every record of ``path`` into ``tmp`` with every index; (messages, their digest)."""
    with open(path, "rb") as f:
        f.seek(0)
        attachments = bool(SeekingReader(f).get_summary().attachment_indexes)  # type: ignore[union-attr]
        f.seek(0)
        indexes = IndexType.CHUNK | IndexType.MESSAGE | IndexType.METADATA
        if attachments:
            indexes |= IndexType.ATTACHMENT
        with open(tmp, "xb") as out:
            writer = Writer(
                out,
                chunk_size=chunk_size,
                compression=CompressionType.ZSTD,
                index_types=indexes,
                enable_data_crcs=True,
            )
            copy = _Copy(writer)
            try:
                for record in StreamReader(f, validate_crcs=True).records:
                    copy.add(record)
            except (*_UNREADABLE, KeyError) as err:
                raise LogError(
                    f"{path} is damaged and was left as it was: {type(err).__name__}: {err}"
                ) from None
            writer.finish()
            out.flush()
            os.fsync(out.fileno())
    return copy.count, copy.digest.hexdigest()


class _Copy:
    """The records of one MCAP file written again by ``writer``: schemas and channels under
    the ids it gives them, and a count and digest of the messages copied."""

    def __init__(self, writer: Writer) -> None:
        self.writer = writer
        self.schemas: dict[int, int] = {0: 0}  # the old id -> the new
        self.channels: dict[int, int] = {}
        self.topics: dict[int, str] = {}  # the old channel id -> its topic
        self.count, self.digest = 0, hashlib.blake2b()

    def add(self, record: object) -> None:
        """Write ``record`` again (a KeyError where it names a schema or channel never seen)."""
        writer = self.writer
        if isinstance(record, Header):
            writer.start(profile=record.profile, library=record.library)
        elif isinstance(record, Schema):
            if record.id not in self.schemas:
                self.schemas[record.id] = writer.register_schema(
                    record.name, record.encoding, record.data
                )
        elif isinstance(record, Channel):
            if record.id not in self.channels:
                self.channels[record.id] = writer.register_channel(
                    record.topic,
                    record.message_encoding,
                    self.schemas[record.schema_id],
                    dict(record.metadata),
                )
                self.topics[record.id] = record.topic
        elif isinstance(record, Message):
            writer.add_message(
                self.channels[record.channel_id],
                log_time=record.log_time,
                data=record.data,
                publish_time=record.publish_time,
                sequence=record.sequence,
            )
            _digest(self.digest, self.topics[record.channel_id], record)
            self.count += 1
        elif isinstance(record, Metadata):
            writer.add_metadata(record.name, dict(record.metadata))
        elif isinstance(record, Attachment):
            writer.add_attachment(
                record.create_time, record.log_time, record.name, record.media_type, record.data
            )


def _verify(path: Path, tmp: Path, count: int, digest: str) -> None:
    """``tmp`` holds the same messages as ``path`` (in the same order, read through its
    message indexes), the same metadata, and every index."""
    check, n = hashlib.blake2b(), 0
    for m in indexed_messages(tmp):
        _digest(check, m.topic, m)
        n += 1
    if n != count or check.hexdigest() != digest:
        raise LogError(
            f"re-indexing {path} did not reproduce its messages ({n} read back of {count}); "
            "the original was left as it was"
        )
    with open(path, "rb") as a, open(tmp, "rb") as b:
        a.seek(0), b.seek(0)
        old = [(m.name, m.metadata) for m in SeekingReader(a).iter_metadata()]
        new = [(m.name, m.metadata) for m in SeekingReader(b).iter_metadata()]
    left = index_problems(tmp)
    if old != new or left:
        raise LogError(f"re-indexing {path} failed its check ({'; '.join(left) or 'metadata'})")


def _sync_dir(folder: Path) -> None:
    """Make a rename in ``folder`` durable."""
    fd = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
