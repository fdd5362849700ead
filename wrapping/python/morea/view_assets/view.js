// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The front navigator page: plain JavaScript and SVG, no libraries.
"use strict";

const SVG = "http://www.w3.org/2000/svg";
const state = { run: null, selected: null, axis: "axial", slices: {}, order: [] };
const $ = (id) => document.getElementById(id);

function svgElement(name, attributes, parent) {
  const e = document.createElementNS(SVG, name);
  for (const [k, v] of Object.entries(attributes || {})) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}

function format(v) {
  if (v === null || v === undefined || Number.isNaN(v)) return "n/a";
  if (typeof v !== "number") return String(v);
  const a = Math.abs(v);
  if (a !== 0 && (a < 1e-3 || a >= 1e5)) return v.toExponential(3);
  return Number(v.toPrecision(4)).toString();
}

function range(values) {
  let lo = Math.min(...values), hi = Math.max(...values);
  if (!(hi > lo)) { const pad = Math.abs(lo) * 0.5 || 1e-9; lo -= pad; hi += pad; }
  const pad = (hi - lo) * 0.05;
  return [lo - pad, hi + pad];
}

function ticks(lo, hi, wanted) {
  const raw = (hi - lo) / (wanted || 5);
  const magnitude = Math.pow(10, Math.floor(Math.log10(raw)));
  let step = magnitude;
  for (const m of [1, 2, 2.5, 5, 10]) { if (m * magnitude >= raw) { step = m * magnitude; break; } }
  const out = [];
  for (let t = Math.ceil(lo / step) * step; t <= hi + step * 1e-9; t += step) out.push(Math.abs(t) < step * 1e-9 ? 0 : t);
  return out;
}

// Dark blue to yellow, as the plots' colour of the third objective.
function sequential(t) {
  const stops = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
  t = Math.min(1, Math.max(0, t || 0)) * 4;
  const i = Math.min(3, Math.floor(t)), f = t - i;
  const c = stops[i].map((a, k) => Math.round(a + (stops[i + 1][k] - a) * f));
  return `rgb(${c[0]},${c[1]},${c[2]})`;
}

function drawScatter() {
  const svg = $("scatter");
  svg.innerHTML = "";
  const front = state.run.front;
  const xo = $("x-objective").value, yo = $("y-objective").value;
  const co = state.run.objectives.find((o) => o !== xo && o !== yo);
  $("colour-note").textContent = `colour: rank of ${co} (dark = low)`;
  const W = +svg.getAttribute("width"), H = +svg.getAttribute("height");
  const box = { left: 80, top: 16, width: W - 100, height: H - 70 };
  const [x0, x1] = range(front.map((s) => s[xo])), [y0, y1] = range(front.map((s) => s[yo]));
  // Colour by rank of the third objective: a few outliers do not flatten the scale.
  const rank = new Map([...front].sort((a, b) => a[co] - b[co]).map((s, r) => [s.index, r]));
  const shade = (s) => sequential(front.length > 1 ? rank.get(s.index) / (front.length - 1) : 0.5);
  const X = (v) => box.left + (v - x0) / (x1 - x0) * box.width;
  const Y = (v) => box.top + box.height - (v - y0) / (y1 - y0) * box.height;
  for (const t of ticks(x0, x1)) {
    svgElement("line", { x1: X(t), x2: X(t), y1: box.top, y2: box.top + box.height, class: "grid-line" }, svg);
    svgElement("text", { x: X(t), y: box.top + box.height + 16, "text-anchor": "middle" }, svg).textContent = format(t);
  }
  for (const t of ticks(y0, y1)) {
    svgElement("line", { x1: box.left, x2: box.left + box.width, y1: Y(t), y2: Y(t), class: "grid-line" }, svg);
    svgElement("text", { x: box.left - 6, y: Y(t) + 4, "text-anchor": "end" }, svg).textContent = format(t);
  }
  svgElement("rect", { x: box.left, y: box.top, width: box.width, height: box.height, fill: "none", class: "axis-line" }, svg);
  svgElement("text", { x: box.left + box.width / 2, y: H - 12, "text-anchor": "middle" }, svg).textContent = xo;
  svgElement("text", { x: 16, y: box.top + box.height / 2, "text-anchor": "middle",
    transform: `rotate(-90 16 ${box.top + box.height / 2})` }, svg).textContent = yo;
  for (const s of front) {
    const c = svgElement("circle", { cx: X(s[xo]), cy: Y(s[yo]), r: 5, class: "point", "data-index": s.index,
      fill: shade(s) }, svg);
    const title = svgElement("title", {}, c);
    title.textContent = `solution ${s.id}${s.chosen ? " (" + s.chosen + ")" : ""}\nmagnitude ${format(s.magnitude)}\n` +
      `intensity ${format(s.intensity)}\nguidance ${format(s.guidance)}`;
    c.addEventListener("click", () => select(s.index));
    if (s.chosen) svgElement("circle", { cx: X(s[xo]), cy: Y(s[yo]), r: 9, class: "chosen-ring" }, svg);
  }
  markSelected();
}

