// The GymFG-IL web cockpit: draws the display model the server sends each frame (the same
// readings the pygame window draws: gymfg_il.display.readings) and sends back what the pilot
// does, one input message per frame drawn (gymfg_il.web.protocol). Physics is on the server.
"use strict";

const SKY = "rgb(40,110,190)", GROUND = "rgb(125,85,45)", TAPE = "rgb(35,40,50)";
const EDGE = "rgb(120,130,150)", WHITE = "#fff", MAGENTA = "rgb(230,60,220)";
const YELLOW = "rgb(250,210,40)", DIM = "rgb(150,158,170)", FG = "rgb(223,227,234)";
const RED = "rgb(235,70,70)", GREEN = "rgb(80,200,120)";
const PX_PER_DEG = 6, PX_PER_DOT = 30, SLIP_PX_PER_DEG = 12;
// the primary flight display's instruments (gymfg_il.tasks.guidance.PRIMARY)
const PFD = new Set(["airspeed", "altitude", "vertical_speed", "bank", "pitch", "heading", "slip"]);

// browser key codes -> pygame key names (what the server's bindings use)
const KEYS = {
  Space: "space", KeyE: "e", Backspace: "backspace", KeyP: "p", KeyT: "t", KeyQ: "q",
  Escape: "escape", KeyH: "h", F1: "f1", KeyG: "g", KeyB: "b",
  ArrowLeft: "left", ArrowRight: "right", ArrowUp: "up", ArrowDown: "down",
  PageUp: "page up", PageDown: "page down", Home: "home", End: "end", Insert: "insert",
  Delete: "delete", NumpadEnter: "enter", Enter: "return", Comma: ",", Period: ".",
  Digit5: "5",
};
for (let d = 0; d <= 9; d++) KEYS["Numpad" + d] = "[" + d + "]";

const canvas = document.getElementById("cockpit");
const ctx = canvas.getContext("2d");
const stateText = document.getElementById("state");
const deviceSelect = document.getElementById("device");
const calibrateText = document.getElementById("calibrate");
const invite = new URLSearchParams(location.hash.slice(1)).get("invite") || "";

let ws = null, welcome = null, frame = null, seq = 0, pending = [], closedWhy = "";
let wanted = false, retry = null;
let pad = { index: -1, axes: [], buttons: [], centre: [] };

function connect() {
  if (!invite) { stateText.textContent = "no invite in this link"; return; }
  wanted = true;
  const scheme = location.protocol === "https:" ? "wss:" : "ws:";
  const socket = new WebSocket(scheme + "//" + location.host + "/ws");
  ws = socket;
  pending = []; held.clear();  // nothing pressed before this socket reaches its session
  stateText.textContent = "connecting";
  stateText.className = "";
  socket.onopen = () => {
    socket.send(JSON.stringify({ type: "hello", invite: invite, device: deviceSelect.value }));
  };
  socket.onmessage = (event) => {
    if (socket !== ws) return;
    const message = JSON.parse(event.data);
    if (message.type === "welcome") {
      welcome = message;
      closedWhy = "";
      stateText.textContent = "flying as " + message.pilot + " (" + message.device + ")";
      calibrateText.hidden = message.device !== "joystick";
      // the new session hears of the pad again; its centre, measured once, is kept
      pad = { index: -1, axes: [], buttons: [], centre: pad.centre };
      canvas.focus();
    } else if (message.type === "frame") {
      frame = message;
      window.__frame = message;  // what tests compare the drawing with
      pollPad();
      answer();
      redraw();
    }
  };
  socket.onclose = (event) => {
    if (socket !== ws) return;  // a socket this page replaced
    closedWhy = event.reason || ("connection closed (" + event.code + ")");
    stateText.textContent = closedWhy;
    stateText.className = "bad";
    ws = null;
    pending = []; held.clear();
    const again = event.code === 1006 || event.code === 1001 || event.code === 1011;
    if (wanted && again) retry = setTimeout(connect, 1000);  // a dropped line: resume
    redraw();
  };
}

let drawing = false;  // one draw waits for the screen at a time (a hidden tab piles none up)
function redraw() {
  if (drawing) return;
  drawing = true;
  requestAnimationFrame(() => { drawing = false; draw(); });
}

