"""Report-consistency probes, run by ``probe_hostile.py``: what the HTML report (``lilium case``'s
``report.html``, ``lilium lineup``'s), the console and ``lineup.json`` show must be what the
``result.json`` files hold. "Pictures they can judge and a conclusion they can sign": a report
that shows another conclusion, another LR, another camera, hides a cap, a warning or a term
switched off, or pictures another photo, is a silently wrong answer.

Each probe runs ``lilium case`` (one photo, several, ``--joint``), ``lilium lineup`` (several
candidates, one with several photos, candidates that tie, one whose SFO fails) or ``lilium sfo``
on inputs that reach different states (success, a failed SFO, warnings ``view_mismatch``,
``outside_prior``, ``landmark_outside_mask``, ``mesh_part_left_out``, a term switched off, the
caps of the conclusion, a skull outside the head) and checks, from the files alone:

- every SFO section of the report links its ``result.json``, shows its photo and method, its
  failure (the same message), every warning code beside it (section and summary, the same
  multiset), every term switched off, the focal, the method's own score, each term value, the
  landmark table's estimates and errors (the projection of ``result.json``'s 3D facial landmarks
  with its camera), "implausible" exactly when the identification names the skull outside the
  head;
- the overlay each section links exists, is a readable PNG of its photo's size, and is that
  photo with this camera's skull drawn on it (unchanged pixels where the photo is; the drawn
  pixels' box where ``result.json``'s camera projects the skull); the embedded photo picture is
  the photo's region, the skull layer lies where the camera projects the skull;
- each conclusion row shows ``result.json``'s conclusion, log10 LR, every cap and consistency
  code and the calibration model; the joint SFO's row its ``result.json``'s;
- the console's conclusion line of each SFO and decision says what ``result.json`` (or the
  report's row of that decision) says;
- a lineup's order follows its LRs (ties broken as documented: the views' log10 LRs added, then
  the unbounded score), and the report's ranking rows, the console's and ``lineup.json``'s agree.

The console is captured by wrapping :func:`lilium.cli.main.main` while a probe runs (the set-up
arms it; nothing else changes). Budgets: POSEST-SFO, or Lilium with 5 x 2. ::

    python benchmarks/probe_hostile_report.py --work /tmp/report-probes [--only TEXT]
"""

import base64
import importlib
import io
import re
import sys
import urllib.parse
from html.parser import HTMLParser
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from probe_hostile import Probe  # noqa: E402
from probe_hostile_casework import TINY, _calibration, _only_models, _quiet_main  # noqa: E402
from probe_hostile_semantic import (  # noqa: E402
    _edit_json,
    _in,
    _invert_mask,
    _json,
    _syn,
    _then,
    _view,
)

# -- the console ------------------------------------------------------------------------------

_ARMED = []


def _recording_main(argv=None):
    """:func:`lilium.cli.main.main`, recording the streams it prints to on the armed workspace."""
    module = importlib.import_module("lilium.cli.main")
    ws = _ARMED.pop() if _ARMED else None
    if ws is not None:
        ws.console = (sys.stdout, sys.stderr)
    return module._report_probe_real_main(argv)


def _install():
    """Wrap :func:`lilium.cli.main.main` (once): ``run_probe`` imports it before the set-up
    runs, so the wrapper is in place when the probes are made. Transparent when not armed."""
    module = importlib.import_module("lilium.cli.main")
    if not hasattr(module, "_report_probe_real_main"):
        module._report_probe_real_main = module.main
        module.main = _recording_main


def _arm(ws):
    """Set-up (last step): the next ``lilium`` command records its console on ``ws``."""
    _install()
    _ARMED.clear()
    _ARMED.append(ws)
    ws.console = None


def _console(ws):
    streams = getattr(ws, "console", None)
    if not streams:
        return "", ""
    return tuple(s.getvalue() if isinstance(s, io.StringIO) else "" for s in streams)


# -- the page ---------------------------------------------------------------------------------

_VOID = {"img", "br", "input", "meta", "link", "hr", "col", "source", "wbr", "area", "base"}


class _Node:
    def __init__(self, tag, attrs, parent=None):
        self.tag, self.attrs, self.parent, self.children = tag, dict(attrs), parent, []

    def cls(self):
        return (self.attrs.get("class") or "").split()

    def text(self):
        return "".join(c if isinstance(c, str) else c.text() for c in self.children)

    def find_all(self, tag=None, cls=None, **attrs):
        out = []
        for c in self.children:
            if isinstance(c, str):
                continue
            if (
                (tag is None or c.tag == tag)
                and (cls is None or cls in c.cls())
                and all(c.attrs.get(k) == v for k, v in attrs.items())
            ):
                out.append(c)
            out += c.find_all(tag, cls, **attrs)
        return out

    def find(self, tag=None, cls=None, **attrs):
        found = self.find_all(tag, cls, **attrs)
        return found[0] if found else None


