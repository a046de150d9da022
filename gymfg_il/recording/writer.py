"""The MCAP trajectory log: every step of every aircraft, written as it happens.

The log is the write-ahead log of a collection session: the chunk in progress is finished,
flushed and fsynced at every episode boundary, so ``kill -9`` at any moment loses at most the
episode in progress; ``recording.reader`` reads what an unfinished file holds.

It takes the rollout loop's records: ``log_tick`` one step at a time (the manual session, a
recorded team run) or ``write_episode`` a whole flown episode (collection on workers).
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np
import orjson
from mcap.writer import CompressionType, IndexType, Writer

from gymfg_il.recording import foxglove as fg
from gymfg_il.recording import schemas
from gymfg_il.recording.schemas import EPISODE_TOPIC, aircraft_topic, view_topic
from gymfg_il.recording.session import CHANNELS_METADATA, SESSION_COPY, SESSION_METADATA, checked
from gymfg_il.rollout.records import Episode, OpponentView, Start, Tick
from gymfg_il.sim.properties import ACTION_NAMES, INDEX, NAMES
from gymfg_il.tasks.library import task_landmarks
from gymfg_il.units import DEG_TO_RAD, FT_TO_M

_INITIAL = ("lat_deg", "lon_deg", "altitude_ft")
_HEADING = INDEX["heading_deg"]
_NO_COVARIANCE = [0.0] * 9


def _start_record(s: Start) -> dict[str, Any]:
    """One aircraft's start as the log keeps it: target, position, the whole catalogue
    state (a camera redraws the first frame from it) and the task's plan, if it has one."""
    record = {
        "target": s.target,
        "initial_state": dict(zip(_INITIAL, s.state[:3].tolist(), strict=True)),
        "state": s.state.tolist(),
    }
    if s.task.get("plan") is not None:
        record["plan"] = s.task["plan"]
    return record


