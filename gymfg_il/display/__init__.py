"""What a person at the window is given: the display model (``readings``), each task's
targets and guidance (``guidance``), and the briefing and debrief (``briefing``)."""
