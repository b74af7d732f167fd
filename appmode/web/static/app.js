// appmode web: the pad, tilt, gamepad, parameters, waveforms and the command line over
// one websocket. The page says it is alive every HEARTBEAT_MS, and a held direction is
// sent again as often; the server stops the car when either stops coming (a dropped
// network, a frozen page), however the motion began, and on every release.
"use strict";

const HEARTBEAT_MS = 100;
const RECONNECT_MS = 1000;
const GONE_AFTER = 2; // failed reconnections after which the server is called gone
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

// ---------------------------------------------------------------- the joystick

// On the APP port the stick is the app's direction page: eight sectors, a dead zone in
// the middle, the sector under the finger held as a key is. On UART2 it is analog: the
// farther from the centre, the faster. Either way, letting go stops the car.
const STICK_DEAD_ZONE = 0.28; // of the radius
const stick = { id: null, x: 0, y: 0, beat: null };
const analog = () => Boolean(status && status.commands.includes("velocity"));

function drawSectors() {
  const wedge = (i) => {
    const point = (degrees, r) => {
      const a = (degrees * Math.PI) / 180;
      return `${(r * Math.cos(a)).toFixed(1)} ${(-r * Math.sin(a)).toFixed(1)}`;
    };
    const [from, to] = [i * 45 - 22.5, i * 45 + 22.5];
    return `M${point(from, 28)} L${point(from, 98)} A98 98 0 0 0 ${point(to, 98)} L${point(to, 28)} A28 28 0 0 1 ${point(from, 28)}Z`;
  };
  $("sectors").replaceChildren(...SECTORS.map((name, i) => {
    const path = document.createElementNS("http://www.w3.org/2000/svg", "path");
    path.setAttribute("d", wedge(i));
    path.dataset.name = name;
    return path;
  }));
}
drawSectors();

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
    send({ t: "stick", x, y });
  }
}

$("stick").addEventListener("pointerdown", (event) => {
  event.preventDefault();
  $("stick").setPointerCapture(event.pointerId);
  stick.id = event.pointerId;
  stick.beat = null;
  stickAt(event);
  if (analog()) {
    stick.beat = setInterval(() => send({ t: "stick", x: stick.x, y: stick.y }), HEARTBEAT_MS);
  }
});
$("stick").addEventListener("pointermove", (event) => {
  if (event.pointerId === stick.id) stickAt(event);
});
for (const name of ["pointerup", "pointercancel", "lostpointercapture"]) {
  $("stick").addEventListener(name, (event) => {
    if (event.pointerId !== stick.id) return;
    stick.id = null;
    $("knob").style.transform = "";
    document.querySelectorAll("#sectors path").forEach((path) => path.classList.remove("lit"));
    if (stick.beat !== null) {
      clearInterval(stick.beat);
      stick.beat = null;
      send({ t: "release" });
    } else {
      release("joystick");
    }
  });
}
$("stick").addEventListener("contextmenu", (event) => event.preventDefault());
$("rotate").addEventListener("click", () => command(`rotate ${$("angle").value.trim()}`));

let usePad = localStorage.getItem("appmode-control") === "pad";
$("use-pad").addEventListener("click", () => {
  usePad = !usePad;
  localStorage.setItem("appmode-control", usePad ? "pad" : "stick");
  if (status) showControl(status);
});

function showControl(message) {
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
      button.textContent = GLYPHS[name] || name;
      button.title = name;
      holdable(button, () => name);
      return button;
    }));
  }
}

// ---------------------------------------------------------------- instruments

const LINK_WORDS = {
  up: "link up", late: "link late", degraded: "link degraded", lost: "LINK LOST",
  opening: "port open", silent: "port silent",
};

function linkText(link, noun) {
  if (link.state === "lost") return "LINK LOST";
  if (link.age === null) return LINK_WORDS[link.state];
  const errors = link.recent_errors ? ` · ${link.recent_errors} errors in 5 s` : "";
  const late = link.state === "late" ? ` · ${link.age.toFixed(1)} s ago` : "";
  return `${LINK_WORDS[link.state]} · ${Math.round(link.rate)} ${noun}/s${errors}${late}`;
}

