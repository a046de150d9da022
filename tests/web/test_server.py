"""The web cockpit end to end: a real server process, pilots over real websockets on
loopback, the data they leave."""

from __future__ import annotations

import asyncio
import os
import signal

import numpy as np
import orjson
import pytest

from gymfg_il.recording.reader import read_log
from gymfg_il.web.headless import fly, fly_many

pytestmark = pytest.mark.network


def _episodes(out):
    logs = sorted((out / "logs").glob("*.mcap"))
    return [e for log in logs for e in read_log(log).complete_episodes]


def test_the_web_pilot_records_what_the_synthetic_pilot_records_at_this_machine(serve, tmp_path):
    """Through the server, the page's protocol and real time, the display-bound pilot's
    actions are those of `collect manual --pilot synthetic` on the same seeds, bit for bit,
    and the dataset says the pilot, the rate and the input's delay."""
    from gymfg_il.cockpit.session import ManualSession
    from gymfg_il.collectors.config import ManualConfig

    served = serve("--episode-time", "4", "--pilots", "2", "--seed", "700")
    flown = asyncio.run(fly(served.ws, served.invites["pilot-2"], 2, skill=0.7))
    assert flown.saved == 2 and flown.welcome["pilot"] == "pilot-2"
    served.wait_for(r"pilot pilot-2 saved episode 2")
    assert served.stop() == 0
    served.wait_for(r"saved 2 episode\(s\) from 2 invite\(s\); dataset: ")
    web = _episodes(served.out)
    assert [e.start["seed"] for e in web] == [10_700, 10_701]  # pilot 2's block of seeds
    assert {e.start["pilot"] for e in web} == {"pilot-2"}

    local = tmp_path / "local"
    ManualSession(
        ManualConfig(
            pilot="synthetic", episodes=2, seed=10_700, episode_time_s=4, agent_hz=30, out=local
        )
    ).run()
    here = _episodes(local)
    for a, b in zip(web, here, strict=True):
        assert np.array_equal(a.steps["ego"].action, b.steps["ego"].action)
        assert np.array_equal(a.steps["ego"].observation, b.steps["ego"].observation)
        end = a.end
        assert end["late_frames"] == 0 and 29.0 < end["rate_hz"] < 31.0
        assert end["input_age_frames"] >= 1 and end["input_delay_ms"] > 0

    # each step's record says when the input it flew arrived, and how old it was
    from mcap.reader import make_reader

    with (served.out / "logs").glob("*.mcap").__next__().open("rb") as f:
        steps = [
            orjson.loads(m.data)
            for _, c, m in make_reader(f).iter_messages()
            if c.topic.endswith("/step")
        ]
    assert len(steps) == 240 and {s["input_age_frames"] for s in steps} == {1}
    # (arrived before the frame that read it; within about a period, a late frame's more)
    assert all(0 < s["wall_time_s"] - s["input_arrived_s"] < 0.1 for s in steps)

    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    data = LeRobotDataset("local/web", root=served.out / "dataset")
    episodes = data.meta.episodes
    assert data.num_episodes == 2 and list(episodes["gymfg/pilot"]) == ["pilot-2"] * 2
    assert all(d > 0 for d in episodes["gymfg/input_delay_ms"])
    card = (served.out / "dataset" / "README.md").read_text()
    assert "input delay p99" in card and "pilot-2" in card
    assert "keyboard (2 episodes)" in card  # the device each episode was flown with


def test_a_dropped_page_loses_its_episode_in_flight_and_the_same_invite_flies_it_again(serve):
    """The socket goes mid-episode: the episode is discarded (the server says so), nothing
    saved is touched; the same invite resumes and flies the same case again."""
    served = serve("--episode-time", "3", "--pilots", "1")
    token = served.invites["pilot-1"]
    assert asyncio.run(fly(served.ws, token, 1)).saved == 1

    async def leave_mid_episode():
        from websockets.asyncio.client import connect

        async with connect(served.ws) as ws:
            await ws.send(orjson.dumps({"type": "hello", "invite": token, "device": "keyboard"}))
            return (await _start_episode(ws, 21))["seed"]  # leave, mid-episode

    seed = asyncio.run(leave_mid_episode())
    served.wait_for(r"pilot pilot-1: the connection dropped; the episode in flight was discarded")
    again = asyncio.run(fly(served.ws, token, 2))  # counts the one saved before
    assert again.saved == 2
    assert served.stop() == 0
    episodes = _episodes(served.out)
    assert [e.start["seed"] for e in episodes] == [1000, seed] and seed == 1001


def test_quit_on_the_page_closes_its_socket_with_the_reason_and_the_session_waits(serve):
    served = serve("--episode-time", "3", "--pilots", "1")
    token = served.invites["pilot-1"]

    async def press_q():
        from websockets.asyncio.client import connect
        from websockets.exceptions import ConnectionClosed

        async with connect(served.ws) as ws:
            await ws.send(orjson.dumps({"type": "hello", "invite": token}))
            seq = 0
            try:
                async for data in ws:
                    message = orjson.loads(data)
                    if message["type"] == "frame":
                        seq += 1
                        events = [["down", "space"]] if seq == 1 else []
                        events += [["down", "q"], ["up", "q"]] if seq == 10 else []
                        await ws.send(
                            orjson.dumps(
                                {
                                    "type": "input",
                                    "seq": seq,
                                    "at": 0,
                                    "frame": message["n"],
                                    "events": events,
                                }
                            )
                        )
            except ConnectionClosed:
                pass
            return ws.close_code, ws.close_reason

    code, reason = asyncio.run(press_q())
    assert code == 1000 and reason.startswith("you quit")
    served.wait_for(r"pilot pilot-1: the page quit; the episode in flight was discarded")
    assert asyncio.run(fly(served.ws, token, 1)).saved == 1  # the session waited
    assert served.stop() == 0


