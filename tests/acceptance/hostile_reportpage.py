"""What the report probes (``hostile_report.py``) read, and how: the console of the
``lilium`` command a probe runs, the HTML report page (``lilium case``'s ``report.html``,
``lilium lineup``'s) parsed into its SFO sections, summary and conclusion rows, tables and
pictures, and what the files of a run imply (the skull mesh projected with a ``result.json``'s
camera, the box it covers on the photo).

The console is what the probe's ``lilium`` process printed (recorded on the workspace by
:func:`hostile_machinery.run_probe`); :func:`_console` gives it.
"""

import base64
import io
import re
import urllib.parse
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
from hostile_fixtures import _json

# -- the console ------------------------------------------------------------------------------


def _arm(ws):
    """Set-up (last step): forget any console recorded before the probe's command (the
    command's own is recorded on ``ws`` by :func:`hostile_machinery.run_probe`)."""
    ws.console = None


def _console(ws):
    """``(stdout, stderr)`` of the probe's command."""
    return getattr(ws, "console", None) or ("", "")


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


# -- the facts of one report page --------------------------------------------------------------


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
