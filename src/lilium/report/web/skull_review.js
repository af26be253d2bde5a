/* skull_review.js: a skull's cranial landmarks in 3D, reviewed (lilium.report.skull_review
   writes the page).

   The skull is drawn with meshgl.js through an orbit camera: a pinhole (meshgl.js states the
   convention) whose rotation R turns about the skull's centre P (the mesh's bounding-box
   centre), P at camera-frame [shift, distance]:

     t = [shift_x, shift_y, distance] - R P     focal = zoom * FOCAL_PER_SIDE * min(W, H)

   W x H being the canvas in device pixels, the principal point its centre, and the view the
   whole canvas, so a canvas pixel is a camera pixel. Dragging turns R about the camera's own
   axes (the skull follows the pointer), shift-drag pans, the wheel zooms (focal length). The
   start is the frontal view (skull frame: x = subject's left, y = up, z = anterior; the camera
   looks along -z at the face, the subject's left on the image's right), or ?view=left, right,
   top (anterior up) or front.

   A landmark is in sight when its depth is at most the drawn surface's (Renderer.depthAt) plus
   VISIBLE_TOLERANCE_MM; hidden ones are not drawn. Dragging a landmark moves it along the
   surface: the first surface point under the pointer (pickSurface), the grab offset kept.

   A point flagged "orientation_dependent" (lilium skull: porion, orbitale, gonion, zygion, whose
   place depends on the head's orientation) is ringed red and its row marked "check" until the
   examiner moves or ticks it.

   Save offers cranial_landmarks.json: {"landmarks": {name: [x, y, z]}, "landmark_sources":
   {name: {"source": "reviewed", "quality": <the original quality>, "confirmed": true}}} with
   the points switched on only; a point never moved keeps its coordinates exactly.

   Test hook (?test[&tick=NAME,...]): after the first draw, writes <pre id="first-draw-ms">,
   ticks the named landmarks' checkboxes, drags the first switched-on landmark in sight by
   (+15, +8) CSS pixels with pointer events, writes <pre id="dragged"> ({name, from_uv, to_uv,
   point}) and <pre id="visible"> (the names in sight), and presses Save, which then fills the
   download link and <pre id="saved"> without clicking (no file in ~/Downloads). */