function flying() { return ws !== null && ws.readyState === WebSocket.OPEN && welcome !== null; }

function answer() {
  if (!ws || ws.readyState !== WebSocket.OPEN || !frame) return;
  seq += 1;
  ws.send(JSON.stringify({
    type: "input", seq: seq, at: performance.now(), frame: frame.n, events: pending.splice(0, 64),
  }));
}

document.getElementById("join").onclick = () => {
  if (retry) clearTimeout(retry);
  const old = ws;
  closedWhy = "";
  connect();
  if (old) old.close();
};

// -- input -----------------------------------------------------------------------------
const held = new Set();
window.addEventListener("keydown", (event) => {
  if (event.code === "KeyC" && welcome && welcome.device === "joystick") { calibrate(); return; }
  const name = KEYS[event.code];
  if (!name || !flying()) return;
  event.preventDefault();
  if (event.repeat || held.has(name)) return;
  held.add(name);
  pending.push(["down", name]);
});
window.addEventListener("keyup", (event) => {
  const name = KEYS[event.code];
  if (!name || !held.has(name)) return;
  event.preventDefault();
  held.delete(name);
  pending.push(["up", name]);
});
window.addEventListener("blur", () => {  // keys held when the page loses focus are let go
  for (const name of held) pending.push(["up", name]);
  held.clear();
});
canvas.addEventListener("mousemove", (event) => {
  if (!flying() || welcome.device !== "mouse") return;
  for (let i = pending.length - 1; i >= 0; i--) {  // only the newest pointer position counts
    if (pending[i][0] === "mouse") { pending.splice(i, 1); break; }
  }
  const rect = canvas.getBoundingClientRect();
  const [w, h] = welcome.stick.size;
  // the stick box is centred on the attitude indicator, the pointer scaled to the server's
  const x = (event.clientX - rect.left) / rect.width * canvas.width;
  const y = (event.clientY - rect.top) / rect.height * canvas.height;
  const scale = welcome.stick.span / 150;  // 150 canvas px of pointer: full deflection
  pending.push(["mouse", w / 2 + (x - AI.cx) * scale, h / 2 + (y - AI.cy) * scale]);
});

function calibrate() {
  const gp = currentPad();
  if (gp) pad.centre = gp.axes.slice(0, 8);
}

function currentPad() {
  const pads = navigator.getGamepads ? navigator.getGamepads() : [];
  for (const gp of pads) if (gp && gp.connected) return gp;
  return null;
}

function pollPad() {
  if (!welcome || welcome.device !== "joystick") return;
  const gp = currentPad();
  if (!gp) {
    if (pad.index >= 0) { pending.push(["pad", 0]); pad.index = -1; }
    return;
  }
  if (pad.index < 0) {
    pad.index = gp.index;
    pad.axes = []; pad.buttons = [];
    if (!pad.centre.length) pad.centre = gp.axes.slice(0, 8);  // calibrated at connection
    pending.push(["pad", 1]);
  }
  const throttle = welcome.axes.throttle;
  gp.axes.slice(0, 8).forEach((raw, i) => {
    // the sticks read from their calibrated centre; the throttle lever is absolute
    const v = Math.max(-1, Math.min(1, i === throttle ? raw : raw - (pad.centre[i] || 0)));
    if (pad.axes[i] === undefined || Math.abs(pad.axes[i] - v) > 0.002) {
      pad.axes[i] = v;
      pending.push(["axis", i, v]);
    }
  });
  gp.buttons.slice(0, 32).forEach((b, i) => {
    const down = b.pressed ? 1 : 0;
    if ((pad.buttons[i] || 0) !== down) { pad.buttons[i] = down; pending.push(["button", i, down]); }
  });
}

// -- drawing ---------------------------------------------------------------------------
const AI = { cx: 420, cy: 250, size: 300 };

function text(s, x, y, color, size, align) {
  ctx.fillStyle = color || FG;
  ctx.font = (size || 14) + "px ui-monospace, monospace";
  ctx.textAlign = align || "left";
  ctx.fillText(s, x, y);
}

function readingsOf(f) {
  return f.readings.map((r) => ({ name: r[0], value: r[1], unit: r[2], instrument: r[3],
    role: r[4], label: r[5] }));
}

