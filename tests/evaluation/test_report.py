"""The lines ``eval`` prints beside its table."""

from gymfg_il.evaluation.report import ratio_line, shares


def test_a_row_is_set_beside_the_controller_and_beside_any_other_row():
    controller = {"agent": "controller", "mean_return": 80.0, "success_rate": 1.0}
    pilot = {"agent": "pilot:synthetic-keyboard", "mean_return": 60.0, "success_rate": 0.5}
    policy = {"agent": "policy:p", "mean_return": 72.0, "success_rate": 0.0}
    policy |= shares(policy, controller)
    assert ratio_line(policy) == "policy:p / controller: return 90.0%, success 0.0%"
    assert ratio_line(policy, pilot) == (
        "policy:p / pilot:synthetic-keyboard: return 120.0%, success 0.0% "
        "(success rates 0% and 50%)"
    )
    assert ratio_line(pilot, policy) == (
        "pilot:synthetic-keyboard / policy:p: return 83.3%, success n/a (the policy:p's is 0) "
        "(success rates 50% and 0%)"
    )


def test_a_share_of_success_above_one_says_both_rates():
    """#53: eval printed "success 200.0%" for a policy that succeeded twice as often as the
    controller, which reads as a success rate of 200%."""
    controller = {"agent": "controller", "mean_return": 100.0, "success_rate": 0.5}
    policy = {"agent": "policy:p", "mean_return": 90.0, "success_rate": 1.0}
    assert ratio_line(policy, controller) == (
        "policy:p / controller: return 90.0%, success 200.0% (success rates 100% and 50%)"
    )