(function () {
  "use strict";
  const $ = (id) => document.getElementById(id);
  const DATA = Page.json("review-data");
  const G = MeshGL;

  /** Degrees turned per CSS pixel dragged; zoom factor per wheel notch. */
  const TURN_DEG_PER_PX = 0.4, WHEEL_ZOOM = 1.15;
  /** Focal length (px) per pixel of the canvas' short side: a 10 degree field of view, far
      enough (about 2 m for a skull) that a lateral view's profile is the midline's, as in an
      orthographic view, and a midline landmark on it is in sight. */
  const FOCAL_PER_SIDE = 0.5 / Math.tan(5 * Math.PI / 180);
  /** Depth (mm) a landmark may lie behind the drawn surface and still be in sight: the drawn
      mesh may be decimated, and a pixel spans a slope. */
  const VISIBLE_TOLERANCE_MM = 2.0;
  /** The ``flag`` of a point to check first (lilium.skull.prepare.FLAG). */
  const FLAG = "orientation_dependent";
  /** Marker radius and label size, CSS pixels; the test drag, CSS pixels. */
  const MARK_R = 6, LABEL_PX = 12, TEST_DRAG = [15, 8];
  /** Camera looking direction and image-down direction of each view, from the skull's
      anatomical axes in the mesh's frame (DATA.axes: left, up, anterior; the skull frame's own
      x, y, z when the mesh is in it). */
  const neg = (a) => a.map((x) => -x);
  const AX = DATA.axes;
  const VIEWS = {
    front: {forward: neg(AX.anterior), down: neg(AX.up)},
    left: {forward: neg(AX.left), down: neg(AX.up)},
    right: {forward: AX.left, down: neg(AX.up)},
    top: {forward: neg(AX.up), down: neg(AX.anterior)},
  };

  const mesh = G.mesh(Page.float32("mesh-positions"), Page.uint32("mesh-indices"),
    DATA.mesh_origin_mm);
  const PIVOT = G.add(mesh.origin, mesh.centre);
  /** Distance (mm) at which the mesh's bounding sphere fills the short side at zoom 1. */
  const DISTANCE = mesh.radius * Math.sqrt(1 + 4 * FOCAL_PER_SIDE * FOCAL_PER_SIDE);
  /** The zoom of the views: the skull's longest side (a view along an axis shows at most that)
      fills 90% of the canvas' short side. */
  const START_ZOOM = 0.9 * 2 * mesh.radius / Math.max(...DATA.extent_mm);

  const orbit = {R: null, shift: [0, 0], zoom: 1};
  function setView(name) {
    const v = VIEWS[name] || VIEWS.front;
    orbit.R = G.lookRotation(v.forward, v.down); orbit.shift = [0, 0]; orbit.zoom = START_ZOOM;
  }

  // ---- the stage: canvas and marks, in device pixels (a canvas pixel is a camera pixel) ----
  const stage = $("stage"), canvas = $("skull"), marks = $("marks");
  let renderer = null;
  try {
    renderer = new G.Renderer(canvas);
    renderer.setMesh(mesh);
  } catch (err) {  // no WebGL 2: the list and Save still work
    $("no-webgl").textContent = "The skull cannot be drawn: " + err.message;
    $("no-webgl").hidden = false;
  }
  let W = 1, H = 1, dpr = 1;
  function layout() {
    const rect = stage.getBoundingClientRect();
    dpr = window.devicePixelRatio || 1;
    W = canvas.width = Math.max(1, Math.round(rect.width * dpr));
    H = canvas.height = Math.max(1, Math.round(rect.height * dpr));
    marks.setAttribute("viewBox", [-0.5, -0.5, W, H].join(" "));
    for (const el of marks.querySelectorAll("circle")) el.setAttribute("r", MARK_R * dpr);
    for (const el of marks.querySelectorAll("text")) el.setAttribute("font-size", LABEL_PX * dpr);
  }
  const view = () => ({x: -0.5, y: -0.5, width: W, height: H});
  function camera() {
    const focal = orbit.zoom * FOCAL_PER_SIDE * Math.min(W, H);
    return G.orbitCamera(orbit.R, PIVOT, DISTANCE, orbit.shift, focal, [(W - 1) / 2, (H - 1) / 2]);
  }
  /** The canvas pixel [u, v] of a pointer event, and back (client coordinates). */
  function pixelOf(e) {
    const rect = canvas.getBoundingClientRect();
    return [(e.clientX - rect.left) * W / rect.width - 0.5,
            (e.clientY - rect.top) * H / rect.height - 0.5];
  }
  function clientOf(uv) {
    const rect = canvas.getBoundingClientRect();
    return [rect.left + (uv[0] + 0.5) * rect.width / W, rect.top + (uv[1] + 0.5) * rect.height / H];
  }

  // ---- landmarks: a mark and a list row each --------------------------------------------
  const names = Object.keys(DATA.landmarks_mm);
  const state = {};
  const xyz = (p) => p.map((x) => x.toFixed(1)).join(", ");
  for (const name of names) {
    const quality = (DATA.sources[name] || {}).quality || "manual";
    const flagged = (DATA.sources[name] || {}).flag === FLAG;
    const g = Page.svg("g", {class: "lm", id: "lm-" + name}, $("g-marks"));
    const dot = Page.svg("circle", {r: MARK_R}, g);
    Page.svg("title", {}, dot).textContent = name + " (" + quality + (flagged ? ", check" : "")
      + ")";
    const label = Page.svg("text", {}, g);
    label.textContent = name;
    const row = document.createElement("tr");
    const box = document.createElement("input");
    box.type = "checkbox"; box.id = "on-" + name;
    const cells = [document.createElement("label"), quality, ""].map((content) => {
      const td = row.insertCell();
      td.append(content);
      return td;
    });
    if (flagged) {
      const mark = document.createElement("span");
      mark.className = "flag";
      mark.title = "depends on the head's orientation: check it";
      mark.textContent = "check";
      cells[1].append(" ", mark);
    }
    const swatch = document.createElement("span");
    cells[0].firstChild.append(box, " ", swatch, " ", name);
    $("rows").append(row);
    const s = state[name] = {point: DATA.landmarks_mm[name].slice(), quality, flagged,
      moved: false, touched: false, on: quality !== "template", uv: [NaN, NaN], visible: false,
      g, dot, label, box, row, swatch, coords: cells[2]};
    box.checked = s.on;
    box.onchange = () => { s.on = box.checked; s.touched = true; schedule(); };
    dot.addEventListener("pointerdown", (e) => startDrag(e, name));
    dot.addEventListener("pointermove", moveDrag);
    dot.addEventListener("pointerup", endDrag);
  }
  /** A mark's class: quality colour (or "reviewed" once the examiner moved or ticked it),
      ringed while flagged and not yet reviewed. */
  function markClass(s) {
    const reviewed = s.moved || s.touched && s.on;
    return "lm " + (reviewed ? "reviewed" : s.quality) + (s.flagged && !reviewed ? " flagged" : "")
      + (s.on ? "" : " off");
  }

  // ---- drawing -------------------------------------------------------------------------
  function updateMarks(cam) {
    const points = names.map((n) => state[n].point), uvs = G.project(points, cam);
    const depths = renderer ? renderer.depthAt(cam, view(), W, H, uvs, 1)
      : uvs.map(() => Infinity);
    names.forEach((n, i) => {
      const s = state[n], uv = uvs[i], z = G.toCamera(s.point, cam)[2];
      s.uv = uv;
      s.visible = Number.isFinite(uv[0]) && z <= depths[i] + VISIBLE_TOLERANCE_MM;
      s.g.style.display = s.visible ? "" : "none";
      s.g.setAttribute("class", markClass(s));
      s.dot.setAttribute("cx", uv[0]); s.dot.setAttribute("cy", uv[1]);
      s.row.className = (s.on ? "" : "off") + (s.visible ? "" : " behind");
      s.swatch.className = markClass(s).replace("lm", "sw");
      s.coords.textContent = xyz(s.point);
    });
    placeLabels();
    marks.classList.toggle("names", $("show-names").checked);
    $("count").textContent = names.filter((n) => state[n].on).length + " of " + names.length;
  }
  /** Each label right of its mark, moved down below any label it would overlap (top to
      bottom; nearly coincident landmarks such as prosthion and subspinale). */
  function placeLabels() {
    const placed = [], line = 1.15 * LABEL_PX * dpr, em = 0.65 * LABEL_PX * dpr;
    const shown = names.filter((n) => state[n].visible);
    shown.sort((a, b) => state[a].uv[1] - state[b].uv[1]);
    for (const n of shown) {
      const x = state[n].uv[0] + 1.6 * MARK_R * dpr, w = em * n.length;
      let y = state[n].uv[1] + 0.35 * LABEL_PX * dpr;
      for (const [qx, qy, qw] of placed) {
        if (x < qx + qw && qx < x + w && Math.abs(qy - y) < line) y = qy + line;
      }
      placed.push([x, y, w]);
      state[n].label.setAttribute("x", x); state[n].label.setAttribute("y", y);
    }
  }
  function redraw() {
    const cam = camera();
    if (renderer) renderer.draw(cam, view(), {alpha: 1, outline: 0});
    updateMarks(cam);
  }
  let pending = false;
  function schedule() {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => { pending = false; redraw(); });
  }

  // ---- dragging a landmark along the surface ---------------------------------------------
  let grab = null;  // {name, offset: mark minus pointer (px), at: the latest pointer pixel}
  function startDrag(e, name) {
    e.stopPropagation(); e.preventDefault();
    try { e.target.setPointerCapture(e.pointerId); } catch (err) { /* synthetic event */ }
    const p = pixelOf(e), uv = state[name].uv;
    grab = {name, offset: [uv[0] - p[0], uv[1] - p[1]], at: p, pending: false};
  }
  /** Moves the grabbed landmark to the first surface point under the pointer (plus the grab
      offset); off the skull it stays where it was. */
  function follow() {
    if (!grab) return;
    const s = state[grab.name];
    const hit = G.pickSurface(mesh, camera(), grab.at[0] + grab.offset[0],
      grab.at[1] + grab.offset[1]);
    if (hit) { s.point = hit.point; s.moved = true; }
    redraw();
  }
  function moveDrag(e) {
    if (!grab) return;
    e.stopPropagation();
    grab.at = pixelOf(e);
    if (grab.pending) return;
    grab.pending = true;
    requestAnimationFrame(() => { if (grab) { grab.pending = false; follow(); } });
  }
  function endDrag(e) {
    if (!grab) return;
    e.stopPropagation();
    grab.at = pixelOf(e);
    follow();
    grab = null;
  }

  // ---- the orbit: drag turns, shift-drag pans, wheel zooms --------------------------------
  let turn = null;
  stage.addEventListener("pointerdown", (e) => {
    if (grab) return;
    turn = {x: e.clientX, y: e.clientY};
    try { stage.setPointerCapture(e.pointerId); } catch (err) { /* synthetic event */ }
    e.preventDefault();
  });
  stage.addEventListener("pointermove", (e) => {
    if (!turn) return;
    const dx = e.clientX - turn.x, dy = e.clientY - turn.y;
    turn.x = e.clientX; turn.y = e.clientY;
    if (e.shiftKey) {
      const mmPerPx = DISTANCE / camera().focal_px * dpr;
      orbit.shift = [orbit.shift[0] + dx * mmPerPx, orbit.shift[1] + dy * mmPerPx];
    } else {  // the skull's near side follows the pointer
      const Q = G.matmul(G.rotation([1, 0, 0], dy * TURN_DEG_PER_PX),
        G.rotation([0, 1, 0], -dx * TURN_DEG_PER_PX));
      orbit.R = G.matmul(Q, orbit.R);
    }
    schedule();
  });
  stage.addEventListener("pointerup", () => { turn = null; });
  stage.addEventListener("wheel", (e) => {
    e.preventDefault();
    const notches = e.deltaY / (e.deltaMode === 1 ? 3 : 100);
    orbit.zoom *= Math.pow(WHEEL_ZOOM, -notches);
    schedule();
  }, {passive: false});
  window.addEventListener("resize", () => { layout(); schedule(); });
  for (const name of Object.keys(VIEWS)) {
    $("view-" + name).onclick = () => { setView(name); schedule(); };
  }
  $("show-names").onchange = schedule;

  // ---- Save ------------------------------------------------------------------------------
  const testing = Page.params().has("test");
  function saved() {
    const out = {landmarks: {}, landmark_sources: {}};
    for (const n of names) {
      const s = state[n];
      if (!s.on) continue;
      out.landmarks[n] = s.moved ? s.point.map((x) => Math.round(x * 1e4) / 1e4) : s.point;
      out.landmark_sources[n] = {source: "reviewed", quality: s.quality, confirmed: true};
    }
    return JSON.stringify(out, null, 1);
  }
  $("save").onclick = () => {  // under test the link is only filled (no file in Downloads)
    const text = saved();
    Page.offerDownload($("download"), text, "application/json", !testing);
    $("saved").textContent = text;
  };

  // ---- first draw, and the test hook -------------------------------------------------------
  setView(Page.params().get("view") || "front");
  layout();
  redraw();
  if (testing) {
    if (renderer) {  // one pixel read back: the first draw has finished on the GPU
      renderer.gl.readPixels(0, 0, 1, 1, renderer.gl.RGBA, renderer.gl.UNSIGNED_BYTE,
        new Uint8Array(4));
    }
    const out = (id, text) => {
      const pre = document.createElement("pre"); pre.id = id; pre.textContent = text;
      $("test-output").append(pre);
    };
    out("first-draw-ms", performance.now().toFixed(1));
    for (const n of (Page.params().get("tick") || "").split(",")) {
      if (state[n] && !state[n].on) state[n].box.click();
    }
    redraw();
    const name = names.find((n) => state[n].on && state[n].visible);
    if (name) {
      const s = state[name], from = s.uv.slice(), [x, y] = clientOf(from);
      const at = (dx, dy) => ({clientX: x + dx, clientY: y + dy, pointerId: 1, bubbles: true});
      s.dot.dispatchEvent(new PointerEvent("pointerdown", at(0, 0)));
      s.dot.dispatchEvent(new PointerEvent("pointermove", at(...TEST_DRAG)));
      s.dot.dispatchEvent(new PointerEvent("pointerup", at(...TEST_DRAG)));
      out("dragged", JSON.stringify({name, from_uv: from, to_uv: s.uv, point: s.point}));
    }
    out("visible", JSON.stringify(names.filter((n) => state[n].visible)));
    $("save").onclick();
  }
})();