function draw() {
  ctx.fillStyle = "#0e1014";
  ctx.fillRect(0, 0, canvas.width, canvas.height);
  if (!frame || !welcome) {
    text(invite ? "Choose a device and press Fly." : "Open the invite link you were given.",
      40, 60, FG, 20);
    if (closedWhy) text(closedWhy, 40, 100, RED, 16);
    return;
  }
  const readings = readingsOf(frame);
  const values = {}, drawn = new Set();  // drawn: every reading this frame shows (tests read it)
  for (const r of readings) {
    if (r.role === "value" && PFD.has(r.instrument)) { values[r.name] = r.value; drawn.add(r.name); }
  }
  const bugs = (instrument) => readings.filter((r) => r.instrument === instrument && r.role === "bug")
    .map((r) => { drawn.add(r.name); return r.value; });
  statusBar();
  attitude(values, bugs("pitch"), bugs("bank"));
  for (const r of readings) if (r.role === "needle") { ils(r.instrument, r.value); drawn.add(r.name); }
  tape(AI.cx - AI.size / 2 - 100, values.airspeed_kts, 10, 6, "kt", bugs("airspeed"));
  tape(AI.cx + AI.size / 2 + 12, values.altitude_ft, 100, 0.6, "ft", bugs("altitude"));
  verticalSpeed(AI.cx + AI.size / 2 + 112, values.vertical_speed_fps || 0);
  heading(values.heading_deg, bugs("heading"));
  slip(values.beta_deg || 0, bugs("slip"));
  controls();
  panel(readings, drawn);
  words();
  window.__drawn = Array.from(drawn);
  if (frame.help) help();
  if (closedWhy) banner(closedWhy, RED, 700);
}

function statusBar() {
  const f = frame, t = (f.steps * welcome.dt).toFixed(1), total = (welcome.max_steps * welcome.dt).toFixed(0);
  const rec = f.status === "recording";
  ctx.fillStyle = rec ? RED : f.status === "paused" ? YELLOW : DIM;
  ctx.beginPath(); ctx.arc(24, 22, 8, 0, 2 * Math.PI); ctx.fill();
  text(rec ? "REC" : f.status.toUpperCase(), 40, 28, rec ? RED : FG, 16);
  text(welcome.label + "  |  " + welcome.pilot + "  |  episode " + (f.episode + 1) +
    "  |  case " + f.seed + "  |  " + t + " / " + total + " s" +
    (f.human ? "" : "  |  ASSISTANT FLIES (T: take over)"), 120, 28, FG, 15);
  if (f.late) banner(f.late, YELLOW, 48);
}

function banner(s, color, y) {
  ctx.fillStyle = "rgba(0,0,0,0.75)";
  ctx.fillRect(20, y - 20, canvas.width - 40, 28);
  text(s, canvas.width / 2, y, color, 15, "center");
}

