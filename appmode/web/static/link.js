// The safety core: the page's one websocket to appmode web, its heartbeat, the keys
// held (a pointer, a key, the tilt, the stick), and what the page says when it loses
// the server. The page says it is alive every HEARTBEAT_MS, and a held direction is
// sent again as often; the server stops the car when either stops coming (a dropped
// network, a frozen page), however the motion began, and on every release.
import { RECEIVE, SEND } from "./messages.js";

export const HEARTBEAT_MS = 100;
const RECONNECT_MS = 1000;
const GONE_AFTER = 2; // failed reconnections after which the server is called gone

export const $ = (id) => document.getElementById(id);
export const page = { status: null }; // the last status the server sent

let socket = null;
const held = new Map(); // who holds -> key name
let current = null;
let beat = null;
let failures = 0; // connections in a row that closed (or never opened)
let wasMoving = false; // the car was last told to move when the connection was lost
const listeners = { [RECEIVE.status]: [], [RECEIVE.error]: [], open: [] };

export function on(kind, listener) { listeners[kind].push(listener); }

export function send(message) {
  if (socket && socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify(message));
}

export function command(line) { send({ t: SEND.command, line }); }

function drive() {
  const keys = [...held.values()];
  const next = keys.length ? keys[keys.length - 1] : null;
  if (next === current) return;
  current = next;
  clearInterval(beat);
  beat = null;
  if (next === null || next === "stop") {
    send({ t: next === "stop" ? SEND.stop : SEND.release });
    return;
  }
  send({ t: SEND.press, key: next });
  beat = setInterval(() => send({ t: SEND.hold, key: next }), HEARTBEAT_MS);
}

export function press(who, key) {
  if (held.get(who) === key) return;
  held.delete(who);
  held.set(who, key);
  drive();
}

export function release(who) {
  if (held.delete(who)) drive();
}

export function releaseAll() {
  const moving = current !== null;
  held.clear();
  current = null;
  clearInterval(beat);
  beat = null;
  if (moving || (page.status && page.status.role === "driver")) send({ t: SEND.stop });
}

function connect() {
  const scheme = location.protocol === "https:" ? "wss" : "ws";
  socket = new WebSocket(`${scheme}://${location.host}/ws`);
  socket.addEventListener("open", () => {
    failures = 0;
    $("connection").hidden = true;
    listeners.open.forEach((listener) => listener());
  });
  socket.addEventListener("message", (event) => {
    const message = JSON.parse(event.data);
    if (message.t === RECEIVE.status) page.status = message;
    (listeners[message.t] || []).forEach((listener) => listener(message));
  });
  socket.addEventListener("close", () => {
    if (failures === 0) { // what the car was last told, as this page knows it
      wasMoving = current !== null || (page.status !== null && page.status.instruments.moving);
    }
    held.clear();
    current = null;
    clearInterval(beat);
    failures += 1;
    lostConnection();
    setTimeout(connect, RECONNECT_MS);
  });
}

// What the page says when it loses appmode web: only what it knows. A server that runs
// stops the car when its page goes quiet; a server that was killed, or whose machine
// is down, stops nothing, and the car keeps its last command (no time-out).
function lostConnection() {
  $("connection").hidden = false;
  const car = wasMoving
    ? "The car was last told to move: it may still be moving."
    : "The car was last told to stop.";
  $("connection").textContent = failures > GONE_AFTER
    ? `APPMODE WEB IS NOT ANSWERING. ${car} If the server ended or its machine is down, `
      + "nothing stops the car: stop it by hand, then start appmode web again. Trying again…"
    : `CONNECTION TO APPMODE WEB LOST. ${car} A server that still runs stops it within a `
      + "quarter of a second; a server that ended cannot. Reconnecting…";
  $("in-force").textContent = wasMoving ? "unknown: no connection (it may still be moving)"
    : "unknown: no connection";
  $("link").textContent = "no connection to appmode";
  $("link").className = "chip lost";
  document.querySelectorAll("#pad button").forEach((b) => b.classList.remove("lit"));
}

export function start() {
  connect();
  setInterval(() => send({ t: SEND.alive }), HEARTBEAT_MS);
  document.addEventListener("visibilitychange", () => { if (document.hidden) releaseAll(); });
  window.addEventListener("pagehide", releaseAll);
  window.addEventListener("blur", () => { if (held.size) releaseAll(); });
}
