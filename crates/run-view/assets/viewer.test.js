// Tests of viewer.js's pure functions: `node --test crates/run-view/assets/` (run by the
// run-view crate's `viewer_js` test when node is installed).
"use strict";
const test = require("node:test");
const assert = require("node:assert/strict");
const v = require("./viewer.js");

const close = (a, b, tol = 1e-9) => assert.ok(Math.abs(a - b) <= tol, `${a} vs ${b}`);

test("sampleAt finds the sample before a time and the fraction to the next", () => {
  const t = [0, 0.5, 1, 2];
  assert.deepEqual(v.sampleAt(t, -1), { k: 0, f: 0 });
  assert.deepEqual(v.sampleAt(t, 0), { k: 0, f: 0 });
  assert.deepEqual(v.sampleAt(t, 0.75), { k: 1, f: 0.5 });
  assert.deepEqual(v.sampleAt(t, 1.5), { k: 2, f: 0.5 });
  assert.deepEqual(v.sampleAt(t, 9), { k: 3, f: 0 });
  assert.deepEqual(v.sampleAt(t, NaN), { k: 0, f: 0 });
  // Interpolated rows lie between their neighbours.
  const rows = [[0, 0], [2, -4], [2, 0], [0, 0]];
  assert.deepEqual(v.lerpRow(rows, v.sampleAt(t, 0.25)), [1, -2]);
  assert.deepEqual(v.lerpRow(rows, v.sampleAt(t, 2)), [0, 0]);
  assert.deepEqual(v.points([1, 2, 3, 4], 2), [[1, 2, 0], [3, 4, 0]]);
  assert.deepEqual(v.points([1, 2, 3, 4, 5, 6], 3), [[1, 2, 3], [4, 5, 6]]);
});

test("ticks are round, cover the range and print in plain notation", () => {
  const { ticks, step } = v.niceTicks(0, 32.1, 5);
  assert.equal(step, 10);
  assert.deepEqual(ticks, [0, 10, 20, 30]);
  const small = v.niceTicks(-0.0031, 0.0042, 4);
  assert.equal(small.step, 0.002);
  assert.deepEqual(small.ticks.map((x) => v.formatTick(x, small.step)), ["-0.002", "0.000", "0.002", "0.004"]);
  const quarter = v.niceTicks(0, 1, 4);
  assert.equal(quarter.step, 0.25);
  assert.deepEqual(quarter.ticks.map((x) => v.formatTick(x, quarter.step)), ["0.00", "0.25", "0.50", "0.75", "1.00"]);
  // A range holding one multiple of the first step (here 2) still reads as a scale.
  const one = v.niceTicks(-1.6, 1.9, 3);
  assert.deepEqual(one.ticks, [-1, 0, 1]);
  for (const [lo, hi] of [[1e-7, 3e-7], [-5e4, 2e5], [3, 3], [0.1, 0.7], [-1.6, 1.9], [-0.12, 0.15]]) {
    const r = v.niceTicks(lo, hi, 5);
    assert.ok(r.ticks.length >= 2 && r.ticks.length <= 12, `${lo}..${hi}: ${r.ticks}`);
    for (const x of r.ticks) assert.doesNotMatch(v.formatTick(x, r.step), /e|^-0$/);
  }
  assert.equal(v.formatValue(32.113, 4), "32.11");
  assert.equal(v.formatValue(0.000123456, 3), "0.000123");
  assert.equal(v.formatValue(-0.00001, 2), "-0.000010");
  assert.equal(v.formatValue(123456789, 3), "123456789");
});

test("a planar arm's grid is square, with lines on both axes and labels apart", () => {
  // The report's side-by-side panel: 1.2 m wide and 1.1 m tall at 400 px a metre.
  for (const [x0, x1, y0, y1, w, h] of [
    [-0.6, 0.6, -0.05, 1.05, 480, 440],
    [-0.05, 0.5, -0.1, 1.3, 300, 763],
    [-3, 3, -0.5, 0.5, 900, 150],
  ]) {
    const g = v.squareGrid(x0, x1, y0, y1, w, h);
    assert.ok(g.x.length >= 2 && g.y.length >= 2, JSON.stringify(g));
    const pixels = (g.step * w) / (x1 - x0);
    assert.ok(pixels * g.xEvery >= 45 && pixels * g.yEvery >= 20);
    for (const [ticks, lo, hi] of [[g.x, x0, x1], [g.y, y0, y1]]) {
      ticks.forEach((t, k) => {
        assert.ok(t >= lo - 1e-12 && t <= hi + 1e-12);
        if (k > 0) assert.ok(Math.abs(t - ticks[k - 1] - g.step) < 1e-12);
      });
    }
  }
});

