import pytest

from gymfg_il.aircraft import Aircraft, a320, available_models, c172p, f15
from gymfg_il.errors import ConfigError, UnknownAircraftError


def test_paper_factories_name_jsbsim_models():
    assert (f15("x").model, c172p("x").model, a320("x").model) == ("f15", "c172p", "A320")


def test_aircraft_compare_by_model_and_callsign():
    assert f15("red-one") == f15("red-one")
    assert hash(f15("red-one")) == hash(Aircraft("F15", "red-one"))
    assert f15("red-one") != f15("red-two")
    assert {f15("red-one"): 1}[f15("red-one")] == 1


def test_any_shipped_model_is_accepted():
    models = available_models()
    assert len(models) > 30 and "737" in models
    assert Aircraft("737", "x").model == "737"


def test_unknown_model_names_the_closest():
    with pytest.raises(UnknownAircraftError, match="c172p") as err:
        Aircraft("c172q", "x")
    assert "available_models" in str(err.value)


@pytest.mark.parametrize("callsign", ["", "   ", None])
def test_callsign_must_be_named(callsign):
    with pytest.raises(ConfigError, match="callsign"):
        Aircraft("c172p", callsign)
