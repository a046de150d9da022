"""Flying by hand: pygame input devices and their bindings, the ManualController (a person as
an Agent), the controls GUI, and Takeover (a person sharing the controls with an assistant).
The real-time collection session that uses them is ``gymfg_il.collectors.manual``."""
