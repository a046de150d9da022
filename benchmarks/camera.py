"""The camera: frames per second of ``viz.camera.Camera`` at 128x128 on one thread, and (when
``moderngl`` is installed, which the project does not need) the same scene drawn by an
offscreen OpenGL context on Mesa's software rasteriser, one thread, read back to memory.
Beside them, the manual window's pilot's view: ms per 320x320 frame in the legible mode against
the default mode, on the approach's runway 4 NM out, three gates and a lead at the formation
slot (paired rounds)."""

from __future__ import annotations

import os
import statistics
import time

import numpy as np

from benchmarks.common import Row

_FRAGMENT = """#version 330
in vec2 uv; out vec4 c; uniform mat3 R; uniform vec3 eye; uniform float f;
void main() {
  vec3 d = R * vec3(1.0, uv.x / f, -uv.y / f);
  if (d.z > 1e-4) {
    float t = eye.z / d.z; vec2 g = eye.xy + t * d.xy;
    int k = (int(floor(g.x / 500.0)) + int(floor(g.y / 500.0))) & 1;
    int b = (int(floor(g.x / 4000.0)) + int(floor(g.y / 4000.0))) & 1;
    vec3 col = vec3(0.4, 0.5, 0.25) + 0.05 * float(k) + 0.05 * float(b);
    c = vec4(mix(vec3(0.75, 0.8, 0.84), col, exp(-t / 30000.0)), 1);
  } else {
    float up = -d.z / length(d);
    c = vec4(mix(vec3(0.78, 0.87, 0.94), vec3(0.23, 0.43, 0.75), sqrt(up)), 1);
  }
}"""


def _states(n: int) -> np.ndarray:
    from gymfg_il.sim.properties import INDEX, NAMES

    rng = np.random.default_rng(0)
    states = np.zeros((n, len(NAMES)))
    states[:, INDEX["roll_deg"]] = rng.uniform(-60, 60, n)
    states[:, INDEX["pitch_deg"]] = rng.uniform(-15, 15, n)
    states[:, INDEX["heading_deg"]] = rng.uniform(0, 360, n)
    states[:, INDEX["altitude_ft"]] = states[:, INDEX["altitude_agl_ft"]] = 5000.0
    states[:, INDEX["lat_deg"]] = 37.6 + rng.uniform(0, 0.1, n)
    states[:, INDEX["lon_deg"]] = -122.4
    return states


def _ours(frames: int) -> float:
    from gymfg_il.viz.camera import Camera

    camera, states = Camera(128, 128), _states(frames)
    camera.frame(states[0])
    t0 = time.perf_counter()
    for s in states:
        camera.frame(s)
    return frames / (time.perf_counter() - t0)


def _window_scene() -> tuple[np.ndarray, list]:
    """Attitudes on a 3 degree path 4 NM from a runway, with three gates and a lead ahead."""
    from gymfg_il.sim.properties import INDEX
    from gymfg_il.tasks.geometry import offset_position
    from gymfg_il.tasks.scenery import Landmark

    states = _states(100)
    out = 4 * 6076.1
    states[:, INDEX["altitude_ft"]] = states[:, INDEX["altitude_agl_ft"]] = out * 0.0524
    states[:, INDEX["roll_deg"]] *= 0.3
    states[:, INDEX["pitch_deg"]] *= 0.3
    states[:, INDEX["heading_deg"]] = 20.0 * np.sin(np.arange(len(states)) / 10.0)
    lat, lon = 37.6, -122.4
    states[:, INDEX["lat_deg"]], states[:, INDEX["lon_deg"]] = offset_position(lat, lon, -out, 0)
    marks = [Landmark("runway", lat, lon, 0.0, 0.0, width_ft=150.0, length_ft=5000.0)]
    for k, (north, east) in enumerate(((-out + 5000, -800), (-out + 9000, 0), (-out + 14000, 900))):
        where = offset_position(lat, lon, north, east)
        marks.append(Landmark("gate", *where, 1200.0, 0.0, 0.0, 0.0, 600.0, 300.0, k == 0))
    lead = offset_position(lat, lon, -out + 150.0, -100.0)
    marks.append(Landmark("aircraft", *lead, 1270.0, 0.0, 15.0, 0.0))
    return states, marks


