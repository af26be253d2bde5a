/* workbench.js: the overlay workbench (lilium.report.workbench writes the page).

   The skull is drawn with the SFO's camera over the photo (meshgl.js states the camera
   convention). The examiner changes the pose relative to the SFO's:

     Ra = Rot(up, yaw) Rot(left, pitch) Rot(anterior, roll)   anatomical axes, skull frame
     R  = R_sfo Ra                                            turned about the pivot P
     C  = distance * unit((u_P + du - cx) / f, (v_P + dv - cy) / f, 1)
     t  = C - R P

   P is the skull's centre (DATA.pivot_mm), (u_P, v_P) its projection by the SFO's camera, so
   the shifts du, dv (px) move its image, `distance` (mm) is from the camera centre to P along
   its ray, and a new focal length f zooms about P's image point. With every field at its SFO
   value the camera is exactly the SFO's. lilium.report.workbench.adjusted_camera is the same
   in Python.

   Test hooks (a headless browser reads them): ?test[&yaw=D][&pitch=D][&roll=D] turns the
   skull, draws, and writes pre elements: skull-box, "u0 v0 u1 v1" (the drawn skull's pixels'
   extreme centres, photo pixels, read back with gl.readPixels); camera (its JSON); pick (a
   surface pick at the projected nasion); timing (ms from opening to the first draw, and to
   the end of the hooks); and presses Save, which then fills the download link only. */
