"""JSON schemas of the MCAP channels, derived from the state-variable catalogue.

Channels (Foxglove conventions: JSON messages with a ``jsonschema`` schema):

- ``/gymfg/episode`` (``gymfg.EpisodeEvent``): start (seed, source, and per aircraft its
  target and initial position), end (outcome), discard.
- ``/gymfg/<callsign>/step`` (``gymfg.Step``): every agent step: observation, action, label
  (the demonstrator's action), reward, flags.
- ``/gymfg/<callsign>/state`` (``gymfg.State``): the full state after every step.
- ``/gymfg/<callsign>/location`` (``foxglove.LocationFix``): position, heading and velocity
  for Foxglove's Map.
- ``/gymfg/<callsign>/tf`` (``foxglove.FrameTransform``): the aircraft's pose in the episode's
  local ENU frame, for Foxglove's 3D panel (``recording.foxglove`` gives the conventions).
- ``/gymfg/<callsign>/scene`` (``foxglove.SceneUpdate``): the aircraft drawn in its frame and
  its task's target (at the reset, and again whenever a dynamic target has moved).
- ``/gymfg/team/<team>/opponents`` (``gymfg.OpponentView``): what a team saw of the other
  teams after every step (team runs only).

Session metadata (the flight spec, each aircraft's task and observation names, the source,
package versions) is an MCAP metadata record named ``gymfg.session``
(``recording.session``).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

from gymfg_il.recording import foxglove
from gymfg_il.sim.properties import ACTION_NAMES, CATALOGUE
from gymfg_il.tasks.grades import GRADES

EPISODE_TOPIC = "/gymfg/episode"


def aircraft_topic(callsign: str, channel: str) -> str:
    """One aircraft's channel: ``step``, ``state``, ``location``, ``tf`` or ``scene``."""
    return f"/gymfg/{callsign}/{channel}"


def view_topic(team: str) -> str:
    return f"/gymfg/team/{team}/opponents"


_ACTION = {
    "type": "object",
    "properties": {n: {"type": "number"} for n in ACTION_NAMES},
    "required": list(ACTION_NAMES),
}

STEP = {
    "title": "gymfg.Step",
    "type": "object",
    "properties": {
        "episode": {"type": "integer", "description": "episode number in this log"},
        "step": {"type": "integer", "description": "agent steps since the reset (1 = first)"},
        "time_s": {"type": "number", "description": "simulated seconds since the reset"},
        "observation": {
            "type": "array",
            "items": {"type": "number"},
            "description": "the task observation the action was chosen from",
        },
        "action": {**_ACTION, "description": "the action applied (after clipping)"},
        "label": {**_ACTION, "description": "the demonstrator's action (before any noise)"},
        "reward": {"type": "number"},
        "terminated": {"type": "boolean"},
        "truncated": {"type": "boolean"},
        "intervention": {"type": "boolean", "description": "a human flew this step"},
        "wall_time_s": {
            "type": "number",
            "description": "real time only: the wall clock (Unix s) when the input was read",
        },
        "input_arrived_s": {
            "type": "number",
            "description": "from afar (collect web): the wall clock (Unix s) when the input "
            "flown arrived",
        },
        "input_delay_ms": {
            "type": "number",
            "description": "from afar: that input's round trip, from the frame it answered "
            "being sent to its arrival",
        },
        "input_age_frames": {
            "type": "integer",
            "description": "from afar: frames between the frame it answered and this step",
        },
    },
    "required": ["episode", "step", "observation", "action", "label", "reward"],
}

STATE = {
    "title": "gymfg.State",
    "type": "object",
    "description": "the aircraft's full state after a step (the property catalogue)",
    "properties": {
        "episode": {"type": "integer"},
        "step": {"type": "integer"},
        **{
            v.name: {"type": "number", "description": f"{v.description} [{v.unit}] ({v.prop})"}
            for v in CATALOGUE
        },
    },
}

MARKS = ("success", "failure")  # what a pilot may mark an ended episode

EPISODE_EVENT = {
    "title": "gymfg.EpisodeEvent",
    "type": "object",
    "properties": {
        "event": {"type": "string", "enum": ["start", "end", "discard", "mark"]},
        "episode": {"type": "integer"},
        "seed": {"type": "integer"},
        "aircraft": {
            "type": "object",
            "description": "callsign -> target and initial_state (lat_deg, lon_deg, altitude_ft)",
        },
        "outcome": {"type": "string"},
        "steps": {"type": "integer"},
        "source": {"type": "string"},
        "interventions": {"type": "integer"},
        "pilot": {"type": "string", "description": "start: who flew (--pilot-name)"},
        "success": {"type": "boolean", "description": "end: the task's verdict"},
        "verdict": {"type": "string", "description": "end: the verdict in words"},
        "grade": {
            "type": "string",
            "enum": list(GRADES),
            "description": "end: the task's grade of the episode (gymfg_il.tasks.grades)",
        },
        "late_frames": {"type": "integer", "description": "end, real time: frames late"},
        "rate_hz": {"type": "number", "description": "end, real time: frames per second"},
        "jitter_ms": {"type": "number", "description": "end, real time: std of loop periods"},
        "input_delay_ms": {
            "type": "number",
            "description": "end, from afar (collect web): p99 of an input's round trip",
        },
        "input_age_frames": {
            "type": "integer",
            "description": "end, from afar: p99 of the frames between a frame and its input",
        },
        "mark": {
            "type": "string",
            "enum": list(MARKS),
            "description": "mark: the pilot's own mark of an ended episode (the last counts)",
        },
    },
    "required": ["event", "episode"],
}

OPPONENT_VIEW = {
    "title": "gymfg.OpponentView",
    "type": "object",
    "description": "what a team saw of the other teams' aircraft after a step",
    "properties": {
        "episode": {"type": "integer"},
        "step": {"type": "integer"},
        "names": {"type": "array", "items": {"type": "string"}},
        "callsigns": {"type": "array", "items": {"type": "string"}},
        "values": {"type": "array", "items": {"type": "array", "items": {"type": "number"}}},
    },
}

# Foxglove's built-in schema, matched by its exact name and field layout: Foxglove's own.
LOCATION_FIX = foxglove.schema("foxglove.LocationFix")


def encoded(schema: Mapping[str, object]) -> bytes:
    return json.dumps(schema).encode()


def register_all(w: Any) -> dict[str, int]:
    """Register the log's message schemas with ``w`` (an ``mcap.writer.Writer``), ours then
    Foxglove's 3D ones; their ids by name."""
    ours = {
        "gymfg.Step": STEP,
        "gymfg.EpisodeEvent": EPISODE_EVENT,
        "gymfg.State": STATE,
        "foxglove.LocationFix": LOCATION_FIX,
        "gymfg.OpponentView": OPPONENT_VIEW,
    }
    ids = {
        name: w.register_schema(name, "jsonschema", encoded(body)) for name, body in ours.items()
    }
    for name in ("foxglove.FrameTransform", "foxglove.SceneUpdate"):
        ids[name] = w.register_schema(name, "jsonschema", encoded(foxglove.schema(name)))
    return ids
