// appmode web: the pad, tilt, gamepad, parameters, waveforms and the command line over
// one websocket. The page says it is alive every HEARTBEAT_MS, and a held direction is
// sent again as often; the server stops the car when either stops coming (a dropped
// network, a frozen page), however the motion began, and on every release.
"use strict";

const HEARTBEAT_MS = 100;
const RECONNECT_MS = 1000;
const DEAD_ZONE = 10; // degrees of tilt in which the car stops
const STICK_DEAD = 0.35; // a gamepad stick's dead zone
const KEYS = {
  q: "front-left", w: "forward", e: "front-right",
  a: "left", s: "stop", d: "right",
  z: "rear-left", x: "backward", c: "rear-right",
  ArrowUp: "forward", ArrowDown: "backward", ArrowLeft: "left", ArrowRight: "right",
};
const POSITIONS = ["front-left", "forward", "front-right", "left", "stop", "right",
  "rear-left", "backward", "rear-right"]; // what a cell is called by where it is
const GLYPHS = {
  "front-left": "↖", forward: "↑", "front-right": "↗", left: "←", stop: "■", right: "→",
  "rear-left": "↙", backward: "↓", "rear-right": "↘", "rotate-ccw": "↺", "rotate-cw": "↻",
};
const SECTORS = ["right", "front-right", "forward", "front-left", "left", "rear-left",
  "backward", "rear-right"]; // by angle, counter-clockwise from the right
const TONES = ["label", "on", "ok", "warn", "alert", "late", "low", "dim"];

let socket = null;
let status = null;
const held = new Map(); // who holds (a pointer, a key, the tilt, the stick) -> key name
let current = null;
let beat = null;
const $ = (id) => document.getElementById(id);

function send(message) {
  if (socket && socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify(message));
}

function command(line) {
  send({ t: "command", line });
}

// ---------------------------------------------------------------- driving

function drive() {
  const keys = [...held.values()];
  const next = keys.length ? keys[keys.length - 1] : null;
  if (next === current) return;
  current = next;
  clearInterval(beat);
  beat = null;
  if (next === null || next === "stop") {
    send({ t: next === "stop" ? "stop" : "release" });
    return;
  }
  send({ t: "press", key: next });
  beat = setInterval(() => send({ t: "hold", key: next }), HEARTBEAT_MS);
}

function press(who, key) {
  if (held.get(who) === key) return;
  held.delete(who);
  held.set(who, key);
  drive();
}

function release(who) {
  if (held.delete(who)) drive();
}

function releaseAll() {
  const moving = current !== null;
  held.clear();
  current = null;
  clearInterval(beat);
  beat = null;
  if (moving || (status && status.role === "driver")) send({ t: "stop" });
}

function holdable(button, key) {
  button.addEventListener("pointerdown", (event) => {
    event.preventDefault();
    button.setPointerCapture(event.pointerId);
    press(`p${event.pointerId}`, key());
  });
  for (const name of ["pointerup", "pointercancel", "lostpointercapture"]) {
    button.addEventListener(name, (event) => release(`p${event.pointerId}`));
  }
  button.addEventListener("contextmenu", (event) => event.preventDefault());
  button.addEventListener("click", (event) => {
    if (event.detail === 0) { // keyboard activation (Enter, Space): a tap
      press("click", key());
      setTimeout(() => release("click"), HEARTBEAT_MS);
    }
  });
}

document.querySelectorAll("#pad button").forEach((button) => {
  holdable(button, () => button.getAttribute("aria-label"));
});

document.addEventListener("keydown", (event) => {
  if (event.target.closest && event.target.closest("input, form")) return;
  if (event.key === " ") { event.preventDefault(); releaseAll(); return; }
  const position = KEYS[event.key] || KEYS[event.key.toLowerCase()];
  if (!position) return;
  event.preventDefault();
  const cell = document.querySelectorAll("#pad button")[POSITIONS.indexOf(position)];
  if (!event.repeat) press(`k${event.code}`, cell.getAttribute("aria-label"));
});
document.addEventListener("keyup", (event) => release(`k${event.code}`));
document.addEventListener("visibilitychange", () => { if (document.hidden) releaseAll(); });
window.addEventListener("pagehide", releaseAll);
window.addEventListener("blur", () => { if (held.size) releaseAll(); });

