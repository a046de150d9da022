"""Starting FlightGear as a view of a JSBSim aircraft, and reading what it shows.

``FlightGear(port=..., telnet_port=...)`` starts ``fgfs`` with the external FDM switched off
and the native-fdm socket listening (``--fdm=null --native-fdm=socket,in,RATE,,PORT,udp``),
no sound, no scenery download and a telnet property server, so a program can read FlightGear's
own ``/position`` and ``/orientation``. With ``multiplayer_port`` the view also listens for
multiplayer traffic, so the simulation's other aircraft appear in it (``multiplayer``).
Debian/Ubuntu: ``apt-get install flightgear`` (it lands
in /usr/games); under Xvfb it needs ``dbus-run-session`` in front, which the launcher adds when
it is there.

What of ``flightgear-python`` (a dependency, for the cockpit's FGNetCtrls struct) is not used
here, and why: the native-fdm stream is JSBSim's own (its ``FLIGHTGEAR`` output directive
writes net_fdm, so no codec of ours or theirs is involved); its ``TelnetConnection`` connects
once, at construction, and parses prompts, while this launcher's property client asks in
FlightGear's ``data`` mode (one line a reply) and connects again after a failure, since
fgfs accepts connections seconds before it answers them; and it has no multiplayer protocol
(``flightgear.multiplayer`` is ours).
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time
from pathlib import Path

from gymfg_il.errors import GymFGError

SEARCH = (os.environ.get("PATH", ""), "/usr/games", "/usr/local/games")

# Without an FDM of its own FlightGear leaves every tank's density and capacity at 0, and its
# tank properties then turn any fuel level the native-fdm stream sends into 0 (the c172p then
# shows "Out of fuel!"). 6 lb per US gallon, as JSBSim counts, and room for any tank.
FUEL_TANKS = tuple(
    f"--prop:/consumables/fuel/tank[{i}]/{name}"
    for i in range(4)
    for name in ("density-kgpm3=718.9", "capacity-m3=100")
)


# Rendering light enough for fgfs under Xvfb to leave a core to the simulation (what it
# costs against full rendering: docs/results/flightgear.md); use with geometry="320x240"
LIGHTWEIGHT = (
    "--disable-clouds",
    "--disable-clouds3d",
    "--disable-random-objects",
    "--disable-random-vegetation",
    "--disable-random-buildings",
    "--prop:/sim/frame-rate-throttle-hz=30",
)


class FlightGearError(GymFGError, RuntimeError):
    """FlightGear is missing, failed to start, or stopped answering."""


def find_fgfs() -> str | None:
    return shutil.which("fgfs", path=os.pathsep.join(SEARCH))


def _check_multiplayer(multiplayer_port: int | None, multiplayer_out: int | None) -> None:
    """Raise unless the multiplayer ports are ones FlightGear can use, the out port only
    with an in port."""
    from gymfg_il.flightgear.multiplayer import port_problem

    problems = [port_problem(p) for p in (multiplayer_port, multiplayer_out) if p is not None]
    if any(problems):
        raise FlightGearError("; ".join(p for p in problems if p))
    if multiplayer_out is not None and multiplayer_port is None:
        raise FlightGearError(
            "multiplayer_out needs a multiplayer_port too: without --multiplay=in fgfs "
            "binds its out port itself"
        )


def _following(port: int | None, rate_hz: int) -> tuple[str, ...]:
    """The options that make fgfs draw the native-fdm stream on ``port`` instead of flying
    with its own FDM (none without a port)."""
    if port is None:
        return ()
    return ("--fdm=null", f"--native-fdm=socket,in,{rate_hz},,{port},udp")


def _traffic(
    rate_hz: int, multiplayer_port: int | None, multiplayer_out: int | None, callsign: str
) -> tuple[str, ...]:
    """The options that show other aircraft, from ``multiplayer_port`` (none without it)."""
    if not multiplayer_port:
        return ()
    # FlightGear only listens when it also has somewhere to send its own position: the
    # discard port, so no view ever sees another view's aircraft twice
    return (
        f"--multiplay=in,{rate_hz},127.0.0.1,{multiplayer_port}",
        f"--multiplay=out,{rate_hz},127.0.0.1,{multiplayer_out or 9}",
        f"--callsign={callsign}",
    )


class FlightGear:
    """A running ``fgfs`` bound to one native-fdm UDP port.

    Args:
        port: UDP port the view listens on (the env's ``views`` send there); None:
            FlightGear flies the aircraft itself, with its own FDM (a person's aircraft,
            seen by the env through ``multiplayer_out``).
        telnet_port: FlightGear's property server (``get /position/altitude-ft``).
        aircraft: FlightGear aircraft to draw (``c172p`` ships with the Debian package).
        rate_hz: packets per second FlightGear expects.
        geometry: window size.
        display: X display (e.g. an Xvfb's ``:99``); the current one by default.
        airport: where FlightGear starts (and loads scenery) before the first packet moves
            it; GymFG's default start is near KSFO, whose scenery ships with FlightGear.
        multiplayer_port: UDP port for other aircraft (``EnvConfig.traffic``); at most
            32767, which is all FlightGear 2020.3 can store.
        multiplayer_out: where FlightGear sends its own aircraft (a ``MultiplayerConfig``'s
            ``listen_port`` on this machine); the discard port by default.
        callsign: FlightGear's callsign in multiplayer (7 characters are kept).
        extra: more fgfs options.
    """

    def __init__(
        self,
        port: int | None,
        telnet_port: int,
        aircraft: str = "c172p",
        rate_hz: int = 30,
        geometry: str = "800x600",
        display: str | None = None,
        airport: str = "KSFO",
        multiplayer_port: int | None = None,
        extra: tuple[str, ...] = (),
        multiplayer_out: int | None = None,
        callsign: str = "gymfg-view",
    ) -> None:
        _check_multiplayer(multiplayer_port, multiplayer_out)
        exe = find_fgfs()
        if exe is None:
            raise FlightGearError(
                "fgfs (FlightGear) is not installed or not on the PATH; on Debian or Ubuntu: "
                "sudo apt-get install flightgear (it installs into /usr/games)"
            )
        self.port, self.telnet_port = port, telnet_port
        self.multiplayer_port = multiplayer_port
        self.home = tempfile.mkdtemp(prefix="gymfg-fghome-")
        cmd = [
            exe,
            *_following(port, rate_hz),
            f"--aircraft={aircraft}",
            f"--telnet=socket,bi,30,localhost,{telnet_port},tcp",  # served each frame
            "--disable-sound",
            "--disable-terrasync",
            "--launcher=0",
            "--timeofday=noon",
            f"--geometry={geometry}",
            "--disable-splash-screen",
            "--disable-ai-traffic",
            f"--airport={airport}",
            "--prop:/sim/rendering/multi-sample-buffers=0",
            *(FUEL_TANKS if port is not None else ()),
            *_traffic(rate_hz, multiplayer_port, multiplayer_out, callsign),
            *extra,
        ]
        self._start(cmd, display)
        self._sock: socket.socket | None = None

    def _start(self, cmd: list[str], display: str | None) -> None:
        """Run ``cmd`` (under ``dbus-run-session`` where there is one) in its own session,
        its FG_HOME this view's, its output into ``log_path``."""
        if shutil.which("dbus-run-session"):
            cmd = ["dbus-run-session", "--", *cmd]
        env = {**os.environ, "FG_HOME": self.home}
        if display:
            env["DISPLAY"] = display
        self.log_path = Path(self.home) / "fgfs.log"
        self._log = open(self.log_path, "wb")  # noqa: SIM115 (closed in stop())
        self.proc = subprocess.Popen(
            cmd, env=env, stdout=self._log, stderr=subprocess.STDOUT, start_new_session=True
        )

    def wait_ready(self, timeout_s: float = 300.0) -> None:
        """Wait until FlightGear has loaded its scenery (the first start also builds a navaid
        cache; software rendering under Xvfb draws about a frame a second)."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise FlightGearError(
                    f"fgfs exited with {self.proc.returncode}; see {self.log_path}"
                )
            try:
                if self.get("/sim/sceneryloaded") in ("true", "1"):
                    return
            except OSError:
                pass
            time.sleep(1.0)
        raise FlightGearError(f"fgfs did not come up within {timeout_s:g} s; see {self.log_path}")

    def _connect(self) -> socket.socket:
        if self._sock is None:
            # software-rendered FlightGear answers once a frame: be patient
            sock = socket.create_connection(("127.0.0.1", self.telnet_port), timeout=30)
            sock.sendall(b"data\r\n")  # raw replies, no prompts
            self._sock = sock
        return self._sock

    def get(self, prop: str) -> str:
        """A property's value as FlightGear shows it."""
        sock = self._connect()
        try:
            sock.sendall(f"get {prop}\r\n".encode())
            data = b""
            while not data.endswith(b"\n"):
                chunk = sock.recv(4096)
                if not chunk:
                    raise OSError("FlightGear closed the property connection")
                data += chunk
        except OSError:
            self._sock = None
            raise
        return data.decode(errors="replace").strip()

    def get_float(self, prop: str) -> float:
        return float(self.get(prop))

    def set(self, prop: str, value: object) -> None:
        """Set a property, as a person's stick or switch would (no reply comes back)."""
        sock = self._connect()
        try:
            sock.sendall(f"set {prop} {value}\r\n".encode())
        except OSError:
            self._sock = None
            raise

    def stop(self) -> None:
        if self._sock is not None:
            self._sock.close()
            self._sock = None
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(15)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait(5)
        self._log.close()
        if self.proc.returncode in (0, -signal.SIGTERM, -signal.SIGKILL):
            shutil.rmtree(self.home, ignore_errors=True)  # a crash keeps its log