function drawParallel() {
  const svg = $("parallel");
  svg.innerHTML = "";
  const front = state.run.front, objectives = state.run.objectives;
  const W = +svg.getAttribute("width"), H = +svg.getAttribute("height");
  const top = 30, bottom = H - 30, left = 70, right = W - 70;
  const ranges = objectives.map((o) => range(front.map((s) => s[o])));
  const X = (k) => left + k * (right - left) / (objectives.length - 1);
  const Y = (k, v) => bottom - (v - ranges[k][0]) / (ranges[k][1] - ranges[k][0]) * (bottom - top);
  for (const s of front) {
    const points = objectives.map((o, k) => `${X(k)},${Y(k, s[o])}`).join(" ");
    const line = svgElement("polyline", { points, class: "line", "data-index": s.index }, svg);
    svgElement("title", {}, line).textContent = `solution ${s.id}`;
    line.addEventListener("click", () => select(s.index));
  }
  objectives.forEach((o, k) => {
    svgElement("line", { x1: X(k), x2: X(k), y1: top, y2: bottom, class: "axis-line" }, svg);
    svgElement("text", { x: X(k), y: top - 10, "text-anchor": "middle" }, svg).textContent = o;
    const values = front.map((s) => s[o]);
    svgElement("text", { x: X(k), y: bottom + 16, "text-anchor": "middle" }, svg).textContent =
      "min " + format(Math.min(...values));
    svgElement("text", { x: X(k) + 4, y: top + 4, "text-anchor": "start" }, svg).textContent =
      "max " + format(Math.max(...values));
  });
  markSelected();
}

function markSelected() {
  document.querySelectorAll("#scatter circle.point, #parallel polyline.line").forEach((e) => {
    e.classList.toggle("selected", +e.dataset.index === state.selected);
  });
  const line = document.querySelector(`#parallel polyline[data-index="${state.selected}"]`);
  if (line) line.parentNode.appendChild(line); // on top
}

function sliceUrl() {
  const p = new URLSearchParams({ solution: state.selected, axis: state.axis, slice: state.slices[state.axis],
    view: $("view").value, contours: $("contours").checked ? "1" : "0", width: "512" });
  return "/api/slice?" + p.toString();
}

function showSlice() {
  if (state.selected === null) return;
  const size = state.run.layout.size;
  const count = { sagittal: size[0], coronal: size[1], axial: size[2] }[state.axis];
  const slider = $("slice");
  slider.max = count - 1;
  slider.value = state.slices[state.axis];
  $("slice-label").textContent = `${state.axis} ${state.slices[state.axis]} of ${count - 1}`;
  document.querySelectorAll("button.axis").forEach((b) => b.classList.toggle("active", b.dataset.axis === state.axis));
  const img = $("slice-image"), url = sliceUrl(), solution = state.selected;
  $("loading").textContent = "rendering...";
  img.dataset.loaded = "";
  img.onload = () => { img.dataset.loaded = url; img.dataset.solution = solution; $("loading").textContent = ""; };
  img.onerror = () => { $("loading").textContent = "could not render this slice"; };
  img.src = url;
}

function legend() {
  const box = $("legend");
  box.innerHTML = "";
  const layout = state.run.layout;
  layout.structures.forEach((name, i) => {
    const item = document.createElement("span");
    item.innerHTML = `<span class="swatch" style="background:${layout.colors[i]}"></span>` +
      `<span class="swatch dashed" style="border-color:${layout.colors[i]}"></span>${name}`;
    box.appendChild(item);
  });
  const note = document.createElement("span");
  note.textContent = "solid: fixed contour, dashed: warped moving contour; Jacobian: blue < 1 < red, black: folded";
  box.appendChild(note);
}

