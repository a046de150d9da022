"""Trajectory recording: the MCAP log (write-ahead log of every step), reader, replay."""
