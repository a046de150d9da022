"""The cockpit session's keys: the session commands (Space, E, Backspace, P, T, Q, H) and the
help overlay that lists them with the device's flying controls."""

from __future__ import annotations

from gymfg_il.manual.bindings import KeyboardBindings

COMMAND_KEYS = {
    "space": "start",
    "e": "end",
    "backspace": "discard",
    "p": "pause",
    "t": "takeover",
    "q": "quit",
    "escape": "quit",
    "h": "help",
    "f1": "help",
    "g": "mark success",
    "b": "mark failure",
}


def help_lines(device: str, kb: KeyboardBindings) -> list[str]:
    """The help overlay's lines for a pilot flying with ``device``."""

    def keys(names: list[str]) -> str:
        return " / ".join(names)

    lines = [
        "SESSION  Space: start episode   E: end + save   Backspace: discard + fly again",
        "         P: pause   T: take over / hand back   Q or Esc: quit   H: this help",
        "MARK     after an episode, your own verdict: G good (success)  |  B bad (failure)",
    ]
    if device == "mouse":
        lines.append("STICK    the mouse pointer (offset from the window centre)")
    elif device == "joystick":
        lines.append("STICK    joystick axes (see the recipe's [collector.joystick])")
    elif device == "flightgear":
        return [*lines, "CONTROLS FlightGear's cockpit (its --native-ctrls stream)"]
    else:
        lines += [
            f"AILERON  {keys(kb.aileron_left)}  |  {keys(kb.aileron_right)}",
            f"ELEVATOR {keys(kb.elevator_down)} (nose down)  |  {keys(kb.elevator_up)} (nose up)",
        ]
    lines += [
        f"RUDDER   {keys(kb.rudder_left)}  |  {keys(kb.rudder_right)}",
        f"THROTTLE {keys(kb.throttle_up)}  |  {keys(kb.throttle_down)}",
        f"CENTRE   {keys(kb.center)}  (surfaces return to the trim at {kb.centering:g}/s)",
    ]
    if device != "joystick":
        lines += [
            f"TRIM     elevator {keys(kb.trim_nose_down)} (nose down)  |  "
            f"{keys(kb.trim_nose_up)} (nose up)",
            f"         rudder {keys(kb.trim_rudder_left)}  |  {keys(kb.trim_rudder_right)}"
            f"  ({kb.trim_rate:g}/s; the ticks on the stick box and rudder bar)",
        ]
    return lines
