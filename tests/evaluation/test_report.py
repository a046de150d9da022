"""The lines ``eval`` prints beside its table."""

from gymfg_il.evaluation.report import ratio_line, shares


def test_a_row_is_set_beside_the_controller_and_beside_any_other_row():
    controller = {"agent": "controller", "mean_return": 80.0, "success_rate": 1.0}
    pilot = {"agent": "pilot:synthetic-keyboard", "mean_return": 60.0, "success_rate": 0.5}
    policy = {"agent": "policy:p", "mean_return": 72.0, "success_rate": 0.0}
    policy |= shares(policy, controller)
    assert ratio_line(policy) == "policy:p / controller: return 90.0%, success 0.0%"
    assert ratio_line(policy, pilot) == (
        "policy:p / pilot:synthetic-keyboard: return 120.0%, success 0.0%"
    )
    assert ratio_line(pilot, policy) == (
        "pilot:synthetic-keyboard / policy:p: return 83.3%, success n/a (the policy:p's is 0)"
    )
