"""``review.html``: the photo, every landmark (draggable, each can be switched off), the mask
outline and the priors, in one self-contained page (no network, no server).

A page opened from ``file://`` cannot write to disk, so **Save** offers the edited landmarks
as a download, ``landmarks.json`` (a ``data:`` link): ``{"landmarks": {name: [u, v]},
"landmark_sources": {name: {"source": "reviewed", "quality": ..., "confirmed": true}}}``,
the contract's landmark file that ``lilium case --landmarks`` and ``lilium photo --landmarks``
read. Only the points switched on are saved; template points start switched off, so saving
without looking confirms none of them. Opened with ``?test``, the page drags the first
landmark by (+10, +5) px with pointer events, presses Save and shows the file in
``<pre id="saved">`` (for the headless-browser test).
"""

import base64
import html
import io
import json
import re

import numpy as np

_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>Review: __TITLE__</title>
<style>
body{font-family:sans-serif;margin:0;display:flex;gap:1em}
#view{flex:1;min-width:0} svg{width:100%;height:auto;max-height:96vh;touch-action:none}
#side{width:22em;padding:.5em;font-size:90%} .lm{cursor:move} .off{opacity:.25}
.tracked{fill:#f33} .template{fill:#39f} text{font-size:__FONT__px;fill:#ff0;paint-order:stroke;
stroke:#000;stroke-width:2px;pointer-events:none} pre{white-space:pre-wrap;font-size:80%}
</style></head><body>
<div id="view"><svg id="svg" viewBox="-0.5 -0.5 __W__ __H__">
<image href="__IMAGE__" x="-0.5" y="-0.5" width="__W__" height="__H__"
preserveAspectRatio="none"/>
<polygon id="outline" points="__OUTLINE__" fill="none" stroke="#0f0" stroke-width="__STROKE__"/>
<g id="points"></g></svg></div>
<div id="side"><h3>__TITLE__</h3><p>__MESSAGE__</p>
<p>Drag a point to move it; untick it to leave it out. <b>Template</b> points (blue) are the
face model's guess: tick them only once you have checked them.</p>
<div id="list"></div><p><button id="save">Save landmarks.json</button>
<a id="download" download="landmarks.json" href="#" hidden>landmarks.json</a></p>
<h4>Priors</h4><pre id="priors"></pre><pre id="saved"></pre></div>
<script>
const DATA = __DATA__;
const svg = document.getElementById("svg"), group = document.getElementById("points");
const state = {};
function toSvg(evt) {
  const p = svg.createSVGPoint(); p.x = evt.clientX; p.y = evt.clientY;
  return p.matrixTransform(svg.getScreenCTM().inverse());
}
function place(name) {
  const s = state[name];
  s.dot.setAttribute("cx", s.uv[0]); s.dot.setAttribute("cy", s.uv[1]);
  s.label.setAttribute("x", s.uv[0] + DATA.r * 1.5); s.label.setAttribute("y", s.uv[1]);
  s.dot.classList.toggle("off", !s.on); s.label.classList.toggle("off", !s.on);
  s.coords.textContent = s.uv[0].toFixed(1) + ", " + s.uv[1].toFixed(1);
}
for (const [name, uv] of Object.entries(DATA.landmarks)) {
  const quality = (DATA.sources[name] || {}).quality || "manual";
  const dot = document.createElementNS("http://www.w3.org/2000/svg", "circle");
  dot.setAttribute("r", DATA.r); dot.setAttribute("class", "lm " + quality);
  dot.id = "lm-" + name;
  const label = document.createElementNS("http://www.w3.org/2000/svg", "text");
  label.textContent = name; group.append(dot, label);
  const row = document.createElement("div");
  const box = document.createElement("input"); box.type = "checkbox"; box.id = "on-" + name;
  const coords = document.createElement("span");
  row.append(box, " " + name + " (" + quality + ") ", coords);
  document.getElementById("list").append(row);
  state[name] = {uv: uv.slice(), on: quality !== "template", quality, dot, label, coords};
  box.checked = state[name].on;
  box.onchange = () => { state[name].on = box.checked; place(name); };
  dot.addEventListener("pointerdown", (e) => {
    dot.setPointerCapture(e.pointerId); state[name].drag = true; e.preventDefault();
  });
  dot.addEventListener("pointermove", (e) => {
    if (!state[name].drag) return;
    const p = toSvg(e); state[name].uv = [p.x, p.y]; place(name);
  });
  dot.addEventListener("pointerup", () => { state[name].drag = false; });
  place(name);
}
document.getElementById("priors").textContent = JSON.stringify(DATA.priors, null, 1);
function saved() {
  const out = {landmarks: {}, landmark_sources: {}};
  for (const [name, s] of Object.entries(state)) {
    if (!s.on) continue;
    out.landmarks[name] = [Math.round(s.uv[0] * 100) / 100, Math.round(s.uv[1] * 100) / 100];
    out.landmark_sources[name] = {source: "reviewed", quality: s.quality, confirmed: true};
  }
  return JSON.stringify(out, null, 1);
}
document.getElementById("save").onclick = () => {
  const text = saved(), link = document.getElementById("download");
  link.href = "data:application/json;charset=utf-8," + encodeURIComponent(text);
  link.hidden = false; link.click();
  document.getElementById("saved").textContent = text;
};
if (new URLSearchParams(location.search).has("test")) {
  const first = Object.keys(state)[0], dot = state[first].dot;
  const m = svg.getScreenCTM(), uv = state[first].uv;
  const at = (du, dv) => ({clientX: m.a * (uv[0] + du) + m.e, clientY: m.d * (uv[1] + dv) + m.f,
                           pointerId: 1, bubbles: true});
  const start = at(0, 0), end = at(10, 5);
  dot.dispatchEvent(new PointerEvent("pointerdown", start));
  dot.dispatchEvent(new PointerEvent("pointermove", end));
  dot.dispatchEvent(new PointerEvent("pointerup", end));
  document.getElementById("save").onclick();
}
</script></body></html>
"""


#: Long side (pixels) of the picture embedded in the page; the page's coordinates stay the
#: photo's own pixels (the SVG stretches the picture over them).
PAGE_SIDE_PX = 2000


def _data_url(image):
    from PIL import Image

    picture = Image.fromarray(image)
    if max(picture.size) > PAGE_SIDE_PX:
        picture.thumbnail((PAGE_SIDE_PX, PAGE_SIDE_PX), Image.BILINEAR)
    buffer = io.BytesIO()
    picture.save(buffer, format="JPEG", quality=90)
    return "data:image/jpeg;base64," + base64.b64encode(buffer.getvalue()).decode("ascii")


#: What :func:`script_json` writes for the characters that could end a ``<script>`` or open a
#: comment or entity in it.
_SCRIPT_ESCAPES = {"<": "\\u003c", ">": "\\u003e", "&": "\\u0026"}


def script_json(value):
    """``value`` as JSON to embed in a ``<script>``: no ``</script>`` or ``<!--`` can appear.

    ``<``, ``>`` and ``&`` (found only inside JSON strings) become ``\\u003c``, ``\\u003e`` and
    ``\\u0026``, which JSON and JavaScript read back as the same characters; non-ASCII text is
    escaped too (``json.dumps``' default), so U+2028 and U+2029 cannot break the line.
    """
    text = json.dumps(value)
    return re.sub("[<>&]", lambda match: _SCRIPT_ESCAPES[match.group(0)], text)


def fill_template(template, values):
    """``template`` with every placeholder (a key of ``values``) replaced, in one pass.

    The values are never scanned again, so a placeholder's text inside one of them (a photo
    named ``a__W__.png`` in the title) stays as it is. Escape the values for where they go.

    Parameters
    ----------
    template : str
    values : dict of str -> str
        Placeholder (e.g. ``"__TITLE__"``) -> its text.
    """
    pattern = re.compile("|".join(re.escape(key) for key in sorted(values, key=len, reverse=True)))
    return pattern.sub(lambda match: values[match.group(0)], template)


def review_page(image, landmarks, sources, outline_uv, priors, title, message="", faces=()):
    """The review page as a string.

    Parameters
    ----------
    image : ndarray of shape (H, W, 3), uint8
    landmarks : dict of str -> (u, v)
    sources : dict of str -> dict
        ``landmark_sources`` (their ``quality`` colours the points).
    outline_uv : ndarray of shape (N, 2)
        Mask outline.
    priors : dict
        Shown as written to ``photo.json``.
    title, message : str
    faces : sequence of dict
        ``photo.json``'s ``faces`` (not drawn yet).
    """
    h, w = image.shape[:2]
    data = {
        "landmarks": {k: [float(x) for x in v] for k, v in landmarks.items()},
        "sources": sources,
        "priors": priors,
        "r": max(1.5, max(h, w) / 250),
    }
    outline = " ".join(f"{u:.1f},{v:.1f}" for u, v in np.asarray(outline_uv).reshape(-1, 2))
    values = {
        "__TITLE__": html.escape(title),
        "__MESSAGE__": html.escape(message),
        "__W__": str(w),
        "__H__": str(h),
        "__FONT__": f"{max(8, max(h, w) / 60):.0f}",
        "__STROKE__": f"{max(1, max(h, w) / 400):.1f}",
        "__OUTLINE__": outline,
        "__IMAGE__": _data_url(image),
        "__DATA__": script_json(data),
    }
    return fill_template(_PAGE, values)
