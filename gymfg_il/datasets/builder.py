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

from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.datasets import lerobot_api as lr
from gymfg_il.datasets.features import check_compatible
from gymfg_il.errors import ConfigError


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

    def add_episode(
        self, columns: dict[str, np.ndarray], task: str, metadata: dict[str, Any] | None = None
    ) -> int:
        """Append one episode; ``columns`` maps each of our features to a (frames, ...) array."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        meta = self.meta
        n = len(columns["action"])
        if n == 0:
            raise ConfigError("an episode needs at least one frame")
        index = meta.total_episodes
        start = meta.total_frames
        frames = {
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
        stats = lr.episode_stats(frames, meta.features)
        if self._schema is None:
            self._schema = lr.arrow_schema(meta.features)
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
        table = pa.Table.from_arrays(arrays, schema=self._schema)
        chunk, file = self._data_file()
        if self._writer is None:
            path = self.root / meta.data_path.format(chunk_index=chunk, file_index=file)
            path.parent.mkdir(parents=True, exist_ok=True)
            self._writer = pq.ParquetWriter(path, schema=self._schema, compression="snappy")
        self._writer.write_table(table)
        episode_meta = {
            "data/chunk_index": chunk,
            "data/file_index": file,
            "dataset_from_index": start,
            "dataset_to_index": start + n,
            **{f"gymfg/{k}": v for k, v in (metadata or {}).items()},
        }
        lr.save_episode(meta, index, n, task, stats, episode_meta)
        return index

    def finalize(self) -> None:
        """Close the data file and flush LeRobot's buffered episode table (mandatory: before
        it the dataset is incomplete)."""
        if self._writer is not None:
            self._writer.close()
            self._writer = None
        self.meta.finalize()