$("take").addEventListener("click", () => send({ t: "take" }));
$("read").addEventListener("click", () => {
  command(status && status.commands.includes("settings") ? "settings" : "params");
});
$("save").addEventListener("click", () => command("save"));
$("slower").addEventListener("click", () => command("speed -100"));
$("faster").addEventListener("click", () => command("speed +100"));
document.querySelectorAll("#pages button").forEach((button) => {
  button.addEventListener("click", () => command(`page ${button.dataset.page}`));
});
$("command").addEventListener("submit", (event) => {
  event.preventDefault();
  if ($("line").value.trim()) command($("line").value);
  $("line").value = "";
});

// ---------------------------------------------------------------- the analog pad (UART2)

const stick = { id: null, x: 0, y: 0, beat: null };

function stickAt(event) {
  const box = $("stick").getBoundingClientRect();
  const radius = box.width / 2;
  let x = (event.clientX - box.left - radius) / radius;
  let y = -(event.clientY - box.top - radius) / radius;
  const length = Math.hypot(x, y);
  if (length > 1) { x /= length; y /= length; }
  const round = (v) => Math.round(v * 20) / 20;
  [x, y] = [round(x), round(y)];
  $("knob").style.transform = `translate(${x * radius}px, ${-y * radius}px)`;
  if (x !== stick.x || y !== stick.y || stick.beat === null) {
    stick.x = x;
    stick.y = y;
    send({ t: "stick", x, y });
  }
}

$("stick").addEventListener("pointerdown", (event) => {
  event.preventDefault();
  $("stick").setPointerCapture(event.pointerId);
  stick.id = event.pointerId;
  stick.beat = null;
  stickAt(event);
  stick.beat = setInterval(() => send({ t: "stick", x: stick.x, y: stick.y }), HEARTBEAT_MS);
});
$("stick").addEventListener("pointermove", (event) => {
  if (event.pointerId === stick.id) stickAt(event);
});
for (const name of ["pointerup", "pointercancel", "lostpointercapture"]) {
  $("stick").addEventListener(name, (event) => {
    if (event.pointerId !== stick.id) return;
    stick.id = null;
    clearInterval(stick.beat);
    stick.beat = null;
    $("knob").style.transform = "";
    send({ t: "release" });
  });
}
$("rotate").addEventListener("click", () => command(`rotate ${$("angle").value.trim()}`));

// ---------------------------------------------------------------- pages of the page

function showTab(name) {
  document.querySelectorAll("nav button").forEach((button) => {
    button.setAttribute("aria-pressed", String(button.dataset.tab === name));
  });
  document.querySelectorAll(".tab").forEach((tab) => { tab.hidden = tab.id !== name; });
  send({ t: "waves", on: name === "waves" });
  if (name !== "tilt") tiltOff();
}
document.querySelectorAll("nav button").forEach((button) => {
  button.addEventListener("click", () => showTab(button.dataset.tab));
});

// ---------------------------------------------------------------- tilt

let tilt = { on: false, beta: null, gamma: null, level: [0, 0] };

function sector(dx, dy) { // dx right, dy forward: the name of the 45° sector
  const angle = (Math.atan2(dy, dx) * 180) / Math.PI;
  return SECTORS[((Math.round(angle / 45) % 8) + 8) % 8];
}

function onTilt(event) {
  if (event.beta === null || event.gamma === null) return;
  tilt.beta = event.beta;
  tilt.gamma = event.gamma;
  const dx = event.gamma - tilt.level[1];
  const dy = -(event.beta - tilt.level[0]); // the top edge down: forward
  const dot = $("tilt-dot");
  const clamp = (v) => Math.max(-45, Math.min(45, v));
  dot.style.transform = `translate(${clamp(dx) * 2}px, ${-clamp(dy) * 2}px)`;
  if (!tilt.on) return;
  if (Math.hypot(dx, dy) < DEAD_ZONE) release("tilt");
  else press("tilt", sector(dx, dy));
}

function tiltNote(text) { $("tilt-note").textContent = text; }

