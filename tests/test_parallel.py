from gymfg_il.collectors.autopilot import record_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.evaluation.parallel import fly_many
from gymfg_il.parallel import AgentSpec, EnvSpec
from gymfg_il.recording.reader import read_log


def test_two_workers_give_what_one_gives(tmp_path):
    spec = EnvSpec("roll", "f15", dynamic=True, episode_time_s=10)
    one = fly_many(spec, AgentSpec.controller(), [4, 5, 6], workers=1)
    two = fly_many(spec, AgentSpec.controller(), [4, 5, 6], workers=2)
    assert [e.seed for e in two] == [4, 5, 6]
    for a, b in zip(one, two, strict=True):
        assert (a.rewards == b.rewards).all() and (a.actions == b.actions).all()
    logs = []
    for workers in (1, 2):
        cfg = CollectConfig(
            task="pitch", episodes=3, episode_time_s=5, noise=0.1, out=tmp_path / f"w{workers}"
        )
        logs.append(read_log(record_autopilot(cfg, workers=workers).log))
    for a, b in zip(logs[0].complete_episodes, logs[1].complete_episodes, strict=True):
        sa, sb = a.steps["ego"], b.steps["ego"]
        assert (sa.state == sb.state).all() and (sa.action == sb.action).all()