function showInstruments(ins) {
  const noun = analog() ? "messages" : "records";
  $("link").textContent = linkText(ins.link, noun);
  $("link").className = `chip ${ins.link.state}`;
  $("in-force").textContent = ins.stop_unsent
    ? `${ins.in_force} — NOT STOPPED: the link to the car is down, it may still be moving`
    : ins.in_force;
  $("force-tile").classList.toggle("moving", ins.moving);
  $("force-tile").classList.toggle("unsent", ins.stop_unsent);
  $("page-name").textContent = ins.page ? `${ins.page} page` : "";
  $("tilt-page").textContent = ins.page || "";
  $("tilt-page-line").hidden = !ins.page;
  const speed = ins.speed; // null: the profile has no speed parameter (the keys change nothing)
  $("speed-name").textContent = speed ? speed.name : "speed";
  $("speed").textContent = !speed ? "fixed" : speed.value === null ? "—" : String(speed.value);
  $("slower").disabled = $("faster").disabled = !speed;
  const t = ins.telemetry;
  const fresh = (age) => age !== null && age <= 0.5;
  $("measured").textContent = t && t.speed !== null ? `now ${Math.round(t.speed)}` : "";
  $("dials").hidden = !t || !t.has_attitude;
  $("battery-text").textContent = "— (no APP port)";
  if (t) {
    $("battery").value = t.battery === null ? 0 : Math.max(0, Math.min(100, t.battery));
    $("battery-text").textContent = t.battery === null ? "—" : `${t.battery} %`;
    $("battery-tile").classList.toggle("stale", !fresh(t.battery_age));
    $("dials").classList.toggle("stale", !fresh(t.attitude_age));
    if (t.yaw !== null) {
      $("needle").setAttribute("transform", `rotate(${t.yaw})`);
      $("heading").setAttribute("aria-label", `heading ${t.yaw}°`);
      const clamp = (v) => Math.max(-30, Math.min(30, v));
      const [bx, by] = [clamp(t.roll), clamp(-t.pitch)];
      $("bubble").setAttribute("cx", String(bx));
      $("bubble").setAttribute("cy", String(by));
      $("attitude").setAttribute("aria-label", `pitch ${t.pitch}°, roll ${t.roll}°`);
      $("yaw").textContent = `${t.yaw}°`;
      $("tilt-values").textContent = `pitch ${t.pitch}° roll ${t.roll}°`;
    }
    const fields = [...(t.motion || []), ...(t.b || [])]; // a profile's own B record too
    $("motion").textContent = fields.map(([name, v]) => `${name} ${v}`).join("  ");
    $("motion").classList.toggle("stale", !fresh(t.motion_age));
    $("measured").classList.toggle("stale", !fresh(t.motion_age));
  }
  $("driver-tile").hidden = ins.driver === null;
  $("battery-tile").classList.toggle("wide", ins.driver === null);
  $("driver").textContent = ins.driver === null ? "" : ins.driver;
  $("wheels-tile").hidden = ins.driver === null;
  showWheels(ins.wheels, ins.wheels_age, speed ? speed.value : null);
  showParams(ins.values, ins.values_read);
}

function showWheels(wheels, age, speed) {
  const box = $("wheels");
  if (!wheels) {
    box.textContent = "— (the encoder report is off, or none came yet)";
    return;
  }
  const top = Math.max(1, speed || 0, ...wheels.flatMap((w) => [Math.abs(w.target), Math.abs(w.actual)]));
  const bar = (kind, v) => {
    const part = document.createElement("span");
    part.className = kind;
    const width = (Math.abs(v) / top) * 50;
    part.style.width = `${width}%`;
    if (v < 0) part.style.left = `${50 - width}%`;
    return part;
  };
  box.classList.toggle("stale", age === null || age > 0.5);
  box.replaceChildren(...wheels.map((w) => {
    const row = document.createElement("div");
    row.className = "wheel";
    const bars = document.createElement("div");
    bars.className = "bars";
    bars.append(bar("target", w.target), bar("actual", w.actual));
    bars.setAttribute("role", "img");
    bars.setAttribute("aria-label", `wheel ${w.name}: target ${w.target}, actual ${w.actual}`);
    const [name, numbers] = [document.createElement("span"), document.createElement("span")];
    name.textContent = w.name.toUpperCase();
    numbers.textContent = `${w.target}/${w.actual}`;
    row.append(name, bars, numbers);
    return row;
  }));
}

// ---------------------------------------------------------------- parameters

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

