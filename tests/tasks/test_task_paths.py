"""Tasks named by import path (red team #52.8): a path is ``package.module:ClassName`` with
no empty part, a record may name neither ``__main__`` nor a base no aircraft can fly, and the
empty module name is never trusted."""

import abc
import sys

import pytest

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import ConfigError, UntrustedTaskError
from gymfg_il.tasks import DummyTask
from gymfg_il.tasks.library import task_class
from gymfg_il.tasks.paths import record_task_problem


class HalfTask(DummyTask, abc.ABC):
    """A user's base: abstract, its reward left to subclasses."""

    @abc.abstractmethod
    def task_reward(self, ctx): ...


class WholeTask(HalfTask):
    def task_reward(self, ctx):
        return 1.0


NOT_PATHS = [
    ":AltitudeTask",
    ":",
    "gymfg_il.tasks.library:",
    "gymfg_il..library:DummyTask",
    ".gymfg_il:DummyTask",
    "gymfg_il.tasks.library:Dummy Task",
    "gymfg_il.tasks.library:DummyTask:x",
    "gymfg_il.tasks.library:f.<locals>.DummyTask",
    "1st.module:DummyTask",
    "gymfg_il.tasks.library:class",
]


@pytest.mark.parametrize("trusted", [None, "", " , ", "gymfg_il.tasks.library"])
@pytest.mark.parametrize("path", NOT_PATHS)
def test_a_path_with_an_empty_or_invalid_part_is_never_trusted(path, trusted, monkeypatch):
    if trusted is None:
        monkeypatch.delenv("GYMFG_TASK_MODULES", raising=False)
    else:
        monkeypatch.setenv("GYMFG_TASK_MODULES", trusted)
    problem = record_task_problem(path)
    assert problem is not None and repr(path) in problem and "package.module:ClassName" in problem
    with pytest.raises(ConfigError, match=r"package\.module:ClassName"):
        task_class(path)  # a ConfigError, not importlib's ValueError "Empty module name"


@pytest.mark.parametrize("module", ["__main__", "__mp_main__"])
def test_a_record_never_trusts_the_script_that_runs_now(module, monkeypatch):
    monkeypatch.setenv("GYMFG_TASK_MODULES", module)
    monkeypatch.setattr(sys.modules["__main__"], "AltitudeTask", WholeTask, raising=False)
    problem = record_task_problem(f"{module}:AltitudeTask")
    assert problem is not None and f"'{module}'" in problem and "module of its own" in problem


BASES = ["gymfg_il.tasks.base:Task", "gymfg_il.tasks.targets:TargetTask", f"{__name__}:HalfTask"]


@pytest.mark.parametrize("path", BASES)
def test_a_base_no_aircraft_can_fly_is_refused(path):
    assert __name__ in sys.modules  # imported: the record check looks the class up in it
    problem = record_task_problem(path)
    assert problem is not None and repr(path) in problem and "no aircraft can fly" in problem
    with pytest.raises(ConfigError, match="no aircraft can fly"):
        task_class(path)
    record = FlightSpec.solo("c172p", "altitude").to_dict()
    record["teams"][0]["roster"][0]["task"] = path
    with pytest.raises(UntrustedTaskError, match="no aircraft can fly"):
        FlightSpec.from_dict(record)


@pytest.mark.parametrize(
    "path, needle",
    [
        ("gymfg_il.tasks.rewards:RewardFn", "not a Task class"),
        ("gymfg_il.tasks.library:TASK_FAMILIES", "not a Task class"),
        ("gymfg_il.tasks.library:NoSuchTask", "has no 'NoSuchTask'"),
    ],
)
def test_a_record_naming_what_is_not_a_task_is_refused_before_building(path, needle):
    problem = record_task_problem(path)
    assert problem is not None and needle in problem


def test_a_concrete_task_of_an_imported_module_is_trusted():
    for path, cls in [
        ("gymfg_il.tasks.library:DummyTask", DummyTask),
        (f"{__name__}:WholeTask", WholeTask),
    ]:
        assert record_task_problem(path) is None
        assert task_class(path) is cls
    assert record_task_problem("altitude") is None  # a family: checked where it is built
