"""Flying by hand: pygame input devices and their bindings, the ManualController (a person as
an Agent), the controls GUI, and Takeover (a person sharing the controls with an assistant).
The real-time collection session that uses them is ``gymfg_il.collectors.manual``."""

import warnings

# pygame 2.6 imports setuptools' deprecated pkg_resources (pygame/pkgdata.py), whose warning
# then opened every manual run; only that warning, from that module, is silenced
warnings.filterwarnings(
    "ignore", "pkg_resources is deprecated", UserWarning, module=r"pygame\.pkgdata"
)
