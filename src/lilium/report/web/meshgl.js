/* meshgl.js: a triangle mesh drawn through Lilium's pinhole camera with raw WebGL 2, and the
   same camera on the CPU (project, rays, surface pick). No third-party code.

   The camera (docs/contract.md, lilium.geometry.camera), written once for every page:

     camera = {focal_px: f, principal_point_px: [cx, cy], skull2cam: [[4 x 4], rows]}
     X_cam = R X + t        skull frame (mm) -> camera frame (x right, y down, z forward)
     u = cx + f x / z       u = column, v = row, in pixels; the centre of the top-left pixel is
     v = cy + f y / z       (0, 0); square pixels, no distortion

   Points at or behind the camera (z <= MIN_DEPTH_MM) project to NaN, so item i stays point i.

   A view is the part of the photo a canvas (or an offscreen target) shows, in photo pixels:
   {x, y, width, height}, x and y the left and top EDGES. The whole W x H photo is
   {x: -0.5, y: -0.5, width: W, height: H}; the canvas stretches the view over all its pixels.

   A mesh: MeshGL.mesh(positions, indices, origin): positions a Float32Array (V * 3) of skull
   frame points minus origin (mm; float32 keeps ~1e-5 mm near the origin), indices a
   Uint32Array (F * 3), origin [x, y, z] mm. Every point a function returns is in the skull
   frame, origin added back.
*/
const MeshGL = (function () {
  "use strict";

  /** Depth (mm) at or below which a point is behind the camera (lilium.constants). */
  const MIN_DEPTH_MM = 1e-6;
  /** Colour (RGB in [0, 1]) and headlight of lilium.imaging.overlay.render_mesh_shaded:
      two-sided Lambert, intensity 0.25 + 0.75 |n . light|, one colour per triangle. */
  const SKULL_RGB = [235 / 255, 225 / 255, 190 / 255];
  const LIGHT_DIR_CAM = normalize([-0.3, -0.4, -1.0]);
  /** Orange of the overlay's silhouette outline. */
  const OUTLINE_RGB = [1.0, 170 / 255, 0.0];

  // ---- 3-vectors and 3x3 matrices (arrays of rows) ------------------------------------------
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function cross(a, b) {
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  }
  function add(a, b) { return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]; }
  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function scale(a, s) { return [a[0] * s, a[1] * s, a[2] * s]; }
  function norm(a) { return Math.sqrt(dot(a, a)); }
  function normalize(a) { return scale(a, 1 / norm(a)); }
  function apply(M, x) { return [dot(M[0], x), dot(M[1], x), dot(M[2], x)]; }
  function transpose(M) { return [0, 1, 2].map((j) => [M[0][j], M[1][j], M[2][j]]); }
  function matmul(A, B) {
    const Bt = transpose(B);
    return A.map((row) => Bt.map((col) => dot(row, col)));
  }
  /** Rotation by `deg` degrees about the unit `axis` (right hand), Rodrigues' formula. */
  function rotation(axis, deg) {
    const [x, y, z] = normalize(axis), a = deg * Math.PI / 180;
    const c = Math.cos(a), s = Math.sin(a), k = 1 - c;
    return [
      [c + x * x * k, x * y * k - z * s, x * z * k + y * s],
      [y * x * k + z * s, c + y * y * k, y * z * k - x * s],
      [z * x * k - y * s, z * y * k + x * s, c + z * z * k],
    ];
  }

  // ---- the camera on the CPU ----------------------------------------------------------------
  function rotationOf(camera) { return camera.skull2cam.slice(0, 3).map((r) => r.slice(0, 3)); }
  function translationOf(camera) { return camera.skull2cam.slice(0, 3).map((r) => r[3]); }
  /** The camera {focal_px, principal_point_px, skull2cam} of a rotation, translation, focal. */
  function makeCamera(R, t, focal, principal) {
    const rows = R.map((r, i) => [r[0], r[1], r[2], t[i]]);
    return {focal_px: focal, principal_point_px: principal.slice(), skull2cam: rows.concat(
      [[0, 0, 0, 1]])};
  }
  /** The rotation (skull2cam's R: rows are the camera's x, y, z axes in the skull frame) of a
      camera looking along `forward` with the image's down (+v) along `down` (its part across
      `forward`); x = y cross z, so the frame is right-handed. */
  function lookRotation(forward, down) {
    const z = normalize(forward);
    const y = normalize(sub(down, scale(z, dot(down, z))));
    return [cross(y, z), y, z];
  }
  /** An orbit camera: rotation R, and the skull-frame point `pivot` (mm) at camera-frame
      [shift[0], shift[1], distance] (mm), so turning R turns the skull about the pivot and
      `shift` pans it across the image. */
  function orbitCamera(R, pivot, distance, shift, focal, principal) {
    const t = sub([shift[0], shift[1], distance], apply(R, pivot));
    return makeCamera(R, t, focal, principal);
  }
  /** A skull-frame point in the camera frame (mm). */
  function toCamera(point, camera) {
    return add(apply(rotationOf(camera), point), translationOf(camera));
  }
  /** Pixel coordinates [[u, v], ...] of skull-frame points [[x, y, z], ...]; NaN behind. */
  function project(points, camera) {
    const R = rotationOf(camera), t = translationOf(camera);
    const f = camera.focal_px, [cx, cy] = camera.principal_point_px;
    return points.map((p) => {
      const X = add(apply(R, p), t);
      if (!(X[2] > MIN_DEPTH_MM)) return [NaN, NaN];
      return [cx + f * X[0] / X[2], cy + f * X[1] / X[2]];
    });
  }
  /** The ray through pixel (u, v), skull frame: {origin: the camera centre, direction: unit}. */
  function ray(camera, u, v) {
    const R = rotationOf(camera), Rt = transpose(R), t = translationOf(camera);
    const [cx, cy] = camera.principal_point_px, f = camera.focal_px;
    return {origin: scale(apply(Rt, t), -1),
            direction: normalize(apply(Rt, [(u - cx) / f, (v - cy) / f, 1]))};
  }

  // ---- meshes ------------------------------------------------------------------------------
  function mesh(positions, indices, origin) {
    let lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < positions.length; i += 3) {
      for (let k = 0; k < 3; k++) {
        lo[k] = Math.min(lo[k], positions[i + k]); hi[k] = Math.max(hi[k], positions[i + k]);
      }
    }
    const centre = scale(add(lo, hi), 0.5);  // relative to origin
    return {positions, indices, origin: (origin || [0, 0, 0]).slice(), centre,
            radius: norm(sub(hi, lo)) / 2};
  }

  /** The first surface point the ray through pixel (u, v) meets (Moller-Trumbore, every face,
      both windings). Returns {point: [x, y, z] skull frame mm, face: index, distance: mm from
      the camera centre} or null when the ray misses the mesh. */
  function pickSurface(m, camera, u, v) {
    const r = ray(camera, u, v), o = sub(r.origin, m.origin), d = r.direction;
    const P = m.positions, I = m.indices;
    let best = Infinity, face = -1;
    for (let f = 0; f < I.length; f += 3) {
      const a = 3 * I[f], b = 3 * I[f + 1], c = 3 * I[f + 2];
      const e1x = P[b] - P[a], e1y = P[b + 1] - P[a + 1], e1z = P[b + 2] - P[a + 2];
      const e2x = P[c] - P[a], e2y = P[c + 1] - P[a + 1], e2z = P[c + 2] - P[a + 2];
      const px = d[1] * e2z - d[2] * e2y, py = d[2] * e2x - d[0] * e2z, pz = d[0] * e2y - d[1] * e2x;
      const det = e1x * px + e1y * py + e1z * pz;
      if (Math.abs(det) < 1e-12) continue;  // the ray runs along the triangle's plane
      const inv = 1 / det, sx = o[0] - P[a], sy = o[1] - P[a + 1], sz = o[2] - P[a + 2];
      const s = (sx * px + sy * py + sz * pz) * inv;
      if (s < 0 || s > 1) continue;
      const qx = sy * e1z - sz * e1y, qy = sz * e1x - sx * e1z, qz = sx * e1y - sy * e1x;
      const w = (d[0] * qx + d[1] * qy + d[2] * qz) * inv;
      if (w < 0 || s + w > 1) continue;
      const dist = (e2x * qx + e2y * qy + e2z * qz) * inv;
      if (dist > 0 && dist < best) { best = dist; face = f / 3; }
    }
    if (face < 0) return null;
    return {point: add(r.origin, scale(d, best)), face, distance: best};
  }

  // ---- WebGL 2 ----------------------------------------------------------------------------
  // The vertex shader is the projection above, written in clip coordinates with w = z, so the
  // hardware's divide gives u, v exactly, triangles are clipped at the near plane and
  // interpolation is perspective-correct: NDC x = 2 (u - view.x) / view.width - 1 and
  // NDC y = 1 - 2 (v - view.y) / view.height, both multiplied by z; depth is the usual
  // perspective depth between near and far (mm), which bracket the mesh.
  const MESH_VS = `#version 300 es
  precision highp float;
  in vec3 position;           // skull frame minus the mesh origin, mm
  uniform mat3 R;             // skull2cam rotation
  uniform vec3 t;             // skull2cam translation plus R * origin (mm)
  uniform float focal;        // pixels
  uniform vec2 principal;     // pixels
  uniform vec4 view;          // left edge, top edge, width, height (photo pixels)
  uniform vec2 depth;         // near, far (mm)
  out vec3 rotated;           // R * position: camera-frame offsets, for the face normal
  void main() {
    rotated = R * position;
    vec3 X = rotated + t;
    float x = 2.0 * (focal * X.x + (principal.x - view.x) * X.z) / view.z - X.z;
    float y = X.z - 2.0 * (focal * X.y + (principal.y - view.y) * X.z) / view.w;
    float n = depth.x, f = depth.y;
    gl_Position = vec4(x, y, ((f + n) * X.z - 2.0 * f * n) / (f - n), X.z);
  }`;
  // One colour per triangle, as the overlay: the face normal from the screen derivatives of
  // the camera-frame position (flat shading without a normal per vertex).
  const MESH_FS = `#version 300 es
  precision highp float;
  in vec3 rotated;
  uniform vec3 light;
  uniform vec3 color;
  out vec4 fragment;
  void main() {
    vec3 n = normalize(cross(dFdx(rotated), dFdy(rotated)));
    fragment = vec4((0.25 + 0.75 * abs(dot(n, light))) * color, 1.0);
  }`;
  // Camera-frame depth instead of a colour: (z - near) / (far - near) in 24 bits (r, g, b
  // high to low), alpha 1 where the mesh is; Renderer.depthAt reads it back.
  const DEPTH_FS = `#version 300 es
  precision highp float;
  in vec3 rotated;
  uniform vec3 t;
  uniform vec2 depth;
  out vec4 fragment;
  void main() {
    float s = clamp((rotated.z + t.z - depth.x) / (depth.y - depth.x), 0.0, 1.0);
    float k = floor(s * 16777215.0 + 0.5);
    float r = floor(k / 65536.0);
    float g = floor((k - r * 65536.0) / 256.0);
    fragment = vec4(r, g, k - r * 65536.0 - g * 256.0, 255.0) / 255.0;
  }`;
  // Full-canvas triangle that blends the offscreen skull at `alpha` (premultiplied) and draws
  // its silhouette's inner `outline.w` pixels opaque in `outline.rgb`.
  const QUAD_VS = `#version 300 es
  void main() {
    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0);
  }`;
  const COMPOSITE_FS = `#version 300 es
  precision highp float;
  uniform sampler2D skull;
  uniform float alpha;
  uniform vec4 outline;
  out vec4 fragment;
  bool covered(ivec2 p) {
    ivec2 size = textureSize(skull, 0);
    if (p.x < 0 || p.y < 0 || p.x >= size.x || p.y >= size.y) return false;
    return texelFetch(skull, p, 0).a > 0.5;
  }
  void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 c = texelFetch(skull, p, 0);
    if (c.a < 0.5) { fragment = vec4(0.0); return; }
    for (int k = 1; k <= 8; k++) {
      if (float(k) > outline.w) break;
      if (!covered(p + ivec2(k, 0)) || !covered(p - ivec2(k, 0)) ||
          !covered(p + ivec2(0, k)) || !covered(p - ivec2(0, k))) {
        fragment = vec4(outline.rgb, 1.0); return;
      }
    }
    fragment = vec4(c.rgb * alpha, alpha);
  }`;

  function compile(gl, vs, fs) {
    const program = gl.createProgram();
    for (const [type, source] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
      const shader = gl.createShader(type);
      gl.shaderSource(shader, source); gl.compileShader(shader);
      if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) {
        throw new Error("shader: " + gl.getShaderInfoLog(shader));
      }
      gl.attachShader(program, shader);
    }
    gl.bindAttribLocation(program, 0, "position");
    gl.linkProgram(program);
    if (!gl.getProgramParameter(program, gl.LINK_STATUS)) {
      throw new Error("program: " + gl.getProgramInfoLog(program));
    }
    const uniforms = {};
    for (let i = 0; i < gl.getProgramParameter(program, gl.ACTIVE_UNIFORMS); i++) {
      const name = gl.getActiveUniform(program, i).name;
      uniforms[name] = gl.getUniformLocation(program, name);
    }
    return {program, uniforms};
  }

  /** An offscreen colour texture and depth buffer of width x height pixels. */
  function target(gl, width, height) {
    const texture = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, texture);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, width, height, 0, gl.RGBA, gl.UNSIGNED_BYTE, null);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) {
      gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
    }
    const depth = gl.createRenderbuffer();
    gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, width, height);
    const framebuffer = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, framebuffer);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, texture, 0);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, depth);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    return {width, height, texture, depth, framebuffer};
  }

  /** Draws one mesh on one canvas: `draw(camera, view, style)`; `coverage(...)` reads back
      where it lands. The canvas keeps its drawing buffer (preserveDrawingBuffer), so a
      screenshot or readPixels sees what was drawn. */
  class Renderer {
    constructor(canvas) {
      const gl = canvas.getContext("webgl2", {antialias: false, alpha: true,
        premultipliedAlpha: true, preserveDrawingBuffer: true});
      if (!gl) throw new Error("this page needs WebGL 2 (any current browser has it)");
      this.gl = gl; this.canvas = canvas; this.targets = {};
      this.meshProgram = compile(gl, MESH_VS, MESH_FS);
      this.depthProgram = compile(gl, MESH_VS, DEPTH_FS);
      this.compositeProgram = compile(gl, QUAD_VS, COMPOSITE_FS);
      this.vao = gl.createVertexArray();
      this.quad = gl.createVertexArray();  // no attributes: the vertices come from gl_VertexID
    }
    setMesh(m) {
      const gl = this.gl;
      this.mesh = m;
      gl.bindVertexArray(this.vao);
      gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
      gl.bufferData(gl.ARRAY_BUFFER, m.positions, gl.STATIC_DRAW);
      gl.enableVertexAttribArray(0);
      gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer());
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, m.indices, gl.STATIC_DRAW);
      gl.bindVertexArray(null);
    }
    /** The offscreen target `name`, (re)made at width x height. */
    target(name, width, height) {
      const old = this.targets[name];
      if (old && old.width === width && old.height === height) return old;
      if (old) {
        this.gl.deleteFramebuffer(old.framebuffer); this.gl.deleteTexture(old.texture);
        this.gl.deleteRenderbuffer(old.depth);
      }
      return (this.targets[name] = target(this.gl, width, height));
    }
    /** The shaded mesh (opaque) into the bound framebuffer of width x height pixels; with
        `shader` (a compiled program; default the shaded one) another fragment shader over the
        same projection.
        Returns the [near, far] depths (mm) it used, or null when nothing was drawn. */
    drawMesh(camera, view, width, height, style, shader) {
      const gl = this.gl, m = this.mesh, {program, uniforms} = shader || this.meshProgram;
      gl.viewport(0, 0, width, height);
      gl.clearColor(0, 0, 0, 0); gl.clearDepth(1);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      if (!m) return null;
      const R = rotationOf(camera), t = add(translationOf(camera), apply(R, m.origin));
      // Near and far planes bracket the mesh's bounding sphere (1% margin).
      const zc = apply(R, m.centre)[2] + t[2], r = 1.01 * m.radius;
      const far = zc + r, near = Math.max(zc - r, 1e-4 * far);
      if (far <= MIN_DEPTH_MM) return null;  // the whole mesh is behind the camera
      gl.useProgram(program);
      gl.uniformMatrix3fv(uniforms.R, false, [].concat(...transpose(R)));  // column-major
      gl.uniform3fv(uniforms.t, t);
      gl.uniform1f(uniforms.focal, camera.focal_px);
      gl.uniform2fv(uniforms.principal, camera.principal_point_px);
      gl.uniform4f(uniforms.view, view.x, view.y, view.width, view.height);
      gl.uniform2f(uniforms.depth, near, far);
      if (uniforms.light) gl.uniform3fv(uniforms.light, (style && style.light) || LIGHT_DIR_CAM);
      if (uniforms.color) gl.uniform3fv(uniforms.color, (style && style.color) || SKULL_RGB);
      gl.enable(gl.DEPTH_TEST); gl.depthFunc(gl.LESS);
      gl.bindVertexArray(this.vao);
      gl.drawElements(gl.TRIANGLES, m.indices.length, gl.UNSIGNED_INT, 0);
      gl.bindVertexArray(null);
      gl.disable(gl.DEPTH_TEST);
      return [near, far];
    }
    /** The mesh on the whole canvas, showing `view` of the photo. style: {alpha (opacity, 0-1),
        outline (px, 0 = none), outlineColor, color, light}. */
    draw(camera, view, style) {
      const gl = this.gl, s = style || {}, w = this.canvas.width, h = this.canvas.height;
      const skull = this.target("display", w, h);
      gl.bindFramebuffer(gl.FRAMEBUFFER, skull.framebuffer);
      this.drawMesh(camera, view, w, h, s);
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.viewport(0, 0, w, h); gl.clearColor(0, 0, 0, 0); gl.clear(gl.COLOR_BUFFER_BIT);
      const {program, uniforms} = this.compositeProgram;
      gl.useProgram(program);
      gl.activeTexture(gl.TEXTURE0); gl.bindTexture(gl.TEXTURE_2D, skull.texture);
      gl.uniform1i(uniforms.skull, 0);
      gl.uniform1f(uniforms.alpha, s.alpha === undefined ? 1 : s.alpha);
      gl.uniform4f(uniforms.outline, ...(s.outlineColor || OUTLINE_RGB), s.outline || 0);
      gl.bindVertexArray(this.quad);
      gl.drawArrays(gl.TRIANGLES, 0, 3);
      gl.bindVertexArray(null);
    }
    /** Where the mesh lands: rendered offscreen at width x height over `view` and read back
        (gl.readPixels). Returns {mask: Uint8Array (1 = mesh), width, height, view}, rows from
        the top: pixel (row i, column j) has its centre at photo pixel
        (view.x + (j + 0.5) view.width / width, view.y + (i + 0.5) view.height / height). */
    coverage(camera, view, width, height) {
      const gl = this.gl, off = this.target("coverage", width, height);
      gl.bindFramebuffer(gl.FRAMEBUFFER, off.framebuffer);
      this.drawMesh(camera, view, width, height, {});
      const rgba = new Uint8Array(4 * width * height);
      gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, rgba);
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      const mask = new Uint8Array(width * height);
      for (let i = 0; i < height; i++) {  // readPixels' rows run from the bottom
        const src = 4 * (height - 1 - i) * width, dst = i * width;
        for (let j = 0; j < width; j++) mask[dst + j] = rgba[src + 4 * j + 3] > 127 ? 1 : 0;
      }
      return {mask, width, height, view};
    }
    /** The camera-frame depth (mm) of the nearest surface around each photo pixel [u, v] of
        `points`, drawn offscreen at width x height over `view`: for each point the FARTHEST
        such depth among the pixels within `radius` pixels (default 1) of its pixel, Infinity
        where one of them shows no mesh, NaN where the point is off the picture (or not
        finite). A point on the surface is in sight when its own depth is at most this plus a
        tolerance (a silhouette or a steep slope keeps it in sight). */
    depthAt(camera, view, width, height, points, radius) {
      const gl = this.gl, off = this.target("depth", width, height), k = radius === undefined
        ? 1 : radius;
      gl.bindFramebuffer(gl.FRAMEBUFFER, off.framebuffer);
      const range = this.drawMesh(camera, view, width, height, {}, this.depthProgram);
      const side = 2 * k + 1, rgba = new Uint8Array(4 * side * side);
      const out = points.map(([u, v]) => {
        const j = Math.floor((u - view.x) * width / view.width);
        const i = Math.floor((v - view.y) * height / view.height);
        if (!(j >= 0 && i >= 0 && j < width && i < height)) return NaN;
        if (!range) return Infinity;
        const j0 = Math.max(0, j - k), j1 = Math.min(width - 1, j + k);
        const i0 = Math.max(0, i - k), i1 = Math.min(height - 1, i + k);
        const w = j1 - j0 + 1, h = i1 - i0 + 1;
        gl.readPixels(j0, height - 1 - i1, w, h, gl.RGBA, gl.UNSIGNED_BYTE, rgba);
        let far = -Infinity;
        for (let p = 0; p < w * h; p++) {
          if (rgba[4 * p + 3] < 128) return Infinity;
          const s = (rgba[4 * p] * 65536 + rgba[4 * p + 1] * 256 + rgba[4 * p + 2]) / 16777215;
          far = Math.max(far, range[0] + s * (range[1] - range[0]));
        }
        return far;
      });
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      return out;
    }
  }

  return {MIN_DEPTH_MM, SKULL_RGB, LIGHT_DIR_CAM, OUTLINE_RGB, add, sub, scale, dot, cross, norm,
    normalize, apply, transpose, matmul, rotation, rotationOf, translationOf, makeCamera,
    lookRotation, orbitCamera, toCamera, project, ray, mesh, pickSurface, Renderer};
})();
