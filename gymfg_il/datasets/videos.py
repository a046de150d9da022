"""Camera features of a dataset: frames drawn from the logged states, encoded as LeRobot video.

A dataset with ``--images front`` (or ``chase``) holds ``observation.images.front`` as a
LeRobot video feature. Its frames are not logged: the camera is deterministic, so the build
draws each frame from the logged state the observation was taken in (the start state for
frame 0, the state after step t-1 for frame t) with the task's landmarks, and a rebuild
(``collect recover``) draws the same pixels again.

Encoding uses LeRobot's own encoder settings (``lerobot_api.video_encoder``: H.264, yuv420p,
a key frame every 2 frames as LeRobot's defaults have for random access, the ``ultrafast``
preset) through PyAV, the library LeRobot encodes with. Each build writes one video file per
camera, appending every episode to it as it goes, on a thread of its own (PyAV releases the
GIL while it encodes), so drawing the next episode overlaps encoding this one. LeRobot's
own per-episode path (a temporary file per episode, then concatenated) ran at ~220 frames/s
here; this one is measured by ``benchmarks/data.py`` (``dataset_build_with_images``).
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Sequence
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.recording.reader import Log, LoggedEpisode
from gymfg_il.tasks.library import task_landmarks
from gymfg_il.tasks.scenery import Landmark, aircraft_landmark
from gymfg_il.viz.camera import VIEWS, Camera

IMAGE_PREFIX = "observation.images."
DEFAULT_IMAGE_SIZE = 128


def image_key(view: str) -> str:
    return f"{IMAGE_PREFIX}{view}"


def check_views(views: Sequence[str]) -> tuple[str, ...]:
    """The camera views a dataset asks for, checked (each at most once)."""
    views = tuple(views)
    unknown = [v for v in views if v not in VIEWS]
    if unknown or len(set(views)) != len(views):
        raise ConfigError(
            f"images {list(views)}: give each of {', '.join(VIEWS)} at most once "
            "(e.g. --images front or --images front,chase)"
        )
    return views


def episode_frames(log: Log, episode: LoggedEpisode, callsign: str, camera: Camera) -> np.ndarray:
    """The camera's frame of every observation of ``callsign`` in ``episode``: (n, H, W, 3)."""
    start = episode.start_of(callsign)
    steps = episode.steps[callsign]
    if "state" not in start:
        raise ConfigError(
            f"{log.path.name} predates camera datasets (its episodes do not record the start "
            "state); collect again to build images"
        )
    states = np.vstack([np.asarray(start["state"])[None], steps.state[:-1]])
    task = log.aircraft(callsign).get("task", {}).get("task", "")
    plan = start.get("plan")
    others = [c for c in episode.steps if c != callsign]
    out = np.empty((len(states), camera.height, camera.width, 3), np.uint8)
    for k, state in enumerate(states):
        marks: list[Landmark] = task_landmarks(task, plan, k) if plan else []
        for other in others:
            theirs = episode.steps[other].state
            if 0 < k <= len(theirs):
                marks.append(aircraft_landmark(theirs[k - 1]))
        out[k] = camera.frame(state, marks)
    return out


class VideoTrack:
    """One camera's video file of a build: episodes are appended in order, each encoded on a
    background thread; ``close()`` waits for the encoder and reports any failure."""

    def __init__(self, path: Path, fps: int, encoder: Any) -> None:
        self.path, self.fps, self.encoder = Path(path), fps, encoder
        self.frames = 0
        self.location = (0, 0)  # (chunk, file) of the dataset's video layout
        self._queue: queue.Queue[np.ndarray | None] = queue.Queue(maxsize=2)
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, name=f"encode {path.name}", daemon=True)
        self._thread.start()

    def add(self, frames: np.ndarray) -> tuple[float, float]:
        """Queue an episode's frames; its (from, to) timestamps in the file, in seconds."""
        if self._error is not None:
            raise ConfigError(f"encoding {self.path} failed: {self._error}") from self._error
        start = self.frames
        self.frames += len(frames)
        self._queue.put(frames)
        return start / self.fps, self.frames / self.fps

    def close(self) -> None:
        self._queue.put(None)
        self._thread.join()
        if self._error is not None:
            raise ConfigError(f"encoding {self.path} failed: {self._error}") from self._error

    def _run(self) -> None:
        import av

        container: Any = None
        stream: Any = None
        pts = 0
        try:
            while (frames := self._queue.get()) is not None:
                if container is None:
                    self.path.parent.mkdir(parents=True, exist_ok=True)
                    container = av.open(str(self.path), "w")
                    stream = container.add_stream(
                        self.encoder.vcodec,
                        self.fps,
                        options=self.encoder.get_codec_options(1, as_strings=True),
                    )
                    stream.pix_fmt = self.encoder.pix_fmt
                    stream.height, stream.width = frames.shape[1:3]
                    stream.time_base = Fraction(1, self.fps)
                for image in frames:
                    frame = av.VideoFrame.from_ndarray(image, format="rgb24")
                    frame.pts, frame.time_base = pts, Fraction(1, self.fps)
                    pts += 1
                    container.mux(stream.encode(frame))
            if container is not None:
                container.mux(stream.encode())
                container.close()
        except BaseException as exc:  # reported by add() / close() on the building thread
            self._error = exc
            while self._queue.get() is not None:  # let the builder finish handing frames over
                pass


def decode_camera(root: Path, key: str, meta: Any) -> np.ndarray:
    """Every frame of camera feature ``key`` of the dataset at ``root`` (``meta``: its
    ``LeRobotDatasetMetadata``) in dataset order: (frames, H, W, 3) uint8. Each video file
    is decoded once, front to back (training needs them all; decoding them one timestamp at
    a time, as the per-item loader does, is ~100x slower)."""
    import av

    if key not in meta.video_keys:
        raise ConfigError(
            f"the dataset at {root} has no camera {key!r} (it has {meta.video_keys or 'none'}); "
            "collect one with `collect autopilot --images front`"
        )
    height, width = meta.features[key]["shape"][:2]
    out = np.empty((meta.total_frames, height, width, 3), np.uint8)
    # per video file: frame in the file -> dataset index, from each episode's time span
    files: dict[tuple[int, int], dict[int, int]] = {}
    for ep in meta.episodes:
        where = (int(ep[f"videos/{key}/chunk_index"]), int(ep[f"videos/{key}/file_index"]))
        first = round(float(ep[f"videos/{key}/from_timestamp"]) * meta.fps)
        begin, end = int(ep["dataset_from_index"]), int(ep["dataset_to_index"])
        files.setdefault(where, {}).update(
            zip(range(first, first + end - begin), range(begin, end), strict=True)
        )
    filled = 0
    for (chunk, file), rows in files.items():
        path = Path(root) / meta.video_path.format(
            video_key=key, chunk_index=chunk, file_index=file
        )
        with av.open(str(path)) as container:
            for k, frame in enumerate(container.decode(video=0)):
                row = rows.get(k)
                if row is not None:
                    out[row] = frame.to_ndarray(format="rgb24")
                    filled += 1
    if filled != meta.total_frames:
        raise ConfigError(
            f"the videos of {key} in {root} hold {filled} of the dataset's {meta.total_frames} "
            "frames; rebuild the dataset from its logs (collect recover)"
        )
    return out
