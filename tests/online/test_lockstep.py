"""Teams in lockstep through a real server: an online run is the offline run bit for bit, a
team too many is refused, and a team that is killed or leaves holds up no one."""

import sys
from pathlib import Path

import numpy as np
import pytest

from gymfg_il.online.client import OnlineEnv
from gymfg_il.online.protocol import ServerError

pytestmark = pytest.mark.network
sys.path.insert(0, str(Path(__file__).parent))
import run_team  # noqa: E402
from waiting import Lines  # noqa: E402


def test_online_run_matches_the_offline_env_bit_for_bit(server, tmp_path):
    address, _ = server("--mode", "fixed", "--teams", "2", "--secret", "s")
    # red polls for the server's replies (the default), blue sleeps on them at once
    red = run_team.start(address, "s", "red", 5, 6, tmp_path / "red.npy")
    blue = run_team.start(address, "s", "blue", 5, 6, tmp_path / "blue.npy", spin_us=0)
    for proc in (red, blue):
        out = proc.communicate(timeout=60)[0].decode()
        assert proc.returncode == 0, out
    online_red, online_blue = np.load(tmp_path / "red.npy"), np.load(tmp_path / "blue.npy")

    teams = run_team.teams(6)
    blue_states = []
    # the same two teams in one offline simulation, seeded alike
    from gymfg_il.envs import EnvConfig, World

    world = World([teams["red"], teams["blue"]], EnvConfig())
    world.reset(np.random.default_rng(5))
    agents = {
        s.callsign: run_team.controller_for(
            s.task, s.aircraft.model, world.dt, s.aircraft.profile.cruise_throttle
        )
        for s in world.slots
    }
    red_states = []
    for _ in range(60):
        actions = [
            tuple(np.clip(agents[s.callsign].act(world.observation(s)), [-1, -1, -1, 0], 1))
            for s in world.slots
        ]
        world.advance(actions)
        red_states.append(np.stack([s.state for s in world.team_slots["red"]]))
        blue_states.append(np.stack([s.state for s in world.team_slots["blue"]]))
    world.close()
    assert online_red.shape == (60, 2, len(red_states[0][0]))
    assert np.array_equal(online_red, np.array(red_states))
    assert np.array_equal(online_blue, np.array(blue_states))


def test_the_k_plus_first_team_is_refused(server):
    address, _ = server("--mode", "fixed", "--teams", "1")
    teams = run_team.teams(3)
    first = OnlineEnv(address)
    first.reset(teams["red"], seed=0)  # k = 1: the simulation has its team
    second = OnlineEnv(address, timeout_s=5)
    with pytest.raises(ServerError, match="full"):
        second.reset(teams["blue"], seed=0)
    first.close()
    second.close()


@pytest.mark.slow
def test_a_killed_client_neither_hangs_nor_crashes_the_others_and_can_rejoin(server, tmp_path):
    address, srv = server(
        "--mode", "fixed", "--teams", "2", "--secret", "s", "--timeout", "1", "--on-stall", "drop"
    )
    red = run_team.start(address, "s", "red", 1, 300, tmp_path / "red.npy")
    blue = run_team.start(address, "s", "blue", 1, 300, tmp_path / "blue.npy")
    procs = [red, blue]
    try:
        red_out, blue_out = Lines(red), Lines(blue)
        blue_out.wait_for("step 1")
        # blue's second life starts up while blue flies (seconds on a busy machine) and
        # tries to join until the server has dropped blue, so red, flying alone once blue
        # is dropped, cannot finish before blue is back
        again = run_team.start(address, "s", "blue", 1, 300, tmp_path / "blue2.npy", rejoin=True)
        procs.append(again)
        again_out = Lines(again)
        assert "already connected" in again_out.wait_for("refused")
        blue.kill()
        blue.wait()
        # deadlines on silence: a slow lockstep passes, a hung one fails
        assert red_out.wait_for("done ") == "done 3000 team red completed", red_out.tail()
        assert "team red completed" in again_out.wait_for("done "), again_out.tail()
        assert red.wait(60) == 0 and again.wait(60) == 0
        assert "dropped team blue" in srv.log.read_text()  # after its 1 s timeout
        assert srv.poll() is None  # the server is still serving
    finally:
        for proc in procs:
            if proc.poll() is None:
                proc.kill()
                proc.wait()


def test_a_team_that_leaves_holds_up_no_one(server):
    """``close`` sends ``leave`` and lets it go out: the other team flies on at once, not
    after the server's stall timeout (60 s here, beyond the client's 5 s), and stops seeing
    the team that left."""
    import threading

    from gymfg_il import Team
    from gymfg_il.aircraft import c172p
    from gymfg_il.tasks import DummyTask

    address, _ = server("--mode", "open", "--timeout", "60")
    blue = OnlineEnv(address, timeout_s=5)
    blue.reset(Team("blue", [(c172p("blue-1"), DummyTask)], episode_time_s=1e4), seed=1)

    def fly_blue():  # alone until red joins, then 5 steps in lockstep with red, then leave
        while "red-1" not in blue.step(np.zeros(4))[5]["opponent_callsigns"]:
            pass
        for _ in range(5):
            blue.step(np.zeros(4))
        blue.close()

    thread = threading.Thread(target=fly_blue)
    thread.start()
    red = OnlineEnv(address, timeout_s=5)
    red.reset(Team("red", [(c172p("red-1"), DummyTask)]), seed=0)
    seen = [red.step(np.zeros(4))[5]["opponent_callsigns"] for _ in range(12)]
    thread.join(10)
    red.close()
    assert seen[0] == ["blue-1"] and seen[-1] == []
