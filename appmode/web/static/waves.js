// The waveforms: the last seconds of the A and B records, a strip a channel, each with a
// scale that fits its data; channels hidden and the drawing paused by the user.
import { $ } from "./link.js";

const hiddenChannels = new Set();
let paused = false;
let lastTraces = null;

export function setUpWaves() {
  $("pause").addEventListener("click", () => {
    paused = !paused;
    $("pause").setAttribute("aria-pressed", String(paused));
    $("pause").textContent = paused ? "Resume" : "Pause";
  });
}

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

export function showWaves(traces) {
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
