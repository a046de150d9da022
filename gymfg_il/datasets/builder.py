"""Writing LeRobot v3.0 datasets whole episodes at a time.

LeRobot's own metadata (``LeRobotDatasetMetadata``, through ``datasets.lerobot_api``) writes
``info.json``, the task table, the episode table and the statistics; the episode's frames go
to the data parquet as one Arrow table in LeRobot's schema. LeRobot's per-frame path
(``add_frame`` + ``save_episode``) spends most of its time in a per-row ``datasets.map`` and a
per-frame task lookup; writing columns directly is what lets a dataset be rebuilt from logs at
tens of thousands of frames per second. Stock ``LeRobotDataset`` opens the result, and the
parity test checks it against LeRobot's own writer.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.datasets import lerobot_api as lr
from gymfg_il.datasets.features import (
    ENVIRONMENT_STATE,
    NO_WALL_TIME,
    WALL_TIME,
    check_compatible,
)
from gymfg_il.datasets.videos import VideoTrack
from gymfg_il.errors import ConfigError
from gymfg_il.sim.properties import task_columns

log = logging.getLogger(__name__)


class DatasetBuilder:
    """Create (or append to) the LeRobot dataset at ``root``.

    Args:
        root: dataset folder; created when absent, appended to when it holds a dataset.
        repo_id: the dataset's name (``gymfg/altitude-c172p``); no Hub is contacted.
        fps: frames per second (the agent rate).
        features: our features (``datasets.features.dataset_features``).
        robot_type: stored in ``info.json`` (the aircraft model).
    """

    def __init__(
        self,
        root: Path,
        repo_id: str,
        fps: int,
        features: dict[str, dict[str, Any]],
        robot_type: str | None = None,
    ) -> None:
        root = Path(root)
        self.root = root
        if (root / "meta" / "info.json").is_file():
            meta = lr.open_metadata(root, repo_id)
            check_compatible(meta.features, features, str(root))
            if meta.fps != fps:
                raise ConfigError(
                    f"cannot append to the dataset at {root}: it was recorded at {meta.fps} "
                    f"fps, the new data at {fps}; use the same agent rate or another folder"
                )
        elif root.exists() and any(root.iterdir()):
            raise ConfigError(
                f"{root} exists and is not a LeRobot dataset (no meta/info.json); give an empty "
                "or new folder, or the folder of an existing dataset to append to"
            )
        else:
            if root.exists():
                root.rmdir()
            meta = lr.create_metadata(root, repo_id, fps, features, robot_type)
        self.meta = meta
        self.repo_id = repo_id
        # LeRobot loads meta/episodes only when every file has the same columns: episodes
        # appended to a dataset carry the gymfg/* columns its episodes have, no others (an
        # older dataset lacks the newer ones; LeRobot's editing drops them all)
        self._episode_columns: set[str] | None = None
        if meta.episodes is not None and len(meta.episodes) > 0:
            self._episode_columns = {
                c for c in meta.episodes.column_names if c.startswith("gymfg/")
            }
        # the environment state is drawn from the observation (absent in older datasets)
        self._environment: list[int] | None = None
        if ENVIRONMENT_STATE in meta.features:
            self._environment = task_columns(meta.features["observation.state"]["names"])
        self.video_keys = [k for k, f in features.items() if f.get("dtype") == "video"]
        self._tracks: dict[str, VideoTrack] = {}
        self._writer: Any = None
        self._schema: Any = None
        self._file: tuple[int, int] | None = None

    def _data_file(self) -> tuple[int, int]:
        """The (chunk, file) this build writes: the one after the newest existing file."""
        if self._file is None:
            chunk, file = 0, 0
            episodes = self.meta.episodes
            if episodes is not None and len(episodes) > 0:
                last = episodes[-1]
                chunk, file = lr.next_data_file(
                    last["data/chunk_index"], last["data/file_index"], self.meta.chunks_size
                )
            self._file = (chunk, file)
        return self._file

    def _shape(self, key: str) -> tuple[int, ...]:
        shape = tuple(self.meta.features[key]["shape"])
        return () if shape == (1,) else shape

    def _track(self, key: str) -> VideoTrack:
        """The camera's video file of this build: the one after the newest existing file."""
        track = self._tracks.get(key)
        if track is None:
            chunk, file = 0, 0
            episodes = self.meta.episodes
            column = f"videos/{key}/chunk_index"
            if episodes is not None and len(episodes) > 0 and column in episodes.column_names:
                last = episodes[-1]
                chunk, file = lr.next_data_file(
                    last[column], last[f"videos/{key}/file_index"], self.meta.chunks_size
                )
            path = lr.video_path(self.meta, key, chunk, file)
            track = self._tracks[key] = VideoTrack(path, self.meta.fps, lr.video_encoder())
            track.location = (chunk, file)
        return track

    def add_episode(
        self,
        columns: dict[str, np.ndarray],
        task: str,
        metadata: dict[str, Any] | None = None,
        images: dict[str, np.ndarray] | None = None,
    ) -> int:
        """Append one episode; ``columns`` maps each of our features to a (frames, ...) array
        (the environment state, when left out, is taken from ``observation.state``), ``images``
        each camera feature to its (frames, H, W, 3) uint8 frames."""
        meta = self.meta
        n = len(columns["action"])
        if n == 0:
            raise ConfigError("an episode needs at least one frame")
        index = meta.total_episodes
        start = meta.total_frames
        frames = self._frames(self._features(columns, n), n, index, start, task)
        stats = lr.episode_stats(frames, meta.features)
        videos = self._add_videos(images or {}, n, stats)
        chunk, file = self._write(self._table(frames))
        episode_meta = {
            "data/chunk_index": chunk,
            "data/file_index": file,
            "dataset_from_index": start,
            "dataset_to_index": start + n,
            **videos,
            **self._episode_metadata(metadata or {}),
        }
        lr.save_episode(meta, index, n, task, stats, episode_meta)
        return index

    def _features(self, columns: dict[str, np.ndarray], n: int) -> dict[str, np.ndarray]:
        """The episode's columns completed (the environment state drawn from the observation,
        a wall time of none) and checked against the dataset's features, in their order."""
        meta = self.meta
        given = dict(columns)
        if self._environment is not None and ENVIRONMENT_STATE not in given:
            state = np.asarray(columns["observation.state"])
            given[ENVIRONMENT_STATE] = np.ascontiguousarray(state[:, self._environment])
        if WALL_TIME in meta.features and WALL_TIME not in given:
            given[WALL_TIME] = np.full(n, NO_WALL_TIME)  # flown faster than real time
        unknown = sorted(set(given) - set(meta.features) - {WALL_TIME})
        if unknown:
            raise ConfigError(f"the dataset has no features {unknown}; its: {list(meta.features)}")
        # in the features' order, as LeRobot's writer keeps its statistics; a wall time the
        # dataset has no column for (one begun faster than real time) is left out
        return {k: given[k] for k in meta.features if k in given}

    def _frames(
        self, columns: dict[str, np.ndarray], n: int, index: int, start: int, task: str
    ) -> dict[str, np.ndarray]:
        """Every column of the episode's ``n`` frames in LeRobot's dtypes and shapes, with its
        bookkeeping: timestamps, frame, episode, dataset and task indexes."""
        meta = self.meta
        return {
            # shape-(1,) features are scalars per frame, as LeRobot stores them
            **{
                k: np.asarray(v).reshape(n, *self._shape(k)).astype(meta.features[k]["dtype"])
                for k, v in columns.items()
            },
            # float64 as LeRobot's own writer computes its statistics; stored as float32
            "timestamp": np.arange(n) / meta.fps,
            "frame_index": np.arange(n, dtype=np.int64),
            "episode_index": np.full(n, index, dtype=np.int64),
            "index": np.arange(start, start + n, dtype=np.int64),
            "task_index": np.full(n, lr.task_index(meta, task), dtype=np.int64),
        }

    def _add_videos(
        self, images: dict[str, np.ndarray], n: int, stats: dict[str, Any]
    ) -> dict[str, Any]:
        """Append each camera's ``n`` frames to its video file and its statistics to
        ``stats``; the episode's ``videos/*`` columns (where in which file)."""
        videos: dict[str, Any] = {}
        missing = sorted(set(self.video_keys) - set(images))
        if missing:
            raise ConfigError(
                f"the dataset has camera features {missing} but the episode has no frames for them"
            )
        for key in self.video_keys:
            pictures = images[key]
            if len(pictures) != n:
                raise ConfigError(f"{key}: {len(pictures)} frames for an episode of {n}")
            stats[key] = lr.image_stats(pictures)
            track = self._track(key)
            begin, end = track.add(pictures)
            chunk, file = track.location
            videos |= {
                f"videos/{key}/chunk_index": chunk,
                f"videos/{key}/file_index": file,
                f"videos/{key}/from_timestamp": begin,
                f"videos/{key}/to_timestamp": end,
            }
        return videos

    def _table(self, frames: dict[str, np.ndarray]) -> Any:
        """The episode's frames as one Arrow table in LeRobot's schema (timestamps float32,
        vectors fixed-size lists)."""
        import pyarrow as pa

        if self._schema is None:
            self._schema = lr.arrow_schema(self.meta.features)
        arrays = []
        for field in self._schema:
            values = frames[field.name]
            if field.name == "timestamp":
                values = values.astype(np.float32)
            if values.ndim == 1:
                arrays.append(pa.array(values, type=field.type))
            else:
                flat = pa.array(values.ravel(), type=field.type.value_type)
                arrays.append(pa.FixedSizeListArray.from_arrays(flat, values.shape[1]))
        return pa.Table.from_arrays(arrays, schema=self._schema)

    def _write(self, table: Any) -> tuple[int, int]:
        """Write ``table`` to this build's data file, opened on first use; its (chunk, file)."""
        import pyarrow.parquet as pq

        chunk, file = self._data_file()
        if self._writer is None:
            path = self.root / self.meta.data_path.format(chunk_index=chunk, file_index=file)
            path.parent.mkdir(parents=True, exist_ok=True)
            # page checksums: `collect recover` finds a flipped byte in a data page
            self._writer = pq.ParquetWriter(
                path, schema=self._schema, compression="snappy", write_page_checksum=True
            )
        self._writer.write_table(table)
        return chunk, file

    def _episode_metadata(self, metadata: dict[str, Any]) -> dict[str, Any]:
        """The ``gymfg/*`` columns of a new episode, as many as the dataset's episodes have."""
        columns = {f"gymfg/{k}": v for k, v in metadata.items()}
        if self._episode_columns is None:
            return columns
        dropped = sorted(set(columns) - self._episode_columns)
        if dropped:
            log.info(
                "%s: the new episodes leave out %s, which its older episodes lack",
                self.root,
                ", ".join(dropped),
            )
        return {k: v for k, v in columns.items() if k in self._episode_columns}

    def finalize(self, card_root: Path | None = None) -> None:
        """Close the data file and flush LeRobot's buffered episode table (mandatory: before
        it the dataset is incomplete), then write the dataset card (``datasets.card``;
        ``card_root``: where the dataset will live, for the card's loading example, when it is
        built elsewhere and moved)."""
        if self._writer is not None:
            self._writer.close()
            self._writer = None
        tracks, self._tracks = self._tracks, {}
        for track in tracks.values():
            track.close()
        for key in tracks:
            lr.record_video_info(self.meta, key, lr.video_encoder())
        self.meta.finalize()
        from gymfg_il.datasets.card import write_card

        try:  # the card describes the data: a card it cannot write costs no finished build
            write_card(self.root, self.repo_id, shown_root=card_root, meta=self.meta)
        except (ValueError, KeyError, TypeError, OSError) as err:
            log.warning("dataset %s: no card written (%s)", self.root, err)
