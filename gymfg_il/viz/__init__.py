"""Images: the headless camera (``camera``: what a pilot sees, ``render()``, image
observations) and the window that shows its frames (``window``). FlightGear is
``gymfg_il.flightgear``; plots of flown episodes are ``gymfg_il.evaluation``."""