test("a reference curve is dotted in its coordinate's colour; twenty colours before a repeat", () => {
  const styles = v.curveStyles(["a1", "a1 ref", "a2", "a2 ref", "orphan ref"]);
  assert.equal(styles[0].colour, styles[1].colour);
  assert.equal(styles[2].colour, styles[3].colour);
  assert.notEqual(styles[0].colour, styles[2].colour);
  assert.deepEqual(styles.map((s) => s.reference), [false, true, false, true, false]);
  const names = [];
  for (let i = 1; i <= 16; i++) names.push("az" + i, "az" + i + " ref");
  const colours = v.curveStyles(names).filter((s) => !s.reference).map((s) => s.colour);
  assert.equal(new Set(colours).size, 16);
});

test("torque colours run from blue at rest to red at the limit, darker beyond", () => {
  assert.deepEqual(v.torqueColour(0), [49, 99, 170]);
  assert.deepEqual(v.torqueColour(1), [214, 39, 40]);
  assert.deepEqual(v.torqueColour(-1), [214, 39, 40]);
  assert.deepEqual(v.torqueColour(1.5), [120, 0, 20]);
  // Between two stops, every channel lies between theirs (green at 0.4, amber at 0.7).
  for (let r = 0.4; r <= 0.7; r += 0.05) {
    v.torqueColour(r).forEach((c, i) => {
      const [a, b] = [[44, 160, 44][i], [240, 170, 20][i]];
      assert.ok(c >= Math.min(a, b) && c <= Math.max(a, b), `ratio ${r}: ${c}`);
    });
  }
  const limited = { joint_torque: [[1, -8]], torque_limit: [4, 4] };
  assert.deepEqual(v.torqueScale(limited), { limits: [4, 4], of: "limit" });
  assert.deepEqual(v.torqueScale({ joint_torque: [[1, -8], [2, 3]] }), { limits: [8, 8], of: "peak" });
  assert.equal(v.torqueScale({ joint_torque: [] }), null);
});

test("the camera's basis is orthonormal and right-handed in every view", () => {
  for (const camera of [...Object.values(v.VIEWS), { yaw: 37, pitch: -61 }]) {
    const { right, up, toward } = v.basis(camera);
    const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    for (const [a, b, want] of [[right, right, 1], [up, up, 1], [toward, toward, 1], [right, up, 0], [up, toward, 0], [right, toward, 0]]) {
      close(dot(a, b), want, 1e-12);
    }
    // right x up = toward.
    const cross = [right[1] * up[2] - right[2] * up[1], right[2] * up[0] - right[0] * up[2], right[0] * up[1] - right[1] * up[0]];
    cross.forEach((c, i) => close(c, toward[i], 1e-12));
  }
});

test("preset views look along the axes they name", () => {
  const camera = (view) => Object.assign({ target: [0, 0, 0], scale: 100, panX: 0, panY: 0, width: 200, height: 100 }, v.VIEWS[view]);
  // From above, x is right and y is up the screen (canvas y grows downwards).
  assert.deepEqual(v.project(camera("top"), [1, 0, 0]).slice(0, 2).map(Math.round), [200, 50]);
  assert.deepEqual(v.project(camera("top"), [0, 1, 0]).slice(0, 2).map(Math.round), [100, -50]);
  close(v.project(camera("top"), [0, 0, 1])[2], 1);
  // From the front, z is up and y is depth (away from the viewer).
  assert.deepEqual(v.project(camera("front"), [0, 0, 1]).slice(0, 2).map(Math.round), [100, -50]);
  close(v.project(camera("front"), [0, 1, 0])[2], -1);
  // From the side, y is right.
  assert.deepEqual(v.project(camera("side"), [0, 1, 0]).slice(0, 2).map(Math.round), [200, 50]);
});

