"""The web cockpit (``collect web``): pilots fly from their browsers, physics stays on the
server, every saved episode goes to one dataset. ``server`` serves it, ``protocol`` checks
what a page sends, ``link`` is a browser pilot's input and window in the cockpit session,
``invites`` says who may fly, ``headless`` is the synthetic pilot flying through the same
protocol."""
