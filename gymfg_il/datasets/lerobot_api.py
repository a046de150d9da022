"""The one boundary to LeRobot: every LeRobot import of the project happens here.

What the project needs of LeRobot 0.6 is small: its dataset metadata (``info.json``, tasks,
the episode table, statistics), its Arrow schema of features, its per-episode statistics, and
its ``LeRobotDataset`` to read a dataset. Each is reached here with keyword arguments, after
checking that the installed LeRobot is one this module was written against (``SUPPORTED``):
an upgrade that moves these names fails here with a clear error, and the parity test
(``tests/datasets/test_lerobot_parity.py``) tells whether the format itself changed.

The Hugging Face Hub is never needed: datasets are local. Entry points call ``hub_offline()``
before anything imports LeRobot, so a missing local file is an error and not a download.
"""

from __future__ import annotations

import functools
import os
from pathlib import Path
from typing import Any

from gymfg_il.errors import ConfigError

SUPPORTED = ((0, 6), (0, 7))  # [0.6, 0.7)
SUPPORTED_TEXT = ">=0.6,<0.7"


def hub_offline() -> None:
    """Keep LeRobot (and ``huggingface_hub``) off the network; call before importing them."""
    os.environ["HF_HUB_OFFLINE"] = "1"


@functools.cache
def check_version() -> str:
    """The installed LeRobot's version; a clear error when it is not a supported one."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        found = version("lerobot")
    except PackageNotFoundError:
        raise ConfigError(
            f"LeRobot is not installed; GymFG-IL needs lerobot[dataset]{SUPPORTED_TEXT} "
            "(pip install -e .)"
        ) from None
    parts = tuple(int(p) for p in found.split(".")[:2] if p.isdigit())
    if not SUPPORTED[0] <= parts < SUPPORTED[1]:
        raise ConfigError(
            f"LeRobot {found} is installed, but GymFG-IL writes and reads datasets through "
            f"LeRobot {SUPPORTED_TEXT}; install that range (pip install 'lerobot[dataset]"
            f"{SUPPORTED_TEXT}')"
        )
    return found


def load() -> None:
    """Import the LeRobot modules used here (seconds, once per process), so that what is
    timed afterwards is the work, not the import."""
    check_version()
    # jinja2 and huggingface_hub's repocard make the dataset card (``dataset_card``)
    import huggingface_hub.repocard  # noqa: F401
    import jinja2  # noqa: F401
    import lerobot.datasets.compute_stats
    import lerobot.datasets.dataset_metadata
    import lerobot.datasets.feature_utils
    import lerobot.datasets.lerobot_dataset
    import lerobot.datasets.utils  # noqa: F401


def open_metadata(root: Path, repo_id: str = "gymfg/local") -> Any:
    """The ``LeRobotDatasetMetadata`` of the dataset at ``root``."""
    check_version()
    from lerobot.datasets.dataset_metadata import LeRobotDatasetMetadata

    return LeRobotDatasetMetadata(repo_id=repo_id, root=Path(root))


def create_metadata(
    root: Path, repo_id: str, fps: int, features: dict[str, Any], robot_type: str | None
) -> Any:
    """New dataset metadata at ``root`` (which must not exist); videos only when a feature
    is a camera."""
    check_version()
    from lerobot.datasets.dataset_metadata import LeRobotDatasetMetadata

    return LeRobotDatasetMetadata.create(
        repo_id=repo_id,
        fps=fps,
        features=features,
        robot_type=robot_type,
        root=Path(root),
        use_videos=any(f.get("dtype") == "video" for f in features.values()),
    )


def video_encoder() -> Any:
    """LeRobot's encoder settings for camera features: lossless H.264 (crf 0, full colour:
    yuv444p) with a key frame every 2 frames (LeRobot's default, for random access) and the
    fastest preset (``datasets.videos`` gives the figures).

    Lossless because a vision policy flies by the camera's own frames: trained on frames
    that went through lossy H.264 (crf 23, yuv420p: 2.0 levels off on average, up to 32), its
    roll estimate on the camera's frames was off by 0.59 deg RMS against 0.25 on decoded ones,
    with heading-dependent biases up to 1.2 deg. Lossless frames are within one level of the
    drawn ones (the colour conversion), encode as fast, and take ~7.6 KiB a 128x128 frame
    against ~2.5 (measured here)."""
    check_version()
    from lerobot.configs.video import RGBEncoderConfig

    return RGBEncoderConfig(vcodec="h264", pix_fmt="yuv444p", g=2, crf=0, preset="ultrafast")


def image_stats(frames: Any) -> dict[str, Any]:
    """LeRobot's statistics of one episode's camera frames ((n, H, W, 3) uint8), as its own
    writer computes them (the frames it samples, per channel, scaled to [0, 1], shape
    (3, 1, 1)), over every 4th pixel of every 4th row: the quantiles of all pixels cost
    ~1 s per 900-frame episode, of 1/16 of them ~0.05 s, and the figures agree within 0.015."""
    check_version()
    import numpy as np
    from lerobot.datasets.compute_stats import (
        auto_downsample_height_width,
        get_feature_stats,
        sample_indices,
    )

    chosen = frames[sample_indices(len(frames)), ::4, ::4].transpose(0, 3, 1, 2)
    sampled = np.stack([auto_downsample_height_width(img) for img in chosen])
    stats = get_feature_stats(sampled, axis=(0, 2, 3), keepdims=True)
    return {k: v if k == "count" else np.squeeze(v / 255.0, axis=0) for k, v in stats.items()}


def video_path(meta: Any, key: str, chunk: int, file: int) -> Path:
    return Path(meta.root) / meta.video_path.format(
        video_key=key, chunk_index=chunk, file_index=file
    )


def record_video_info(meta: Any, key: str, encoder: Any) -> None:
    """Probe the camera's first video file and record codec, size and encoder in
    ``info.json``, as LeRobot's writer does after its first episode."""
    from lerobot.datasets.io_utils import write_info

    meta.update_video_info(key, video_encoder=encoder)
    write_info(meta.info, meta.root)


def open_dataset(root: Path, repo_id: str = "gymfg/local") -> Any:
    """Stock ``LeRobotDataset`` over the dataset at ``root`` (decoding with PyAV)."""
    check_version()
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    return LeRobotDataset(repo_id=repo_id, root=Path(root), video_backend="pyav")


def arrow_schema(features: dict[str, Any]) -> Any:
    """The Arrow schema LeRobot stores the frames of ``features`` in."""
    check_version()
    from lerobot.datasets.feature_utils import get_hf_features_from_features

    return get_hf_features_from_features(features=features).arrow_schema


def episode_stats(frames: dict[str, Any], features: dict[str, Any]) -> dict[str, Any]:
    """LeRobot's statistics of one episode's frames."""
    check_version()
    from lerobot.datasets.compute_stats import compute_episode_stats

    stats: dict[str, Any] = compute_episode_stats(episode_data=frames, features=features)
    return stats


def next_data_file(chunk: int, file: int, chunks_size: int) -> tuple[int, int]:
    """The (chunk, file) after ``(chunk, file)`` in LeRobot's data layout."""
    check_version()
    from lerobot.datasets.utils import update_chunk_file_indices

    found = update_chunk_file_indices(chunk_idx=chunk, file_idx=file, chunks_size=chunks_size)
    return int(found[0]), int(found[1])


def task_index(meta: Any, task: str) -> int:
    """The index of ``task`` in the dataset's task table (added when new)."""
    meta.save_episode_tasks(tasks=[task])
    return int(meta.get_task_index(task=task))


def save_episode(
    meta: Any,
    index: int,
    length: int,
    task: str,
    stats: dict[str, Any],
    metadata: dict[str, Any],
) -> None:
    """Register one episode (its table row and statistics) with LeRobot's metadata, which
    rewrites ``info.json`` and ``stats.json``."""
    meta.save_episode(
        episode_index=index,
        episode_length=length,
        episode_tasks=[task],
        episode_stats=stats,
        episode_metadata=metadata,
    )


def dataset_card(
    meta: Any,
    description: str,
    tags: list[str],
    *,
    license: str | None,
    homepage: str,
    paper: str,
    citation: str,
) -> str:
    """The text of a dataset card made with LeRobot's own template (``card_template.md``,
    through ``create_lerobot_dataset_card``): its YAML front matter (``license``: a Hub
    license id, or None), ``description``, the template's homepage and paper lines, and the
    dataset's ``info.json``. ``citation`` (Markdown) stands where the template asks for a
    BibTeX entry, for a dataset no publication describes. No ``repo_id`` goes in: the
    template would link a Hub page the local dataset does not have."""
    check_version()
    from lerobot.datasets.utils import create_lerobot_dataset_card

    marker = "GYMFG_CITATION"
    card = create_lerobot_dataset_card(
        tags=tags,
        dataset_info=meta.info,
        dataset_description=description,
        license=license,
        url=homepage,
        paper=paper,
        citation_bibtex=marker,
    )
    text = str(card)
    block = f"**BibTeX:**\n\n```bibtex\n{marker}\n```"
    assert text.count(block) == 1, "LeRobot's card template changed its citation block"
    return text.replace(block, citation)
