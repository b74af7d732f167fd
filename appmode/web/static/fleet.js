// appmode web --fleet: every car the key opens, as a card (what its host says, shown as
// text only), a stop-all button with each car's confirmation, and a link per card to
// drive that car. The message vocabulary is the server's (messages.js).
import { FLEET_RECEIVE, FLEET_SEND } from "./messages.js";

const $ = (id) => document.getElementById(id);
const RETRY_MS = 1000;
let socket = null;

function cell(name, text, className = "") {
  const label = document.createElement("span");
  label.className = "name";
  label.textContent = name;
  const value = document.createElement("span");
  value.className = className;
  value.textContent = text;
  return [label, value];
}

function card(car, driving) {
  const item = document.createElement("li");
  const link = document.createElement("a");
  link.className = "card";
  link.href = `/car/${encodeURIComponent(car.name)}`;
  const title = document.createElement("strong");
  title.textContent = car.name;
  const badge = document.createElement("span");
  badge.className = `badge ${car.simulated ? "simulated" : "real"}`;
  badge.textContent = car.simulated ? "SIMULATED" : "REAL BOARD";
  const head = document.createElement("span");
  head.className = "head";
  head.append(title, " ", badge);
  if (car.name === driving) head.append(" ", Object.assign(document.createElement("em"), { textContent: "driven here" }));
  const battery = car.battery === null ? "—" : `${car.battery} %`;
  const links = Object.entries(car.links || {}).map(([port, up]) => `${port} ${up ? "up" : "DOWN"}`).join(", ");
  const driver = car.driver ? car.driver.machine : "nobody";
  link.append(
    head,
    ...cell("in force", car.in_force || (car.moving ? "moving (its records)" : "stopped"), car.in_force || car.moving ? "moving" : ""),
    ...cell("battery", battery),
    ...cell("link", links || "—", links.includes("DOWN") ? "down" : ""),
    ...cell("driven from", driver),
    ...cell("profile", car.profile || "?"),
    ...cell("answers in", `${car.latency_ms} ms`),
  );
  item.append(link);
  return item;
}

function showFleet(message) {
  $("cars").replaceChildren(...message.cars.map((car) => card(car, message.driving)));
  $("none").hidden = message.cars.length > 0;
  $("count").textContent = `${message.cars.length} car${message.cars.length === 1 ? "" : "s"}`;
}

function said(answer) {
  if (!answer.sent) return "its stop was NOT delivered (its link is down): it may still be moving";
  if (answer.confirmed === null) return "stop sent (no telemetry to confirm it)";
  return answer.confirmed ? "stopped (confirmed)" : "stop sent, NOT confirmed";
}

function showStopped(message) {
  $("stop-all").disabled = false;
  $("stopped").hidden = false;
  const lines = message.answers.map((answer) => {
    const line = document.createElement("div");
    line.textContent = `${answer.name}: ${said(answer)}`;
    return line;
  });
  if (!lines.length) lines.push(Object.assign(document.createElement("div"), { textContent: "no car answered: nothing was stopped" }));
  $("stopped").replaceChildren(...lines);
}

const HANDLERS = {
  [FLEET_RECEIVE.fleet]: showFleet,
  [FLEET_RECEIVE.stopped]: showStopped,
  [FLEET_RECEIVE.error]: (message) => { $("stopped").hidden = false; $("stopped").textContent = message.text; },
};

function connect() {
  const scheme = location.protocol === "https:" ? "wss" : "ws";
  socket = new WebSocket(`${scheme}://${location.host}/fleet/ws`);
  socket.addEventListener("open", () => {
    $("link").textContent = "connected";
    $("link").className = "chip up";
    $("connection").hidden = true;
  });
  socket.addEventListener("message", (event) => {
    const message = JSON.parse(event.data);
    const handler = HANDLERS[message.t];
    if (handler) handler(message);
  });
  socket.addEventListener("close", () => {
    $("link").textContent = "lost";
    $("link").className = "chip lost";
    $("connection").hidden = false;
    $("connection").textContent = "Lost the appmode server: the cars' hosts still stop a car whose driver goes silent. Reconnecting…";
    $("stop-all").disabled = false;
    setTimeout(connect, RETRY_MS);
  });
}

$("stop-all").addEventListener("click", () => {
  if (!socket || socket.readyState !== WebSocket.OPEN) return;
  $("stop-all").disabled = true;
  $("stopped").hidden = false;
  $("stopped").textContent = "stopping every car…";
  socket.send(JSON.stringify({ t: FLEET_SEND.stop_all }));
});
connect();
