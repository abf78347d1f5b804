/*
 * hrm's run viewer: plays a run of a hyper-redundant arm (planar in its plane, spatial in 3-D)
 * in sync with its time series. One file, no dependencies, no network: the Rust crate run-view
 * embeds it in every page it writes (report.html, `hrm view`, Jupyter).
 *
 * The page holds one <div class="hrm-view"> per scene with a <script type="application/json">
 * child: {title, caption, runs: [RunView, ...]} (docs/run-view.md). Each run has `dims` (2 or
 * 3), sample times `t`, per sample the arm's points `joints` (flattened, base first), and
 * optionally `tip_ref`, `joint_torque`, `torque_limit`, `series`, `obstacles`, `channels`.
 *
 * The pure functions (sampling, projection, ticks, colours) are exported for node's tests
 * (viewer.test.js); in a browser the script mounts every .hrm-view of the page.
 */
(function (global, factory) {
  "use strict";
  const api = factory();
  if (typeof module === "object" && module.exports) {
    module.exports = api;
  } else {
    global.HrmViewer = api;
    const start = () => api.mountAll(global.document);
    if (global.document.readyState === "loading") {
      global.document.addEventListener("DOMContentLoaded", start);
    } else {
      start();
    }
  }
})(this, function () {
  "use strict";

  // ---- Sampling ----------------------------------------------------------------------------

  /** The sample at or before `time` and the fraction of the way to the next: {k, f}. */
  function sampleAt(t, time) {
    const n = t.length;
    if (n === 0 || !(time > t[0])) return { k: 0, f: 0 };
    if (time >= t[n - 1]) return { k: n - 1, f: 0 };
    let lo = 0;
    let hi = n - 1;
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (t[mid] <= time) lo = mid;
      else hi = mid;
    }
    return { k: lo, f: (time - t[lo]) / (t[hi] - t[lo]) };
  }

  /** Row `k` of `rows` moved the fraction `f` towards row `k + 1`. */
  function lerpRow(rows, at) {
    const a = rows[at.k];
    if (at.f === 0 || at.k + 1 >= rows.length) return a.slice();
    const b = rows[at.k + 1];
    return a.map((v, i) => v + (b[i] - v) * at.f);
  }

  /** The points of a flattened row of `dims` numbers each, as [x, y, z] (z = 0 when planar). */
  function points(row, dims) {
    const out = [];
    for (let i = 0; i + dims <= row.length; i += dims) {
      out.push([row[i], row[i + 1], dims === 3 ? row[i + 2] : 0]);
    }
    return out;
  }

  // ---- Numbers ----------------------------------------------------------------------------

  /**
   * About `count` round tick values covering [lo, hi] (never fewer than two, so that every
   * axis reads as a scale), and their step.
   */
  function niceTicks(lo, hi, count) {
    if (!(hi > lo)) {
      const pad = Math.abs(lo) > 0 ? Math.abs(lo) * 0.5 : 1;
      return niceTicks(lo - pad, hi + pad, count);
    }
    const raw = (hi - lo) / Math.max(1, count);
    const power = Math.pow(10, Math.floor(Math.log10(raw)));
    const step = [1, 2, 2.5, 5, 10].map((m) => m * power).find((s) => s >= raw);
    const ticks = [];
    for (let v = Math.ceil(lo / step - 1e-9) * step; v <= hi + step * 1e-9; v += step) {
      ticks.push(Math.abs(v) < step * 1e-9 ? 0 : v);
    }
    // A range that holds one multiple of the step gets a finer step.
    if (ticks.length < 2 && count < 64) return niceTicks(lo, hi, 2 * Math.max(1, count));
    return { ticks, step };
  }

  /** The multiples of `step` in [lo, hi], as `niceTicks` gives them. */
  function multiples(lo, hi, step) {
    const ticks = [];
    for (let k = Math.ceil(lo / step - 1e-9); k * step <= hi + step * 1e-9; k++) {
      ticks.push(k === 0 ? 0 : k * step);
    }
    return ticks;
  }

  /**
   * The square grid of a planar arm's panel of `width` x `height` pixels showing [x0, x1] x
   * [y0, y1] at one scale: one step on both axes (the finer of the two axes' nice steps, so that
   * neither shows a single line), and on each axis every `every`-th line labelled, so that labels
   * stay `minX` (x) and `minY` (y) pixels apart.
   */
  function squareGrid(x0, x1, y0, y1, width, height) {
    const xs = niceTicks(x0, x1, Math.max(2, Math.floor(width / 90)));
    const ys = niceTicks(y0, y1, Math.max(2, Math.floor(height / 70)));
    const step = Math.min(xs.step, ys.step);
    const pixels = (step * width) / (x1 - x0);
    const every = (min) => Math.max(1, Math.ceil(min / pixels));
    return {
      step,
      x: multiples(x0, x1, step),
      y: multiples(y0, y1, step),
      xEvery: every(45),
      yEvery: every(20),
    };
  }

  /** The fewest decimals that write every multiple of `step` exactly (0.25 -> 2, 50 -> 0). */
  function decimalsOf(step) {
    for (let d = 0; d < 12; d++) {
      const scaled = step * Math.pow(10, d);
      if (Math.abs(scaled - Math.round(scaled)) < 1e-6 * scaled) return d;
    }
    return 12;
  }

  /** Tick `v` in plain notation with the decimals its `step` needs (never `3.2e1`, never `-0`). */
  function formatTick(v, step) {
    const text = v.toFixed(decimalsOf(step));
    return /^-0(\.0*)?$/.test(text) ? text.slice(1) : text;
  }

  /** `v` with `significant` digits in plain notation (values of 1e6 and more as integers). */
  function formatValue(v, significant) {
    if (!Number.isFinite(v)) return String(v);
    if (v === 0) return "0";
    const magnitude = Math.floor(Math.log10(Math.abs(v)));
    const decimals = Math.max(0, Math.min(12, significant - 1 - magnitude));
    const text = v.toFixed(decimals);
    return /^-0(\.0*)?$/.test(text) ? text.slice(1) : text;
  }

  // ---- Colours ----------------------------------------------------------------------------

  /** Curve colours (Tableau 10). */
  const PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"];

  /** Ten more colours after the `PALETTE` for panels of many curves (a spatial arm's 16 coordinates). */
  const MORE_COLOURS = ["#393b79", "#637939", "#8c6d31", "#843c39", "#7b4173", "#3182bd", "#31a354", "#756bb1", "#e6550d", "#636363"];

  /**
   * The colour and line of each curve of a panel named `names`: a curve named `X ref` is drawn
   * dotted in the colour of `X`, every other curve in the next colour of `PALETTE` and then
   * `MORE_COLOURS` (repeating past twenty).
   */
  function curveStyles(names) {
    const colours = PALETTE.concat(MORE_COLOURS);
    const index = new Map();
    for (const n of names) if (!n.endsWith(" ref") && !index.has(n)) index.set(n, index.size);
    return names.map((n) => {
      const reference = n.endsWith(" ref") && index.has(n.slice(0, -4));
      const k = reference ? index.get(n.slice(0, -4)) : index.has(n) ? index.get(n) : index.size;
      return { colour: colours[k % colours.length], reference };
    });
  }

  /**
   * The colour of a link whose joint torque is `ratio` of its limit: blue at rest, through
   * green and amber to red at the limit, dark red beyond it. Returns [r, g, b].
   */
  function torqueColour(ratio) {
    const stops = [
      [0, [49, 99, 170]],
      [0.4, [44, 160, 44]],
      [0.7, [240, 170, 20]],
      [1, [214, 39, 40]],
    ];
    const r = Math.abs(ratio);
    if (!Number.isFinite(r)) return [90, 0, 0];
    if (r > 1) return [120, 0, 20];
    for (let i = 1; i < stops.length; i++) {
      if (r <= stops[i][0]) {
        const [r0, c0] = stops[i - 1];
        const [r1, c1] = stops[i];
        const f = (r - r0) / (r1 - r0);
        return c0.map((c, j) => Math.round(c + (c1[j] - c) * f));
      }
    }
    return stops[stops.length - 1][1];
  }

  function css(rgb) {
    return "rgb(" + rgb.join(",") + ")";
  }

  /** What a run's links are coloured against: its limits, else its peak |torque| per joint. */
  function torqueScale(run) {
    if (!run.joint_torque || run.joint_torque.length === 0) return null;
    if (run.torque_limit && run.torque_limit.length) return { limits: run.torque_limit, of: "limit" };
    let peak = 0;
    for (const row of run.joint_torque) for (const v of row) peak = Math.max(peak, Math.abs(v));
    return { limits: run.joint_torque[0].map(() => peak || 1), of: "peak" };
  }

  // ---- The camera -------------------------------------------------------------------------

  const DEG = Math.PI / 180;
  /** Preset views of a spatial arm (z up): yaw about z, pitch above the horizon (degrees). */
  const VIEWS = {
    iso: { yaw: -35, pitch: 25 },
    top: { yaw: 0, pitch: 90 },
    front: { yaw: 0, pitch: 0 },
    side: { yaw: 90, pitch: 0 },
  };

  /** The camera's unit vectors: right, up (on the screen) and towards the viewer. */
  function basis(camera) {
    const y = camera.yaw * DEG;
    const p = camera.pitch * DEG;
    const [cy, sy, cp, sp] = [Math.cos(y), Math.sin(y), Math.cos(p), Math.sin(p)];
    return {
      right: [cy, sy, 0],
      up: [-sy * sp, cy * sp, cp],
      toward: [sy * cp, -cy * cp, sp],
    };
  }

  /**
   * Orthographic projection of world point `p` ([x, y, z], m) to the canvas: [sx, sy, depth]
   * (pixels; depth grows towards the viewer). camera = {yaw, pitch, target, scale (px/m),
   * panX, panY, width, height}.
   */
  function project(camera, p, b) {
    const axes = b || basis(camera);
    const d = [p[0] - camera.target[0], p[1] - camera.target[1], p[2] - camera.target[2]];
    const dot = (u) => u[0] * d[0] + u[1] * d[1] + u[2] * d[2];
    return [
      camera.width / 2 + camera.panX + camera.scale * dot(axes.right),
      camera.height / 2 + camera.panY - camera.scale * dot(axes.up),
      dot(axes.toward),
    ];
  }

  /** The camera turned by a mouse drag of (dx, dy) pixels; the pitch stays within +-89 deg. */
  function orbit(camera, dx, dy) {
    const pitch = Math.max(-89, Math.min(89, camera.pitch + dy * 0.4));
    return Object.assign({}, camera, { yaw: camera.yaw - dx * 0.4, pitch });
  }

  /** The camera zoomed by `factor` about the canvas point (x, y), which stays put. */
  function zoom(camera, factor, x, y) {
    const f = Math.max(0.05, Math.min(20, factor));
    const cx = camera.width / 2 + camera.panX;
    const cy = camera.height / 2 + camera.panY;
    return Object.assign({}, camera, {
      scale: camera.scale * f,
      panX: camera.panX + (x - cx) * (1 - f),
      panY: camera.panY + (y - cy) * (1 - f),
    });
  }

  /** Every world point a run draws (joints of every sample, reference, obstacles, channels). */
  function worldPoints(run) {
    const out = [];
    const step = Math.max(1, Math.floor(run.joints.length / 60));
    for (let k = 0; k < run.joints.length; k += step) out.push(...points(run.joints[k], run.dims));
    out.push(...points(run.joints[run.joints.length - 1], run.dims));
    for (const p of run.tip_ref || []) out.push(points(p, run.dims)[0]);
    for (const o of run.obstacles || []) {
      const r = o.radius || 0;
      for (const c of [o.centre, o.a, o.b]) {
        if (!c) continue;
        const h = o.half || [r, r, r];
        const q = points(c, run.dims)[0];
        out.push([q[0] - h[0], q[1] - h[1], q[2] - (run.dims === 3 ? h[2] || 0 : 0)]);
        out.push([q[0] + h[0], q[1] + h[1], q[2] + (run.dims === 3 ? h[2] || 0 : 0)]);
      }
    }
    for (const c of run.channels || []) for (const p of c.points) out.push(points(p, run.dims)[0]);
    return out;
  }

  /**
   * The camera that shows `pts` whole in a width x height canvas: planar runs seen from above
   * (x right, y up), spatial ones from `view` (a key of VIEWS); the scale fits the bounding box
   * (planar) or the bounding sphere (spatial, so that orbiting keeps everything in view).
   */
  function fitCamera(pts, dims, width, height, view) {
    const lo = [Infinity, Infinity, Infinity];
    const hi = [-Infinity, -Infinity, -Infinity];
    for (const p of pts) for (let i = 0; i < 3; i++) {
      lo[i] = Math.min(lo[i], p[i]);
      hi[i] = Math.max(hi[i], p[i]);
    }
    if (!(hi[0] >= lo[0])) return { yaw: 0, pitch: 90, target: [0, 0, 0], scale: 100, panX: 0, panY: 0, width, height };
    const target = lo.map((v, i) => (v + hi[i]) / 2);
    const angles = dims === 3 ? VIEWS[view || "iso"] : VIEWS.top;
    let scale;
    if (dims === 3) {
      const radius = Math.max(1e-6, Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2);
      scale = (0.92 * Math.min(width, height)) / (2 * radius);
    } else {
      const spanX = Math.max(1e-6, hi[0] - lo[0]);
      const spanY = Math.max(1e-6, hi[1] - lo[1]);
      scale = 0.88 * Math.min(width / spanX, height / spanY);
    }
    return { yaw: angles.yaw, pitch: angles.pitch, target, scale, panX: 0, panY: 0, width, height };
  }

  // ---- Drawing the arm --------------------------------------------------------------------

  function polyline(ctx, camera, b, pts) {
    ctx.beginPath();
    pts.forEach((p, i) => {
      const s = project(camera, p, b);
      if (i === 0) ctx.moveTo(s[0], s[1]);
      else ctx.lineTo(s[0], s[1]);
    });
    ctx.stroke();
  }

  /** A light grid with labelled round coordinates (planar), or the axes at the base (spatial). */
  function drawFrame(ctx, camera, b, dims) {
    ctx.save();
    ctx.font = "11px sans-serif";
    if (dims === 2) {
      const x0 = camera.target[0] - (camera.width / 2 + camera.panX) / camera.scale;
      const x1 = x0 + camera.width / camera.scale;
      const y1 = camera.target[1] + (camera.height / 2 + camera.panY) / camera.scale;
      const y0 = y1 - camera.height / camera.scale;
      const grid = squareGrid(x0, x1, y0, y1, camera.width, camera.height);
      const labelled = (v, every) => Math.round(v / grid.step) % every === 0;
      ctx.strokeStyle = "#e6e6e6";
      ctx.fillStyle = "#777";
      ctx.lineWidth = 1;
      for (const x of grid.x) {
        const s = project(camera, [x, 0, 0], b)[0];
        ctx.beginPath();
        ctx.moveTo(s, 0);
        ctx.lineTo(s, camera.height);
        ctx.stroke();
        if (s > 2 && s < camera.width - 30 && labelled(x, grid.xEvery)) {
          ctx.fillText(formatTick(x, grid.step), s + 2, camera.height - 4);
        }
      }
      for (const y of grid.y) {
        const s = project(camera, [0, y, 0], b)[1];
        ctx.beginPath();
        ctx.moveTo(0, s);
        ctx.lineTo(camera.width, s);
        ctx.stroke();
        if (s > 14 && s < camera.height - 16 && labelled(y, grid.yEvery)) {
          ctx.fillText(formatTick(y, grid.step), 3, s - 3);
        }
      }
      ctx.fillText("x, y (m)", camera.width - 52, 12);
    } else {
      const length = 60 / camera.scale;
      const origin = project(camera, [0, 0, 0], b);
      ["x", "y", "z"].forEach((name, i) => {
        const end = [0, 0, 0];
        end[i] = length;
        const s = project(camera, end, b);
        ctx.strokeStyle = ["#c44", "#4a4", "#44c"][i];
        ctx.fillStyle = ctx.strokeStyle;
        ctx.lineWidth = 1.5;
        ctx.beginPath();
        ctx.moveTo(origin[0], origin[1]);
        ctx.lineTo(s[0], s[1]);
        ctx.stroke();
        ctx.fillText(name, s[0] + 3, s[1] - 3);
      });
    }
    ctx.restore();
  }

  /**
   * A tube of `width` pixels through world points `pts` in the current stroke colour: a round
   * line, or a disc when it is seen end-on (a zero-length line draws nothing).
   */
  function tube(ctx, camera, b, pts, width) {
    const s = pts.map((p) => project(camera, p, b));
    const long = s.some((q) => Math.hypot(q[0] - s[0][0], q[1] - s[0][1]) > 0.5);
    ctx.lineWidth = Math.max(1, width);
    ctx.lineCap = "round";
    ctx.lineJoin = "round";
    if (long) {
      polyline(ctx, camera, b, pts);
    } else {
      ctx.save();
      ctx.fillStyle = ctx.strokeStyle;
      ctx.beginPath();
      ctx.arc(s[0][0], s[0][1], Math.max(0.5, width / 2), 0, 2 * Math.PI);
      ctx.fill();
      ctx.restore();
    }
  }

  function drawObstacles(ctx, camera, b, run) {
    ctx.save();
    for (const c of run.channels || []) {
      ctx.strokeStyle = "rgba(120,170,220,0.35)";
      tube(ctx, camera, b, c.points.map((p) => points(p, run.dims)[0]), c.width * camera.scale);
    }
    ctx.fillStyle = "rgba(110,110,110,0.45)";
    ctx.strokeStyle = "rgba(60,60,60,0.8)";
    for (const o of run.obstacles || []) {
      ctx.lineWidth = 1;
      if (o.kind === "circle" || o.kind === "sphere") {
        const s = project(camera, points(o.centre, run.dims)[0], b);
        ctx.beginPath();
        ctx.arc(s[0], s[1], o.radius * camera.scale, 0, 2 * Math.PI);
        ctx.fill();
        ctx.stroke();
      } else if (o.kind === "capsule") {
        ctx.save();
        ctx.strokeStyle = "rgba(110,110,110,0.45)";
        tube(ctx, camera, b, [points(o.a, run.dims)[0], points(o.b, run.dims)[0]], 2 * o.radius * camera.scale);
        ctx.restore();
      } else if (o.kind === "box") {
        const c = points(o.centre, run.dims)[0];
        const h = [o.half[0], o.half[1], run.dims === 3 ? o.half[2] : 0];
        // The faces, farthest first.
        const corner = (sx, sy, sz) => [c[0] + sx * h[0], c[1] + sy * h[1], c[2] + sz * h[2]];
        const faces = [];
        for (let axis = 0; axis < (run.dims === 3 ? 3 : 1); axis++) {
          for (const side of [-1, 1]) {
            const quad = [[-1, -1], [1, -1], [1, 1], [-1, 1]].map(([u, v]) => {
              const s = [0, 0, 0];
              s[axis] = side;
              s[(axis + 1) % 3] = u;
              s[(axis + 2) % 3] = v;
              return corner(s[0], s[1], s[2]);
            });
            faces.push(quad.map((p) => project(camera, p, b)));
          }
        }
        if (run.dims === 2) faces.splice(0, faces.length, [[-1, -1], [1, -1], [1, 1], [-1, 1]].map(([u, v]) => project(camera, corner(u, v, 0), b)));
        faces.sort((p, q) => p.reduce((a, s) => a + s[2], 0) - q.reduce((a, s) => a + s[2], 0));
        for (const face of faces) {
          ctx.beginPath();
          face.forEach((s, i) => (i ? ctx.lineTo(s[0], s[1]) : ctx.moveTo(s[0], s[1])));
          ctx.closePath();
          ctx.fill();
          ctx.stroke();
        }
      }
    }
    ctx.restore();
  }

  /**
   * Draws `runs` (one, or several overlaid) at `time` on a canvas: frame, obstacles, the
   * reference path, the tip's trace up to `time`, then each arm link by link (coloured by its
   * joint torque against the limit for a single run, in the run's colour when overlaid).
   */
  function drawArms(ctx, camera, runs, time, colours) {
    const b = basis(camera);
    ctx.save();
    ctx.fillStyle = "#fff";
    ctx.fillRect(0, 0, camera.width, camera.height);
    drawFrame(ctx, camera, b, runs[0].dims);
    drawObstacles(ctx, camera, b, runs[0]);
    const overlaid = runs.length > 1;
    const ref = runs[0].tip_ref;
    if (ref && ref.length) {
      ctx.strokeStyle = "#d62728";
      ctx.lineWidth = 1.5;
      ctx.setLineDash([6, 4]);
      polyline(ctx, camera, b, ref.map((p) => points(p, runs[0].dims)[0]));
      ctx.setLineDash([]);
    }
    runs.forEach((run, r) => {
      const at = sampleAt(run.t, time);
      const d = run.dims;
      const last = run.joints[0].length / d - 1;
      const trace = [];
      for (let k = 0; k <= at.k; k++) trace.push(points(run.joints[k], d)[last]);
      const arm = points(lerpRow(run.joints, at), d);
      trace.push(arm[last]);
      ctx.strokeStyle = overlaid ? colours[r] : "#2ca02c";
      ctx.lineWidth = 1.5;
      polyline(ctx, camera, b, trace);
      if (ref && ref.length && r === 0) {
        const p = project(camera, points(lerpRow(run.tip_ref, at), d)[0], b);
        ctx.strokeStyle = "#d62728";
        ctx.lineWidth = 2;
        ctx.beginPath();
        ctx.arc(p[0], p[1], 5, 0, 2 * Math.PI);
        ctx.stroke();
      }
      const scale = torqueScale(run);
      const torque = scale ? lerpRow(run.joint_torque, at) : null;
      const screen = arm.map((p) => project(camera, p, b));
      const width = Math.max(3, Math.min(9, 0.02 * camera.scale));
      // Links, farthest first so that near links cover far ones.
      const order = screen.slice(1).map((s, i) => i);
      if (d === 3) order.sort((i, j) => screen[i][2] + screen[i + 1][2] - screen[j][2] - screen[j + 1][2]);
      ctx.lineCap = "round";
      for (const i of order) {
        ctx.strokeStyle = overlaid || !torque ? colours[r] : css(torqueColour(torque[i] / scale.limits[i]));
        ctx.lineWidth = width;
        ctx.beginPath();
        ctx.moveTo(screen[i][0], screen[i][1]);
        ctx.lineTo(screen[i + 1][0], screen[i + 1][1]);
        ctx.stroke();
      }
      ctx.fillStyle = "#222";
      for (const s of screen) {
        ctx.beginPath();
        ctx.arc(s[0], s[1], width * 0.35, 0, 2 * Math.PI);
        ctx.fill();
      }
      ctx.fillRect(screen[0][0] - 6, screen[0][1] - 6, 12, 12);
    });
    ctx.restore();
  }

  // ---- Time series ------------------------------------------------------------------------

  /** Margins of a series panel (pixels): room for the tick labels outside the plotted area. */
  const MARGIN = { left: 58, right: 24, top: 8, bottom: 22 };

  /** The y range of some curves: their extent widened by 5 %, or +-1 about a constant. */
  function yRange(curves) {
    let lo = Infinity;
    let hi = -Infinity;
    for (const c of curves) for (const v of c) {
      lo = Math.min(lo, v);
      hi = Math.max(hi, v);
    }
    if (!(hi >= lo)) return [-1, 1];
    if (hi - lo < 1e-12 * Math.max(1, Math.abs(lo))) return [lo - Math.max(1e-3, Math.abs(lo) * 0.1), hi + Math.max(1e-3, Math.abs(hi) * 0.1)];
    const pad = 0.05 * (hi - lo);
    return [lo - pad, hi + pad];
  }

  /**
   * One panel: the curves of group `g` of each run (solid for the first run, dashed for the
   * second), the torque limits as dotted lines, and a cursor at `time`.
   */
  function drawSeries(ctx, width, height, runs, g, time, tRange, limits) {
    ctx.save();
    ctx.fillStyle = "#fff";
    ctx.fillRect(0, 0, width, height);
    const curves = [];
    runs.forEach((run) => {
      const s = run.series[g];
      if (s) s.values.forEach((v) => curves.push(v));
    });
    if (limits) curves.push(limits, limits.map((v) => -v));
    const [y0, y1] = yRange(curves);
    const [t0, t1] = tRange;
    const w = width - MARGIN.left - MARGIN.right;
    const h = height - MARGIN.top - MARGIN.bottom;
    const sx = (t) => MARGIN.left + ((t - t0) / (t1 - t0 || 1)) * w;
    const sy = (v) => MARGIN.top + (1 - (v - y0) / (y1 - y0)) * h;
    ctx.font = "11px sans-serif";
    ctx.strokeStyle = "#e6e6e6";
    ctx.fillStyle = "#555";
    ctx.lineWidth = 1;
    const yt = niceTicks(y0, y1, Math.max(2, Math.floor(h / 28)));
    ctx.textAlign = "right";
    ctx.textBaseline = "middle";
    for (const v of yt.ticks) {
      if (v < y0 || v > y1) continue;
      ctx.beginPath();
      ctx.moveTo(MARGIN.left, sy(v));
      ctx.lineTo(MARGIN.left + w, sy(v));
      ctx.stroke();
      ctx.fillText(formatTick(v, yt.step), MARGIN.left - 4, sy(v));
    }
    const xt = niceTicks(t0, t1, Math.max(2, Math.floor(w / 70)));
    ctx.textAlign = "center";
    ctx.textBaseline = "top";
    for (const v of xt.ticks) {
      if (v < t0 - 1e-9 || v > t1 + 1e-9) continue;
      ctx.beginPath();
      ctx.moveTo(sx(v), MARGIN.top);
      ctx.lineTo(sx(v), MARGIN.top + h);
      ctx.stroke();
      ctx.fillText(formatTick(v, xt.step), sx(v), MARGIN.top + h + 4);
    }
    ctx.strokeStyle = "#888";
    ctx.strokeRect(MARGIN.left, MARGIN.top, w, h);
    ctx.save();
    ctx.beginPath();
    ctx.rect(MARGIN.left, MARGIN.top, w, h);
    ctx.clip();
    if (limits) {
      ctx.strokeStyle = "#d62728";
      ctx.setLineDash([2, 3]);
      for (const v of [Math.max(...limits), -Math.max(...limits)]) {
        ctx.beginPath();
        ctx.moveTo(MARGIN.left, sy(v));
        ctx.lineTo(MARGIN.left + w, sy(v));
        ctx.stroke();
      }
    }
    runs.forEach((run, r) => {
      const s = run.series[g];
      if (!s) return;
      const styles = curveStyles(s.names);
      s.values.forEach((values, i) => {
        ctx.setLineDash(styles[i].reference ? [1.5, 2.5] : r === 0 ? [] : [5, 3]);
        ctx.strokeStyle = styles[i].colour;
        ctx.lineWidth = 1.5;
        ctx.beginPath();
        values.forEach((v, k) => (k ? ctx.lineTo(sx(run.t[k]), sy(v)) : ctx.moveTo(sx(run.t[k]), sy(v))));
        ctx.stroke();
      });
    });
    ctx.setLineDash([]);
    ctx.strokeStyle = "#000";
    ctx.lineWidth = 1;
    ctx.beginPath();
    ctx.moveTo(sx(time), MARGIN.top);
    ctx.lineTo(sx(time), MARGIN.top + h);
    ctx.stroke();
    ctx.restore();
    ctx.restore();
  }

  // ---- The page ---------------------------------------------------------------------------

  const SPEEDS = [0.1, 0.25, 0.5, 1, 2];

  function element(doc, tag, attrs, children) {
    const e = doc.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === "text") e.textContent = v;
      else e.setAttribute(k, v);
    }
    for (const c of children || []) e.appendChild(c);
    return e;
  }

  function sizeCanvas(canvas, width, height) {
    const ratio = (typeof window !== "undefined" && window.devicePixelRatio) || 1;
    canvas.width = Math.round(width * ratio);
    canvas.height = Math.round(height * ratio);
    canvas.style.width = width + "px";
    canvas.style.height = height + "px";
    const ctx = canvas.getContext("2d");
    ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    return ctx;
  }

  /** Builds the viewer of one scene inside `root` (a .hrm-view holding its JSON). */
  function mount(root, scene) {
    const doc = root.ownerDocument;
    const runs = scene.runs;
    const state = {
      time: 0,
      playing: false,
      speed: 1,
      a: 0,
      b: runs.length > 1 ? 1 : -1,
      layout: "side",
      view: "iso",
      cameras: null,
    };
    const shown = () => [runs[state.a]].concat(state.b >= 0 && state.b !== state.a ? [runs[state.b]] : []);
    const tEnd = () => Math.max(...shown().map((r) => r.t[r.t.length - 1]));
    const tStart = () => Math.min(...shown().map((r) => r.t[0]));
    const spatial = runs[0].dims === 3;

    const play = element(doc, "button", { type: "button", class: "hrm-play", text: "Play" });
    const speed = element(doc, "select", { class: "hrm-speed", title: "playback speed" }, SPEEDS.map((s) => element(doc, "option", { value: String(s), text: s + "x" })));
    speed.value = "1";
    const slider = element(doc, "input", { type: "range", class: "hrm-slider", min: "0", max: "1000", step: "1", value: "0", "aria-label": "time" });
    const clock = element(doc, "span", { class: "hrm-time" });
    const options = (none) => (none ? [element(doc, "option", { value: "-1", text: "(none)" })] : []).concat(runs.map((r, i) => element(doc, "option", { value: String(i), text: r.label })));
    const pickA = element(doc, "select", { class: "hrm-run-a", title: "run" }, options(false));
    const pickB = element(doc, "select", { class: "hrm-run-b", title: "compare with" }, options(true));
    pickB.value = String(state.b);
    const layout = element(doc, "select", { class: "hrm-layout", title: "comparison" }, [
      element(doc, "option", { value: "side", text: "side by side" }),
      element(doc, "option", { value: "overlay", text: "overlaid" }),
    ]);
    const bar = element(doc, "div", { class: "hrm-controls" }, [play, speed, slider, clock]);
    const compare = element(doc, "div", { class: "hrm-controls" });
    if (runs.length > 1) {
      compare.append(element(doc, "label", { text: "run " }, [pickA]), element(doc, "label", { text: " compare with " }, [pickB]), layout);
    }
    const views = element(doc, "span", { class: "hrm-views" });
    if (spatial) {
      for (const name of Object.keys(VIEWS)) {
        const button = element(doc, "button", { type: "button", "data-view": name, text: name });
        button.addEventListener("click", () => setView(name));
        views.appendChild(button);
      }
      compare.appendChild(views);
    }
    const arms = element(doc, "div", { class: "hrm-arms" });
    const legend = element(doc, "div", { class: "hrm-legend" });
    const panels = element(doc, "div", { class: "hrm-series" });
    const status = element(doc, "div", { class: "hrm-status" });
    root.append(bar, compare, element(doc, "div", { class: "hrm-body" }, [element(doc, "div", { class: "hrm-left" }, [arms, legend, status]), panels]));

    let armCanvases = [];
    let seriesCanvases = [];

    function build() {
      arms.textContent = "";
      panels.textContent = "";
      const list = shown();
      const split = list.length > 1 && state.layout === "side";
      const total = Math.max(280, (arms.clientWidth || root.clientWidth / 2 || 482) - 4);
      const width = split ? Math.floor((total - 8) / 2) : total;
      const height = Math.round(Math.min(460, Math.max(240, (split ? 1.1 : 0.75) * width)));
      armCanvases = (split ? list : [list]).map((which) => {
        const canvas = element(doc, "canvas", { class: "hrm-arm" });
        arms.appendChild(canvas);
        return { canvas, ctx: sizeCanvas(canvas, width, height), runs: Array.isArray(which) ? which : [which], width, height };
      });
      const everything = [];
      for (const run of list) everything.push(...worldPoints(run));
      const keep = state.cameras && state.cameras.length === armCanvases.length && state.cameras[0].width === width ? state.cameras : null;
      state.cameras = keep || armCanvases.map(() => fitCamera(everything, list[0].dims, width, height, state.view));
      legend.textContent = "";
      const key = (colour, text, line) => element(doc, "span", { class: "hrm-key" }, [element(doc, "i", { style: "border-top:3px " + (line || "solid") + " " + colour }), doc.createTextNode(text)]);
      if (list[0].tip_ref && list[0].tip_ref.length) legend.appendChild(key("#d62728", "reference path (ring: reference now)", "dashed"));
      if (list.length > 1 && state.layout === "overlay") {
        list.forEach((run, r) => legend.appendChild(key(PALETTE[r], run.label + ": arm and tip trace")));
      } else {
        legend.appendChild(key("#2ca02c", "tip trace"));
        const scale = torqueScale(list[0]);
        if (scale) {
          const ramp = [0, 0.4, 0.7, 1, 1.2].map((v) => css(torqueColour(v)));
          legend.appendChild(element(doc, "span", { class: "hrm-key" }, [element(doc, "i", { class: "hrm-ramp", style: "background:linear-gradient(90deg," + ramp.slice(0, 4).join(",") + ")" }), doc.createTextNode("link colour: |joint torque| from 0 to its " + (scale.of === "limit" ? "limit" : "run's peak (no limits set)") + (scale.of === "limit" ? ", dark red beyond" : ""))]));
        }
      }
      if (list.length > 1) legend.appendChild(element(doc, "span", { class: "hrm-key", text: "series: " + list[0].label + " solid, " + list[1].label + " dashed" }));
      const groups = list[0].series.length;
      const panelWidth = Math.max(280, (panels.clientWidth || 482) - 2);
      seriesCanvases = [];
      for (let g = 0; g < groups; g++) {
        const s = list[0].series[g];
        const head = element(doc, "div", { class: "hrm-panel-title", text: s.title + " (" + s.unit + ")" });
        const styles = curveStyles(s.names);
        const keys = element(doc, "div", { class: "hrm-panel-keys" }, s.names.map((n, i) => key(styles[i].colour, n, styles[i].reference ? "dotted" : "solid")));
        const canvas = element(doc, "canvas", { class: "hrm-plot" });
        panels.append(head, keys, canvas);
        const height = s.names.length > 4 ? 150 : 120;
        const limits = s.title === "joint torques" && list[0].torque_limit && list[0].torque_limit.length ? list[0].torque_limit : null;
        seriesCanvases.push({ ctx: sizeCanvas(canvas, panelWidth, height), g, width: panelWidth, height, limits });
      }
      const stopped = list.filter((r) => r.stopped).map((r) => r.label + " stopped: " + r.stopped);
      status.textContent = stopped.join("; ");
      draw();
    }

    function draw() {
      const list = shown();
      const colours = list.map((_, r) => PALETTE[r]);
      armCanvases.forEach((a, i) => drawArms(a.ctx, state.cameras[i], a.runs, state.time, a.runs.length > 1 ? colours : [colours[list.indexOf(a.runs[0])]]));
      for (const s of seriesCanvases) drawSeries(s.ctx, s.width, s.height, list, s.g, state.time, [tStart(), tEnd()], s.limits);
      const t0 = tStart();
      const t1 = tEnd();
      slider.value = String(Math.round((1000 * (state.time - t0)) / (t1 - t0 || 1)));
      clock.textContent = "t = " + state.time.toFixed(3) + " s of " + formatValue(t1, 4) + " s";
      root.setAttribute("data-time", state.time.toFixed(4));
    }

    function setTime(t) {
      state.time = Math.max(tStart(), Math.min(tEnd(), t));
      draw();
    }

    let last = null;
    function tick(now) {
      if (!state.playing) return;
      if (last !== null) {
        const t = state.time + ((now - last) / 1000) * state.speed;
        if (t >= tEnd()) {
          setTime(tEnd());
          pause();
          return;
        }
        setTime(t);
      }
      last = now;
      root.ownerDocument.defaultView.requestAnimationFrame(tick);
    }
    function start() {
      if (state.playing) return;
      if (state.time >= tEnd()) state.time = tStart();
      state.playing = true;
      play.textContent = "Pause";
      last = null;
      root.ownerDocument.defaultView.requestAnimationFrame(tick);
    }
    function pause() {
      state.playing = false;
      play.textContent = "Play";
    }
    function setView(name) {
      state.view = name;
      state.cameras = null;
      build();
    }
    function step(direction) {
      const t = shown()[0].t;
      const at = sampleAt(t, state.time);
      const k = direction > 0 ? Math.min(t.length - 1, at.k + 1) : Math.max(0, at.f > 0 ? at.k : at.k - 1);
      setTime(t[k]);
    }

    play.addEventListener("click", () => (state.playing ? pause() : start()));
    speed.addEventListener("change", () => (state.speed = Number(speed.value)));
    slider.addEventListener("input", () => setTime(tStart() + (Number(slider.value) / 1000) * (tEnd() - tStart())));
    pickA.addEventListener("change", () => {
      state.a = Number(pickA.value);
      state.cameras = null;
      build();
    });
    pickB.addEventListener("change", () => {
      state.b = Number(pickB.value);
      state.cameras = null;
      build();
    });
    layout.addEventListener("change", () => {
      state.layout = layout.value;
      state.cameras = null;
      build();
    });
    root.setAttribute("tabindex", "0");
    root.addEventListener("keydown", (e) => {
      if (e.target.tagName === "SELECT" || (e.target.tagName === "INPUT" && e.key !== " ")) return;
      const keys = {
        " ": () => (state.playing ? pause() : start()),
        ArrowRight: () => step(1),
        ArrowLeft: () => step(-1),
        Home: () => setTime(tStart()),
        End: () => setTime(tEnd()),
        "]": () => {
          const i = Math.min(SPEEDS.length - 1, SPEEDS.indexOf(state.speed) + 1);
          state.speed = SPEEDS[i];
          speed.value = String(state.speed);
        },
        "[": () => {
          const i = Math.max(0, SPEEDS.indexOf(state.speed) - 1);
          state.speed = SPEEDS[i];
          speed.value = String(state.speed);
        },
      };
      if (keys[e.key]) {
        keys[e.key]();
        e.preventDefault();
      }
    });
    // Mouse: drag orbits (spatial) or pans (planar; with shift, or the right button, pans
    // either), the wheel zooms about the pointer, a double click refits.
    arms.addEventListener("contextmenu", (e) => e.preventDefault());
    arms.addEventListener("pointerdown", (e) => {
      const i = armCanvases.findIndex((a) => a.canvas === e.target);
      if (i < 0) return;
      const panning = !spatial || e.shiftKey || e.button === 2;
      let x = e.clientX;
      let y = e.clientY;
      e.target.setPointerCapture(e.pointerId);
      const move = (m) => {
        const dx = m.clientX - x;
        const dy = m.clientY - y;
        x = m.clientX;
        y = m.clientY;
        state.cameras = state.cameras.map((c) => (panning ? Object.assign({}, c, { panX: c.panX + dx, panY: c.panY + dy }) : orbit(c, dx, dy)));
        draw();
      };
      const up = () => {
        e.target.removeEventListener("pointermove", move);
        e.target.removeEventListener("pointerup", up);
      };
      e.target.addEventListener("pointermove", move);
      e.target.addEventListener("pointerup", up);
    });
    arms.addEventListener("wheel", (e) => {
      const i = armCanvases.findIndex((a) => a.canvas === e.target);
      if (i < 0) return;
      e.preventDefault();
      const rect = e.target.getBoundingClientRect();
      const factor = Math.exp(-e.deltaY * 0.0015);
      state.cameras = state.cameras.map((c) => zoom(c, factor, e.clientX - rect.left, e.clientY - rect.top));
      draw();
    }, { passive: false });
    arms.addEventListener("dblclick", () => {
      state.cameras = null;
      build();
    });
    root.hrmViewer = {
      setTime,
      time: () => state.time,
      play: start,
      pause,
      playing: () => state.playing,
      setView,
      camera: () => Object.assign({}, state.cameras[0]),
      end: tEnd,
    };
    build();
    let width = root.clientWidth;
    root.ownerDocument.defaultView.addEventListener("resize", () => {
      if (root.clientWidth !== width) {
        width = root.clientWidth;
        state.cameras = null;
        build();
      }
    });
  }

  /**
   * The run with a "joint torques" panel added to its series, made from the torques that
   * colour its links (the page carries them once), with the run's other panels first.
   */
  function withTorquePanel(run) {
    const series = (run.series || []).slice();
    if (run.joint_torque && run.joint_torque.length && !series.some((s) => s.title === "joint torques")) {
      const n = run.joint_torque[0].length;
      series.push({
        title: "joint torques",
        unit: "N m",
        names: Array.from({ length: n }, (_, i) => "tau_" + (i + 1)),
        values: Array.from({ length: n }, (_, i) => run.joint_torque.map((row) => row[i])),
      });
    }
    return Object.assign({}, run, { series });
  }

  /** Mounts every .hrm-view of `doc`; a scene whose data cannot be read says so in place. */
  function mountAll(doc) {
    for (const root of doc.querySelectorAll(".hrm-view")) {
      const holder = root.querySelector('script[type="application/json"]');
      try {
        const scene = JSON.parse(holder.textContent);
        mount(root, Object.assign({}, scene, { runs: scene.runs.map(withTorquePanel) }));
      } catch (e) {
        root.appendChild(element(doc, "p", { class: "hrm-status", text: "cannot show this run: " + e.message }));
        throw e;
      }
    }
  }

  return {
    sampleAt,
    lerpRow,
    points,
    niceTicks,
    squareGrid,
    curveStyles,
    formatTick,
    formatValue,
    torqueColour,
    torqueScale,
    basis,
    project,
    orbit,
    zoom,
    fitCamera,
    worldPoints,
    yRange,
    withTorquePanel,
    VIEWS,
    mount,
    mountAll,
  };
});
