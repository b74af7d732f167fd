// The 3×3 pad and the keys: a cell held (a finger, the mouse, a key) drives, letting go
// stops; the keys besides the grid (a turn) hold the same way.
import { $, HEARTBEAT_MS, press, release, releaseAll } from "./link.js";

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

export function setUpPad() {
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
}

export function showPad(cells, lit, extra) {
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
      button.textContent = GLYPHS[name] || name;
      button.title = name;
      holdable(button, () => name);
      return button;
    }));
  }
}
