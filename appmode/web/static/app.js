// appmode web: the pad, the status and the command line over one websocket.
// A held direction is sent again every HEARTBEAT_MS; the server stops the car when
// they stop coming (a dropped network, a frozen page), and on every release.
"use strict";

const HEARTBEAT_MS = 100;
const RECONNECT_MS = 1000;
const KEYS = {
  q: "front-left", w: "forward", e: "front-right",
  a: "left", s: "stop", d: "right",
  z: "rear-left", x: "backward", c: "rear-right",
  ArrowUp: "forward", ArrowDown: "backward", ArrowLeft: "left", ArrowRight: "right",
};
const TONES = ["label", "on", "ok", "warn", "alert", "late", "low", "dim"];

let socket = null;
let role = "watcher";
const held = new Map(); // pointer or key id -> pad cell, in the order pressed
let current = null; // the cell being driven
let beat = null;

function send(message) {
  if (socket && socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify(message));
}

// ---------------------------------------------------------------- driving

function drive() {
  const cells = [...held.values()];
  const next = cells.length ? cells[cells.length - 1] : null;
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

function press(id, cell) {
  held.delete(id);
  held.set(id, cell);
  drive();
}

function release(id) {
  if (!held.delete(id)) return;
  drive();
}

function releaseAll() {
  held.clear();
  current = null;
  clearInterval(beat);
  beat = null;
  send({ t: "stop" });
}

for (const button of document.querySelectorAll("#pad button")) {
  const cell = button.dataset.key;
  button.addEventListener("pointerdown", (event) => {
    event.preventDefault();
    button.setPointerCapture(event.pointerId);
    press(`p${event.pointerId}`, cell);
  });
  for (const name of ["pointerup", "pointercancel", "lostpointercapture"]) {
    button.addEventListener(name, (event) => release(`p${event.pointerId}`));
  }
  button.addEventListener("contextmenu", (event) => event.preventDefault());
  button.addEventListener("click", (event) => {
    if (event.detail === 0) { // keyboard activation (Enter, Space): a tap
      press("click", cell);
      setTimeout(() => release("click"), HEARTBEAT_MS);
    }
  });
}

document.addEventListener("keydown", (event) => {
  if (event.target.closest && event.target.closest("input, form")) return;
  if (event.key === " ") { event.preventDefault(); releaseAll(); return; }
  const cell = KEYS[event.key] || KEYS[event.key.toLowerCase()];
  if (!cell) return;
  event.preventDefault();
  if (!event.repeat) press(`k${event.code}`, cell);
});
document.addEventListener("keyup", (event) => release(`k${event.code}`));
document.addEventListener("visibilitychange", () => { if (document.hidden) releaseAll(); });
window.addEventListener("pagehide", releaseAll);
window.addEventListener("blur", releaseAll);

document.getElementById("take").addEventListener("click", () => send({ t: "take" }));
document.getElementById("command").addEventListener("submit", (event) => {
  event.preventDefault();
  const input = document.getElementById("line");
  if (input.value.trim()) send({ t: "command", line: input.value });
  input.value = "";
});

// ---------------------------------------------------------------- showing

function span(tone, text) {
  const element = document.createElement("span");
  if (TONES.includes(tone)) element.className = `tone-${tone}`;
  element.textContent = text;
  return element;
}

function showStatus(status) {
  role = status.role;
  document.getElementById("title").textContent = status.title.replace("appmode drive", "appmode web");
  const badge = document.getElementById("badge");
  badge.textContent = status.simulated ? "SIMULATED BOARD" : "REAL BOARD";
  badge.className = `badge ${status.simulated ? "simulated" : "real"}`;
  document.getElementById("url").textContent = status.url;
  document.getElementById("role-text").textContent = role === "driver"
    ? "This page drives the car."
    : `This page watches (${status.pages} pages open): another page drives.`;
  document.getElementById("take").hidden = role === "driver";
  document.body.classList.toggle("watching", role !== "driver");

  const rows = document.getElementById("status");
  rows.replaceChildren(...status.rows.map((row) => {
    const line = document.createElement("div");
    line.className = "row";
    const label = span("label", row.label);
    label.classList.add("row-label");
    line.append(label, ...row.spans.map(([tone, text]) => span(tone, text)));
    if (row.pairs.length) {
      const pairs = document.createElement("span");
      pairs.className = "pairs";
      pairs.textContent = row.pairs.join(" · ");
      line.append(pairs);
    }
    return line;
  }));

  const lit = status.lit ? status.lit[0] * 3 + status.lit[1] : -1;
  document.querySelectorAll("#pad button").forEach((button, index) => {
    button.classList.toggle("lit", index === lit);
    const r = Math.floor(index / 3), c = index % 3;
    button.title = status.grid[r][c];
  });

  const log = document.getElementById("messages");
  log.replaceChildren(...status.messages.map((text) => {
    const line = document.createElement("div");
    line.textContent = text;
    return line;
  }));
  log.scrollTop = log.scrollHeight;
}

function showConnection(text) {
  const banner = document.getElementById("connection");
  banner.hidden = !text;
  banner.textContent = text || "";
}

function connect() {
  const scheme = location.protocol === "https:" ? "wss" : "ws";
  socket = new WebSocket(`${scheme}://${location.host}/ws`);
  socket.addEventListener("open", () => showConnection(""));
  socket.addEventListener("message", (event) => {
    const message = JSON.parse(event.data);
    if (message.t === "status") showStatus(message);
    else if (message.t === "error") showConnection(message.text);
  });
  socket.addEventListener("close", () => {
    held.clear();
    current = null;
    clearInterval(beat);
    showConnection("DISCONNECTED — the server stops the car; reconnecting…");
    setTimeout(connect, RECONNECT_MS);
  });
}

connect();
