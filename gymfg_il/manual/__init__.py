"""Manual flying: pygame input devices, the ManualController, the controls GUI, and the
real-time collection session."""
