"""Trajectory recording: the MCAP log (the write-ahead log of every step), its session record,
reader and replay, and ``Recorder``, which logs any run driven by hand (``recorder``)."""
