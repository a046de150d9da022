"""Evaluation: fly agents on the same seeded cases (``runner``), score them (``trace``,
``metrics``), and report tables, JSON rows and Figure-1 plots (``report``, ``plots``)."""