def _window(rounds: int) -> tuple[list[float], list[float]]:
    """ms per 320x320 frame of the pilot's view, default and legible, rounds alternating."""
    from gymfg_il.viz.camera import Camera

    states, marks = _window_scene()
    cameras = [Camera(320, 320), Camera(320, 320, legible=True)]
    times: list[list[float]] = [[], []]
    for r in range(rounds):
        for k in (0, 1) if r % 2 == 0 else (1, 0):
            cameras[k].frame(states[0], marks)
            t0 = time.perf_counter()
            for s in states:
                cameras[k].frame(s, marks)
            times[k].append((time.perf_counter() - t0) * 1000 / len(states))
    return times[0], times[1]


def _moderngl(frames: int) -> float | None:
    os.environ.setdefault("LP_NUM_THREADS", "1")  # Mesa's rasteriser on one thread
    try:
        import moderngl

        ctx = moderngl.create_standalone_context(backend="egl")
    except Exception:  # not installed, or no EGL here: the reference is skipped
        return None
    prog = ctx.program(
        vertex_shader="#version 330\nin vec2 p; out vec2 uv;"
        "void main() { uv = p; gl_Position = vec4(p, 0, 1); }",
        fragment_shader=_FRAGMENT,
    )
    vbo = ctx.buffer(np.array([-1, -1, 1, -1, -1, 1, 1, 1], "f4").tobytes())
    vao = ctx.vertex_array(prog, [(vbo, "2f", "p")])
    fbo = ctx.simple_framebuffer((128, 128))
    fbo.use()
    prog["f"].value, prog["eye"].value = 1.0, (1000.0, 2000.0, 5000.0)
    buf = bytearray(128 * 128 * 3)
    t0 = time.perf_counter()
    for i in range(frames):
        c, s = np.cos(0.01 * i), np.sin(0.01 * i)
        prog["R"].write(np.array([[1, 0, 0], [0, c, -s], [0, s, c]], "f4").tobytes())
        vao.render(moderngl.TRIANGLE_STRIP)
        fbo.read_into(buf, components=3)
        np.frombuffer(buf, np.uint8).reshape(128, 128, 3).copy()
    rate = frames / (time.perf_counter() - t0)
    ctx.release()
    return rate


def rows(quick: bool) -> list[Row]:
    frames, rounds = (300, 3) if quick else (2000, 7)
    ours, theirs = [], []
    for _ in range(rounds):
        ours.append(_ours(frames))
        gl = _moderngl(frames)
        if gl is not None:
            theirs.append(gl)
    value = statistics.median(ours)
    detail = [f"ours: numpy, one thread         {value:9,.0f} frames/s (median of {rounds})"]
    if theirs:
        gl = statistics.median(theirs)
        detail.append(
            f"moderngl + EGL (llvmpipe, 1 thread) {gl:9,.0f} frames/s, sky and ground only"
        )
    else:
        detail.append("moderngl + EGL reference skipped (pip install moderngl to measure it)")
    plain, legible = _window(rounds * 2)
    ratios = [b / a for a, b in zip(plain, legible, strict=True)]
    detail.append(
        f"pilot's view 320x320 with runway, gates, lead: default {statistics.median(plain):.2f} "
        f"ms/frame, legible {statistics.median(legible):.2f} (worst {max(legible):.2f}); "
        f"legible/default {statistics.median(ratios):.2f} (worst {max(ratios):.2f})"
    )
    return [Row("camera_frames_per_s", value, "frames/s", 2000, detail=detail)]
