"""What a person at the window is given: the display model (``readings``: the instruments,
and each task's targets and guidance as the task declares them, ``tasks.guidance``), and the
briefing and debrief (``briefing``)."""
