"""A real browser flies the web cockpit: Debian's Chromium driven by Playwright (the system
executable; nothing downloaded). It opens an invite, presses keys or moves an emulated
gamepad, and the logged actions follow."""

from __future__ import annotations

import contextlib
import shutil

import numpy as np
import pytest

from gymfg_il.recording.reader import read_log

pytestmark = pytest.mark.network

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
playwright = pytest.importorskip("playwright.sync_api", reason="pip install playwright")
if CHROMIUM is None:
    pytest.skip("no Chromium (apt-get install chromium)", allow_module_level=True)

# a gamepad the page reads through navigator.getGamepads(), its axes set by the test
FAKE_PAD = """
window.__pad = {id: "test pad", index: 0, connected: true, mapping: "standard",
                axes: [0, 0, 0, 0], buttons: Array.from({length: 8}, () => ({pressed: false}))};
navigator.getGamepads = () => [window.__pad];
"""


def _browser(p):
    return p.chromium.launch(executable_path=CHROMIUM, headless=True, args=["--no-sandbox"])


def _episodes(out):
    logs = sorted((out / "logs").glob("*.mcap"))
    return [e for log in logs for e in read_log(log).complete_episodes]


@contextlib.contextmanager
def _page(errors, init: str | None = None):
    """A Chromium page whose script errors go to ``errors`` (``init``: a script run first)."""
    with playwright.sync_playwright() as p:
        browser = _browser(p)
        page = browser.new_page(viewport={"width": 1280, "height": 860}, bypass_csp=True)
        page.on("pageerror", lambda err: errors.append(str(err)))
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        if init is not None:
            page.add_init_script(init)
        yield page
        browser.close()


def _fly_with(page, served, device: str) -> None:
    """Open the invite, choose ``device`` and fly (the page first joins with the keyboard)."""
    page.goto(f"{served.base}/fly#invite={served.invites['pilot-1']}")
    page.reload()
    page.select_option("#device", device)
    page.click("#join")
    page.wait_for_function(f"document.getElementById('state').textContent.includes('{device}')")


@pytest.mark.slow
@pytest.mark.parametrize("task", ["formation", "waypoints", "turn"])
def test_the_page_draws_every_reading_of_the_display_model(serve, task):
    """As the pygame window does (tests/display): each task's every reading, bugs, needles,
    the slot and the guidance, is on the page (the approach's: the keys test below)."""
    served = serve("--episode-time", "5", "--pilots", "1", "--task", task)
    errors: list[str] = []
    with _page(errors) as page:
        page.goto(f"{served.base}/fly#invite={served.invites['pilot-1']}")
        page.wait_for_function("document.getElementById('state').textContent.startsWith('flying')")
        page.keyboard.press("Space")
        page.wait_for_function("window.__frame && window.__frame.status === 'recording'")
        page.wait_for_timeout(500)
        drawn, frame = page.evaluate("[window.__drawn, window.__frame]")
    assert not errors, errors
    assert set(drawn) == {r[0] for r in frame["readings"]}
    assert served.stop() == 0


def test_keys_pressed_in_chromium_are_the_actions_in_the_log(serve, tmp_path):
    served = serve("--episode-time", "4", "--pilots", "1", "--task", "approach")
    errors: list[str] = []
    with _page(errors) as page:
        page.goto(f"{served.base}/fly#invite={served.invites['pilot-1']}")
        page.wait_for_function("document.getElementById('state').textContent.startsWith('flying')")
        page.wait_for_timeout(500)
        page.screenshot(path=str(tmp_path / "idle.png"))
        page.keyboard.press("Space")  # start
        served.wait_for(r"pilot pilot-1 joined")
        page.wait_for_timeout(800)
        page.keyboard.down("ArrowDown")  # pull: the elevator goes nose up (negative)
        page.wait_for_timeout(700)
        page.screenshot(path=str(tmp_path / "approach.png"))
        drawn, frame = page.evaluate("[window.__drawn, window.__frame]")
        page.keyboard.up("ArrowDown")
        served.wait_for(r"pilot pilot-1 saved episode 1", timeout=30)
        page.wait_for_timeout(300)
        text = page.evaluate("document.getElementById('state').textContent")
    assert not errors, errors
    assert text.startswith("flying as pilot-1")
    names = {r[0] for r in frame["readings"]}
    assert set(drawn) == names and "glideslope_dots" in names  # the ILS and all the rest
    (episode,) = _episodes(served.out)
    elevator = episode.steps["ego"].action[:, 1]
    # held for 0.7 s at 1.5 a second: the stick came back about 1 below where it was
    assert elevator.min() < elevator[0] - 0.6
    assert (tmp_path / "approach.png").stat().st_size > 10_000
    assert served.stop() == 0


@pytest.mark.slow
def test_an_emulated_gamepad_flies_after_its_calibration(serve):
    served = serve("--episode-time", "3", "--pilots", "1")
    errors: list[str] = []
    with _page(errors, FAKE_PAD) as page:
        page.goto(f"{served.base}/fly")  # no invite in the link: it says so, and waits
        assert "no invite" in page.evaluate("document.getElementById('state').textContent")
        page.evaluate("window.__pad.axes[1] = 0.1")  # a stick that rests off centre
        _fly_with(page, served, "joystick")
        page.evaluate("window.__pad.axes[1] = 0.1")  # at rest: calibrated away
        page.keyboard.press("c")
        page.keyboard.press("Space")
        page.wait_for_timeout(1000)
        page.evaluate("window.__pad.axes[1] = 0.9")  # push
        page.wait_for_timeout(800)
        page.evaluate("window.__pad.axes[1] = 0.1")
        served.wait_for(r"pilot pilot-1 saved episode 1", timeout=30)
    assert not errors, errors
    (episode,) = _episodes(served.out)
    assert episode.start["pilot"] == "pilot-1"
    elevator = episode.steps["ego"].action[:, 1]
    start = elevator[0]
    assert np.allclose(elevator[:10], start)  # the resting offset is calibrated away
    assert elevator.max() > start + 0.4  # the push reached the surface
    assert served.stop() == 0


@pytest.mark.slow
def test_the_mouse_stick_follows_the_pointer_over_the_attitude_indicator(serve):
    served = serve("--episode-time", "3", "--pilots", "1")
    errors: list[str] = []
    with _page(errors) as page:
        _fly_with(page, served, "mouse")
        box = page.locator("#cockpit").bounding_box()
        scale = box["width"] / 1200

        def at(dx: float) -> tuple[float, float]:  # canvas px right of the indicator's centre
            return box["x"] + (420 + dx) * scale, box["y"] + 250 * scale

        page.mouse.move(*at(0))
        page.keyboard.press("Space")
        page.wait_for_timeout(700)
        page.mouse.move(*at(75), steps=5)  # half the stick's travel to the right
        page.wait_for_timeout(700)
        page.mouse.move(*at(-150), steps=5)  # full left
        served.wait_for(r"pilot pilot-1 saved episode 1", timeout=30)
    assert not errors, errors
    (episode,) = _episodes(served.out)
    aileron = episode.steps["ego"].action[:, 0]
    assert aileron.max() > 0.4 and aileron.min() < -0.9
    assert served.stop() == 0
