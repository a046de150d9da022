"""Visualization: plots of flown episodes (and, later, the FlightGear bridge)."""
