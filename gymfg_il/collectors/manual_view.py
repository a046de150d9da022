"""Moved to ``gymfg_il.cockpit.windows.pygame_window`` (the cockpit's pygame window); this
path keeps working for now, with a DeprecationWarning."""

from gymfg_il.moved import forward

GONE = {
    "window_frame": "a window is passed each frame's view (cockpit.windows.view."
    "CockpitView); PygameWindow.frame(view) makes the GUI's frame of it",
}
__getattr__ = forward(__name__, "gymfg_il.cockpit.windows.pygame_window", GONE)
