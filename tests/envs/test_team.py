import pytest

from gymfg_il import Team
from gymfg_il.agent import ConstantAgent
from gymfg_il.aircraft import c172p, f15
from gymfg_il.envs import OfflineEnv
from gymfg_il.errors import ConfigError, DuplicateNameError
from gymfg_il.tasks import DummyTask


def test_paper_listings_build():
    Team(
        name="red",
        roster=[(f15("red-one"), DummyTask)],
        reward_function_targets={f15("red-one"): []},
    )
    team = Team(
        name="red",
        roster=[(f15("red-one"), DummyTask), (f15("red-two"), DummyTask)],
        reward_function_targets={f15("red-one"): [f15("red-two")], f15("red-two"): []},
    )
    assert team.callsigns == ["red-one", "red-two"] and team.episode_time_s == 90
    names = ["red", "blue"]
    planes = [f15(f"{n}-one") for n in names]
    teams = [
        Team(
            name=n,
            roster=[(p, DummyTask)],
            reward_function_targets={p: [q for q in planes if q != p]},
        )
        for n, p in zip(names, planes, strict=True)
    ]
    assert teams[0].targets_of(planes[0]) == [planes[1]]


def test_duplicate_callsign_in_team():
    with pytest.raises(DuplicateNameError, match="red-one"):
        Team("red", [(f15("red-one"), DummyTask), (c172p("red-one"), DummyTask)])


def test_duplicate_team_names_and_callsigns_across_teams():
    red = Team("red", [(f15("one"), DummyTask)])
    other_red = Team("red", [(f15("two"), DummyTask)])
    with pytest.raises(DuplicateNameError, match="two teams"):
        OfflineEnv([(other_red, [ConstantAgent()])]).reset(red)
    blue = Team("blue", [(c172p("one"), DummyTask)])
    with pytest.raises(DuplicateNameError, match="callsign 'one'"):
        OfflineEnv([(blue, [ConstantAgent()])]).reset(red)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"name": "", "roster": [(f15("a"), DummyTask)]}, "name"),
        ({"name": "r", "roster": []}, "roster"),
        ({"name": "r", "roster": [("f15", DummyTask)]}, "not an Aircraft"),
        ({"name": "r", "roster": [(f15("a"), 5)]}, "not a Task"),
        ({"name": "r", "roster": [(f15("a"), DummyTask)], "episode_time_s": 0}, "episode_time_s"),
        (
            {
                "name": "r",
                "roster": [(f15("a"), DummyTask)],
                "reward_function_targets": {f15("zz"): []},
            },
            "not in the roster",
        ),
        (
            {
                "name": "r",
                "roster": [(f15("a"), DummyTask)],
                "reward_function_targets": {f15("a"): [f15("a")]},
            },
            "itself",
        ),
    ],
)
def test_bad_teams_say_what_is_wrong(kwargs, match):
    with pytest.raises(ConfigError, match=match):
        Team(**kwargs)