async function tiltOn() {
  if (!window.isSecureContext) {
    tiltNote("Tilt is unavailable: browsers give the sensor only to secure pages (https, or this machine's own address).");
    return;
  }
  if (typeof DeviceOrientationEvent === "undefined") {
    tiltNote("Tilt is unavailable: this browser has no orientation sensor API.");
    return;
  }
  if (typeof DeviceOrientationEvent.requestPermission === "function") {
    const answer = await DeviceOrientationEvent.requestPermission().catch(() => "denied");
    if (answer !== "granted") {
      tiltNote("Tilt is unavailable: the browser was not allowed to read the sensor.");
      return;
    }
  }
  tilt.on = true;
  $("tilt-on").setAttribute("aria-pressed", "true");
  if (status && status.commands.includes("page")) command("page gravity"); // the app's I
  tiltNote("Tilting drives; inside the circle the car stops.");
  setTimeout(() => {
    if (tilt.on && tilt.beta === null) tiltNote("No tilt sensor answered: this device has none.");
  }, 1500);
}

function tiltOff() {
  if (tilt.on && status && status.commands.includes("page")) command("page direction");
  tilt.on = false;
  $("tilt-on").setAttribute("aria-pressed", "false");
  release("tilt");
}

window.addEventListener("deviceorientation", onTilt);
$("tilt-on").addEventListener("click", () => (tilt.on ? tiltOff() : tiltOn()));
$("level").addEventListener("click", () => {
  if (tilt.beta === null) {
    tiltNote("No tilt sensor has answered: there is no level to set.");
    return;
  }
  tilt.level = [tilt.beta, tilt.gamma];
  tiltNote("Level set: hold the phone like this to stop.");
});

// ---------------------------------------------------------------- gamepad

function pollGamepad() {
  const pads = navigator.getGamepads ? [...navigator.getGamepads()].filter(Boolean) : [];
  if (pads.length) {
    const pad = pads[0];
    const [dx, dy] = [pad.axes[0] || 0, -(pad.axes[1] || 0)];
    if (pad.buttons[0] && pad.buttons[0].pressed) releaseAll();
    else if (Math.hypot(dx, dy) < STICK_DEAD) release("stick");
    else press("stick", sector(dx, dy));
  } else {
    release("stick");
  }
  requestAnimationFrame(pollGamepad);
}
requestAnimationFrame(pollGamepad);

// ---------------------------------------------------------------- showing

function span(tone, text) {
  const element = document.createElement("span");
  if (TONES.includes(tone)) element.className = `tone-${tone}`;
  element.textContent = text;
  return element;
}

function showRows(rows) {
  $("status").replaceChildren(...rows.map((row) => {
    const line = document.createElement("div");
    line.className = "row";
    const label = span("label", row.label);
    label.classList.add("row-label");
    line.append(label, ...row.spans.map(([tone, text]) => span(tone, text)));
    if (row.pairs.length) line.append(span("", ` ${row.pairs.join(" · ")}`));
    return line;
  }));
}

function showPad(cells, lit, extra) {
  document.querySelectorAll("#pad button").forEach((button, index) => {
    const name = cells[Math.floor(index / 3)][index % 3];
    button.setAttribute("aria-label", name);
    button.textContent = GLYPHS[name] || "?";
    button.classList.toggle("lit", lit !== null && index === lit[0] * 3 + lit[1]);
  });
  const bar = $("extra");
  if (bar.dataset.keys !== extra.join()) {
    bar.dataset.keys = extra.join();
    bar.replaceChildren(...extra.map((name) => {
      const button = document.createElement("button");
      button.type = "button";
      button.setAttribute("aria-label", name);
      button.textContent = `${GLYPHS[name] || ""} ${name}`;
      holdable(button, () => name);
      return button;
    }));
  }
}

function showValues(rows) {
  const row = rows.find((r) => r.label === "params" || r.label === "settings");
  const body = document.querySelector("#values tbody");
  if (!row || !row.pairs.length) {
    if (!body.children.length) {
      body.innerHTML = "<tr><td>Not read yet: Read asks the board.</td></tr>";
    }
    return;
  }
  const pairs = row.pairs.map((pair) => [pair.slice(0, pair.lastIndexOf(" ")), pair.slice(pair.lastIndexOf(" ") + 1)]);
  if (body.dataset.names !== pairs.map((p) => p[0]).join()) {
    body.dataset.names = pairs.map((p) => p[0]).join();
    body.replaceChildren(...pairs.map(([name]) => {
      const tr = document.createElement("tr");
      tr.innerHTML = "<th></th><td class=value></td><td><input inputmode=numeric size=8></td><td><button type=button>Set</button></td>";
      tr.querySelector("th").textContent = name;
      const input = tr.querySelector("input");
      input.setAttribute("aria-label", `new ${name}`);
      tr.querySelector("button").setAttribute("aria-label", `set ${name}`);
      tr.querySelector("button").addEventListener("click", () => {
        if (input.value.trim()) command(`set ${name} ${input.value.trim()}`);
        input.value = "";
      });
      return tr;
    }));
  }
  pairs.forEach(([, value], i) => { body.children[i].querySelector(".value").textContent = value; });
}

