"""The primary flight display's instruments: which flight variable each one shows
(``display.readings`` draws a reading on its instrument; ``display.guidance`` puts each
task's targets on the instrument of their variable)."""

from __future__ import annotations

# each flight variable and the instrument that shows it
PRIMARY: dict[str, str] = {
    "airspeed_kts": "airspeed",
    "altitude_ft": "altitude",
    "vertical_speed_fps": "vertical_speed",
    "roll_deg": "bank",
    "pitch_deg": "pitch",
    "heading_deg": "heading",
    "beta_deg": "slip",
}
