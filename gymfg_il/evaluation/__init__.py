"""Evaluation: what a run is (``config``: EvalConfig), what it flies (``plan``: the flight
and the agents), flying every agent on the same seeded cases (``runner``), scoring them
(``trace``, ``metrics``), and the table, JSON rows and plots it reports (``report``,
``plots``, ``tracks``)."""
