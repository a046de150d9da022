"""The cockpit session (``collect manual``): a person or the synthetic pilot flies in a window,
in real time, and every completed episode becomes data at once."""
