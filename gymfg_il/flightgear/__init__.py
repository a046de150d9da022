"""Everything that talks to FlightGear.

Modules: ``launcher`` (start ``fgfs`` as a view and read its property server), ``netfdm``
(the native-fdm packet a view follows), ``multiplayer`` (the position message other aircraft
travel in, and ``python -m gymfg_il.flightgear.multiplayer listen``), ``peers`` (FlightGear
aircraft heard over multiplayer: decoding, ``MultiplayerConfig``, ``MultiplayerLink``),
``display`` (a world's views and traffic, sent every step) and ``cockpit`` (the pilot's
controls, read from FlightGear's native-ctrls stream).
"""
