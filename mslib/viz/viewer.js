// The mslib 3-D skeleton viewer: an anywidget front-end module drawn with Canvas 2D (no WebGL, no imports).
// State (mslib/viz/viewer.py, viewer_state): motions as base64 little-endian float32 (or int16 mm) positions (T, J, 3),
// metres, Y up, the character facing +Z with its left at +X; the bone chains and their sides; colours.
// Camera: an orbit around a target, azimuth from +Z towards +X, elevation above the floor, perspective.

const FOV = (35 * Math.PI) / 180;           // vertical field of view
const NEAR = 0.05;                          // metres in front of the camera
const HOME = { az: (35 * Math.PI) / 180, el: (12 * Math.PI) / 180, zoom: 1 };
const SPEEDS = [0.25, 0.5, 1, 2];
const BACKGROUND = "#fbfbfb";

function decodePositions(b64, encoding) {          // little-endian float32, or int16 millimetres
  const bin = atob(b64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  if (encoding !== "int16") return new Float32Array(bytes.buffer);
  return Float32Array.from(new Int16Array(bytes.buffer), (v) => v / 1000);
}

// ---------------------------------------------------------------- the scene: motions, bounds, panels
function buildScene(state) {
  const motions = state.motions.map((m) => {
    const p = decodePositions(m.positions, m.encoding);    // (T * J * 3)
    const J = m.joints, T = m.frames;
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < T * J; i++) {
      for (let k = 0; k < 3; k++) {
        const v = p[3 * i + k];
        if (v < lo[k]) lo[k] = v;
        if (v > hi[k]) hi[k] = v;
      }
    }
    const contacts = (m.contacts || []).map((s) => Array.from(s, (c) => c === "1"));
    return { title: m.title, T, J, p, lo, hi, contacts };
  });
  const groups = state.overlay ? [motions.map((_, i) => i)] : motions.map((_, i) => [i]);
  const panels = groups.map((ids) => {
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const i of ids) for (let k = 0; k < 3; k++) {
      lo[k] = Math.min(lo[k], motions[i].lo[k]);
      hi[k] = Math.max(hi[k], motions[i].hi[k]);
    }
    lo[1] = Math.min(lo[1], 0);                              // the floor is in view
    const centre = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2];
    const radius = Math.max(0.6, 0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));
    // floor grid: 0.5 m squares (1 m beyond 12 m) around everything, 0.5 m margin
    const spacing = Math.max(hi[0] - lo[0], hi[2] - lo[2]) > 12 ? 1 : 0.5;
    const g0 = [Math.floor((lo[0] - 0.5) / spacing) * spacing, Math.floor((lo[2] - 0.5) / spacing) * spacing];
    const g1 = [Math.ceil((hi[0] + 0.5) / spacing) * spacing, Math.ceil((hi[2] + 0.5) / spacing) * spacing];
    const height = Math.max(1.2, hi[1] - lo[1]);              // the body's size, for the follow camera
    return { ids, centre, radius, height, grid: { g0, g1, spacing } };
  });
  const radius = Math.max(...panels.map((q) => q.radius));  // one scale for every panel
  const height = Math.max(...panels.map((q) => q.height));
  const frames = Math.max(...motions.map((m) => m.T));
  return { motions, panels, radius, height, frames, fps: state.fps };
}

// ---------------------------------------------------------------- camera and projection
function makeCamera(view, target, distance, w, h, x0) {
  const ce = Math.cos(view.el), se = Math.sin(view.el), ca = Math.cos(view.az), sa = Math.sin(view.az);
  const back = [sa * ce, se, ca * ce];                       // from the target towards the eye
  const eye = [target[0] + distance * back[0], target[1] + distance * back[1], target[2] + distance * back[2]];
  const f = [-back[0], -back[1], -back[2]];
  const rn = Math.hypot(f[2], f[0]) || 1;
  const r = [-f[2] / rn, 0, f[0] / rn];                      // f × up: screen right (+X seen from +Z)
  const u = [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]];
  const focal = (0.5 * h) / Math.tan(FOV / 2);
  return { eye, r, u, f, focal, cx: x0 + w / 2, cy: h / 2 };
}

