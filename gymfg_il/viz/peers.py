"""Moved to ``gymfg_il.flightgear.peers`` (the package of everything that talks to FlightGear);
this path keeps working for now, with a DeprecationWarning."""

from gymfg_il.moved import forward

__getattr__ = forward(__name__, "gymfg_il.flightgear.peers")