@pytest.mark.slow
def test_kill_9_of_the_server_loses_no_saved_episode(serve):
    """The server is killed without warning while pilots fly: `collect recover` rebuilds every
    saved episode from the logs."""
    served = serve("--episode-time", "3", "--pilots", "2")
    tokens = list(served.invites.values())
    flown = asyncio.run(fly_many(served.ws, tokens, 2))
    assert [f.saved for f in flown] == [2, 2]

    async def fly_and_kill():
        task = asyncio.ensure_future(fly(served.ws, tokens[0], 4))
        await asyncio.sleep(1.5)  # an episode in flight
        os.kill(served.proc.pid, signal.SIGKILL)
        return await task

    asyncio.run(fly_and_kill())
    served.proc.wait(30)
    from gymfg_il.collectors.commands import recover

    assert recover(served.out) == 0
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    data = LeRobotDataset("local/web", root=served.out / "dataset")
    assert data.num_episodes == 4
    assert sorted(data.meta.episodes["gymfg/pilot"]) == ["pilot-1"] * 2 + ["pilot-2"] * 2


def test_serving_beyond_this_machine_says_so_and_how_to_do_it_safely(serve):
    served = serve("--pilots", "1", "--host", "0.0.0.0")
    warning = served.wait_for(r"^WARNING: serving on 0\.0\.0\.0")
    assert "TLS proxy" in warning and "docs/guides/web.md" in warning
    assert served.stop() == 0


@pytest.mark.slow
def test_pages_racing_for_one_invite_leave_the_newest_flying(serve):
    """Six pages open one invite at once, while its session is still starting: one flies,
    each of the others is told why it closed."""
    from websockets.asyncio.client import connect
    from websockets.exceptions import ConnectionClosed

    served = serve("--pilots", "2", "--episode-time", "3")  # (4 sockets a pilot: room for 6)
    hello = orjson.dumps({"type": "hello", "invite": served.invites["pilot-1"]})

    async def page():
        frames = 0
        async with connect(served.ws) as ws:
            await ws.send(hello)
            try:
                async with asyncio.timeout(6):
                    async for data in ws:
                        frames += orjson.loads(data)["type"] == "frame"
            except (TimeoutError, ConnectionClosed):
                pass
            return frames, ws.close_reason

    async def race():
        return await asyncio.gather(*(page() for _ in range(6)))

    results = asyncio.run(race())
    flying = [r for r in results if r[0] > 60]  # frames still coming after seconds
    assert len(flying) == 1, results
    told = [r[1] for r in results if r not in flying]
    assert told == ["this invite was opened again elsewhere"] * 5, results
    assert asyncio.run(fly(served.ws, served.invites["pilot-1"], 1)).saved == 1
    assert served.stop() == 0


async def _start_episode(ws, frames: int, events=()) -> dict:
    """Press Space, fly ``frames`` frames of the episode answering each (``events`` once);
    the last frame seen."""
    seq = 0
    async for data in ws:
        message = orjson.loads(data)
        if message["type"] != "frame":
            continue
        seq += 1
        sent = [["down", "space"], ["up", "space"]] if message["status"] == "idle" else []
        if message["status"] == "recording":
            frames -= 1
            sent, events = list(events), ()
        await ws.send(orjson.dumps({"type": "input", "seq": seq, "at": 0, "frame": message["n"],
                                    "events": sent}))  # fmt: skip
        if frames <= 0:
            return message
    raise AssertionError("the socket closed")


def test_a_page_that_goes_silent_or_is_replaced_loses_its_episode_in_flight(serve):
    """A line that dies without closing (a laptop asleep) or another page opening the same
    invite: the episode in flight is discarded, never saved with input nobody gave."""
    from websockets.asyncio.client import connect

    served = serve("--episode-time", "3", "--pilots", "1")
    hello = orjson.dumps({"type": "hello", "invite": served.invites["pilot-1"]})

    async def silent():
        async with connect(served.ws) as ws:
            await ws.send(hello)
            await _start_episode(ws, 10, [["down", "up"]])  # holding a key, then nothing
            await asyncio.sleep(4.0)  # longer than the episode: it would have ended

    async def replaced():
        async with connect(served.ws) as first:
            await first.send(hello)
            await _start_episode(first, 10, [["down", "up"]])
            async with connect(served.ws) as second:
                await second.send(hello)
                await asyncio.sleep(4.0)

    asyncio.run(silent())
    served.wait_for(r"pilot pilot-1: no input for 1 s")
    asyncio.run(replaced())
    assert len(served.said(r"the connection dropped; the episode in flight was discarded")) == 2
    assert not served.said(r"saved episode")
    assert served.stop() == 0
    assert _episodes(served.out) == []


@pytest.mark.slow
def test_episodes_caps_what_a_pilot_saves_whatever_device_they_fly(serve):
    served = serve("--episode-time", "2", "--pilots", "1", "--episodes", "2")
    token = served.invites["pilot-1"]
    assert asyncio.run(fly(served.ws, token, 1)).saved == 1
    flown = asyncio.run(fly(served.ws, token, 5, device="mouse"))  # a new session: one left
    assert flown.saved == 1 and flown.closed == "thank you: you saved your 2 episode(s)"
    again = asyncio.run(fly(served.ws, token, 1))
    assert again.closed == "you have saved your 2 episode(s); thank you"
    assert served.stop() == 0
    assert len(_episodes(served.out)) == 2