function toCamera(cam, x, y, z) {                            // (right, up, depth)
  const dx = x - cam.eye[0], dy = y - cam.eye[1], dz = z - cam.eye[2];
  return [dx * cam.r[0] + dy * cam.r[1] + dz * cam.r[2], dx * cam.u[0] + dy * cam.u[1] + dz * cam.u[2],
          dx * cam.f[0] + dy * cam.f[1] + dz * cam.f[2]];
}

function toScreen(cam, c) {
  return [cam.cx + (cam.focal * c[0]) / c[2], cam.cy - (cam.focal * c[1]) / c[2]];
}

function segment(ctx, cam, a, b) {                           // a, b camera points; clipped at the near plane
  if (a[2] < NEAR && b[2] < NEAR) return false;
  if (a[2] < NEAR || b[2] < NEAR) {
    const t = (NEAR - a[2]) / (b[2] - a[2]);
    const m = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), NEAR];
    if (a[2] < NEAR) a = m; else b = m;
  }
  const p = toScreen(cam, a), q = toScreen(cam, b);
  ctx.moveTo(p[0], p[1]);
  ctx.lineTo(q[0], q[1]);
  return true;
}

function joint(m, t, j) {
  const o = 3 * (t * m.J + j);
  return [m.p[o], m.p[o + 1], m.p[o + 2]];
}

// ---------------------------------------------------------------- drawing
function drawGrid(ctx, cam, grid) {
  const { g0, g1, spacing } = grid;
  ctx.lineWidth = 1;
  for (const strong of [false, true]) {
    ctx.beginPath();
    ctx.strokeStyle = strong ? "#b4b4b4" : "#dddddd";
    for (let x = g0[0]; x <= g1[0] + 1e-6; x += spacing) {
      if ((Math.abs(x) < 1e-6) === strong) segment(ctx, cam, toCamera(cam, x, 0, g0[1]), toCamera(cam, x, 0, g1[1]));
    }
    for (let z = g0[1]; z <= g1[1] + 1e-6; z += spacing) {
      if ((Math.abs(z) < 1e-6) === strong) segment(ctx, cam, toCamera(cam, g0[0], 0, z), toCamera(cam, g1[0], 0, z));
    }
    ctx.stroke();
  }
}

function drawPath(ctx, cam, m, t, colour) {
  const line = (from, to, width, alpha) => {
    ctx.beginPath();
    for (let k = from; k < to; k++) {
      const a = joint(m, k, 0), b = joint(m, k + 1, 0);
      segment(ctx, cam, toCamera(cam, a[0], 0, a[2]), toCamera(cam, b[0], 0, b[2]));
    }
    ctx.globalAlpha = alpha;
    ctx.lineWidth = width;
    ctx.strokeStyle = colour;
    ctx.stroke();
    ctx.globalAlpha = 1;
  };
  line(0, m.T - 1, 1, 0.35);                                 // the whole root path, faint
  line(0, Math.min(t, m.T - 1), 2, 0.8);                     // the part already walked
  const r = joint(m, t, 0), c = toCamera(cam, r[0], 0, r[2]);
  if (c[2] > NEAR) {
    const s = toScreen(cam, c);
    ctx.beginPath();
    ctx.arc(s[0], s[1], 3, 0, 2 * Math.PI);
    ctx.fillStyle = colour;
    ctx.fill();
  }
}