function attitude(values, pitchBugs, bankBugs) {
  const { cx, cy, size } = AI, roll = values.roll_deg || 0, pitch = values.pitch_deg || 0;
  ctx.save();
  ctx.beginPath(); ctx.rect(cx - size / 2, cy - size / 2, size, size); ctx.clip();
  ctx.translate(cx, cy);
  ctx.rotate(-roll * Math.PI / 180);
  const horizon = pitch * PX_PER_DEG;
  ctx.fillStyle = SKY; ctx.fillRect(-size, -size * 2 + horizon, size * 2, size * 2);
  ctx.fillStyle = GROUND; ctx.fillRect(-size, horizon, size * 2, size * 2);
  ctx.strokeStyle = WHITE; ctx.lineWidth = 2;
  ctx.beginPath(); ctx.moveTo(-size, horizon); ctx.lineTo(size, horizon); ctx.stroke();
  ctx.lineWidth = 1;
  for (let deg = -30; deg <= 30; deg += 5) {
    if (deg === 0) continue;
    const y = horizon - deg * PX_PER_DEG, half = deg % 10 === 0 ? 40 : 20;
    ctx.beginPath(); ctx.moveTo(-half, y); ctx.lineTo(half, y); ctx.stroke();
    if (deg % 10 === 0) text(String(Math.abs(deg)), half + 6, y + 5, WHITE, 12);
  }
  ctx.strokeStyle = MAGENTA; ctx.lineWidth = 4;
  for (const target of pitchBugs) {
    const y = horizon - target * PX_PER_DEG;
    ctx.beginPath(); ctx.moveTo(-60, y); ctx.lineTo(60, y); ctx.stroke();
  }
  ctx.restore();
  ctx.strokeStyle = EDGE; ctx.lineWidth = 1; ctx.strokeRect(cx - size / 2, cy - size / 2, size, size);
  ctx.strokeStyle = YELLOW; ctx.lineWidth = 5;
  ctx.beginPath(); ctx.moveTo(cx - 70, cy); ctx.lineTo(cx - 22, cy); ctx.moveTo(cx + 22, cy);
  ctx.lineTo(cx + 70, cy); ctx.stroke();
  const radius = size / 2 - 10;
  ctx.strokeStyle = WHITE; ctx.lineWidth = 2;
  for (const mark of [-60, -45, -30, -20, -10, 0, 10, 20, 30, 45, 60]) {
    const a = (mark - 90) * Math.PI / 180, inner = radius - (mark % 30 === 0 ? 14 : 7);
    ctx.beginPath(); ctx.moveTo(cx + inner * Math.cos(a), cy + inner * Math.sin(a));
    ctx.lineTo(cx + radius * Math.cos(a), cy + radius * Math.sin(a)); ctx.stroke();
  }
  const p = (-roll - 90) * Math.PI / 180;
  dot(cx + (radius - 18) * Math.cos(p), cy + (radius - 18) * Math.sin(p), 6, YELLOW);
  for (const target of bankBugs) {
    const a = (-target - 90) * Math.PI / 180;
    dot(cx + (radius + 6) * Math.cos(a), cy + (radius + 6) * Math.sin(a), 7, MAGENTA);
  }
}

function dot(x, y, r, color) {
  ctx.fillStyle = color; ctx.beginPath(); ctx.arc(x, y, r, 0, 2 * Math.PI); ctx.fill();
}

function ils(instrument, dots) {
  const { cx, cy, size } = AI, shown = Math.max(-2.5, Math.min(2.5, dots)) * PX_PER_DOT;
  let x, y;
  ctx.strokeStyle = WHITE; ctx.lineWidth = 1;
  if (instrument === "glideslope") {
    x = cx + size / 2 - 20;
    for (const k of [-2, -1, 1, 2]) { ctx.beginPath(); ctx.arc(x, cy - k * PX_PER_DOT, 4, 0, 7); ctx.stroke(); }
    y = cy - shown;
  } else {
    y = cy + size / 2 - 20;
    for (const k of [-2, -1, 1, 2]) { ctx.beginPath(); ctx.arc(cx + k * PX_PER_DOT, y, 4, 0, 7); ctx.stroke(); }
    x = cx - shown;
  }
  ctx.fillStyle = MAGENTA;
  ctx.beginPath(); ctx.moveTo(x, y - 10); ctx.lineTo(x + 10, y); ctx.lineTo(x, y + 10);
  ctx.lineTo(x - 10, y); ctx.closePath(); ctx.fill();
}

function tape(left, value, step, pxPerUnit, unit, targets) {
  const top = AI.cy - AI.size / 2, h = AI.size, w = 88, cy = AI.cy;
  value = value || 0;
  ctx.fillStyle = TAPE; ctx.fillRect(left, top, w, h);
  ctx.save(); ctx.beginPath(); ctx.rect(left, top, w, h); ctx.clip();
  let tick = Math.floor((value - h / 2 / pxPerUnit) / step) * step;
  ctx.strokeStyle = EDGE;
  for (; tick <= value + h / 2 / pxPerUnit; tick += step) {
    const y = cy - (tick - value) * pxPerUnit;
    ctx.beginPath(); ctx.moveTo(left + w - 12, y); ctx.lineTo(left + w, y); ctx.stroke();
    text(tick.toFixed(0), left + 4, y + 5, WHITE, 12);
  }
  for (const target of targets) {
    const y = Math.max(top + 6, Math.min(top + h - 6, cy - (target - value) * pxPerUnit));
    ctx.fillStyle = MAGENTA; ctx.fillRect(left + w - 12, y - 6, 12, 12);
  }
  ctx.restore();
  ctx.fillStyle = "#000"; ctx.fillRect(left, cy - 16, w, 32);
  ctx.strokeStyle = WHITE; ctx.strokeRect(left, cy - 16, w, 32);
  text(value.toFixed(0), left + 6, cy + 6, WHITE, 16);
  text(unit, left, top + h + 16, EDGE, 12);
}

