"""The cockpit session's keys: the session commands (Space, E, Backspace, P, T, Q, H), the
help overlay that lists them with the device's flying controls, and the table of every key,
mouse motion and joystick axis a person uses (``key_rows``), built from the bindings for
``collect manual --help`` and the manual guide, so that neither can drift from them."""

from __future__ import annotations

import re
import textwrap
from typing import NamedTuple

from gymfg_il.manual.bindings import JoystickBindings, KeyboardBindings, MouseBindings

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

# what each session command does (a key's, or a joystick button's), as the key table says it
SAID = {
    "start": "start an episode",
    "end": "end the episode and save it",
    "discard": "discard the episode (the same case is flown again)",
    "pause": "pause the episode, and go on",
    "takeover": "take over from the --assist controller or policy, and hand back",
    "quit": "quit (an episode in flight is discarded)",
    "help": "show or hide the help overlay",
    "mark success": "after an episode: your own mark of it, good (success); the last counts",
    "mark failure": "after an episode: your own mark of it, bad (failure); the last counts",
    "center": "centre the three surfaces on the trim",
}
ANY = ("keyboard", "mouse", "joystick", "flightgear")  # the --device values
LABELS = {"enter": "keypad Enter", "escape": "Esc", "return": "Return"}


class KeyRow(NamedTuple):
    """One line of the key table: what a person presses or moves, what it does, and the
    ``--device`` values it does it with."""

    keys: tuple[str, ...]
    does: str
    devices: tuple[str, ...]
    pressed: bool = True  # keys or buttons; False: a pointer, axes, another program


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


def key_label(name: str) -> str:
    """A pygame key name as a person reads it on the keyboard: ``[4]`` is keypad 4, ``up``
    the Up arrow, ``page up`` Page Up."""
    keypad = re.fullmatch(r"\[(.+)\]", name)
    if keypad:
        return f"keypad {keypad.group(1)}"
    if name in LABELS:
        return LABELS[name]
    if name in ("left", "right", "up", "down"):
        return f"{name.title()} arrow"
    return name.upper() if len(name) == 1 else name.title()


def key_rows(
    kb: KeyboardBindings | None = None,
    mouse: MouseBindings | None = None,
    joy: JoystickBindings | None = None,
) -> list[KeyRow]:
    """Every key, mouse motion and joystick axis or button of a session, with the bindings
    given (the defaults where None), in the order the help and the guide list them: the
    session's keys, the flying keys, then the pointer, the joystick and FlightGear."""
    kb, mouse, joy = kb or KeyboardBindings(), mouse or MouseBindings(), joy or JoystickBindings()
    by_command: dict[str, list[str]] = {}
    for key, command in COMMAND_KEYS.items():
        by_command.setdefault(command, []).append(key_label(key))
    session = [KeyRow(tuple(keys), SAID[c], ANY) for c, keys in by_command.items()]
    return session + _flying_rows(kb, joy) + _device_rows(mouse, joy)


def _flying_rows(kb: KeyboardBindings, joy: JoystickBindings) -> list[KeyRow]:
    """The keyboard's flying keys, with the devices each flies with (``ManualController``:
    with the mouse the pointer is the stick, with a joystick its axes are the controls)."""

    def row(names: list[str], does: str, *devices: str) -> KeyRow:
        return KeyRow(tuple(key_label(n) for n in names), does, devices)

    plugged = ""
    if "throttle" in joy.axes:
        plugged = " (not while a joystick with a throttle axis is plugged in)"
    flying = ("keyboard", "mouse", "joystick")
    return [
        row(kb.aileron_left, "aileron left (roll left)", "keyboard"),
        row(kb.aileron_right, "aileron right (roll right)", "keyboard"),
        row(kb.elevator_down, "elevator down (nose down)", "keyboard"),
        row(kb.elevator_up, "elevator up (nose up)", "keyboard"),
        row(kb.rudder_left, "rudder left (yaw left)", "keyboard", "mouse"),
        row(kb.rudder_right, "rudder right (yaw right)", "keyboard", "mouse"),
        row(kb.throttle_up, f"throttle up{plugged}", *flying),
        row(kb.throttle_down, f"throttle down{plugged}", *flying),
        row(kb.trim_nose_down, "elevator trim, nose down", *flying),
        row(kb.trim_nose_up, "elevator trim, nose up", *flying),
        row(kb.trim_rudder_left, "rudder trim, left", *flying),
        row(kb.trim_rudder_right, "rudder trim, right", *flying),
        row(kb.center, SAID["center"], *flying),
    ]


def _device_rows(mouse: MouseBindings, joy: JoystickBindings) -> list[KeyRow]:
    """The mouse pointer, the joystick's axes and buttons, and FlightGear's cockpit."""
    up = "nose up" if mouse.invert_elevator else "nose down"
    axes = ", ".join(f"{c} {a}" for c, a in sorted(joy.axes.items(), key=lambda i: i[1]))
    reversed_ = f"; reversed: {', '.join(joy.invert)}" if joy.invert else ""
    return [
        KeyRow(
            ("mouse pointer",),
            "the stick: its offset from the window centre deflects aileron and elevator "
            f"(full travel at {mouse.span_px:g} px; pointer up = {up})",
            ("mouse",),
            pressed=False,
        ),
        KeyRow(
            ("joystick axes",),
            f"the controls, by axis number: {axes}{reversed_} (dead zone {joy.dead_zone:g}, "
            f"expo {joy.expo:g})",
            ("joystick",),
            pressed=False,
        ),
        *(
            KeyRow((f"joystick button {b}",), SAID.get(c, c), ("joystick",))
            for b, c in sorted(joy.buttons.items())
        ),
        KeyRow(
            ("FlightGear's cockpit",),
            "the controls, with FlightGear's own joystick and keyboard bindings; this "
            "window's keys run the session",
            ("flightgear",),
            pressed=False,
        ),
    ]


def keys_help(kb: KeyboardBindings | None = None, width: int = 79) -> str:
    """The key table as plain text, for ``--help``: a line per row (wrapped at ``width``),
    the devices a row is for after it; the rows indented, as a block of their own."""
    lines = textwrap.wrap(
        "Keys, mouse and joystick (the defaults; a recipe's [collector.keyboard], "
        "[collector.mouse] and [collector.joystick] tables rebind them):",
        width,
    )
    lines.append("")
    for r in key_rows(kb):
        devices = "" if r.devices == ANY else f" [{', '.join(r.devices)}]"
        lines += textwrap.wrap(
            f"{' / '.join(r.keys):<23} {r.does}{devices}",
            width,
            initial_indent="    ",
            subsequent_indent=" " * 28,
            break_on_hyphens=False,
        )
    return "\n".join(lines)


def keys_markdown(kb: KeyboardBindings | None = None) -> str:
    """The key table as the manual guide's Markdown table (the guide holds it as printed
    here, and a test holds the guide to it)."""
    lines = ["| key | what it does | with `--device` |", "| --- | --- | --- |"]
    for r in key_rows(kb):
        devices = "any" if r.devices == ANY else ", ".join(r.devices)
        keys = " / ".join(f"`{k}`" if r.pressed else k for k in r.keys)
        lines.append(f"| {keys} | {r.does} | {devices} |")
    return "\n".join(lines) + "\n"