class _Tree(HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.root = _Node("root", {})
        self.stack = [self.root]

    def handle_starttag(self, tag, attrs):
        node = _Node(tag, attrs, self.stack[-1])
        self.stack[-1].children.append(node)
        if tag not in _VOID:
            self.stack.append(node)

    def handle_startendtag(self, tag, attrs):
        self.stack[-1].children.append(_Node(tag, attrs, self.stack[-1]))

    def handle_endtag(self, tag):
        for k in range(len(self.stack) - 1, 0, -1):
            if self.stack[k].tag == tag:
                del self.stack[k:]
                return

    def handle_data(self, data):
        self.stack[-1].children.append(data)


def _parse(path):
    tree = _Tree()
    tree.feed(Path(path).read_text(encoding="utf-8"))
    return tree.root


def _rows(table):
    """The ``<tbody>`` rows of a table as lists of cell nodes."""
    body = table.find("tbody") or table
    return [tr.find_all("td") for tr in body.find_all("tr")]


def _header(table):
    return [th.text().strip() for th in table.find_all("th")]


def _norm(text):
    return re.sub(r"\s+", " ", text).strip()


def _decode(src):
    from PIL import Image

    data = base64.b64decode(src.split(",", 1)[1])
    im = Image.open(io.BytesIO(data))
    im.load()
    return im


# -- what the files hold ----------------------------------------------------------------------


def _fmt_lr(lr):
    return "–" if lr is None else f"{lr:+.2f}"


def _project(camera, points):
    T = np.asarray(camera["skull2cam"], float)
    X = np.asarray(points, float) @ T[:3, :3].T + T[:3, 3]
    centre = np.asarray(camera["principal_point_px"], float)
    return centre + camera["focal_px"] * X[:, :2] / X[:, 2:3]


def _skull_vertices(skull_path, landmarks_mm):
    """The skull mesh's vertices of the part holding the cranial landmarks (a fragment apart is
    left out of every picture, as docs/checks.md says)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from lilium.io.mesh import read_mesh

    v, f = read_mesh(skull_path)
    v, f = np.asarray(v, float), np.asarray(f, int)
    edges = np.vstack([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(len(v), len(v)))
    _, label = connected_components(graph, directed=False)
    used = np.zeros(len(v), bool)
    used[f.ravel()] = True
    if landmarks_mm:
        nearest = [int(np.argmin(np.where(used, np.linalg.norm(v - p, axis=1), np.inf)))
                   for p in landmarks_mm]  # fmt: skip
        keep = np.isin(label, label[nearest])
    else:
        keep = used
    return v[keep & used]


def _cranial_points(skull_path):
    path = Path(skull_path).parent / "cranial_landmarks.json"
    if not path.is_file():
        return None
    return [np.asarray(v, float) for v in _json(path)["landmarks"].values()]


def _skull_box(camera, vertices, size_wh):
    """The box (u0, v0, u1, v1) of the projected skull clipped to the photo, or None."""
    uv = _project(camera, vertices)
    uv = uv[np.all(np.isfinite(uv), axis=1)]
    w, h = size_wh
    inside = (uv[:, 0] > -0.5) & (uv[:, 0] < w - 0.5) & (uv[:, 1] > -0.5) & (uv[:, 1] < h - 0.5)
    if not inside.any():
        return None
    uv = np.clip(uv, [0, 0], [w - 1, h - 1])
    return (*uv.min(axis=0), *uv.max(axis=0))


def _box_close(a, b, tol):
    return all(abs(x - y) <= tol for x, y in zip(a, b, strict=True))


# -- the check of one report ------------------------------------------------------------------


class _Report:
    """The facts of one report page, read once."""

    def __init__(self, page):
        self.page = Path(page)
        self.root = _parse(page)
        tables = self.root.find_all("table")
        self.conclusions = next((t for t in tables if "conclusions" in t.cls()), None)
        self.summary = next((t for t in tables if "status" in _header(t)), None)
        self.sections = self.root.find_all("section", "sfo")

    def conclusion_rows(self):
        """``[(label, anchor, conclusion, uncapped or None, lr text, why text, model)]``."""
        out = []
        for cells in _rows(self.conclusions) if self.conclusions is not None else []:
            if len(cells) != 5:
                continue
            link = cells[0].find("a")
            anchor = link.attrs.get("href", "").lstrip("#") if link is not None else ""
            bold = cells[1].find("b")
            muted = cells[1].find("span", "muted")
            uncapped = None
            if muted is not None:
                m = re.search(r"LR alone: (.*)\)", muted.text())
                uncapped = m.group(1) if m else muted.text()
            lr = _norm(cells[2].text()).split(" ")[0]
            model = cells[4].find("code")
            out.append((_norm(cells[0].text()), anchor, _norm(bold.text()) if bold else "",
                        uncapped, lr, _norm(cells[3].text()),
                        model.text() if model is not None else ""))  # fmt: skip
        return out

    def summary_outside(self, index):
        for cells in _rows(self.summary) if self.summary is not None else []:
            if len(cells) >= 13 and _norm(cells[0].text()) == index:
                try:
                    return float(_norm(cells[10].text()))
                except ValueError:
                    return None
        return None

    def summary_rows(self):
        out = {}
        for cells in _rows(self.summary) if self.summary is not None else []:
            if len(cells) < 13:
                continue
            codes = [s.text() for s in cells[11].find_all("span", "warn")]
            codes = [c for c in codes if not c.startswith("landmarks ")]
            out[_norm(cells[0].text())] = dict(
                photo=_norm(cells[1].text()), method=_norm(cells[3].text()),
                status=_norm(cells[4].text()), focal=_norm(cells[5].text()),
                err_px=_norm(cells[7].text()), score=_norm(cells[9].text()).split(" ")[0],
                warnings=codes,
            )  # fmt: skip
        return out


def _section_facts(sec):
    h2 = _norm(sec.find("h2").text())
    m = re.match(r"(\d+)\. (.*) — (.*)$", h2)
    index, photo, method = (m.group(1), m.group(2), m.group(3)) if m else ("?", h2, "?")
    meta = _norm(sec.find("p", "muted").text())
    size = re.search(r"\((\d+)×(\d+) px, (\S+) view\)", meta)
    warnings = []
    for div in sec.find_all("div", "warnings"):
        for li in div.find_all("li"):
            code = li.find("code")
            text = _norm(li.text())
            if code is not None:
                c = code.text()
                warnings.append((c, text[len(c) + 2 :] if text.startswith(c + ": ") else text))
    failure = next(
        (_norm(p.text()) for p in sec.find_all("p", "fail") if "The SFO failed" in p.text()), None
    )
    implausible = any("Implausible" in p.text() for p in sec.find_all("p", "fail"))
    links = {}
    for p in sec.find_all("p"):
        if _norm(p.text()).startswith("Outputs:"):
            links = {a.text(): a.attrs.get("href", "") for a in p.find_all("a")}
    tables = {}
    for t in sec.find_all("table"):
        head = _header(t)
        key = "landmarks" if "facial landmark" in head else head[0] if head else ""
        tables.setdefault(key, t)
    stage = sec.find("div", "stage")
    imgs = {c: img.attrs.get("src", "") for img in sec.find_all("img") for c in img.cls()}
    return dict(
        index=index, photo=photo, method=method, meta=meta,
        size=(int(size.group(1)), int(size.group(2))) if size else None,
        view=size.group(3) if size else None, warnings=warnings, failure=failure,
        implausible=implausible, links=links, tables=tables,
        box=tuple(int(x) for x in stage.attrs["data-box"].split()) if stage is not None else None,
        imgs=imgs, anchor=sec.attrs.get("id"),
    )  # fmt: skip


def _kv(table):
    """A two-column table as ``{first cell text: second cell text}``."""
    out = {}
    for cells in _rows(table):
        if len(cells) >= 2:
            out[_norm(cells[0].text())] = _norm(cells[1].text())
    return out


def _inputs_of(table):
    """The files table: ``{label: path}``."""
    out = {}
    for cells in _rows(table):
        if len(cells) >= 2:
            out.setdefault(_norm(cells[0].text()), _norm(cells[1].text()))
    return out


def _resolve(page, href):
    return page.parent / urllib.parse.unquote(href)


def _fmt4(x):
    return "–" if x is None else f"{x:.4g}"


def _sfo_problems(rep, sec, facts, result, joint, skull_path, ws):
    """What one SFO section shows other than its result (a list of texts)."""
    from PIL import Image

    p = []
    verts = _skull_vertices(skull_path, _cranial_points(skull_path))
    label = f"report section {facts['index']} ({facts['photo']}, {facts['method']})"
    method = result.get("method", "") + (f" {result['variant']}" if result.get("variant") else "")
    method += " joint" if joint else ""
    if facts["method"] != method:
        p.append(f"{label}: shows method {facts['method']!r}, result.json {method!r}")
    if facts["photo"] != result.get("photo"):
        p.append(f"{label}: shows photo {facts['photo']!r}, result.json {result.get('photo')!r}")
    ok = bool(result.get("camera"))
    if ok == bool(facts["failure"]):
        p.append(f"{label}: failure shown {facts['failure']!r}, result.json camera {ok}")
    if not ok and facts["failure"] and result.get("error") and _norm(result["error"]) not in facts["failure"]:  # noqa: E501
        p.append(f"{label}: shows {facts['failure']!r}, result.json error {result['error']!r}")
    # warnings: the section's block and the summary's column, each the result's multiset
    codes = sorted(w["code"] for w in result.get("warnings", []))
    shown = sorted(c for c, _ in facts["warnings"])
    if shown != codes:
        p.append(f"{label}: warnings shown {shown}, result.json {codes}")
    else:
        msgs = sorted(_norm(w["message"]) for w in result.get("warnings", []))
        if sorted(m for _, m in facts["warnings"]) != msgs:
            p.append(f"{label}: warning messages differ from result.json's")
    row = rep.summary_rows().get(facts["index"])
    if row is None:
        p.append(f"{label}: no summary row")
    else:
        if sorted(row["warnings"]) != codes:
            p.append(f"{label}: summary warnings {sorted(row['warnings'])}, result.json {codes}")
        if ok and row["focal"] != f"{result['camera']['focal_px']:.0f}":
            p.append(f"{label}: summary focal {row['focal']}, result.json {result['camera']['focal_px']:.1f}")  # noqa: E501
        if ok != (not row["status"].startswith("failed")):
            p.append(f"{label}: summary status {row['status']!r}, result.json camera {ok}")
        if row["score"] != _fmt4(result.get("fitness")) and ok:
            p.append(f"{label}: summary score {row['score']}, result.json fitness {result.get('fitness')}")  # noqa: E501
        err = (result.get("landmark_error") or {}).get("mean_px")
        if ok and err is not None and row["err_px"] != f"{err:.2f}":
            p.append(f"{label}: summary mean error {row['err_px']} px, result.json {err:.3f}")
    # terms and terms switched off
    terms = facts["tables"].get("term")
    off = result.get("terms_off") or {}
    if terms is None:
        p.append(f"{label}: no terms table")
    else:
        kv = _kv(terms)
        shown_off = {k for k, v in kv.items() if v.startswith("switched off")}
        for key in off:
            name = {"mse_pix": "MSE", "p_cam": "P", "p_skof": "Pskof", "p_pll": "Ppll"}.get(key)
            hit = [k for k in shown_off if key[2:].split("_")[0] in k.replace(" ", "").lower()]
            if not hit:
                p.append(f"{label}: terms_off {key} ({off[key]!r}) not shown as switched off ({name})")  # noqa: E501
        if len(shown_off) > len(off):
            p.append(f"{label}: {len(shown_off)} terms shown off, result.json {sorted(off)}")
        if ok:
            for key, value in (result.get("terms") or {}).items():
                if key in off:
                    continue
                row_ = next((v for k, v in kv.items() if k.replace(" ", "").lower().startswith(
                    {"mse_pix": "msepix", "p_cam": "pcam", "p_skof": "pskof", "p_pll": "ppll"}.get(key, key))), None)  # noqa: E501
                want = "off" if value is None else f"{value:.4g}"
                if row_ is not None and row_ != want:
                    p.append(f"{label}: term {key} shown {row_!r}, result.json {value!r}")
            score = next((v for k, v in kv.items() if k.startswith("method's own score")), None)
            if score is not None and score != _fmt4(result.get("fitness")):
                p.append(f"{label}: score shown {score}, result.json fitness {result.get('fitness')}")  # noqa: E501
    # the camera, and its priors "inside"/"OUTSIDE" against the outside_prior warnings
    cam = facts["tables"].get("")
    if ok and cam is not None:
        kv = _kv(cam)
        focal = kv.get("focal length", "")
        if not focal.startswith(f"{result['camera']['focal_px']:.1f} px"):
            p.append(f"{label}: focal shown {focal!r}, result.json {result['camera']['focal_px']:.1f}")  # noqa: E501
        warned = " ".join(w["message"] for w in result.get("warnings", []) if w["code"] == "outside_prior")  # noqa: E501
        for key, words in (("focal length", "focal length"), ("subject-to-camera distance", "distance")):  # noqa: E501
            shown = kv.get(key, "")
            if "OUTSIDE" in shown and words not in warned:
                p.append(f"{label}: {key} shown {shown!r}, no outside_prior warning on it")
            if ": inside)" in shown and words in warned:
                p.append(f"{label}: {key} shown {shown!r}, but result.json warns: {warned!r}")
    # a skull outside the face: the summary's share against result.json's pixel counts
    if ok and row is not None and result.get("skull_px"):
        share = 100.0 * result.get("outside_px", 0) / result["skull_px"]
        shown = rep.summary_outside(facts["index"])
        if shown is not None and abs(shown - share) > 1.0:
            p.append(f"{label}: summary skull outside face {shown:.2f} %, result.json {result.get('outside_px')} of {result['skull_px']} px ({share:.2f} %)")  # noqa: E501
    # the few_pairs cap names the number of pairs the landmark table lists
    few = ((result.get("identification") or {}).get("caps") or {}).get("few_pairs")
    if few and not joint and facts["tables"].get("landmarks") is not None:
        m = re.search(r"only (\d+) landmark pairs", few)
        n = len([c for c in _rows(facts["tables"]["landmarks"]) if len(c) > 4 and _norm(c[1].text()) not in ("", "mean")])  # noqa: E501
        if m and int(m.group(1)) != n:
            p.append(f"{label}: cap says {few!r}, the landmark table lists {n}")
    # the landmark table against result.json's 3D landmarks and camera
    lm = facts["tables"].get("landmarks")
    per = (result.get("landmark_error") or {}).get("per_landmark_px") or {}
    f3d = result.get("facial_landmarks_3d") or {}
    if lm is not None:
        for cells in _rows(lm):
            name = _norm(cells[1].text()) if len(cells) > 4 else ""
            if not name or name == "mean":
                continue
            est = _norm(cells[3].text())
            if not ok:
                if any(ch.isdigit() for ch in est):
                    p.append(f"{label}: failed SFO shows estimate {est} for {name}")
                continue
            if name not in f3d:
                p.append(f"{label}: landmark {name} shown, not in result.json")
                continue
            uv = _project(result["camera"], [f3d[name]])[0]
            got = [float(x) for x in est.split(",")]
            if np.max(np.abs(np.array(got) - uv)) > 0.06:
                p.append(f"{label}: {name} estimate shown {est}, result.json projects {uv[0]:.1f}, {uv[1]:.1f}")  # noqa: E501
            e = _norm(cells[4].text())
            if name in per and e != f"{per[name]:.2f}":
                p.append(f"{label}: {name} error shown {e} px, result.json {per[name]:.3f}")
    # the implausible mark and the identification's consistency
    idn = result.get("identification") or {}
    if not joint and ok:
        outside = "skull_outside_head" in (idn.get("inconsistent") or {})
        if outside != facts["implausible"]:
            p.append(f"{label}: implausible shown {facts['implausible']}, identification inconsistent {sorted(idn.get('inconsistent') or {})}")  # noqa: E501
    # the photo and its pictures
    files = _inputs_of(facts["tables"].get("input")) if facts["tables"].get("input") else {}
    image = next((Path(v) for k, v in files.items() if "image" in k or "photo" == k), None)
    if image is not None and not image.is_absolute():
        image = Path(ws.root) / image if (Path(ws.root) / image).is_file() else image
    photo_im = None
    if image is None or not image.is_file():
        p.append(f"{label}: the photo image of the inputs table not found ({files})")
    else:
        with Image.open(image) as im:
            from PIL import ImageOps

            photo_im = np.asarray(ImageOps.exif_transpose(im).convert("RGB")).astype(int)
        h, w = photo_im.shape[:2]
        if facts["size"] != (w, h):
            p.append(f"{label}: shows a {facts['size']} photo, {image.name} is {w}x{h}")
    overlay_key = "overlay.png"
    href = facts["links"].get(overlay_key)
    if href is None:
        p.append(f"{label}: no overlay.png link (links {facts['links']})")
    elif photo_im is not None:
        path = _resolve(rep.page, href)
        try:
            with Image.open(path) as im:
                im.verify()
            with Image.open(path) as im:
                fmt = im.format
                ov = np.asarray(im.convert("RGB")).astype(int)
        except Exception as exc:  # noqa: BLE001 - what the probe looks for
            p.append(f"{label}: overlay {href} unreadable: {exc!r}")
            ov = None
        if ov is not None:
            if fmt != "PNG":
                p.append(f"{label}: overlay {href} is {fmt}, not PNG")
            if ov.shape != photo_im.shape:
                p.append(f"{label}: overlay {href} is {ov.shape[1]}x{ov.shape[0]}, the photo {photo_im.shape[1]}x{photo_im.shape[0]}")  # noqa: E501
            else:
                same = np.abs(ov - photo_im).max(axis=2) <= 3
                if same.mean() < 0.4:
                    p.append(f"{label}: overlay {href} is not this photo ({same.mean():.0%} of pixels agree)")  # noqa: E501
                drawn = ~same
                if ok and not drawn.any():
                    p.append(f"{label}: overlay {href} shows no skull for a camera")
                if not ok and drawn.mean() > 0.001:
                    p.append(f"{label}: overlay {href} draws on a failed SFO's photo")
                if ok and drawn.any():
                    box = _skull_box(result["camera"], verts, (ov.shape[1], ov.shape[0]))  # noqa: E501
                    rows, cols = np.nonzero(drawn)
                    got = (cols.min(), rows.min(), cols.max(), rows.max())
                    tol = 0.04 * max(ov.shape[:2]) + 15
                    if box is not None and not _box_close(got, box, tol):
                        p.append(f"{label}: overlay {href} draws in {tuple(int(x) for x in got)}, result.json's camera projects the skull to {tuple(int(x) for x in box)}")  # noqa: E501
        # the overlay and result.json of one folder: the same SFO
        rj = facts["links"].get("result.json") or facts["links"].get("result.json (joint)")
        if rj is not None and not joint and Path(rj).parent != Path(href).parent:
            p.append(f"{label}: overlay {href} and result {rj} in different folders")
    # embedded pictures: the photo region and the skull layer
    if photo_im is not None and facts["box"] and facts["imgs"].get("photo"):
        u0, v0, u1, v1 = facts["box"]
        pic = _decode(facts["imgs"]["photo"]).convert("RGB")
        crop = Image.fromarray(photo_im[v0:v1, u0:u1].astype(np.uint8)).resize(pic.size)
        diff = np.abs(np.asarray(pic, int) - np.asarray(crop, int)).mean()
        if diff > 12:
            p.append(f"{label}: the pictured photo differs from {image.name}'s region ({diff:.1f} grey levels)")  # noqa: E501
        layer = facts["imgs"].get("skull-layer")
        if ok != (layer is not None):
            p.append(f"{label}: skull layer {'missing' if ok else 'shown for a failed SFO'}")
        if ok and layer is not None:
            lay = _decode(layer).convert("RGBA")
            alpha = np.asarray(lay)[..., 3] > 0
            if alpha.any():
                sx, sy = (u1 - u0) / lay.width, (v1 - v0) / lay.height
                rows, cols = np.nonzero(alpha)
                got = (u0 + cols.min() * sx, v0 + rows.min() * sy, u0 + cols.max() * sx, v0 + rows.max() * sy)  # noqa: E501
                box = _skull_box(result["camera"], verts, (photo_im.shape[1], photo_im.shape[0]))
                if box is not None:
                    box = (max(box[0], u0), max(box[1], v0), min(box[2], u1 - 1), min(box[3], v1 - 1))  # noqa: E501
                    if not _box_close(got, box, 0.03 * max(u1 - u0, v1 - v0) + 4):
                        p.append(f"{label}: the skull layer covers {tuple(int(x) for x in got)}, result.json's camera projects it to {tuple(int(x) for x in box)}")  # noqa: E501
            elif _skull_box(result["camera"], verts, (photo_im.shape[1], photo_im.shape[0])):  # noqa: E501
                p.append(f"{label}: an empty skull layer for a camera that sees the skull")
    return p


def _conclusion_problems(label, row, record):
    """A conclusion row ``(label, anchor, conclusion, uncapped, lr, why, model)`` against an
    identification record."""
    p = []
    _, _, conclusion, uncapped, lr, why, model = row
    if conclusion != record.get("conclusion"):
        p.append(f"{label}: report shows {conclusion!r}, the record {record.get('conclusion')!r}")
    want_lr = _fmt_lr(record.get("log10_lr"))
    if lr != want_lr:
        p.append(f"{label}: report shows log10 LR {lr}, the record {record.get('log10_lr')}")
    raw = record.get("conclusion_uncapped")
    if raw not in (None, record.get("conclusion")) and uncapped != raw:
        p.append(f"{label}: report shows uncapped {uncapped!r}, the record {raw!r}")
    if uncapped is not None and raw == record.get("conclusion"):
        p.append(f"{label}: report shows uncapped {uncapped!r}, the record none")
    for code in list(record.get("caps") or {}) + list(record.get("inconsistent") or {}):
        if code not in why:
            p.append(f"{label}: cap/consistency {code!r} of the record not shown (shown: {why!r})")
    want_model = (record.get("calibration") or {}).get("model", "")
    if model != want_model:
        p.append(f"{label}: report shows model {model!r}, the record {want_model!r}")
    return p


_CONSOLE_ID = re.compile(
    r"identification: (?P<c>[a-z ]+?), (?:no LR|log10 LR (?P<lr>[+-]\d+\.\d\d) \(LR [^)]*\))"
    r"(?:; capped: (?P<why>.*?))?(?:; |$)"
)


def _console_problems(label, line, record):
    p = []
    m = _CONSOLE_ID.search(line)
    if m is None:
        return [f"{label}: no identification in the console line {line!r}"]
    if m.group("c") != record.get("conclusion"):
        p.append(f"{label}: console says {m.group('c')!r}, the record {record.get('conclusion')!r}")
    lr = record.get("log10_lr")
    if (m.group("lr") or "–") != _fmt_lr(lr):
        p.append(f"{label}: console log10 LR {m.group('lr')}, the record {lr}")
    if record.get("conclusion") != record.get("conclusion_uncapped"):
        for code, sentence in (record.get("caps") or {}).items():
            if sentence not in line:
                p.append(f"{label}: console does not name the cap {code} that lowered the conclusion")  # noqa: E501
    for code, sentence in (record.get("inconsistent") or {}).items():
        if sentence not in line:
            p.append(f"{label}: console does not name {code}")
    return p


def _load_results(rep, sec, facts):
    """The section's ``result.json`` (a joint one's photo part) and whether it is joint."""
    href = facts["links"].get("result.json") or facts["links"].get("result.json (joint)")
    if href is None:
        return None, None, False
    path = _resolve(rep.page, href)
    data = _json(path)
    if data.get("joint"):
        part = next((ph for ph in data["photos"] if ph.get("photo") == facts["photo"]), None)
        if part is None:
            return None, data, True
        # A joint result's photo: the method and the 3D landmarks are the whole SFO's; its
        # "fitness" is its weighted share (SPEC 9), the section shows its own, unweighted.
        part = {**part, "method": data.get("method"), "variant": data.get("variant"),
                "facial_landmarks_3d": data.get("facial_landmarks_3d"),
                "fitness": part.get("fitness_unweighted", part.get("fitness"))}  # fmt: skip
        return part, data, True
    return data, data, False


def _report_consistent(skull, page="report.html", n_sfos=None, extra=None, reach=()):
    """Check: every SFO section, summary row and conclusion row of ``out/<page>`` against the
    ``result.json`` files it links, the console's lines of each SFO and decision; ``extra(ws,
    rep, problems)`` adds the command's own checks. ``skull(ws)`` is the skull mesh (or the
    subject folder holding ``skull.ply``). ``reach``: what the inputs must have produced in some
    ``result.json`` (the probe's premise): a warning code, a cap or consistency code, a term
    switched off, or ``"failed"``."""

    def check(ws):
        page_path = ws.out / page
        if not page_path.is_file():
            return f"no {page}"
        rep = _Report(page_path)
        problems = []
        if rep.conclusions is None:
            problems.append("no conclusions table")
        skull_path = skull(ws)
        if skull_path.is_dir():
            skull_path = next(skull_path.glob("skull.*"))
        rows = rep.conclusion_rows()
        by_anchor = {r[1]: r for r in rows if r[1]}
        out_text, err_text = _console(ws)
        joints = {}
        if n_sfos is not None and len(rep.sections) != n_sfos:
            problems.append(f"{len(rep.sections)} SFO sections, {n_sfos} SFOs run")
        for sec in rep.sections:
            facts = _section_facts(sec)
            result, whole, joint = _load_results(rep, sec, facts)
            if result is None:
                problems.append(f"section {facts['index']} ({facts['photo']}): no result.json of its own")  # noqa: E501
                continue
            problems += _sfo_problems(rep, sec, facts, result, joint, skull_path, ws)
            if joint:
                joints[id(whole)] = whole
                continue
            idn = result.get("identification")
            row = by_anchor.get(facts["anchor"])
            if idn is None:
                problems.append(f"section {facts['index']}: result.json has no identification")
            elif row is None:
                problems.append(f"section {facts['index']} ({facts['photo']}): no conclusion row")
            else:
                problems += _conclusion_problems(f"conclusion of SFO {facts['index']}", row, idn)
            # the console's line of this SFO: "<photo>: <method>: ..." then "  identification"
            if out_text and idn is not None:
                name = facts["method"]
                lines = out_text.splitlines()
                head = [k for k, ln in enumerate(lines) if ln.startswith(f"{facts['photo']}: {name}: ") and " -> " in ln]  # noqa: E501
                if head:
                    nxt = next((ln for ln in lines[head[0] + 1 :] if ln.startswith("  identification:")), "")  # noqa: E501
                    problems += _console_problems(f"console of SFO {facts['index']}", nxt, idn)
        for whole in joints.values():
            row = next((r for r in rows if r[0].startswith("joint SFO")), None)
            if row is None:
                problems.append("no conclusion row of the joint SFO")
            else:
                problems += _conclusion_problems("joint conclusion", row, whole["identification"])
            line = next((ln for ln in out_text.splitlines() if ln.startswith("  identification:")), "")  # noqa: E501
            if out_text:
                problems += _console_problems("console of the joint SFO", line, whole["identification"])  # noqa: E501
        # decisions over several photos: the console line and the report's row
        for ln in out_text.splitlines():
            m = re.match(r"(photos .* together, \S+): (identification: .*)$", ln)
            if not m:
                continue
            row = next((r for r in rows if r[0] == m.group(1)), None)
            if row is None:
                problems.append(f"console decision {m.group(1)!r} has no report row")
                continue
            c = _CONSOLE_ID.search(m.group(2))
            if c is None or c.group("c") != row[2] or (c.group("lr") or "–") != row[4]:
                problems.append(f"decision {m.group(1)!r}: console {m.group(2)!r}, report {row[2]!r} {row[4]}")  # noqa: E501
        if extra is not None:
            extra(ws, rep, problems)
        reached = set()
        for path in ws.out.rglob("result.json"):
            data = _json(path)
            for part in [data, *(data.get("photos") or [])]:
                reached |= {w["code"] for w in part.get("warnings", [])}
                reached |= set(part.get("terms_off") or {})
                reached |= {"failed"} if "camera" in part and not part["camera"] else set()
                idn = part.get("identification") or {}
                reached |= set(idn.get("caps") or {}) | set(idn.get("inconsistent") or {})
        missing = [r for r in reach if r not in reached]
        if missing:
            problems.append(f"the premise failed: no result reached {missing} (reached {sorted(reached)})")  # noqa: E501
        return "; ".join(problems[:4]) + (f" (+{len(problems) - 4} more)" if len(problems) > 4 else "") if problems else None  # noqa: E501

    return check


# -- lineups ----------------------------------------------------------------------------------


def _rank_key(entry, first):
    rec = entry["identification"]
    lr, views, score = rec.get("log10_lr"), rec.get("views_log10_lr") or [], rec.get("score")
    return (
        entry["method"] != first,
        -(lr if lr is not None else float("-inf")),
        -(sum(views) if views and None not in views else float("-inf")),
        score if score is not None else float("inf"),
    )


def _lineup_extra(expect_tie=False, expect_failed=None, order=None):
    """The lineup's own checks: ``lineup.json``'s order follows its LRs (README: ranked by LR;
    docs/method.md: ties at the bound by the views' sum, then the score), its entries are the
    candidates' ``result.json`` identifications, the report's ranking rows and the console's
    say the same. ``expect_tie``: two candidates must tie on the LR (a probe of tie-breaking);
    ``expect_failed``: that candidate's decision is undetermined without an LR; ``order``: the
    expected candidate order."""

    def extra(ws, rep, problems):
        path = ws.out / "lineup.json"
        if not path.is_file():
            problems.append("no lineup.json")
            return
        ranking = _json(path)["ranking"]
        first = ranking[0]["method"] if ranking else ""
        keys = [_rank_key(e, first) for e in ranking]
        for k in range(len(keys) - 1):
            if keys[k] > keys[k + 1]:
                a, b = ranking[k], ranking[k + 1]
                problems.append(
                    f"lineup.json rank {a['rank']} {a['candidate']} (log10 LR {a['identification'].get('log10_lr')}, score {a['identification'].get('score')}) above rank {b['rank']} {b['candidate']} (log10 LR {b['identification'].get('log10_lr')}, score {b['identification'].get('score')})"  # noqa: E501
                )
        if [e["rank"] for e in ranking] != list(range(1, len(ranking) + 1)):
            problems.append(f"ranks {[e['rank'] for e in ranking]}")
        if order is not None:
            got = [e["candidate"] for e in ranking if e["method"] == first]
            if got != list(order):
                problems.append(f"candidates ranked {got}, expected {list(order)}")
        lrs = [e["identification"].get("log10_lr") for e in ranking if e["method"] == first]
        if expect_tie and len({lr for lr in lrs if lr is not None}) == len([x for x in lrs if x is not None]):  # noqa: E501
            problems.append(f"no tie to break (log10 LRs {lrs}): the probe's premise failed")
        # each single-photo candidate's decision is its result.json's identification
        for e in ranking:
            if len(e["photos"]) == 1:
                found = [
                    _json(r) for r in (ws.out).rglob("result.json")
                    if _json(r).get("photo") == e["photos"][0]
                    and (_json(r)["method"] + ("-" + _json(r)["variant"] if _json(r).get("variant") else "")) == e["method"]  # noqa: E501
                ]
                if len(found) != 1:
                    problems.append(f"{e['candidate']}: {len(found)} result.json for {e['photos'][0]} {e['method']}")  # noqa: E501
                    continue
                rec, own = e["identification"], found[0]["identification"]
                for key in ("conclusion", "log10_lr", "caps", "inconsistent"):
                    if rec.get(key) != own.get(key):
                        problems.append(f"{e['candidate']}: lineup.json {key} {rec.get(key)!r}, result.json {own.get(key)!r}")  # noqa: E501
            if expect_failed == e["candidate"]:
                rec = e["identification"]
                if rec.get("log10_lr") is not None or rec.get("conclusion") != "undetermined":
                    problems.append(f"{e['candidate']} (a failed SFO): {rec.get('conclusion')!r}, log10 LR {rec.get('log10_lr')}")  # noqa: E501
        # the report's ranking rows: the first len(ranking) rows, in order
        rows = rep.conclusion_rows()
        for k, e in enumerate(ranking):
            want = f"{e['rank']}. candidate {e['candidate']} ({len(e['photos'])} photo(s)), {e['method']}"  # noqa: E501
            if k >= len(rows) or rows[k][0] != want:
                problems.append(f"report ranking row {k + 1}: {rows[k][0] if k < len(rows) else None!r}, lineup.json {want!r}")  # noqa: E501
                continue
            problems.extend(_conclusion_problems(f"report ranking row {k + 1}", rows[k], e["identification"]))  # noqa: E501
        # the console: "k. name (method): identification: ..."
        out_text, _ = _console(ws)
        lines = [ln for ln in out_text.splitlines() if re.match(r"\d+\. ", ln)]
        if len(lines) != len(ranking):
            problems.append(f"console ranks {len(lines)} entries, lineup.json {len(ranking)}")
        for ln, e in zip(lines, ranking, strict=False):
            if not ln.startswith(f"{e['rank']}. {e['candidate']} ({e['method']}): "):
                problems.append(f"console {ln[:60]!r}, lineup.json rank {e['rank']} {e['candidate']}")  # noqa: E501
            problems.extend(_console_problems(f"console rank {e['rank']}", ln, e["identification"]))  # noqa: E501

    return extra


# -- lilium sfo: the console against result.json ---------------------------------------------


def _sfo_console(joint=False, failed=False):
    def check(ws):
        path = ws.out / "result.json"
        if not path.is_file():
            return "no result.json"
        data = _json(path)
        out_text, err_text = _console(ws)
        idn = data.get("identification") or {}
        p = []
        parts = data["photos"] if joint else [data]
        for part in parts:
            for w in part.get("warnings", []):
                want = f"warning {w['code']}" + (f" ({part['photo']})" if joint else "") + f": {w['message']}"  # noqa: E501
                if want not in err_text:
                    p.append(f"stderr lacks {want[:80]!r}")
            if part.get("camera"):
                focal = f"focal {part['camera']['focal_px']:.0f} px"
                if focal not in out_text:
                    p.append(f"stdout lacks {focal!r} of {part.get('photo')}")
            for term in part.get("terms_off") or {}:
                if f"{term} switched off" not in out_text:
                    p.append(f"stdout does not say {term} switched off")
        line = next((ln for ln in out_text.splitlines() if ln.startswith("identification:")), "")
        if failed:
            if "SFO failed" not in err_text:
                p.append("stderr does not say the SFO failed")
            if idn.get("conclusion") != "undetermined" or idn.get("log10_lr") is not None:
                p.append(f"a failed SFO's result.json: {idn.get('conclusion')!r}, {idn.get('log10_lr')}")  # noqa: E501
            if line:
                p.extend(_console_problems("console", line, idn))
        else:
            p.extend(_console_problems("console", line, idn))
        return "; ".join(p[:4]) if p else None

    return check


# -- set-ups ----------------------------------------------------------------------------------


def _P(ws):
    return ws.photo


def _S(ws):
    return ws.skull


def _p(name):
    return lambda ws: _in(ws, "photos", name)


def _syn_photo(name):
    return lambda ws: _in(ws, "syn", "photos", "A", name)


def _syn_subject(name):
    return lambda ws: _in(ws, "syn", "subjects", name)


S1 = _syn_subject("s01")
F1, L1, F2, L2 = (_syn_photo(n) for n in ("s01_f00", "s01_l00", "s02_f00", "s02_l00"))


def _keep_landmarks(where, names):
    return _edit_json(
        where, "photo.json",
        lambda d: d.update(landmarks={k: v for k, v in d["landmarks"].items() if k in names}),
    )  # fmt: skip


def _jitter(where, px, seed):
    """Every facial landmark of ``where``'s ``photo.json`` moved by up to ``px`` pixels (placed
    again by hand: another photo, not a copy of one, for the copy check of the case)."""

    def change(d):
        rng = np.random.default_rng(seed)
        d["landmarks"] = {
            k: [u + rng.uniform(-px, px), v + rng.uniform(-px, px)]
            for k, (u, v) in d["landmarks"].items()
        }

    return _edit_json(where, "photo.json", change)


def _other_photo(name="p2", px=4.0, seed=7, scale=0.5):
    """``in/photos/<name>``: another photo of the stand-in: its image at ``scale``, its
    landmarks placed again (``px`` of jitter: 2-3 % of their extent)."""

    def setup(ws):
        from standin_case import scaled_photo

        scaled_photo(ws.photo, _in(ws, "photos", name), scale)
        _jitter(_p(name), px, seed)(ws)

    return setup


#: The stand-in's facial landmarks on the midline (on one plane in 3D, as their skull's).
MIDLINE_FACE = ("glabella", "nasion", "metopion", "bregma", "subnasale", "labiale_superius",
                "pogonion", "gnathion")  # fmt: skip


def _failing_photo(name="fail"):
    """``in/photos/<name>``: another photo of the stand-in (:func:`_other_photo`) with its
    midline landmarks only and no head-rotation prior (POSEST: no 4-point sample of points on
    one plane gives a real camera: the SFO fails, as probe_hostile_geometry.py's)."""

    def no_rotation(d):
        for k in ("head_rotation_skull2cam", "head_tolerance_deg"):
            d.get("priors", {}).pop(k, None)

    return _then(
        _other_photo(name, scale=0.6),
        _keep_landmarks(_p(name), MIDLINE_FACE),
        _edit_json(_p(name), "photo.json", no_rotation),
    )


def _drop_cranial(where, names):
    return _edit_json(
        where, "cranial_landmarks.json",
        lambda d: d.update(landmarks={k: v for k, v in d["landmarks"].items() if k not in names}),
    )  # fmt: skip


def _automatic(where):
    """Every facial landmark of ``photo.json`` tagged automatic, tracked, unreviewed."""

    def change(d):
        d["landmark_sources"] = {
            k: {"source": "automatic", "quality": "tracked"} for k in d["landmarks"]
        }

    return _edit_json(where, "photo.json", change)


def _face_only_mask(where, margin=0.02):
    """The mask cut to the face from the brow to the chin (a mask drawn from the hairline to
    the chin, which README warns of): the vault off the mask, so the skull leaves it."""

    def setup(ws):
        from PIL import Image

        lm = _json(where(ws) / "photo.json")["landmarks"]
        face = np.array([p for k, p in lm.items() if k not in ("metopion", "bregma")], float)
        path = where(ws) / "face_mask.png"
        with Image.open(path) as im:
            a = np.asarray(im.convert("L")) > 0
        h, w = a.shape
        m = margin * max(w, h)
        u0, v0 = np.floor(face.min(axis=0) - m).astype(int)
        u1, v1 = np.ceil(face.max(axis=0) + m).astype(int)
        keep = np.zeros_like(a)
        keep[max(v0, 0) : v1, max(u0, 0) : u1] = True
        Image.fromarray(((a & keep) * 255).astype(np.uint8)).save(path)

    return setup


def _no_mask(where):
    return lambda ws: (where(ws) / "face_mask.png").unlink()


def _fragment_beside(where, dx=-150.0):
    """A fragment (icosphere, 10 mm) ``dx`` mm beside the skull (mesh_part_left_out)."""

    def setup(ws):
        import trimesh

        from lilium.io.mesh import read_mesh, write_mesh

        path = where(ws) / "skull.ply"
        v, f = read_mesh(path)
        s = trimesh.creation.icosphere(subdivisions=3)
        v2 = np.asarray(s.vertices) * 10.0 + [dx, 0.0, 0.0]
        v = np.vstack([np.asarray(v, float), v2])
        f = np.vstack([np.asarray(f), np.asarray(s.faces) + len(v) - len(v2)])
        write_mesh(path, v, f)

    return setup


CAL = lambda ws: _in(ws, "cal.json")  # noqa: E731


def _then_run(argv):
    """Set-up: run ``argv(ws)`` once, quietly (a run to resume)."""
    return lambda ws: _quiet_main(argv(ws))


# -- command lines ----------------------------------------------------------------------------


def _cmd(command, skull, photos, *extra, method=("posest-sfo",)):
    def argv(ws):
        out = [command, "--skull", skull(ws)]
        for ph in photos:
            out += ["--photo", ph(ws)]
        for m in method:
            out += ["--method", m]
        return [*out, "--out", ws.out, *(e(ws) if callable(e) else e for e in extra)]

    return argv


def _case(skull, photos, *extra, method=("posest-sfo",)):
    return _cmd("case", skull, photos, *extra, method=method)


def _sfo(skull, photos, *extra, method="posest-sfo"):
    return _cmd("sfo", skull, photos, *extra, method=(method,))


def _lineup(skull, candidates, *extra, method=("posest-sfo",)):
    def argv(ws):
        out = ["lineup", "--no-progress", "--skull", skull(ws), "--out", ws.out]
        for m in method:
            out += ["--method", m]
        for name, *photos in candidates:
            out += ["--candidate", name, *(ph(ws) for ph in photos)]
        return out + [e(ws) if callable(e) else e for e in extra]

    return argv


def _armed(*setups):
    return _then(*setups, _arm)


# fmt: off


def report_probes():
    """Report, console and result.json against each other (module docstring)."""
    _install()
    L = ("lilium",)
    PL = ("posest-sfo", "lilium")
    syn = lambda *s: _armed(_syn, *s)  # noqa: E731
    ok = lambda *a, **k: _report_consistent(*a, **k)  # noqa: E731
    half = _p("p2")
    return [
        # lilium case
        Probe("report case one photo (posest: outside_prior, single_photo cap)", _case(_S, [_P]), "ok", (), _armed(), check=ok(_S, n_sfos=1, reach=("outside_prior", "single_photo"))),  # noqa: E501
        Probe("report case one photo lilium (P_pll switched off)", _case(_S, [_P], *TINY, method=L), "ok", (), _armed(), check=ok(_S, n_sfos=1, reach=("p_pll",))),  # noqa: E501
        Probe("report case two photos, posest and lilium (decisions together)", _case(_S, [_P, half], *TINY, method=PL), "ok", (), _armed(_other_photo()), check=ok(_S, n_sfos=4)),  # noqa: E501
        Probe("report case --joint two photos, lilium and posest", _case(_S, [_P, half], "--joint", *TINY, method=PL), "ok", (), _armed(_other_photo()), check=ok(_S, n_sfos=4)),  # noqa: E501
        Probe("report case a failed SFO beside a good one", _case(_S, [_P, _p("fail")]), "ok", (), _armed(_failing_photo()), check=ok(_S, n_sfos=2, reach=("failed",)), code=1),  # noqa: E501
        Probe("report case lilium: a photo POSEST fails on beside a good one", _case(_S, [_P, _p("fail")], *TINY, method=L), "ok", (), _armed(_failing_photo()), check=ok(_S, n_sfos=2)),  # noqa: E501
        Probe("report case view_mismatch (lateral_left declared lateral_right)", _case(S1, [L1]), "ok", (), syn(_view(L1, "lateral_right")), check=ok(S1, n_sfos=1, reach=("view_mismatch",))),  # noqa: E501
        Probe("report case view_mismatch beside a good frontal (decision together)", _case(S1, [F1, L1]), "ok", (), syn(_view(L1, "lateral_right")), check=ok(S1, n_sfos=2, reach=("view_mismatch",))),  # noqa: E501
        Probe("report case frontal and lateral (views' LRs added)", _case(S1, [F1, L1], *TINY, method=PL), "ok", (), syn(), check=ok(S1, n_sfos=4)),  # noqa: E501
        Probe("report case inverted mask (landmark_outside_mask, skull outside the head)", _case(_S, [_P]), "ok", (), _armed(_invert_mask(_P)), check=ok(_S, n_sfos=1, reach=("landmark_outside_mask", "skull_outside_head"))),  # noqa: E501
        Probe("report case lilium inverted mask", _case(_S, [_P], *TINY, method=L), "ok", (), _armed(_invert_mask(_P)), check=ok(_S, n_sfos=1, reach=("landmark_outside_mask", "skull_outside_head"))),  # noqa: E501
        Probe("report case mask cut to the face (skull outside the head)", _case(_S, [_P], *TINY, method=PL), "ok", (), _armed(_face_only_mask(_P)), check=ok(_S, n_sfos=2, reach=("skull_outside_head",))),  # noqa: E501
        Probe("report case fragment 150 mm beside the skull (mesh_part_left_out)", _case(_S, [_P], *TINY, method=PL), "ok", (), _armed(_fragment_beside(_S)), check=ok(_S, n_sfos=2, reach=("mesh_part_left_out",))),  # noqa: E501
        Probe("report case lilium skof without a mask (P_skof off)", _case(_S, [_P], "--variant", "skof", *TINY, method=L), "ok", (), _armed(_no_mask(_P)), check=ok(_S, n_sfos=1, reach=("p_skof",))),  # noqa: E501
        Probe("report case posest without a mask", _case(_S, [_P]), "ok", (), _armed(_no_mask(_P)), check=ok(_S, n_sfos=1)),  # noqa: E501
        Probe("report case no mandible (no_mandible cap)", _case(S1, [F1], *TINY, method=PL), "ok", (), syn(_drop_cranial(S1, ("pogonion", "gnathion", "gonion_l", "gonion_r", "infradentale", "mental_foramen_l", "mental_foramen_r"))), check=ok(S1, n_sfos=2, reach=("no_mandible",))),  # noqa: E501
        Probe("report case 7 landmark pairs (few_pairs cap)", _case(_S, [_P]), "ok", (), _armed(_keep_landmarks(_P, ("nasion", "gnathion", "exocanthion_l", "exocanthion_r", "subnasale", "zygion_l", "zygion_r"))), check=ok(_S, n_sfos=1, reach=("few_pairs",))),  # noqa: E501
        Probe("report case unreviewed automatic landmarks (cap)", _case(_S, [_P]), "ok", (), _armed(_automatic(_P)), check=ok(_S, n_sfos=1, reach=("unreviewed_landmarks",))),  # noqa: E501
        Probe("report case two photos, one with unreviewed automatic landmarks", _case(_S, [_P, half]), "ok", (), _armed(_other_photo(), _automatic(half)), check=ok(_S, n_sfos=2, reach=("unreviewed_landmarks",))),  # noqa: E501
        # lilium lineup
        Probe("report lineup true candidate with two photos, another with one", _lineup(S1, [("True", F1, L1), ("Other", F2)]), "ok", (), syn(), check=ok(S1, n_sfos=3, extra=_lineup_extra())),  # noqa: E501
        Probe("report lineup three candidates two methods", _lineup(S1, [("A", F1), ("B", F2), ("C", L2)], *TINY, method=PL), "ok", (), syn(), check=ok(S1, n_sfos=6, extra=_lineup_extra())),  # noqa: E501
        Probe("report lineup candidates tied at the calibration bound", _lineup(_S, [("A", _P), ("B", half)]), "ok", (), _armed(_other_photo()), check=ok(_S, n_sfos=2, extra=_lineup_extra(expect_tie=True))),  # noqa: E501
        Probe("report lineup tie, candidates given in the other order", _lineup(_S, [("B", half), ("A", _P)]), "ok", (), _armed(_other_photo()), check=ok(_S, n_sfos=2, extra=_lineup_extra(expect_tie=True))),  # noqa: E501
        Probe("report lineup a candidate whose SFO fails", _lineup(_S, [("Fails", _p("fail")), ("A", _P)]), "ok", (), _armed(_failing_photo()), check=ok(_S, n_sfos=2, reach=("failed",), extra=_lineup_extra(expect_failed="Fails", order=("A", "Fails")))),  # noqa: E501
        Probe("report lineup a candidate with a failed and a good photo", _lineup(_S, [("Both", _P, _p("fail")), ("Solo", half)]), "ok", (), _armed(_other_photo(), _failing_photo()), check=ok(_S, n_sfos=3, reach=("failed",), extra=_lineup_extra(expect_failed="Both", order=("Solo", "Both")))),  # noqa: E501
        Probe("report lineup view_mismatch candidate", _lineup(S1, [("True", L1), ("Other", F2)]), "ok", (), syn(_view(L1, "lateral_right")), check=ok(S1, n_sfos=2, reach=("view_mismatch",), extra=_lineup_extra())),  # noqa: E501
        # another calibration: no model for the decision (no LR; ranked by the score), and a
        # case resumed with it (the stored SFOs identified again, result.json rewritten)
        Probe("report lineup calibration without models (no LR for anyone)", _lineup(S1, [("A", F1), ("B", F2)], "--calibration", CAL), "ok", (), syn(_calibration(lambda d: d.update(models={}))), check=ok(S1, n_sfos=2, extra=_lineup_extra())),  # noqa: E501
        Probe("report case resumed with a calibration without the method's model", _case(_S, [_P, half], *TINY, "--calibration", CAL, method=PL), "ok", (), _armed(_other_photo(), _then_run(_case(_S, [_P, half], *TINY, method=PL)), _calibration(_only_models("posest-sfo//frontal"))), check=ok(_S, n_sfos=4)),  # noqa: E501
        Probe("report case --joint resumed with a calibration without the joint model", _case(_S, [_P, half], "--joint", *TINY, "--calibration", CAL, method=L), "ok", (), _armed(_other_photo(), _then_run(_case(_S, [_P, half], "--joint", *TINY, method=L)), _calibration(_only_models("lilium/skof+pll/frontal"))), check=ok(_S, n_sfos=2)),  # noqa: E501
        # lilium sfo: console against result.json
        Probe("report sfo console (posest)", _sfo(_S, [_P]), "ok", (), _armed(), check=_sfo_console()),  # noqa: E501
        Probe("report sfo console lilium (a term off, warnings)", _sfo(_S, [_P], *TINY, method="lilium"), "ok", (), _armed(), check=_sfo_console()),  # noqa: E501
        Probe("report sfo console view_mismatch", _sfo(S1, [L1]), "ok", (), syn(_view(L1, "lateral_right")), check=_sfo_console()),  # noqa: E501
        Probe("report sfo console failed SFO", _sfo(_S, [_p("fail")]), "ok", (), _armed(_failing_photo()), check=_sfo_console(failed=True), code=1),  # noqa: E501
        Probe("report sfo console joint", _sfo(_S, [_P, half], *TINY, method="lilium"), "ok", (), _armed(_other_photo()), check=_sfo_console(joint=True)),  # noqa: E501
    ]


# fmt: on


def main(argv=None):
    """Run this group alone (the same verdicts as ``probe_hostile.py``)."""
    from probe_hostile import run_group

    return run_group(report_probes, "report", __doc__, argv, limit_s=120)


if __name__ == "__main__":
    sys.exit(main())