function verticalSpeed(left, fps) {
  const top = AI.cy - AI.size / 2, h = AI.size, fpm = fps * 60;
  ctx.fillStyle = TAPE; ctx.fillRect(left, top, 24, h);
  const y = AI.cy - Math.max(-1, Math.min(1, fpm / 2000)) * h / 2;
  ctx.strokeStyle = WHITE; ctx.lineWidth = 4;
  ctx.beginPath(); ctx.moveTo(left, y); ctx.lineTo(left + 24, y); ctx.stroke(); ctx.lineWidth = 1;
  text((fpm >= 0 ? "+" : "") + fpm.toFixed(0), left - 14, top + h + 16, WHITE, 12);
}

function wrap180(deg) { return ((deg + 180) % 360 + 360) % 360 - 180; }

function heading(value, targets) {
  const left = AI.cx - AI.size / 2, top = AI.cy + AI.size / 2 + 14, w = AI.size, h = 40, px = 4;
  value = value || 0;
  ctx.fillStyle = TAPE; ctx.fillRect(left, top, w, h);
  ctx.save(); ctx.beginPath(); ctx.rect(left, top, w, h); ctx.clip();
  ctx.strokeStyle = EDGE;
  for (let tick = Math.floor((value - 40) / 10) * 10; tick < value + 45; tick += 10) {
    const x = AI.cx + (tick - value) * px;
    ctx.beginPath(); ctx.moveTo(x, top); ctx.lineTo(x, top + 10); ctx.stroke();
    text(String(((tick % 360) + 360) % 360).padStart(3, "0"), x, top + 28, WHITE, 12, "center");
  }
  for (const target of targets) {
    const x = Math.max(left + 6, Math.min(left + w - 6, AI.cx + wrap180(target - value) * px));
    ctx.fillStyle = MAGENTA; ctx.fillRect(x - 6, top, 12, 8);
  }
  ctx.restore();
  ctx.strokeStyle = YELLOW; ctx.lineWidth = 2;
  ctx.beginPath(); ctx.moveTo(AI.cx, top); ctx.lineTo(AI.cx, top + h); ctx.stroke(); ctx.lineWidth = 1;
}

function slip(beta, targets) {
  const cx = AI.cx, cy = AI.cy + AI.size / 2 + 74, half = 70;
  ctx.fillStyle = TAPE; ctx.fillRect(cx - half - 8, cy - 10, 2 * half + 16, 20);
  ctx.strokeStyle = EDGE;
  for (const side of [-1, 1]) { ctx.beginPath(); ctx.moveTo(cx + side * 12, cy - 10); ctx.lineTo(cx + side * 12, cy + 10); ctx.stroke(); }
  ctx.strokeStyle = MAGENTA; ctx.lineWidth = 3;
  for (const target of targets) {
    const x = cx + Math.max(-half, Math.min(half, target * SLIP_PX_PER_DEG));
    ctx.beginPath(); ctx.moveTo(x, cy - 14); ctx.lineTo(x, cy + 14); ctx.stroke();
  }
  ctx.lineWidth = 1;
  dot(cx + Math.max(-half, Math.min(half, beta * SLIP_PX_PER_DEG)), cy, 8, WHITE);
}

function controls() {
  // the stick (aileron, elevator) with its trim, the rudder and the throttle
  const c = frame.controls, trim = frame.trim, x0 = 60, y0 = 640, s = 70;
  text("STICK", x0 - 20, y0 - s - 12, DIM, 12);
  ctx.strokeStyle = EDGE; ctx.strokeRect(x0 - s + 20, y0 - s, 2 * s, 2 * s);
  // elevator positive (nose down: the stick forward) is drawn up, as in the pygame window
  dot(x0 + 20 + trim[0] * s, y0 - trim[1] * s, 4, DIM);
  dot(x0 + 20 + c[0] * s, y0 - c[1] * s, 7, GREEN);
  text("RUDDER", x0 + 110, y0 - s - 12, DIM, 12);
  ctx.strokeRect(x0 + 110, y0 - 8, 120, 16);
  dot(x0 + 170 + c[2] * 60, y0, 6, GREEN);
  text("THR " + (c[3] * 100).toFixed(0) + "%", x0 + 250, y0 - s - 12, DIM, 12);
  ctx.strokeRect(x0 + 260, y0 - s, 16, 2 * s);
  ctx.fillStyle = GREEN; ctx.fillRect(x0 + 260, y0 + s - 2 * s * c[3], 16, 2 * s * c[3]);
}

