"""The cockpit session (``collect manual``): a person or the synthetic pilot flies in a window,
in real time, and every completed episode becomes data at once.

``session`` runs the loop of stages that ``build`` makes from the config: ``pace``, the
``inputs`` (a source of commands and controls), ``phases`` (what the commands do to the
episodes), the rollout step, ``flight_log`` (the MCAP log and the episode's verdict),
``updater`` (the dataset, in a helper process), the display model and the ``windows`` (a sink
that draws each frame). ``timing`` counts the late frames of a real-time session and
``screenshot`` makes the window's pictures.
"""