function showParams(values, read) {
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

// ---------------------------------------------------------------- waveforms

const hiddenChannels = new Set();
let paused = false;
let lastTraces = null;

$("pause").addEventListener("click", () => {
  paused = !paused;
  $("pause").setAttribute("aria-pressed", String(paused));
  $("pause").textContent = paused ? "Resume" : "Pause";
});

function showChannels(traces) {
  const box = $("channels");
  const names = traces.series.map((s) => s.label).join();
  if (box.dataset.names === names) return;
  box.dataset.names = names;
  box.replaceChildren(...traces.series.map((series, i) => {
    const button = document.createElement("button");
    button.type = "button";
    button.textContent = series.label;
    button.style.borderBottom = `4px solid ${channelColour(i)}`;
    button.setAttribute("aria-pressed", String(!hiddenChannels.has(series.label)));
    button.addEventListener("click", () => {
      if (hiddenChannels.has(series.label)) hiddenChannels.delete(series.label);
      else hiddenChannels.add(series.label);
      button.setAttribute("aria-pressed", String(!hiddenChannels.has(series.label)));
      drawWaves(lastTraces);
    });
    return button;
  }));
}

function channelColour(i) { return `hsl(${(i * 67) % 360}, 75%, 42%)`; }

function niceStep(span, count) { // 1, 2 or 5 × a power of ten: about `count` ticks
  const raw = span / count;
  const power = 10 ** Math.floor(Math.log10(raw));
  return [1, 2, 5, 10].map((m) => m * power).find((step) => step >= raw);
}

function showWaves(traces) {
  if (!traces || $("waves").hidden) return;
  showChannels(traces);
  if (paused) return;
  lastTraces = traces;
  drawWaves(traces);
}

function drawWaves(traces) {
  if (!traces) return;
  const canvas = $("chart");
  const ratio = window.devicePixelRatio || 1;
  const [width, height] = [canvas.clientWidth, canvas.clientHeight];
  if (canvas.width !== Math.round(width * ratio)) canvas.width = Math.round(width * ratio);
  if (canvas.height !== Math.round(height * ratio)) canvas.height = Math.round(height * ratio);
  const ctx = canvas.getContext("2d");
  ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
  ctx.clearRect(0, 0, width, height);
  const ink = getComputedStyle(document.body).color;
  ctx.font = "12px system-ui, sans-serif";
  const shown = traces.series.map((series, i) => [series, i]).filter(([s]) => !hiddenChannels.has(s.label));
  const [left, right, axis] = [44, 6, 18]; // room for the scale, the edge, the time axis
  const plotWidth = width - left - right;
  const strip = (height - axis) / Math.max(1, shown.length);
  const xAt = (ago) => left + plotWidth * (1 - ago / traces.seconds);
  ctx.strokeStyle = "rgba(128, 128, 128, 0.35)";
  ctx.fillStyle = ink;
  ctx.textAlign = "center";
  for (let ago = 0; ago <= traces.seconds; ago += 2) { // the time axis: a tick every 2 s
    ctx.beginPath();
    ctx.moveTo(xAt(ago), 0);
    ctx.lineTo(xAt(ago), height - axis);
    ctx.stroke();
    ctx.fillText(ago ? `−${ago} s` : "now", Math.min(xAt(ago), width - 16), height - 4);
  }
  shown.forEach(([series, i], row) => {
    const top = row * strip;
    const values = series.points.map((p) => p[1]);
    let [low, high] = values.length ? [Math.min(...values), Math.max(...values)] : [0, 1];
    if (high - low < 1) { low -= 1; high += 1; }
    const step = niceStep(high - low, Math.max(1, Math.floor(strip / 28)));
    [low, high] = [Math.floor(low / step) * step, Math.ceil(high / step) * step];
    const yAt = (v) => top + strip - 3 - ((v - low) / (high - low)) * (strip - 16);
    ctx.textAlign = "right";
    ctx.fillStyle = ink;
    for (let v = low; v <= high + step / 2; v += step) { // the scale, fitting the data
      ctx.strokeStyle = "rgba(128, 128, 128, 0.35)";
      ctx.beginPath();
      ctx.moveTo(left, yAt(v));
      ctx.lineTo(width - right, yAt(v));
      ctx.stroke();
      ctx.fillText(String(Math.round(v * 100) / 100), left - 4, yAt(v) + 4);
    }
    ctx.strokeStyle = channelColour(i);
    ctx.lineWidth = 2;
    ctx.beginPath();
    series.points.forEach(([ago, value], j) => {
      if (j === 0) ctx.moveTo(xAt(ago), yAt(value)); else ctx.lineTo(xAt(ago), yAt(value));
    });
    ctx.stroke();
    ctx.lineWidth = 1;
    ctx.textAlign = "left";
    ctx.fillStyle = channelColour(i);
    const last = values.length ? values[values.length - 1] : "—";
    ctx.fillText(`${series.label} ${last} ${series.unit}`, left + 4, top + 12);
  });
}

function showStatus(message) {
  status = message;
  $("title").textContent = message.title.replace("appmode drive", "appmode web");
  $("badge").textContent = message.simulated ? "SIMULATED" : "REAL BOARD";
  $("badge").className = `badge ${message.simulated ? "simulated" : "real"}`;
  $("url").textContent = message.url;
  const driving = message.role === "driver";
  $("role-text").textContent = driving
    ? "This page drives the car."
    : `This page watches (${message.pages} pages open): another page drives.`;
  $("take").hidden = driving;
  document.body.classList.toggle("watching", !driving);
  const page = message.instruments.page;
  $("pages").hidden = !message.commands.includes("page");
  document.querySelectorAll("#pages button").forEach((button) => {
    const on = button.dataset.page === "button" ? page === "button" : page !== "button";
    button.setAttribute("aria-pressed", String(on));
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
  socket.addEventListener("open", () => { failures = 0; });
  socket.addEventListener("close", () => {
    if (failures === 0) { // what the car was last told, as this page knows it
      wasMoving = current !== null || (status !== null && status.instruments.moving);
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
let failures = 0; // connections in a row that closed (or never opened)
let wasMoving = false; // the car was last told to move when the connection was lost
function lostConnection() {
  $("connection").hidden = false;
  const gone = failures > GONE_AFTER;
  const car = wasMoving
    ? "The car was last told to move: it may still be moving."
    : "The car was last told to stop.";
  $("connection").textContent = gone
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

connect();
setInterval(() => send({ t: "alive" }), HEARTBEAT_MS);

if ("serviceWorker" in navigator) {  // keeps the page's own files for "the server is not reachable"
  navigator.serviceWorker.register("/sw.js").catch(() => {});  // refused on a certificate the browser distrusts
}
