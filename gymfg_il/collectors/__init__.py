"""Collection sessions: demonstrations flown by the autopilot, by a person (``manual``), and
the bodies of ``collect recover`` and ``collect replay`` (``commands``)."""