function scoresTable(entry) {
  const s = entry.scores || {};
  let html = "<table><tr><th>objective</th><th>value</th></tr>";
  for (const o of state.run.objectives) html += `<tr><td>${o}</td><td>${format(entry[o])}</td></tr>`;
  html += "</table>";
  const structures = s.structures || {};
  const baseline = (state.run.rigid_baseline || {}).structures || {};
  if (Object.keys(structures).length) {
    html += "<table><tr><th>structure</th><th>Dice</th><th>Dice rigid</th><th>HD95 mm</th><th>HD mm</th>" +
      "<th>mean surface mm</th></tr>";
    for (const [name, v] of Object.entries(structures)) {
      const b = baseline[name] || {};
      html += `<tr><td>${name}</td><td>${format(v.dice)}</td><td>${format(b.dice)}</td><td>${format(v.hausdorff95_mm)}</td>` +
        `<td>${format(v.hausdorff_mm)}</td><td>${format(v.mean_surface_distance_mm)}</td></tr>`;
    }
    html += "</table>";
  }
  html += "<table><tr><th>deformation</th><th>value</th></tr>";
  html += `<tr><td>Jacobian determinant min</td><td>${format(s.jacobian_min)}</td></tr>`;
  html += `<tr><td>Jacobian determinant max</td><td>${format(s.jacobian_max)}</td></tr>`;
  if (s.jacobian_nonpositive_fraction !== undefined)
    html += `<tr><td>folded voxels (fraction)</td><td>${format(s.jacobian_nonpositive_fraction)}</td></tr>`;
  if (s.inverse_consistency) html += `<tr><td>inverse consistency mean mm</td><td>${format(s.inverse_consistency.mean_mm)}</td></tr>`;
  if (s.landmarks) html += `<tr><td>landmark TRE mean mm (${s.landmarks.count})</td><td>${format(s.landmarks.tre_mean_mm)}</td></tr>`;
  html += "</table>";
  return html;
}

async function showScores(index) {
  const box = $("scores");
  box.dataset.solution = "";
  box.innerHTML = '<p class="hint">scoring...</p>';
  const response = await fetch(`/api/scores?solution=${index}`);
  const entry = await response.json();
  if (index !== state.selected) return; // another solution was chosen meanwhile
  if (!response.ok) { box.innerHTML = `<p class="error">${entry.error}</p>`; return; }
  box.innerHTML = scoresTable(entry);
  box.dataset.solution = index;
}

function select(index) {
  if (index === state.selected) return;
  state.selected = index;
  const s = state.run.front[index];
  $("solution-title").textContent = `Solution ${s.id}` + (s.chosen ? ` (${s.chosen})` : "") +
    `, ${state.order.indexOf(index) + 1} of ${state.run.front.length} by guidance`;
  $("export").disabled = false;
  $("export-status").textContent = "";
  $("export-status").className = "";
  markSelected();
  showSlice();
  showScores(index);
}

async function exportSolution() {
  const index = state.selected, status = $("export-status");
  status.className = "";
  status.textContent = "exporting...";
  status.dataset.folder = "";
  const response = await fetch(`/api/export?solution=${index}`, { method: "POST" });
  const result = await response.json();
  if (!response.ok) { status.className = "error"; status.textContent = result.error; return; }
  status.textContent = `written to ${result.folder}: ${result.files.join(", ")}`;
  status.dataset.folder = result.folder;
}

async function start() {
  const response = await fetch("/api/run");
  const run = await response.json();
  if (!response.ok) { $("run-info").textContent = run.error; return; }
  state.run = run;
  state.slices = Object.assign({}, run.layout.focus_slices);
  state.order = run.front.map((s) => s.index).sort((a, b) => run.front[a].guidance - run.front[b].guidance);
  const info = run.run || {};
  $("run-info").textContent = `${run.folder}: ${run.front.length} solutions` +
    (info.generations ? `, ${info.generations} generations` : "") + (info.backend ? `, ${info.backend}` : "") +
    (run.layout.focus ? `; slices through ${run.layout.focus}, the structure that changes most` : "");
  for (const [id, initial] of [["x-objective", "guidance"], ["y-objective", "intensity"]]) {
    const select_ = $(id);
    for (const o of run.objectives) select_.add(new Option(o, o, o === initial, o === initial));
    select_.addEventListener("change", drawScatter);
  }
  drawScatter();
  drawParallel();
  legend();
  document.querySelectorAll("button.axis").forEach((b) => b.addEventListener("click", () => {
    state.axis = b.dataset.axis; showSlice();
  }));
  $("view").addEventListener("change", showSlice);
  $("contours").addEventListener("change", showSlice);
  $("slice").addEventListener("input", () => { state.slices[state.axis] = +$("slice").value; showSlice(); });
  $("image-box").addEventListener("wheel", (event) => {
    if (state.selected === null) return;
    event.preventDefault();
    const max = +$("slice").max;
    state.slices[state.axis] = Math.min(max, Math.max(0, state.slices[state.axis] + (event.deltaY > 0 ? 1 : -1)));
    showSlice();
  }, { passive: false });
  document.addEventListener("keydown", (event) => {
    if (event.target.tagName === "INPUT" || event.target.tagName === "SELECT") return;
    if (event.key !== "ArrowLeft" && event.key !== "ArrowRight") return;
    const at = state.selected === null ? -1 : state.order.indexOf(state.selected);
    const next = Math.min(state.order.length - 1, Math.max(0, at + (event.key === "ArrowRight" ? 1 : -1)));
    select(state.order[next]);
  });
  $("export").addEventListener("click", exportSolution);
  const first = run.front.findIndex((s) => s.chosen);
  select(first >= 0 ? first : state.order[0]);
  document.body.dataset.ready = "1";
}

start();
