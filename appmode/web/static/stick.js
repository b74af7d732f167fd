// The round joystick. On the APP port it is the app's direction page: eight sectors, a
// dead zone in the middle, the sector under the finger held as a key is. On UART2 it is
// analog: the farther from the centre, the faster. Either way, letting go stops the car.
import { SEND } from "./messages.js";
import { $, HEARTBEAT_MS, page, press, release, releaseAll, send } from "./link.js";

const SECTORS = ["right", "front-right", "forward", "front-left", "left", "rear-left",
  "backward", "rear-right"]; // by angle, counter-clockwise from the right
const ARROWS = ["→", "↗", "↑", "↖", "←", "↙", "↓", "↘"]; // each sector's label, in that order
const STICK_DEAD_ZONE = 0.28; // of the radius
const stick = { id: null, x: 0, y: 0, beat: null };
let usePad = localStorage.getItem("appmode-control") === "pad";

export const analog = () => Boolean(page.status && page.status.commands.includes("velocity"));

export function sector(dx, dy) { // dx right, dy forward: the name of the 45° sector
  const angle = (Math.atan2(dy, dx) * 180) / Math.PI;
  return SECTORS[((Math.round(angle / 45) % 8) + 8) % 8];
}

function drawSectors() {
  const wedge = (i) => {
    const point = (degrees, r) => {
      const a = (degrees * Math.PI) / 180;
      return `${(r * Math.cos(a)).toFixed(1)} ${(-r * Math.sin(a)).toFixed(1)}`;
    };
    const [from, to] = [i * 45 - 22.5, i * 45 + 22.5];
    return `M${point(from, 28)} L${point(from, 98)} A98 98 0 0 0 ${point(to, 98)} L${point(to, 28)} A28 28 0 0 1 ${point(from, 28)}Z`;
  };
  const svg = (tag) => document.createElementNS("http://www.w3.org/2000/svg", tag);
  $("sectors").replaceChildren(...SECTORS.flatMap((name, i) => {
    const path = svg("path");
    path.setAttribute("d", wedge(i));
    path.dataset.name = name;
    const label = svg("text"); // where the finger goes for it
    const a = (i * 45 * Math.PI) / 180;
    label.setAttribute("x", (64 * Math.cos(a)).toFixed(1));
    label.setAttribute("y", (-64 * Math.sin(a)).toFixed(1));
    label.textContent = ARROWS[i];
    return [path, label];
  }));
}

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
  if (!analog()) {
    const name = Math.hypot(x, y) < STICK_DEAD_ZONE ? null : sector(x, y);
    document.querySelectorAll("#sectors path").forEach((path) => {
      path.classList.toggle("lit", path.dataset.name === name);
    });
    if (name === null) release("joystick"); else press("joystick", name);
    return;
  }
  if (x !== stick.x || y !== stick.y || stick.beat === null) {
    stick.x = x;
    stick.y = y;
    send({ t: SEND.stick, x, y });
  }
}

function letGo(event) {
  if (event.pointerId !== stick.id) return;
  stick.id = null;
  $("knob").style.transform = "";
  document.querySelectorAll("#sectors path").forEach((path) => path.classList.remove("lit"));
  if (stick.beat !== null) {
    clearInterval(stick.beat);
    stick.beat = null;
    send({ t: SEND.release });
  } else {
    release("joystick");
  }
}

export function setUpStick() {
  drawSectors();
  $("stick").addEventListener("pointerdown", (event) => {
    event.preventDefault();
    $("stick").setPointerCapture(event.pointerId);
    stick.id = event.pointerId;
    stick.beat = null;
    stickAt(event);
    if (analog()) {
      stick.beat = setInterval(() => send({ t: SEND.stick, x: stick.x, y: stick.y }), HEARTBEAT_MS);
    }
  });
  $("stick").addEventListener("pointermove", (event) => {
    if (event.pointerId === stick.id) stickAt(event);
  });
  for (const name of ["pointerup", "pointercancel", "lostpointercapture"]) {
    $("stick").addEventListener(name, letGo);
  }
  $("stick").addEventListener("contextmenu", (event) => event.preventDefault());
  $("stop-now").addEventListener("click", () => { // always there, whatever drives
    releaseAll();
    send({ t: SEND.stop });
  });
  $("use-pad").addEventListener("click", () => {
    usePad = !usePad;
    localStorage.setItem("appmode-control", usePad ? "pad" : "stick");
    if (page.status) showControl(page.status);
  });
}

export function showControl(message) {
  const buttonPage = message.instruments.page === "button";
  const pad = usePad || buttonPage;
  $("pad").hidden = !pad;
  $("stick").hidden = pad;
  $("stick").classList.toggle("analog", analog());
  $("use-pad").hidden = buttonPage;
  $("use-pad").setAttribute("aria-pressed", String(usePad));
  if (stick.id === null) { // driven another way (a key, the gamepad, tilt): the sector lights
    const lit = message.lit && message.cells[message.lit[0]][message.lit[1]];
    document.querySelectorAll("#sectors path").forEach((path) => {
      path.classList.toggle("lit", path.dataset.name === lit);
    });
  }
}
