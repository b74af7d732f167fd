// The parameters (or settings) as sliders and fields, each set by the command line's
// `set` and verified by the session; what is not saved to flash is marked.
import { $, command } from "./link.js";

const SLIDER_STEPS = 1000;

function toSlider(value, low, high) { // wide ranges are logarithmic: fine near 0, reaching the top
  if (high - low <= SLIDER_STEPS) return value;
  return Math.round((Math.log1p(value - low) / Math.log1p(high - low)) * SLIDER_STEPS);
}

function fromSlider(position, low, high) {
  if (high - low <= SLIDER_STEPS) return position;
  return low + Math.round(Math.expm1((position / SLIDER_STEPS) * Math.log1p(high - low)));
}

function user(frame, scale) { // the frame's integer as the user's value: 42 at scale 100 is 0.42
  if (scale === 1) return String(frame);
  const digits = Math.max(0, Math.ceil(Math.log10(scale)));
  return String(Number((frame / scale).toFixed(digits)));
}

export function showParams(values, read) {
  const box = $("values");
  if (!read && !box.children.length) {
    box.textContent = "Not read yet: Read asks the board.";
  }
  if (!read) return;
  if (box.dataset.names !== values.map((v) => v.name).join()) {
    box.dataset.names = values.map((v) => v.name).join();
    box.replaceChildren(...values.map((v) => paramRow(v)));
    const first = values[0]; // the command line's example, in this board's own names
    const example = first && first.value !== null ? user(first.value, first.scale) : "";
    if (first) $("line").placeholder = `set ${first.name} ${example} · save · help`;
  }
  values.forEach((v, i) => {
    const row = box.children[i];
    row.classList.toggle("unsaved", v.unsaved);
    row.querySelector(".value").textContent = v.value === null ? "?" : user(v.value, v.scale);
    const slider = row.querySelector("input[type=range]");
    if (v.value !== null && document.activeElement !== slider && !slider.dataset.moved) {
      slider.value = String(toSlider(v.value, v.minimum, v.maximum));
    }
  });
  const unsaved = values.filter((v) => v.unsaved).map((v) => v.name);
  $("unsaved").hidden = !unsaved.length;
  $("unsaved").textContent = `Not saved to flash: ${unsaved.join(", ")}`;
}

function paramRow(v) {
  const row = document.createElement("div");
  row.className = "param";
  row.innerHTML = '<div class="head"><span class="name"></span><span class="value"></span></div>'
    + '<div class="edit"><input type="range"><input type="number" inputmode="numeric">'
    + '<button type="button">Set</button></div>';
  const [low, high] = [user(v.minimum, v.scale), user(v.maximum, v.scale)];
  row.querySelector(".name").textContent = `${v.name} (${low}–${high})`;
  const [slider, input] = row.querySelectorAll("input");
  const wide = v.maximum - v.minimum > SLIDER_STEPS;
  Object.assign(slider, { min: wide ? 0 : v.minimum, max: wide ? SLIDER_STEPS : v.maximum, step: 1 });
  Object.assign(input, { min: low, max: high, step: user(1, v.scale) }); // the user's units
  if (v.scale !== 1) input.inputMode = "decimal";
  if (v.minimum === v.maximum) { // taken and ignored by the firmware: nothing to set
    [slider, input, row.querySelector("button")].forEach((e) => { e.disabled = true; });
  }
  slider.setAttribute("aria-label", `${v.name} slider`);
  input.setAttribute("aria-label", `new ${v.name}`);
  slider.addEventListener("input", () => {
    slider.dataset.moved = "1";
    input.value = user(fromSlider(Number(slider.value), v.minimum, v.maximum), v.scale);
  });
  const button = row.querySelector("button");
  button.setAttribute("aria-label", `set ${v.name}`);
  button.addEventListener("click", () => {
    if (input.value.trim()) command(`set ${v.name} ${input.value.trim()}`);
    input.value = "";
    delete slider.dataset.moved;
  });
  return row;
}
