"""Flying by hand: pygame input devices and their bindings (``bindings``, ``devices``), the
ManualController (a person as an Agent: ``controller``), Takeover (a person sharing the
controls with an assistant: ``takeover``) and the synthetic pilot, a model of a person who
sees only the window (``perception``, ``synthetic``). The cockpit session that flies them in
real time, and its window, are ``gymfg_il.cockpit``."""
