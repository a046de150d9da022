"""Side-by-side benchmarks, printed as ratios against their references in one run.

    python -m benchmarks.run [--quick] [--only physics,data,...] [--json PATH]

Modules by concern, each a ``rows(quick)`` that measures and returns its rows: ``physics``
(env step against raw JSBSim, 8 aircraft against 1), ``data`` (dataset build, training
pipeline), ``workers`` (rollouts on 2 processes against 1), ``manual`` (the real-time loop),
``online`` (the lockstep with 2, 8 and 16 teams). ``common`` holds the row type, paired
rounds and the one printer.
"""