test("orbit keeps distances, zoom keeps the pointed-at point, fitting shows everything", () => {
  const c0 = Object.assign({ target: [0.1, 0.2, 0.3], scale: 80, panX: 5, panY: -3, width: 300, height: 200 }, v.VIEWS.iso);
  const c1 = v.orbit(c0, 40, -25);
  assert.notEqual(c1.yaw, c0.yaw);
  const p = [0.5, -0.2, 0.7];
  const q = [-0.3, 0.4, 0.1];
  const dist = (c) => {
    const a = v.project(c, p);
    const b = v.project(c, q);
    return Math.hypot(a[0] - b[0], a[1] - b[1], (a[2] - b[2]) * c.scale);
  };
  close(dist(c1), dist(c0), 1e-9);
  assert.equal(v.orbit(c0, 0, 1e6).pitch, 89);
  const s0 = v.project(c0, p);
  const c2 = v.zoom(c0, 1.7, s0[0], s0[1]);
  const s2 = v.project(c2, p);
  close(s2[0], s0[0], 1e-9);
  close(s2[1], s0[1], 1e-9);
  close(c2.scale, c0.scale * 1.7);
  // A fitted camera puts every point inside the canvas, from any orbit for a spatial run.
  const pts = [[0, 0, 0], [1, 0.2, -0.1], [0.4, 0.9, 0.6], [-0.2, 0.3, 0.2]];
  for (const view of Object.keys(v.VIEWS)) {
    let c = v.fitCamera(pts, 3, 320, 240, view);
    for (let turn = 0; turn < 8; turn++) {
      for (const point of pts) {
        const s = v.project(c, point);
        assert.ok(s[0] >= 0 && s[0] <= 320 && s[1] >= 0 && s[1] <= 240, `${view}: ${s}`);
      }
      c = v.orbit(c, 45, 13);
    }
  }
  const planar = v.fitCamera([[0, 0, 0], [0.4, 0.6, 0]], 2, 400, 300, "iso");
  assert.equal(planar.pitch, 90);
  close(planar.scale, 0.88 * Math.min(400 / 0.4, 300 / 0.6));
});

test("the world points of a run cover its arm, obstacles and channels", () => {
  const run = {
    dims: 3,
    t: [0, 1],
    joints: [[0, 0, 0, 1, 0, 0], [0, 0, 0, 0, 1, 0]],
    tip_ref: [[1, 0, 0], [0, 1, 0]],
    obstacles: [{ kind: "sphere", centre: [0, 0, 2], radius: 0.5 }, { kind: "box", centre: [3, 0, 0], half: [0.1, 0.2, 0.3] }],
    channels: [{ points: [[0, 0, -1], [0, 0, -2]], width: 0.1 }],
  };
  const pts = v.worldPoints(run);
  const max = (i) => Math.max(...pts.map((p) => p[i]));
  const min = (i) => Math.min(...pts.map((p) => p[i]));
  close(max(2), 2.5);
  close(max(0), 3.1);
  close(min(2), -2);
  close(v.yRange([[1, 3]])[0], 0.9);
  assert.deepEqual(v.yRange([]), [-1, 1]);
});

test("the joint torques get a panel of their own, once", () => {
  const run = { t: [0, 1], joint_torque: [[1, 2], [3, 4]], series: [{ title: "tip error", unit: "mm", names: ["e"], values: [[0, 1]] }] };
  const shown = v.withTorquePanel(run);
  assert.deepEqual(shown.series.map((s) => s.title), ["tip error", "joint torques"]);
  assert.deepEqual(shown.series[1].names, ["tau_1", "tau_2"]);
  assert.deepEqual(shown.series[1].values, [[1, 3], [2, 4]]);
  assert.equal(run.series.length, 1, "the data is left as it was");
  assert.equal(v.withTorquePanel(shown).series.length, 2);
  assert.deepEqual(v.withTorquePanel({ t: [0], joint_torque: [] }).series, []);
});
