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


def test_profiles_say_how_much_longer_their_maneuvers_take():
    from gymfg_il.aircraft import PROFILES, REFERENCE_PROFILE, FlightProfile

    assert PROFILES["c172p"] is REFERENCE_PROFILE and REFERENCE_PROFILE.maneuver_scale == 1.0
    # 400 kt at 45 deg of bank turns 1.7 times slower than 110 kt at 25 deg
    assert PROFILES["f15"].maneuver_scale == pytest.approx(1.696, abs=1e-3)
    assert PROFILES["f15"].turn_rate_dps == pytest.approx(2.73, abs=0.01)
    assert FlightProfile(90.0, 5000.0, 0.7, 40.0, 14000.0).maneuver_scale == 1.0  # never < 1
    assert (PROFILES["f15"].final_approach_kts, PROFILES["A320"].final_approach_kts) == (210, 200)
    with pytest.raises(ConfigError, match="bank_deg=80"):
        FlightProfile(110.0, 5000.0, 0.7, 50.0, 14000.0, bank_deg=80.0)
    with pytest.raises(ConfigError, match="approach_kts=40"):
        FlightProfile(110.0, 5000.0, 0.7, 50.0, 14000.0, approach_kts=40.0)