(function () {
  "use strict";
  const $ = (id) => document.getElementById(id);
  const DATA = Page.json("workbench-data");
  const G = MeshGL;

  /** Degrees turned per CSS pixel dragged; distance change per wheel notch. */
  const TURN_DEG_PER_PX = 0.1, WHEEL_DISTANCE = 0.01, WHEEL_ZOOM = 1.15;
  /** Largest side (pixels) of the offscreen picture the test hook measures the skull box on. */
  const MEASURE_MAX_PX = 4096;

  const mesh = G.mesh(Page.float32("mesh-positions"), Page.uint32("mesh-indices"),
    DATA.mesh_origin_mm);
  const SFO = DATA.camera, [CX, CY] = SFO.principal_point_px, PIVOT = DATA.pivot_mm;
  const AXES = {yaw: DATA.axes.up, pitch: DATA.axes.left, roll: DATA.axes.anterior};
  const R_SFO = G.rotationOf(SFO);
  const PIVOT_CAM = G.toCamera(PIVOT, SFO);
  const PIVOT_UV = G.project([PIVOT], SFO)[0];
  const FIELDS = {yaw: 2, pitch: 2, roll: 2, du: 1, dv: 1, distance: 1, focal: 1};  // decimals
  const sfoState = () => ({yaw: 0, pitch: 0, roll: 0, du: 0, dv: 0,
    distance: G.norm(PIVOT_CAM), focal: SFO.focal_px});
  let state = sfoState();

  /** The camera of the current state (see the header). */
  function camera() {
    const s = state;
    const Ra = G.matmul(G.rotation(AXES.yaw, s.yaw),
      G.matmul(G.rotation(AXES.pitch, s.pitch), G.rotation(AXES.roll, s.roll)));
    const R = G.matmul(R_SFO, Ra);
    const ray = [(PIVOT_UV[0] + s.du - CX) / s.focal, (PIVOT_UV[1] + s.dv - CY) / s.focal, 1];
    const C = G.scale(ray, s.distance / G.norm(ray));
    return G.makeCamera(R, G.sub(C, G.apply(R, PIVOT)), s.focal, SFO.principal_point_px);
  }

  // ---- the stage: photo, skull canvas, marks; `view` is the photo region shown -------------
  const stage = $("stage"), canvas = $("skull"), photo = $("photo"), marks = $("marks");
  let renderer = null;
  try {
    renderer = new G.Renderer(canvas);
    renderer.setMesh(mesh);
  } catch (err) {  // no WebGL 2: the landmarks and their errors still work
    $("no-webgl").textContent = "The skull cannot be drawn: " + err.message;
    $("no-webgl").hidden = false;
  }
  const [W, H] = DATA.image_size_wh;
  const boxView = (b) => ({x: b[0] - 0.5, y: b[1] - 0.5, width: b[2] - b[0], height: b[3] - b[1]});
  let wanted = boxView(DATA.view_box), view = wanted, cssW = 1, cssH = 1;
  if (!DATA.has_image) photo.hidden = true;

  /** Fit `wanted` to the stage's shape (same centre) and size the canvas and the photo. */
  function layout() {
    const rect = stage.getBoundingClientRect();
    cssW = Math.max(1, rect.width); cssH = Math.max(1, rect.height);
    const s = Math.max(wanted.width / cssW, wanted.height / cssH);
    const cx = wanted.x + wanted.width / 2, cy = wanted.y + wanted.height / 2;
    view = {x: cx - s * cssW / 2, y: cy - s * cssH / 2, width: s * cssW, height: s * cssH};
    const dpr = window.devicePixelRatio || 1;
    canvas.width = Math.round(cssW * dpr); canvas.height = Math.round(cssH * dpr);
    const k = 1 / s;  // CSS pixels per photo pixel
    Object.assign(photo.style, {left: (-0.5 - view.x) * k + "px", top: (-0.5 - view.y) * k + "px",
      width: W * k + "px", height: H * k + "px"});
    marks.setAttribute("viewBox", [view.x, view.y, view.width, view.height].join(" "));
    const r = s;  // one CSS pixel, in photo pixels
    for (const el of marks.querySelectorAll("[data-r]")) el.setAttribute("r", el.dataset.r * r);
    for (const el of marks.querySelectorAll("text")) el.setAttribute("font-size", 12 * r);
  }

  // ---- landmarks: marks and the error table ------------------------------------------------
  const cranialNames = Object.keys(DATA.cranial_mm), facialNames = Object.keys(DATA.facial_mm);
  const errorNames = facialNames.filter((n) => n in DATA.photo_uv);  // checks.landmark_error's
  const mark = {};
  function addMark(group, tag, attrs, title) {
    const el = Page.svg(tag, attrs, $(group));
    if (title) Page.svg("title", {}, el).textContent = title;
    return el;
  }
  for (const [c, f] of DATA.pairs) {
    mark["tissue " + c] = addMark("g-tissue", "line", {class: "tissue"}, c + " \u2192 " + f);
  }
  for (const n of errorNames) mark["error " + n] = addMark("g-errors", "line", {class: "err"});
  for (const [n, uv] of Object.entries(DATA.photo_uv)) {
    addMark("g-photo", "circle", {class: "lm", cx: uv[0], cy: uv[1], "data-r": 6}, n + " (photo)");
    const label = addMark("g-photo", "text", {class: "lbl", x: uv[0], y: uv[1]});
    label.textContent = " " + n;
  }
  for (const n of facialNames) {
    mark["facial " + n] = addMark("g-estimate", "circle", {class: "est", "data-r": 3},
      n + " (estimate)");
  }
  for (const n of cranialNames) {
    mark["cranial " + n] = addMark("g-cranial", "circle", {class: "cr", "data-r": 3},
      n + " (skull)");
  }
  const rows = {};
  for (const n of errorNames) {
    const tr = $("error-rows").insertRow();
    tr.insertCell().textContent = n;
    rows[n] = tr.insertCell();
    const at = (DATA.sfo_error_px || {})[n];
    tr.insertCell().textContent = Page.fixed(at === null || at === undefined ? NaN : at, 1);
  }

  function place(el, uv) {
    const ok = Number.isFinite(uv[0]) && Number.isFinite(uv[1]);
    el.style.display = ok ? "" : "none";
    if (ok && el.tagName === "circle") { el.setAttribute("cx", uv[0]); el.setAttribute("cy", uv[1]); }
    return ok;
  }
  function line(el, a, b) {
    if (!place(el, a) || !place(el, b)) return;
    el.setAttribute("x1", a[0]); el.setAttribute("y1", a[1]);
    el.setAttribute("x2", b[0]); el.setAttribute("y2", b[1]);
  }

  /** Landmark marks, the error table and its mean, for `cam`. */
  function updateLandmarks(cam) {
    const cr = {}, fa = {};
    G.project(cranialNames.map((n) => DATA.cranial_mm[n]), cam).forEach((uv, i) => {
      cr[cranialNames[i]] = uv; place(mark["cranial " + cranialNames[i]], uv);
    });
    G.project(facialNames.map((n) => DATA.facial_mm[n]), cam).forEach((uv, i) => {
      fa[facialNames[i]] = uv; place(mark["facial " + facialNames[i]], uv);
    });
    for (const [c, f] of DATA.pairs) line(mark["tissue " + c], cr[c], fa[f]);
    let sum = 0;
    for (const n of errorNames) {
      const p = DATA.photo_uv[n], e = Math.hypot(fa[n][0] - p[0], fa[n][1] - p[1]);
      line(mark["error " + n], p, fa[n]);
      rows[n].textContent = Page.fixed(e, 1);
      sum += e;
    }
    const mean = errorNames.length ? sum / errorNames.length : NaN;
    $("mean-error").textContent = Page.fixed(mean, 2);
    $("mean-bar").textContent = Page.fixed(mean, 2);
  }

  // ---- drawing ---------------------------------------------------------------------------
  function style() {
    const dpr = window.devicePixelRatio || 1;
    return {alpha: $("opacity").value / 100,
            outline: $("outline").checked ? Math.max(1, Math.round(dpr)) : 0};
  }
  function showFields() {
    for (const [k, digits] of Object.entries(FIELDS)) $(k).value = state[k].toFixed(digits);
  }
  function redraw() {
    const cam = camera();
    if (renderer) renderer.draw(cam, view, style());
    updateLandmarks(cam);
    $("camera").textContent = JSON.stringify(cam);
    const wipe = $("wipe").value;
    canvas.style.clipPath = "inset(0px " + (100 - wipe) + "% 0px 0px)";
    $("opacity").nextElementSibling.textContent = $("opacity").value + " %";
    $("wipe").nextElementSibling.textContent = wipe + " %";
    const wipeLine = $("wipe-line");
    wipeLine.style.left = wipe + "%"; wipeLine.hidden = Number(wipe) >= 100;
    for (const g of ["cranial", "photo", "estimate", "tissue", "errors"]) {
      $("g-" + g).style.display = $("show-" + g).checked ? "" : "none";
    }
    marks.classList.toggle("names", $("show-names").checked);
  }
  let pending = false;
  function schedule() {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => { pending = false; redraw(); });
  }

  // ---- controls ---------------------------------------------------------------------------
  for (const k of Object.keys(FIELDS)) {
    $(k).addEventListener("input", () => {
      const x = Number($(k).value);
      const ok = Number.isFinite(x) && (k !== "distance" && k !== "focal" || x > 0);
      $(k).classList.toggle("bad", !ok);
      if (ok) { state[k] = x; schedule(); }
    });
  }
  for (const id of ["opacity", "wipe", "outline", "show-cranial", "show-photo", "show-estimate",
    "show-tissue", "show-errors", "show-names"]) {
    $(id).addEventListener("input", schedule);
    $(id).addEventListener("change", schedule);
  }
  $("reset").onclick = () => { state = sfoState(); showFields(); schedule(); };
  $("view-face").onclick = () => { wanted = boxView(DATA.view_box); layout(); schedule(); };
  $("view-photo").onclick = () => { wanted = boxView([0, 0, W, H]); layout(); schedule(); };
  const testing = Page.params().has("test");
  // camera.json: the camera, and the soft tissue shown with it (the result's facial landmarks,
  // fixed in the skull frame), which `--camera` scores as it is (docs/method/workbench.md).
  $("save").onclick = () => {  // under test the link is only filled (no file in Downloads)
    const saved = Object.assign(camera(), {facial_landmarks_3d: DATA.facial_mm});
    Page.offerDownload($("download"), JSON.stringify(saved, null, 1), null, !testing);
  };

  /** The photo pixel under a pointer event. */
  function photoUv(e) {
    const rect = stage.getBoundingClientRect();
    return [view.x + (e.clientX - rect.left) * view.width / cssW,
            view.y + (e.clientY - rect.top) * view.height / cssH];
  }
  function pick(u, v) {
    const hit = G.pickSurface(mesh, camera(), u, v);
    $("pick-info").textContent = hit ? "skull surface at (" + hit.point.map((x) => x.toFixed(1))
      .join(", ") + ") mm, face " + hit.face : "no skull under (" + u.toFixed(0) + ", " +
      v.toFixed(0) + ")";
    return hit;
  }
  let drag = null;
  stage.addEventListener("pointerdown", (e) => {
    drag = {x: e.clientX, y: e.clientY, moved: 0, move: e.shiftKey};
    try { stage.setPointerCapture(e.pointerId); } catch (err) { /* synthetic event */ }
    e.preventDefault();
  });
  stage.addEventListener("pointermove", (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.x = e.clientX; drag.y = e.clientY; drag.moved += Math.abs(dx) + Math.abs(dy);
    if (drag.move || e.shiftKey) {
      state.du += dx * view.width / cssW; state.dv += dy * view.height / cssH;
    } else {
      state.yaw += dx * TURN_DEG_PER_PX; state.pitch += dy * TURN_DEG_PER_PX;
    }
    showFields(); schedule();
  });
  stage.addEventListener("pointerup", (e) => {
    if (drag && drag.moved < 3) pick(...photoUv(e));
    drag = null;
  });
  stage.addEventListener("wheel", (e) => {
    e.preventDefault();
    const notches = e.deltaY / (e.deltaMode === 1 ? 3 : 100);
    if (e.ctrlKey || e.altKey || e.metaKey) {  // zoom the view about the pointer
      const [u, v] = photoUv(e), k = Math.pow(WHEEL_ZOOM, notches);
      wanted = {x: u - (u - view.x) * k, y: v - (v - view.y) * k,
                width: view.width * k, height: view.height * k};
      layout();
    } else {
      state.distance *= Math.exp(WHEEL_DISTANCE * notches);
      showFields();
    }
    schedule();
  }, {passive: false});
  window.addEventListener("resize", () => { layout(); schedule(); });

  // ---- first draw, and the test hooks ------------------------------------------------------
  /** The drawn skull's box (photo pixels: the extreme covered pixel centres), measured on an
      offscreen picture of the face region widened by half, at most 1 photo pixel a pixel. */
  function skullBox(cam) {
    const b = boxView(DATA.view_box), grow = 0.25;
    const region = {x: b.x - grow * b.width, y: b.y - grow * b.height,
                    width: (1 + 2 * grow) * b.width, height: (1 + 2 * grow) * b.height};
    const k = Math.min(1, MEASURE_MAX_PX / Math.max(region.width, region.height));
    const w = Math.round(region.width * k), h = Math.round(region.height * k);
    const {mask} = renderer.coverage(cam, region, w, h);
    let i0 = h, i1 = -1, j0 = w, j1 = -1;
    for (let i = 0; i < h; i++) {
      for (let j = 0; j < w; j++) {
        if (!mask[i * w + j]) continue;
        i0 = Math.min(i0, i); i1 = Math.max(i1, i); j0 = Math.min(j0, j); j1 = Math.max(j1, j);
      }
    }
    if (i1 < 0) return "none";
    const u = (j) => region.x + (j + 0.5) * region.width / w;
    const v = (i) => region.y + (i + 0.5) * region.height / h;
    const clipped = i0 === 0 || j0 === 0 || i1 === h - 1 || j1 === w - 1 ? " clipped" : "";
    return [u(j0), v(i0), u(j1), v(i1)].map((x) => x.toFixed(2)).join(" ") + clipped;
  }

  const query = Page.params();
  if (query.has("test")) {
    for (const k of ["yaw", "pitch", "roll"]) if (query.has(k)) state[k] = Number(query.get(k));
  }
  showFields();
  layout();
  redraw();
  if (query.has("test")) {
    if (renderer) {  // one pixel read back: the first draw has finished on the GPU
      renderer.gl.readPixels(0, 0, 1, 1, renderer.gl.RGBA, renderer.gl.UNSIGNED_BYTE,
        new Uint8Array(4));
    }
    const firstDrawMs = performance.now(), cam = camera();
    const out = (id, text) => {
      const pre = document.createElement("pre"); pre.id = id; pre.textContent = text;
      $("test-output").append(pre);
    };
    out("skull-box", renderer ? skullBox(cam) : "no WebGL");
    const name = "nasion" in DATA.cranial_mm ? "nasion" : cranialNames[0];
    if (name) {
      const uv = G.project([DATA.cranial_mm[name]], cam)[0], hit = pick(uv[0], uv[1]);
      out("pick", JSON.stringify({landmark: name, uv, point: hit && hit.point,
        face: hit && hit.face}));
    }
    $("save").onclick();
    out("timing", JSON.stringify({first_draw_ms: firstDrawMs, hooks_done_ms: performance.now()}));
  }
})();