function showWaves(traces) {
  const canvas = $("chart");
  if (!traces || canvas.closest(".tab").hidden) return;
  const ctx = canvas.getContext("2d");
  const styles = getComputedStyle(document.body);
  const { width, height } = canvas;
  ctx.clearRect(0, 0, width, height);
  const strip = height / traces.series.length;
  ctx.font = "14px monospace";
  traces.series.forEach((series, i) => {
    const top = i * strip;
    const values = series.points.map((p) => p[1]);
    const low = Math.min(...values, 0);
    const high = Math.max(...values, 1);
    ctx.strokeStyle = "#888";
    ctx.beginPath();
    ctx.moveTo(0, top + strip);
    ctx.lineTo(width, top + strip);
    ctx.stroke();
    ctx.strokeStyle = `hsl(${i * 50}, 70%, 45%)`;
    ctx.lineWidth = 2;
    ctx.beginPath();
    series.points.forEach(([ago, value], j) => {
      const x = width * (1 - ago / traces.seconds);
      const y = top + strip - 4 - ((value - low) / (high - low || 1)) * (strip - 8);
      if (j === 0) ctx.moveTo(x, y); else ctx.lineTo(x, y);
    });
    ctx.stroke();
    ctx.lineWidth = 1;
    ctx.fillStyle = styles.color;
    const last = values.length ? values[values.length - 1] : "—";
    ctx.fillText(`${series.label} ${last}`, 4, top + 16);
  });
}

function showStatus(message) {
  status = message;
  $("title").textContent = message.title.replace("appmode drive", "appmode web");
  $("badge").textContent = message.simulated ? "SIMULATED BOARD" : "REAL BOARD";
  $("badge").className = `badge ${message.simulated ? "simulated" : "real"}`;
  $("url").textContent = message.url;
  const driving = message.role === "driver";
  $("role-text").textContent = driving
    ? "This page drives the car."
    : `This page watches (${message.pages} pages open): another page drives.`;
  $("take").hidden = driving;
  document.body.classList.toggle("watching", !driving);
  $("pages").hidden = !message.commands.includes("page");
  $("analog").hidden = !message.commands.includes("velocity");
  showRows(message.rows);
  showPad(message.cells, message.lit, message.extra);
  showValues(message.rows);
  showWaves(message.traces);
  $("messages").replaceChildren(...message.messages.map((text) => {
    const line = document.createElement("div");
    line.textContent = text;
    return line;
  }));
  $("messages").scrollTop = $("messages").scrollHeight;
}

let noticeTimer = null;
function notice(text) {
  $("notice").hidden = false;
  $("notice").textContent = text;
  clearTimeout(noticeTimer);
  noticeTimer = setTimeout(() => { $("notice").hidden = true; }, 4000);
}

function connect() {
  const scheme = location.protocol === "https:" ? "wss" : "ws";
  socket = new WebSocket(`${scheme}://${location.host}/ws`);
  socket.addEventListener("open", () => {
    $("connection").hidden = true;
    const tab = document.querySelector("nav button[aria-pressed=true]").dataset.tab;
    send({ t: "waves", on: tab === "waves" });
  });
  socket.addEventListener("message", (event) => {
    const message = JSON.parse(event.data);
    if (message.t === "status") showStatus(message);
    else if (message.t === "error") notice(message.text);
  });
  socket.addEventListener("close", () => {
    held.clear();
    current = null;
    clearInterval(beat);
    $("connection").hidden = false;
    $("connection").textContent = "LINK TO APPMODE LOST — the server stops the car; reconnecting…";
    setTimeout(connect, RECONNECT_MS);
  });
}

connect();
setInterval(() => send({ t: "alive" }), HEARTBEAT_MS);

if ("serviceWorker" in navigator) {  // keeps the page's own files for "the server is not reachable"
  navigator.serviceWorker.register("/sw.js").catch(() => {});  // refused on a certificate the browser distrusts
}
