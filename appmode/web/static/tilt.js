// Tilt (the app's gravity page) and a gamepad's stick: each holds the sector it points
// to as a key, and stops the car inside its dead zone.
import { $, command, page, press, release, releaseAll } from "./link.js";
import { sector } from "./stick.js";

const DEAD_ZONE = 10; // degrees of tilt in which the car stops
const STICK_DEAD = 0.35; // a gamepad stick's dead zone
const tilt = { on: false, beta: null, gamma: null, level: [0, 0] };
const pages = () => Boolean(page.status && page.status.commands.includes("page"));

function onTilt(event) {
  if (event.beta === null || event.gamma === null) return;
  tilt.beta = event.beta;
  tilt.gamma = event.gamma;
  const dx = event.gamma - tilt.level[1];
  const dy = -(event.beta - tilt.level[0]); // the top edge down: forward
  const clamp = (v) => Math.max(-45, Math.min(45, v));
  $("tilt-dot").style.transform = `translate(${clamp(dx) * 2}px, ${-clamp(dy) * 2}px)`;
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
  if (pages()) command("page gravity"); // the app's I
  tiltNote("Tilting drives; inside the circle the car stops.");
  setTimeout(() => {
    if (tilt.on && tilt.beta === null) tiltNote("No tilt sensor answered: this device has none.");
  }, 1500);
}

export function tiltOff() {
  if (tilt.on && pages()) command("page direction");
  tilt.on = false;
  $("tilt-on").setAttribute("aria-pressed", "false");
  release("tilt");
}

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

export function setUpTilt() {
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
  requestAnimationFrame(pollGamepad);
}