const SIDES = {
  turn_remaining_deg: ["right", "left"], next_turn_deg: ["right", "left"],
  right_of_slot_ft: ["right", "left"], behind_slot_ft: ["behind", "ahead"],
  below_slot_ft: ["below", "above"], behind_slot_rate_fps: ["falling back", "closing"],
  centerline_offset_ft: ["right", "left"], glidepath_error_ft: ["below", "above"],
};

function spoken(r) {
  // as the pygame window says it (gymfg_il.cockpit.windows.gui.spoken)
  const v = r.value;
  if (SIDES[r.name]) return Math.abs(v).toLocaleString("en", { maximumFractionDigits: 0 }) + " " + r.unit + " " + SIDES[r.name][v >= 0 ? 0 : 1];
  if (r.unit === "deg" && /heading|bearing|course/.test(r.name)) return String(Math.round(((v % 360) + 360) % 360)).padStart(3, "0");
  if (r.unit === "ft" && r.name.includes("distance")) return Math.abs(v) >= 6076.12 ? (v / 6076.12).toFixed(1) + " NM" : v.toFixed(0) + " ft";
  if (r.unit === "1") return v.toFixed(0);
  return (Math.abs(v) < 100 ? v.toFixed(1) : v.toFixed(0)) + " " + r.unit;
}

function panel(readings, drawn) {
  const left = 760, top = 110;
  text("TARGETS AND GUIDANCE", left, top - 20, DIM, 12);
  let y = top;
  for (const r of readings.filter((q) => q.role === "bug" || q.role === "guidance").slice(0, 10)) {
    drawn.add(r.name);
    text(r.label, left, y, DIM, 13);
    text(spoken(r), left + 260, y, r.role === "bug" ? MAGENTA : FG, 14);
    y += 22;
  }
  const slot = {};
  for (const r of readings) if (r.instrument === "slot") { slot[r.name] = r.value; drawn.add(r.name); }
  if (Object.keys(slot).length) {
    const bx = left + 60, by = y + 20, w = 160, h = 180, cx = bx + w / 2, cy = by + h / 2, k = 0.3;
    ctx.strokeStyle = DIM; ctx.strokeRect(bx, by, w, h);
    ctx.strokeStyle = MAGENTA; ctx.lineWidth = 2; ctx.strokeRect(cx - 8, cy - 8, 16, 16); ctx.lineWidth = 1;
    const sx = cx + Math.max(-75, Math.min(75, (slot.right_of_slot_ft || 0) * k));
    const sy = cy + Math.max(-85, Math.min(85, (slot.behind_slot_ft || 0) * k));
    dot(sx, sy, 6, GREEN);
    ctx.strokeStyle = DIM; ctx.strokeRect(bx + w + 6, by, 8, h);
    dot(bx + w + 10, cy + Math.max(-85, Math.min(85, (slot.below_slot_ft || 0) * k)), 5, GREEN);
    text("the slot from above (up: ahead)", bx, by + h + 16, DIM, 12);
  }
}

function words() {
  const f = frame, left = 400, top = 560;
  if (f.message) text(f.message, left, top, YELLOW, 15);
  let lines = [];
  if (f.status === "idle") lines = f.debrief ? f.debrief.lines : welcome.briefing;
  const color = f.debrief && f.status === "idle" ? (f.debrief.success ? GREEN : RED) : FG;
  lines.slice(0, 6).forEach((line, i) => text(line, left, top + 24 + 20 * i, i ? FG : color, 13));
}

function help() {
  ctx.fillStyle = "rgba(0,0,0,0.85)";
  ctx.fillRect(60, 80, canvas.width - 120, 30 + 20 * welcome.help.length);
  welcome.help.forEach((line, i) => text(line, 80, 110 + 20 * i, FG, 13));
}

redraw();
if (invite) connect();
else stateText.textContent = "no invite in this link: open the link you were given";
