"""The cockpit session's windows, each a sink that draws a frame's view (``view``): pygame's
(``pygame_window``, drawn by the controls GUI ``gui`` and its primary flight display
``pfd``), or none."""
