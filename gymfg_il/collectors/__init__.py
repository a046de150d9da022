"""Collection sessions: demonstrations flown by the autopilot (``autopilot``), the configs of
every collection (``config``; a person's or the synthetic pilot's session is
``gymfg_il.cockpit``), and the bodies of ``collect recover`` and ``collect replay``
(``commands``)."""