function drawSkeleton(ctx, cam, state, m, t, spine) {
  const pts = [];
  for (let j = 0; j < m.J; j++) {
    const q = joint(m, t, j);
    pts.push(toCamera(cam, q[0], q[1], q[2]));
  }
  const bones = [];                                          // painter's order: far bones first
  state.chains.forEach((chain, c) => {
    const side = state.sides[c];
    const colour = side === "centre" ? spine : state.colours[side];
    for (let k = 1; k < chain.length; k++) {
      const a = pts[chain[k - 1]], b = pts[chain[k]];
      bones.push({ a, b, colour, depth: (a[2] + b[2]) / 2 });
    }
  });
  bones.sort((x, y) => y.depth - x.depth);
  ctx.lineCap = "round";
  for (const bone of bones) {
    ctx.beginPath();
    if (!segment(ctx, cam, bone.a, bone.b)) continue;
    ctx.lineWidth = Math.max(1.5, Math.min(6, (0.035 * cam.focal) / bone.depth));
    ctx.strokeStyle = bone.colour;
    ctx.stroke();
    for (const p of [bone.a, bone.b]) {
      if (p[2] < NEAR) continue;
      const s = toScreen(cam, p);
      ctx.beginPath();
      ctx.arc(s[0], s[1], Math.max(1.5, Math.min(4, (0.025 * cam.focal) / p[2])), 0, 2 * Math.PI);
      ctx.fillStyle = bone.colour;
      ctx.fill();
    }
  }
  // feet lit while in contact: a glow at the foot joint and its print on the floor
  state.foot_joints.forEach((j, k) => {
    if (!m.contacts[k] || !m.contacts[k][t] || j >= m.J) return;
    const q = joint(m, t, j), p = pts[j], floor = toCamera(cam, q[0], 0, q[2]);
    if (p[2] < NEAR) return;
    const s = toScreen(cam, p);
    const radius = Math.max(3, Math.min(9, (0.06 * cam.focal) / p[2]));
    ctx.beginPath();
    ctx.arc(s[0], s[1], 2 * radius, 0, 2 * Math.PI);
    ctx.fillStyle = state.contact_colour;
    ctx.globalAlpha = 0.35;
    ctx.fill();
    ctx.globalAlpha = 1;
    ctx.beginPath();
    ctx.arc(s[0], s[1], radius, 0, 2 * Math.PI);
    ctx.fill();
    ctx.lineWidth = 1.5;
    ctx.strokeStyle = state.colours[k === 0 ? "left" : "right"];
    ctx.stroke();
    if (floor[2] > NEAR) {
      const f = toScreen(cam, floor);
      ctx.beginPath();
      ctx.ellipse(f[0], f[1], 1.6 * radius, 0.6 * radius, 0, 0, 2 * Math.PI);
      ctx.globalAlpha = 0.5;
      ctx.fill();
      ctx.globalAlpha = 1;
    }
  });
}

function drawPanel(ctx, state, scene, view, panel, x0, w, h, frame) {
  ctx.save();
  ctx.beginPath();
  ctx.rect(x0, 0, w, h);
  ctx.clip();
  const target = panel.centre.slice();
  let distance = scene.radius / Math.sin(FOV / 2);           // everything in view
  if (view.follow) {                                         // the (first) character in the middle, life-size
    const m = scene.motions[panel.ids[0]], r = joint(m, Math.min(frame, m.T - 1), 0);
    target[0] = r[0];
    target[1] = 0.45 * scene.height;
    target[2] = r[2];
    distance = 2.6 * scene.height;
  }
  distance /= view.zoom;
  const cam = makeCamera(view, target, distance, w, h, x0);
  drawGrid(ctx, cam, panel.grid);
  const overlay = panel.ids.length > 1;
  panel.ids.forEach((i, n) => {
    const m = scene.motions[i], t = Math.min(frame, m.T - 1);
    const colour = state.path_colours[i % state.path_colours.length];
    drawPath(ctx, cam, m, t, colour);
    ctx.globalAlpha = overlay && n > 0 ? 0.8 : 1;
    drawSkeleton(ctx, cam, state, m, t, overlay ? colour : state.colours.centre);
    ctx.globalAlpha = 1;
  });
  // titles: centred above the panel, or a legend of path colours when overlaid
  ctx.font = "600 13px system-ui, sans-serif";
  ctx.textBaseline = "top";
  if (!overlay) {
    ctx.textAlign = "center";
    ctx.fillStyle = "#222";
    ctx.fillText(scene.motions[panel.ids[0]].title, x0 + w / 2, 8, w - 16);
  } else {
    ctx.textAlign = "left";
    panel.ids.forEach((i, n) => {
      ctx.fillStyle = state.path_colours[i % state.path_colours.length];
      ctx.fillRect(x0 + 10, 11 + 18 * n, 14, 4);
      ctx.fillStyle = "#222";
      ctx.fillText(scene.motions[i].title, x0 + 30, 6 + 18 * n, w - 40);
    });
  }
  ctx.restore();
}

