"""The cockpit session's inputs, each a source of session commands and controls
(``source``): a person's pygame devices (``devices``) and the synthetic pilot
(``synthetic_pilot``); the session's keys (``keys``)."""