class TrajectoryWriter:
    """Write one session's MCAP log at ``path`` (an existing file is never overwritten).

    Args:
        path: the ``.mcap`` file to create.
        session: the session record (``recording.session.session_record``): the flight
            spec, its aircraft and where the data comes from.
        chunk_size: bytes per MCAP chunk; small chunks bound what a crash can lose.
    """

    def __init__(
        self, path: Path, session: Mapping[str, Any], chunk_size: int = 256 * 1024
    ) -> None:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        self.path = path
        self._file: BinaryIO = open(path, "xb")  # noqa: SIM115 (closed in close())
        try:
            self._open(session, chunk_size)
        except BaseException:
            self._file.close()
            path.unlink()
            raise

    def _open(self, session: Mapping[str, Any], chunk_size: int) -> None:
        callsigns = list(session["callsigns"])
        teams = sorted({a["team"] for a in session["aircraft"].values()})
        # Message indexes too: Foxglove's indexed reader (@mcap/core McapIndexedReader) fails
        # on every read of a file whose chunk indexes have none (~10 % larger with them). No
        # attachment index: nothing is attached, and asking for one wrote an empty group.
        w = self._writer = Writer(
            self._file,
            chunk_size=chunk_size,
            compression=CompressionType.ZSTD,
            index_types=IndexType.CHUNK | IndexType.MESSAGE | IndexType.METADATA,
            enable_data_crcs=True,  # a flip outside every chunk is found too
        )
        w.start(profile="", library="gymfg-il")
        topics = self._channels(callsigns, teams, bool(session.get("online")))
        self._look = {
            c: (a.get("model", ""), teams.index(a["team"])) for c, a in session["aircraft"].items()
        }
        self._frame = fg.LocalFrame(0.0, 0.0, 0.0)
        self._aims: dict[str, fg.Aim] = {}
        self._leads: dict[str, tuple[str, dict[str, Any]]] = {}  # callsign -> (task, plan)
        # Outside every chunk, each with its CRC: the session record twice and the channel
        # table, so that one damaged chunk or record never costs the whole log
        record = checked({k: json.dumps(v) for k, v in session.items()})
        w.add_metadata(SESSION_METADATA, record)
        w.add_metadata(SESSION_COPY, record)
        w.add_metadata(CHANNELS_METADATA, checked({str(c): t for c, t in topics.items()}))
        self._dt_ns = round(float(session["dt"]) * 1e9)
        self._clock_ns = time.time_ns()
        self._base_ns = self._clock_ns  # the log time of the current episode's reset
        self._sequence = 0
        self.episode = -1
        self._in_episode = False
        self._sync()

    def _channels(self, callsigns: list[str], teams: list[str], online: bool) -> dict[int, str]:
        """Register the log's schemas and channels: the episode events, each aircraft's step,
        state, location, pose and scene, and each team's view where teams see others; the
        topic of every channel by its id."""
        w = self._writer
        ids = schemas.register_all(w)
        topics: dict[int, str] = {}

        def channel(topic: str, schema: str) -> int:
            topics[channel_id := w.register_channel(topic, "json", ids[schema])] = topic
            return channel_id

        self._events = channel(EPISODE_TOPIC, "gymfg.EpisodeEvent")
        self._steps = {c: channel(aircraft_topic(c, "step"), "gymfg.Step") for c in callsigns}
        self._states = {c: channel(aircraft_topic(c, "state"), "gymfg.State") for c in callsigns}
        self._fixes = {
            c: channel(aircraft_topic(c, "location"), "foxglove.LocationFix") for c in callsigns
        }
        self._tfs = {
            c: channel(aircraft_topic(c, "tf"), "foxglove.FrameTransform") for c in callsigns
        }
        self._scenes = {
            c: channel(aircraft_topic(c, "scene"), "foxglove.SceneUpdate") for c in callsigns
        }
        self._views = (
            {t: channel(view_topic(t), "gymfg.OpponentView") for t in teams}
            if len(teams) > 1 or online
            else {}
        )
        return topics

    def _sync(self) -> None:
        self._writer.flush()
        os.fsync(self._file.fileno())

    def _emit(self, channel: int, message: Mapping[str, Any]) -> None:
        self._sequence += 1
        self._writer.add_message(
            channel,
            log_time=self._clock_ns,
            data=orjson.dumps(message, option=orjson.OPT_SERIALIZE_NUMPY),
            publish_time=self._clock_ns,
            sequence=self._sequence,
        )

    def _at_step(self, step: int) -> None:
        """Set the log's clock to agent step ``step`` of this episode."""
        self._clock_ns = self._base_ns + step * self._dt_ns

    # -- episodes ------------------------------------------------------------------------
    def start_episode(
        self,
        seed: int,
        starts: Sequence[Start],
        options: Mapping[str, Any] | None = None,
        **info: Any,
    ) -> int:
        """Open the next episode: its seed, every aircraft's start (target, position), the
        reset ``options`` that replay needs (``rollout.records.reset_record``) and ``info``
        (source, iteration, ...)."""
        if self._in_episode:
            raise RuntimeError("end or discard the current episode before starting another")
        self.episode += 1
        self._in_episode = True
        self._base_ns = self._clock_ns
        aircraft = {s.callsign: _start_record(s) for s in starts}
        event = {"event": "start", "episode": self.episode, "seed": seed, "aircraft": aircraft}
        if options:
            event["options"] = dict(options)
        self._emit(self._events, {**event, **info})
        self._draw_starts(starts)
        return self.episode

    def _draw_starts(self, starts: Sequence[Start]) -> None:
        """Foxglove's 3D view at the reset: anchor the ``enu`` frame at the first aircraft,
        place every aircraft, draw it and its task's target (``recording.foxglove``)."""
        self._aims, self._leads = {}, {}  # no episode's before it moves on in this one
        if not starts:
            return
        lat, lon, alt_ft = starts[0].state[:3].tolist()
        self._frame = fg.LocalFrame(lat, lon, alt_ft * FT_TO_M)
        for s in starts:
            if s.callsign not in self._scenes:
                continue
            values = s.state.tolist()
            where, _ = self._transform(s.callsign, values)
            model, team = self._look.get(s.callsign, ("", 0))
            entities = [fg.aircraft_entity(self._clock_ns, s.callsign, model, team)]
            aim = fg.Aim.of(s.task, s.observation)
            entities += fg.target_entities(
                self._clock_ns, s.callsign, s.task, aim.value if aim else s.target, where,
                self._frame,
            )  # fmt: skip
            marks = task_landmarks(s.task.get("task", ""), s.task.get("plan"), 0)
            entities += fg.scenery_entities(self._clock_ns, s.callsign, marks, self._frame)
            deletion = {"timestamp": fg.stamp(self._clock_ns), "type": 1, "id": ""}
            self._emit(self._scenes[s.callsign], {"deletions": [deletion], "entities": entities})
            if aim is not None and aim.dynamic:
                self._aims[s.callsign] = aim
            if any(m.kind == "aircraft" for m in marks):
                self._leads[s.callsign] = (s.task["task"], s.task["plan"])
                self._place_lead(s.callsign, 0)

    def _place_lead(self, callsign: str, step: int) -> None:
        """Move ``callsign``'s lead (a formation's) to where its track has it at ``step``."""
        task, plan = self._leads[callsign]
        for mark in task_landmarks(task, plan, step):
            if mark.kind == "aircraft":
                lead = fg.pose_transform(self._frame, self._clock_ns, f"{callsign}/lead", mark)
                self._emit(self._tfs[callsign], lead)

    def _transform(
        self, callsign: str, values: list[float]
    ) -> tuple[tuple[float, float, float], dict[str, float]]:
        """Log ``callsign``'s pose in ``enu`` (a FrameTransform); (its position there, its
        ground velocity in ENU)."""
        message, where, velocity = fg.transform(self._frame, self._clock_ns, callsign, values)
        self._emit(self._tfs[callsign], message)
        return where, velocity

    def log_tick(
        self, tick: Tick, wall_time_s: float | None = None, afar: dict[str, Any] | None = None
    ) -> None:
        """Log one agent step of the flight: every aircraft's step and each team's view
        (``wall_time_s``: in a session flown in real time, when its input was read;
        ``afar``: the step's ``input_*`` fields, for an input from afar, ``collect web``)."""
        self._at_step(tick.step)
        for s in tick.steps:
            self.log_step(
                s.callsign, s.step, s.state, s.observation, s.action, s.label, s.reward,
                s.terminated, s.truncated, s.intervention, wall_time_s, afar,
            )  # fmt: skip
        for team, view in tick.views.items():
            self.log_view(team, tick.step, view)

    def write_episode(self, episode: Episode, end: dict | None = None, **info: Any) -> None:
        """Log a flown episode, durably (``info``: its start event's; ``end``: its end's)."""
        trajectories = list(episode.trajectories.values())
        starts = [t.start for t in trajectories]
        self.start_episode(episode.seed, starts, episode.options, **info)
        steps = max((len(t) for t in trajectories), default=0)
        for k in range(steps):
            self._at_step(k + 1)
            for t in trajectories:
                if k >= len(t):
                    continue
                last = k == len(t) - 1
                self.log_step(
                    t.callsign, k + 1, t.states[k], t.observations[k], t.actions[k], t.labels[k],
                    t.rewards[k], t.terminated and last, t.truncated and last,
                    bool(t.interventions[k]),
                )  # fmt: skip
            for team, views in episode.views.items():
                self.log_view(team, k + 1, views[k])
        self.end_episode(
            outcome=episode.outcome,
            steps=steps,
            interventions=int(sum(t.interventions.sum() for t in trajectories)),
            **(end or {}),
        )

    def log_step(
        self,
        callsign: str,
        step: int,
        state: np.ndarray,
        observation: np.ndarray,
        action: Sequence[float] | np.ndarray,
        label: Sequence[float] | np.ndarray,
        reward: float,
        terminated: bool = False,
        truncated: bool = False,
        intervention: bool = False,
        wall_time_s: float | None = None,
        afar: dict[str, Any] | None = None,
    ) -> None:
        """Log one agent step of ``callsign`` (state after the step, action that led to it;
        ``wall_time_s`` only in real time: the wall clock when the input was read; ``afar``:
        the ``input_*`` fields of an input from afar)."""
        values = state.tolist()
        clock = {} if wall_time_s is None else {"wall_time_s": float(wall_time_s)}
        if afar:
            clock |= afar
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
                **clock,
            },
        )
        self._emit(
            self._states[callsign],
            {"episode": self.episode, "step": step, **dict(zip(NAMES, values, strict=True))},
        )
        where, velocity = self._transform(callsign, values)
        self._locate(callsign, values, velocity)
        if callsign in self._leads:
            self._place_lead(callsign, step)
        aim = self._aims.get(callsign)
        if aim is not None and aim.moved(observation):
            entities = fg.target_entities(
                self._clock_ns, callsign, aim.task, aim.value, where, self._frame
            )
            self._emit(self._scenes[callsign], {"deletions": [], "entities": entities})

    def _locate(self, callsign: str, values: list[float], velocity: dict[str, float]) -> None:
        """Log ``callsign``'s position as a Foxglove LocationFix (``values``: its state)."""
        self._emit(
            self._fixes[callsign],
            {
                "timestamp": fg.stamp(self._clock_ns),
                "frame_id": callsign,
                "latitude": values[0],
                "longitude": values[1],
                "altitude": values[2] * FT_TO_M,
                "position_covariance": _NO_COVARIANCE,
                "position_covariance_type": 0,
                "heading": values[_HEADING] * DEG_TO_RAD,
                "velocity": velocity,
            },
        )

    def log_view(self, team: str, step: int, view: OpponentView) -> None:
        """Log what ``team`` saw of the other teams after agent step ``step``."""
        channel = self._views.get(team)
        if channel is None:
            return
        self._emit(
            channel,
            {
                "episode": self.episode,
                "step": step,
                "names": list(view.names),
                "callsigns": list(view.callsigns),
                "values": np.asarray(view.values, dtype=np.float64).tolist(),
            },
        )

    def end_episode(self, **info: Any) -> None:
        """Close the episode (``outcome``, ``steps``, ...) and make it durable."""
        self._emit(self._events, {"event": "end", "episode": self.episode, **info})
        self._in_episode = False
        self._sync()

    def mark_episode(self, episode: int, mark: str) -> None:
        """The pilot's own mark of ended ``episode`` (``schemas.MARKS``; the last counts)."""
        if mark not in schemas.MARKS:
            raise ValueError(f"mark={mark!r}: want one of {schemas.MARKS}")
        self._emit(self._events, {"event": "mark", "episode": int(episode), "mark": mark})
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
