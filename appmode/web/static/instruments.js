// What the car and the link are doing, as the page's instruments: the status rows (the
// console's, tone by tone), the link chip, what is in force, the speed, the battery,
// the dials and level, the wheels of the encoder report.
import { $ } from "./link.js";
import { showParams } from "./params.js";
import { analog } from "./stick.js";

const TONES = ["label", "on", "ok", "warn", "alert", "late", "low", "dim"];

function span(tone, text) {
  const element = document.createElement("span");
  if (TONES.includes(tone)) element.className = `tone-${tone}`;
  element.textContent = text;
  return element;
}

export function showRows(rows) {
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

const LINK_WORDS = {
  up: "link up", late: "link late", degraded: "link degraded", lost: "LINK LOST",
  opening: "port open", silent: "port silent",
};

function linkText(link, noun) {
  if (link.state === "lost") return "LINK LOST";
  if (link.age === null) return LINK_WORDS[link.state];
  const errors = link.recent_errors ? ` · ${link.recent_errors} errors in 5 s` : "";
  const late = link.state === "late" ? ` · ${link.age.toFixed(1)} s ago` : "";
  const latency = link.latency === null ? "" : ` · ${link.latency.toFixed(1)} ms`;
  return `${LINK_WORDS[link.state]} · ${Math.round(link.rate)} ${noun}/s${errors}${late}${latency}`;
}

export function showInstruments(ins) {
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
  if (ins.readings.length) { // a chassis port's status, in SI
    $("motion").textContent = ins.readings.map(([name, v]) => `${name} ${v}`).join("  ");
    $("motion").classList.toggle("stale", !fresh(ins.readings_age));
  }
  $("battery").hidden = ins.volts !== null; // a voltage is no percentage: no gauge
  if (ins.volts !== null) {
    $("battery-text").textContent = `${ins.volts.toFixed(2)} V`;
    $("battery-tile").classList.toggle("stale", !fresh(ins.readings_age));
  }
  $("driver-tile").hidden = ins.driver === null;
  $("battery-tile").classList.toggle("wide", ins.driver === null);
  $("driver").textContent = ins.driver === null ? "" : ins.driver;
  $("wheels-tile").hidden = ins.driver === null || ins.readings.length > 0;
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
