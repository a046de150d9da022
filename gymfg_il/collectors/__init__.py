"""Collection sessions: demonstrations flown by the autopilot (and, later, humans)."""
