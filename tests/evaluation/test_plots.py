"""What the plots draw: an angle that goes all the way round is drawn continuously."""

import numpy as np

from gymfg_il.evaluation.plots import drawn, figure1, unit_of
from gymfg_il.evaluation.trace import Trace


def heading_trace(value, target):
    """A heading episode as the task observes it: the value in [0, 360), the error wrapped
    to [-180, 180), and the trace's target value + error."""
    value = np.asarray(value, dtype=float) % 360.0
    error = (np.asarray(target, dtype=float) - value + 180.0) % 360.0 - 180.0
    n = len(value)
    return Trace(
        seed=0,
        variable="heading_deg",
        tolerance=3.0,
        dynamic=False,
        dt=0.1,
        target=value + error,
        value=value,
        error=error,
        actions=np.zeros((n, 4)),
        rewards=np.ones(n),
        terminated=False,
        reason=None,
    )


def test_a_heading_through_north_is_drawn_without_a_step():
    # turning right through north towards a target of 258 deg (= -102): the trace's own
    # target reads -100-ish while the heading is near 0 and 258 once past 180
    trace = heading_trace(np.linspace(300.0, 420.0, 121), np.full(121, 258.0))
    assert np.ptp(trace.target) == 360.0  # the step the plot used to show
    target, value = drawn(trace)
    assert np.abs(np.diff(value)).max() < 2.0 and np.abs(np.diff(target)).max() < 1e-9
    assert np.allclose((target - value + 180.0) % 360.0 - 180.0, trace.error)
    assert np.allclose(target % 360.0, 258.0)


def test_variables_that_do_not_wrap_are_drawn_as_flown():
    trace = heading_trace(np.linspace(10.0, 20.0, 11), np.full(11, 15.0))
    trace.variable = "altitude_ft"
    target, value = drawn(trace)
    assert target is trace.target and value is trace.value
    assert unit_of("altitude_ft") == "ft" and unit_of("beta_deg") == "deg"
    assert unit_of("my_own_variable") == ""


def test_figure1_writes_a_png(tmp_path):
    trace = heading_trace(np.linspace(350.0, 370.0, 50), np.full(50, 5.0))
    path = figure1([trace, trace], 0, "heading", tmp_path / "f.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
