"""A log as a Tacview flight recording: ACMI 2.1 text (``collect export acmi LOG``).

Tacview (the debriefing tool of flight-simulation people) opens the file as it is; every
aircraft of every completed episode becomes an object:

    FileType=text/acmi/tacview
    FileVersion=2.1
    0,ReferenceTime=2026-11-24T23:00:00Z         the log's first message (wall clock, UTC)
    0,Event=Bookmark|episode 0 (seed 5; time limit)
    #0.0000
    101,T=-122.3570000|37.6190000|1524.00|0.00|0.00|90.00,Type=Air+FixedWing,Name=C172,...
    #0.1000
    101,T=...|...|...|...|...|...,TAS=56.59,CAS=55.20,Mach=0.1684,AOA=2.10,AGL=1519.80
    -101                                          the aircraft leaves (its episode ended)

Coordinates follow Tacview's conventions: ``T=Longitude|Latitude|Altitude|Roll|Pitch|Yaw`` in
degrees and metres above sea level, roll positive right wing down, pitch positive nose up, yaw
the true heading (JSBSim's own signs, so no angle changes sign). Speeds are in m/s, AGL in
metres. Each aircraft carries ``Name`` (the aircraft type Tacview knows, ``tacview_name``),
``CallSign``, ``Coalition`` (its team), ``Color`` (by team) and ``Type=Air+FixedWing``.

One file holds the whole log: the episodes are laid end to end on Tacview's timeline (each
starts one second after the previous one ended, with a bookmark naming its index, seed and
outcome), and every episode's aircraft are objects of their own (ids ``<episode><aircraft>`` in
hex), removed when their flight ends, so a crash leaves the scene at its step. A frame at an
episode's start shows the reset state; frame ``k`` the state after step ``k``.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.recording.reader import Log, LoggedEpisode, read_log
from gymfg_il.sim.properties import INDEX
from gymfg_il.units import FT_TO_M, KT_TO_MS, wrap_360

EPISODE_GAP_S = 1.0

# JSBSim model -> the name Tacview's object database knows (others keep their JSBSim name).
TACVIEW_NAMES: dict[str, str] = {
    "c172p": "C172",
    "c172x": "C172",
    "c172r": "C172",
    "f15": "F-15C",
    "f16": "F-16C",
    "f22": "F-22A",
    "A320": "A320",
    "737": "B737",
    "787-8": "B787",
    "B747": "B747",
    "c310": "C310",
    "J3Cub": "J-3 Cub",
    "p51d": "P-51D",
    "Concorde": "Concorde",
    "T37": "T-37",
    "T38": "T-38",
    "MD11": "MD-11",
}
# Tacview's colour names; a team named after one gets it, others take them in order.
COLORS = ("Red", "Orange", "Yellow", "Green", "Cyan", "Blue", "Violet")
PALETTE = ("Blue", "Red", "Green", "Orange", "Violet", "Cyan", "Yellow")

_POSE = [INDEX[n] for n in ("lon_deg", "lat_deg", "altitude_ft", "roll_deg", "pitch_deg")]
_YAW = INDEX["heading_deg"]


@dataclass
class AcmiConfig:
    """Write every aircraft of a log as a Tacview flight recording (ACMI 2.1 text): callsigns,
    teams as coalitions, the aircraft type; the episodes one after another on the timeline.

    Attributes:
        log: an .mcap log, or a session folder holding one (logs/*.mcap).
        out: the .acmi file to write (default: beside the log, its name with .acmi).
        episode: only this episode (default: every completed one).
    """

    log: Path = field(metadata={"positional": True})
    out: Path | None = None
    episode: int | None = None


@dataclass
class AcmiSummary:
    """What ``write_acmi`` wrote."""

    path: Path
    episodes: int
    objects: int
    frames: int


def tacview_name(model: str) -> str:
    """The aircraft type Tacview shows for a JSBSim model (``c172p`` -> ``C172``)."""
    return TACVIEW_NAMES.get(model, model)


def team_colors(teams: list[str]) -> dict[str, str]:
    """A Tacview colour per team: its own name when it names one (``red`` -> ``Red``), else
    the next unused colour of the palette."""
    known = {c.lower(): c for c in COLORS}
    out = {t: known[t.lower()] for t in teams if t.lower() in known}
    spare = [c for c in PALETTE if c not in out.values()] or list(PALETTE)
    for i, team in enumerate(t for t in teams if t not in out):
        out[team] = spare[i % len(spare)]
    return out


def escape(text: str) -> str:
    """A text property value as ACMI needs it: commas and line ends escaped."""
    return text.replace("\\", "\\\\").replace(",", "\\,").replace("\n", "\\\n")


def _angle(value: float) -> str:
    text = f"{value:.2f}"
    return "0.00" if text == "-0.00" else text


def _pose(row: np.ndarray) -> str:
    lon, lat, alt_ft, roll, pitch = (float(row[i]) for i in _POSE)
    yaw = wrap_360(float(row[_YAW]))
    angles = "|".join(_angle(a) for a in (roll, pitch, yaw))
    return f"T={lon:.7f}|{lat:.7f}|{alt_ft * FT_TO_M:.2f}|{angles}"


def _telemetry(row: np.ndarray) -> str:
    tas = row[INDEX["true_airspeed_kts"]] * KT_TO_MS
    cas = row[INDEX["airspeed_kts"]] * KT_TO_MS
    return (
        f"TAS={tas:.2f},CAS={cas:.2f},Mach={row[INDEX['mach']]:.4f},"
        f"AOA={row[INDEX['alpha_deg']]:.2f},AGL={row[INDEX['altitude_agl_ft']] * FT_TO_M:.2f}"
    )


def reference_time(log: Log) -> str:
    """When the log began (its first message; a log without a summary: its file's time), as
    ACMI's ``ReferenceTime`` (ISO 8601, UTC)."""
    stamp = log.path.stat().st_mtime
    if log.finished:
        from mcap.reader import make_reader

        with log.path.open("rb") as f:
            summary = make_reader(f).get_summary()
        if summary is not None and summary.statistics is not None:
            stamp = summary.statistics.message_start_time / 1e9
    when = dt.datetime.fromtimestamp(int(stamp), tz=dt.UTC)
    return when.strftime("%Y-%m-%dT%H:%M:%SZ")


def chosen_episodes(log: Log, episode: int | None) -> list[LoggedEpisode]:
    """The completed episodes of ``log`` (``episode``: that one); a clear error when none."""
    complete = log.complete_episodes
    if episode is not None:
        complete = [e for e in complete if e.index == episode]
        if not complete:
            have = [e.index for e in log.complete_episodes]
            raise ConfigError(
                f"{log.path.name} has no completed episode {episode}; it has {have or 'none'}"
            )
    if not complete:
        raise ConfigError(f"{log.path.name} holds no completed episode: nothing to export")
    return complete


def acmi_lines(log: Log, episodes: list[LoggedEpisode]) -> Iterator[str]:
    """The ACMI 2.1 text of ``episodes`` of ``log``, line by line (see the module docstring)."""
    from gymfg_il.recording.session import package_versions

    step_s = 1.0 / log.spec.agent_hz
    teams = [t.name for t in log.spec.teams]
    colors = team_colors(teams)
    yield "FileType=text/acmi/tacview"
    yield "FileVersion=2.1"
    yield f"0,ReferenceTime={reference_time(log)}"
    jsbsim = package_versions().get("jsbsim", "?")
    yield f"0,DataSource={escape(f'GymFG-IL on JSBSim {jsbsim}')}"
    yield "0,DataRecorder=gymfg_il.export.acmi"
    yield f"0,Title={escape(log.path.name)}"
    start = 0.0
    for k, ep in enumerate(episodes):
        end = ep.end or {}
        outcome = str(end.get("outcome", ""))
        note = f"episode {ep.index} (seed {ep.start.get('seed')}; {outcome or 'ended'})"
        callsigns = list(ep.steps)
        ids = {c: f"{(k + 1) * 0x100 + i + 1:x}" for i, c in enumerate(callsigns)}
        statics = {}
        for c in callsigns:
            info = log.aircraft(c)
            team = str(info.get("team", ""))
            statics[c] = (
                f"Type=Air+FixedWing,Name={escape(tacview_name(str(info.get('model', ''))))},"
                f"CallSign={escape(c)},Coalition={escape(team)},"
                f"Color={colors.get(team, PALETTE[0])}"
            )
        yield f"#{start:.4f}"
        yield f"0,Event=Bookmark|{escape(note)}"
        declared: set[str] = set()
        for c in callsigns:
            first = ep.start_of(c).get("state")
            if first is not None:
                row = np.asarray(first, dtype=np.float64)
                yield f"{ids[c]},{_pose(row)},{statics[c]},{_telemetry(row)}"
                declared.add(c)
        states = {c: ep.steps[c].state for c in callsigns}
        length = max(len(s) for s in states.values())
        for i in range(1, length + 2):
            lines = []
            for c in callsigns:
                n = len(states[c])
                if i <= n:
                    row = states[c][i - 1]
                    head = f"{ids[c]},{_pose(row)}"
                    if c not in declared:
                        head += "," + statics[c]
                        declared.add(c)
                    lines.append(f"{head},{_telemetry(row)}")
                elif i == n + 1:
                    lines.append(f"-{ids[c]}")  # its flight ended with the step before
            if lines:
                yield f"#{start + i * step_s:.4f}"
                yield from lines
        start += (length + 1) * step_s + EPISODE_GAP_S


def write_acmi(log_path: Path, out: Path | None = None, episode: int | None = None) -> AcmiSummary:
    """Write the completed episodes of the log at ``log_path`` (a session folder: its one
    log) as ACMI 2.1 text to ``out`` (default: beside the log, ``.acmi``)."""
    log_path = Path(log_path)
    if log_path.is_dir():
        found = sorted((log_path / "logs").glob("*.mcap"))
        if len(found) != 1:
            what = f"{len(found)} logs" if found else "no logs/*.mcap"
            raise ConfigError(
                f"{log_path} holds {what}: give one .mcap log (an ACMI file shows one log)"
            )
        log_path = found[0]
    log = read_log(log_path)
    episodes = chosen_episodes(log, episode)
    out = Path(out) if out is not None else log_path.with_suffix(".acmi")
    if out.suffix.lower() not in (".acmi", ".txt"):
        raise ConfigError(f"--out {out}: Tacview opens text recordings named *.acmi")
    tmp = out.with_name(out.name + ".tmp")
    frames = 0
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        with tmp.open("w", encoding="utf-8", newline="\n") as f:
            for line in acmi_lines(log, episodes):
                frames += line.startswith("#")
                f.write(line + "\n")
        tmp.replace(out)
    except OSError as err:
        raise ConfigError(
            f"--out {out}: cannot write there ({err.strerror}); give a path you may write to"
        ) from None
    objects = sum(len(e.steps) for e in episodes)
    return AcmiSummary(out, len(episodes), objects, frames)


def export_acmi(cfg: AcmiConfig) -> int:
    """``collect export acmi``: write the file and say what it holds."""
    s = write_acmi(cfg.log, cfg.out, cfg.episode)
    print(
        f"wrote {s.path}: {s.episodes} episode(s), {s.objects} aircraft tracks, "
        f"{s.frames} frames (open it in Tacview)"
    )
    return 0