function drawAll(ctx, state, scene, view, frame, w, h) {
  ctx.fillStyle = BACKGROUND;
  ctx.fillRect(0, 0, w, h);
  const pw = w / scene.panels.length;
  scene.panels.forEach((panel, k) => drawPanel(ctx, state, scene, view, panel, k * pw, pw, h, frame));
  ctx.strokeStyle = "#e0e0e0";
  for (let k = 1; k < scene.panels.length; k++) {
    ctx.beginPath();
    ctx.moveTo(Math.round(k * pw) + 0.5, 0);
    ctx.lineTo(Math.round(k * pw) + 0.5, h);
    ctx.stroke();
  }
  // the side colours' key, bottom left
  ctx.font = "11px system-ui, sans-serif";
  ctx.textBaseline = "alphabetic";
  ctx.textAlign = "left";
  [["left side", state.colours.left], ["right side", state.colours.right], ["foot contact", state.contact_colour]]
    .forEach(([label, colour], n) => {
      ctx.fillStyle = colour;
      ctx.fillRect(10 + 88 * n, h - 16, 12, 8);
      ctx.fillStyle = "#555";
      ctx.fillText(label, 26 + 88 * n, h - 8);
    });
}

// ---------------------------------------------------------------- the widget: canvas, controls, events
function element(tag, props, style) {
  const e = Object.assign(document.createElement(tag), props || {});
  Object.assign(e.style, style || {});
  return e;
}

