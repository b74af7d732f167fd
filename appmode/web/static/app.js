// appmode web: the page. It draws what the server sends (`status`) and wires the page's
// parts to the safety core (link.js: the socket, the heartbeat, the keys held): the pad
// and keys, the joystick, tilt and a gamepad, the instruments, the parameters and the
// waveforms. The message vocabulary is the server's (messages.js, made from Python).
import { RECEIVE, SEND } from "./messages.js";
import { showInstruments, showRows } from "./instruments.js";
import { $, command, on, page, send, start } from "./link.js";
import { setUpPad, showPad } from "./pad.js";
import { analog, setUpStick, showControl } from "./stick.js";
import { setUpTilt, tiltOff } from "./tilt.js";
import { setUpWaves, showWaves } from "./waves.js";

function showTab(name) {
  document.querySelectorAll("nav button").forEach((button) => {
    button.setAttribute("aria-pressed", String(button.dataset.tab === name));
  });
  document.querySelectorAll(".tab").forEach((tab) => { tab.hidden = tab.id !== name; });
  send({ t: SEND.waves, on: name === "waves" });
  if (name !== "tilt") tiltOff();
}

function showStatus(message) {
  const title = message.title.replace("appmode drive", "appmode web");
  $("title").textContent = message.fleet ? `${message.fleet} · ${title}` : title;
  $("fleet-link").hidden = !message.fleet;
  $("badge").textContent = message.simulated ? "SIMULATED" : "REAL BOARD";
  $("badge").className = `badge ${message.simulated ? "simulated" : "real"}`;
  $("url").textContent = message.url;
  const driving = message.role === "driver";
  $("role-text").textContent = driving
    ? "This page drives the car."
    : `This page watches (${message.pages} pages open): another page drives.`;
  $("take").hidden = driving;
  document.body.classList.toggle("watching", !driving);
  const board = message.instruments.page;
  $("pages").hidden = !message.commands.includes("page");
  document.querySelectorAll("#pages button").forEach((button) => {
    const pressed = button.dataset.page === "button" ? board === "button" : board !== "button";
    button.setAttribute("aria-pressed", String(pressed));
  });
  $("turn").hidden = !message.commands.includes("rotate");
  document.body.classList.toggle("uart2", analog());
  showControl(message);
  showRows(message.rows);
  showPad(message.cells, message.lit, message.extra);
  showInstruments(message.instruments);
  $("waves-note").hidden = message.instruments.telemetry !== null;
  $("chart").hidden = message.instruments.telemetry === null;
  showWaves(message.traces);
  $("messages").replaceChildren(...message.messages.map((text) => {
    const line = document.createElement("div");
    line.textContent = text;
    return line;
  }));
  $("messages").scrollTop = $("messages").scrollHeight;
}

let noticeTimer = null;
function notice(message) {
  $("notice").hidden = false;
  $("notice").textContent = message.text;
  clearTimeout(noticeTimer);
  noticeTimer = setTimeout(() => { $("notice").hidden = true; }, 4000);
}

function setUpCommands() {
  $("take").addEventListener("click", () => send({ t: SEND.take }));
  $("read").addEventListener("click", () => {
    command(page.status && page.status.commands.includes("settings") ? "settings" : "params");
  });
  $("save").addEventListener("click", () => command("save"));
  $("slower").addEventListener("click", () => command("speed -100"));
  $("faster").addEventListener("click", () => command("speed +100"));
  $("rotate").addEventListener("click", () => command(`rotate ${$("angle").value.trim()}`));
  document.querySelectorAll("#pages button").forEach((button) => {
    button.addEventListener("click", () => command(`page ${button.dataset.page}`));
  });
  $("command").addEventListener("submit", (event) => {
    event.preventDefault();
    if ($("line").value.trim()) command($("line").value);
    $("line").value = "";
  });
  document.querySelectorAll("nav button").forEach((button) => {
    button.addEventListener("click", () => showTab(button.dataset.tab));
  });
}

setUpPad();
setUpStick();
setUpTilt();
setUpWaves();
setUpCommands();
on(RECEIVE.status, showStatus);
on(RECEIVE.error, notice);
on("open", () => {
  const tab = document.querySelector("nav button[aria-pressed=true]").dataset.tab;
  send({ t: SEND.waves, on: tab === "waves" });
});
start();

if ("serviceWorker" in navigator) { // keeps the page's own files for "the server is not reachable"
  navigator.serviceWorker.register("/sw.js").catch(() => {}); // refused on a certificate the browser distrusts
}