function render({ model, el }) {
  let state = model.get("data");
  let scene = buildScene(state);
  const view = { ...HOME, follow: Boolean(state.follow) };
  let frame = 0, clock = 0, playing = false, speed = 1, last = null, dirty = true, raf = 0;

  const root = element("div", { className: "mslib-viewer" },
    { display: "inline-block", fontFamily: "system-ui, sans-serif", fontSize: "12px", userSelect: "none" });
  const canvas = element("canvas", { className: "mslib-viewer-canvas", tabIndex: 0 },
    { display: "block", border: "1px solid #ddd", borderRadius: "4px", cursor: "grab", touchAction: "none" });
  const bar = element("div", { className: "mslib-viewer-controls" },
    { display: "flex", alignItems: "center", gap: "8px", marginTop: "4px" });
  const play = element("button", { className: "mslib-viewer-play", type: "button", textContent: "▶ play" },
    { minWidth: "72px" });
  const scrub = element("input", { className: "mslib-viewer-scrub", type: "range", min: 0, step: 1, value: 0 },
    { flex: "1" });
  const clockLabel = element("span", { className: "mslib-viewer-time" },
    { fontVariantNumeric: "tabular-nums", minWidth: "120px" });
  const speedBox = element("select", { className: "mslib-viewer-speed", title: "speed" });
  for (const s of SPEEDS) speedBox.appendChild(element("option", { value: s, textContent: `×${s}`, selected: s === 1 }));
  const followLabel = element("label", { title: "camera follows the character" }, {});
  const follow = element("input", { className: "mslib-viewer-follow", type: "checkbox", checked: view.follow });
  followLabel.append(follow, " follow");
  const reset = element("button", { className: "mslib-viewer-reset", type: "button", textContent: "reset view" });
  bar.append(play, scrub, clockLabel, speedBox, followLabel, reset);
  root.append(canvas, bar);
  el.appendChild(root);
  const ctx = canvas.getContext("2d");

  function resize() {
    const ratio = window.devicePixelRatio || 1;
    canvas.width = Math.round(state.width * ratio);
    canvas.height = Math.round(state.height * ratio);
    canvas.style.width = `${state.width}px`;
    canvas.style.height = `${state.height}px`;
    bar.style.width = `${state.width}px`;
    ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    scrub.max = scene.frames - 1;
    invalidate();
  }

  function setFrame(f) {
    frame = Math.max(0, Math.min(scene.frames - 1, f));
    clock = frame / scene.fps;
    invalidate();
  }

  function setPlaying(on) {
    playing = on;
    last = null;
    play.textContent = on ? "❚❚ pause" : "▶ play";
    if (on && frame >= scene.frames - 1) setFrame(0);
    invalidate();
  }

  function draw() {
    drawAll(ctx, state, scene, view, frame, state.width, state.height);
    scrub.value = frame;
    clockLabel.textContent = `${(frame / scene.fps).toFixed(2)} s / ${((scene.frames - 1) / scene.fps).toFixed(2)} s`;
    root.dataset.frame = String(frame);                    // read by the browser tests
    root.dataset.playing = String(playing);
    dirty = false;
  }

  function tick(now) {                                       // one animation frame; asks for the next while playing
    raf = 0;
    if (playing) {
      if (last !== null) clock += ((now - last) / 1000) * speed;
      last = now;
      const f = Math.floor(clock * scene.fps + 1e-6) % scene.frames;   // loops
      if (f !== frame) { frame = f; dirty = true; }
      if (clock * scene.fps >= scene.frames) clock -= scene.frames / scene.fps;
    }
    if (dirty) draw();
    if (playing) wake();
  }

  function wake() {
    if (!raf) raf = requestAnimationFrame(tick);
  }

  function invalidate() {                                    // redraw at the next animation frame
    dirty = true;
    wake();
  }

  // controls
  play.addEventListener("click", () => setPlaying(!playing));
  scrub.addEventListener("input", () => { setPlaying(false); setFrame(Number(scrub.value)); });
  speedBox.addEventListener("change", () => { speed = Number(speedBox.value); });
  follow.addEventListener("change", () => { view.follow = follow.checked; invalidate(); });
  reset.addEventListener("click", () => { Object.assign(view, HOME); invalidate(); });
  // orbit with a drag, zoom with the wheel, reset with a double-click, keys when focused
  let drag = null;
  canvas.addEventListener("pointerdown", (e) => {
    drag = { x: e.clientX, y: e.clientY };
    canvas.setPointerCapture(e.pointerId);
    canvas.style.cursor = "grabbing";
    canvas.focus({ preventScroll: true });
  });
  canvas.addEventListener("pointermove", (e) => {
    if (!drag) return;
    view.az -= 0.01 * (e.clientX - drag.x);
    view.el = Math.max(-0.15, Math.min(1.5, view.el + 0.01 * (e.clientY - drag.y)));
    drag = { x: e.clientX, y: e.clientY };
    invalidate();
  });
  const endDrag = () => { drag = null; canvas.style.cursor = "grab"; };
  canvas.addEventListener("pointerup", endDrag);
  canvas.addEventListener("pointercancel", endDrag);
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    view.zoom = Math.max(0.3, Math.min(8, view.zoom * Math.exp(-0.0015 * e.deltaY)));
    invalidate();
  }, { passive: false });
  canvas.addEventListener("dblclick", () => { Object.assign(view, HOME); invalidate(); });
  canvas.addEventListener("keydown", (e) => {
    if (e.key === " ") { setPlaying(!playing); e.preventDefault(); }
    if (e.key === "ArrowRight" || e.key === "ArrowLeft") {
      setPlaying(false);
      setFrame(frame + (e.key === "ArrowRight" ? 1 : -1));
      e.preventDefault();
    }
  });
  // new motions from Python (widget only): keep the camera, restart at frame 0
  const onData = () => {
    state = model.get("data");
    scene = buildScene(state);
    setFrame(0);
    resize();
  };
  model.on("change:data", onData);

  resize();
  return () => {                                             // anywidget calls this when the view goes away
    cancelAnimationFrame(raf);
    model.off("change:data", onData);
    root.remove();
  };
}

export default { render };
