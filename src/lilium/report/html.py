"""A self-contained HTML report of one case: one skull, one or more photos, one or more methods.

Each SFO gets a section with

- the overlay as two stacked pictures (the photo, and the shaded skull as an RGBA layer that is
  transparent off the skull), an opacity slider for the skull layer and a wipe (slider, or drag
  on the picture) that shows the skull only left of a position, by CSS ``clip-path``; the
  landmarks as an SVG layer (photo landmark: ring, estimate: dot, joined by a line) and, with a
  face mask, the skull pixels outside it;
- the landmark table (photo point, projected estimate, error in pixels), the camera (focal
  length, subject-to-camera distance, rotation, ``skull2cam``), each fitness term, the fitness
  curve (inline SVG);
- the inputs' provenance (SHA-256 of each file, software versions, seed, method, date).

A summary table on top lists every SFO of the page. Nothing is fetched from the network: the
pictures are base64 ``data:`` URIs, styles and script are inline.
"""

import base64
import datetime as _dt
import html
import io
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..geometry.rotations import geodesic_angle_deg, matrix_to_rotvec
from ..imaging.overlay import SKULL_RGB, render_mesh_shaded
from ..io.provenance import sha256_of, software_versions

#: Longest side (pixels) of the pictures embedded in the report; larger photos are scaled down.
MAX_REPORT_PX = 2000

#: Margin around skull, mask and landmarks in the pictured region (fraction of its size), and
#: the area fraction above which the whole photo is shown instead.
VIEW_MARGIN = 0.12
FULL_VIEW_FRACTION = 0.6

#: Smallest longest side (pixels) of the skull layer: small regions are rendered finer.
MIN_LAYER_PX = 1400

#: Initial skull-layer opacity (percent).
DEFAULT_OPACITY_PCT = 60

#: Skull outline drawn on the skull layer (RGB) and its width at report scale (pixels).
OUTLINE_RGB = (255, 214, 0)
OUTLINE_PX = 2

#: Skull pixels outside the face mask (RGBA).
OUTSIDE_RGBA = (255, 0, 200, 170)


@dataclass(frozen=True)
class ReportEntry:
    """One SFO to report.

    Attributes
    ----------
    skull : lilium.inputs.Skull
    photo : lilium.inputs.Photo
        Read with its image.
    result : lilium.methods.result.SfoResult
    inputs : dict of str -> Path
        Input files, labelled (``{"skull mesh": path, ...}``); hashed into the provenance.
    notes : dict of str -> str
        Extra facts shown with the camera (e.g. where each prior came from).
    outputs : dict of str -> str
        Output files, labelled, as links relative to the report.
    """

    skull: object
    photo: object
    result: object
    inputs: dict = field(default_factory=dict)
    notes: dict = field(default_factory=dict)
    outputs: dict = field(default_factory=dict)


# --------------------------------------------------------------------------------------------
# Pictures


def _scale_of(size_wh, max_px=MAX_REPORT_PX):
    return min(1.0, max_px / max(size_wh))


def skull_layer_rgba(result, skull, box, scale=1.0):
    """The shaded, outlined skull as an RGBA picture, transparent off the skull.

    Parameters
    ----------
    result : SfoResult
        Successful.
    skull : Skull
    box : tuple (u0, v0, u1, v1), int
        The region of the photo to picture: columns ``u0 <= u < u1``, rows ``v0 <= v < v1``
        (``(0, 0, W, H)`` for the whole photo).
    scale : float
        Picture pixels per photo pixel (the camera is scaled with it).

    Returns
    -------
    rgba : ndarray of shape (round(scale * (v1 - v0)), round(scale * (u1 - u0)), 4), uint8
    """
    import cv2

    u0, v0, u1, v1 = box
    w, h = max(1, round(scale * (u1 - u0))), max(1, round(scale * (v1 - v0)))
    camera = result.camera.cropped((u0, v0), scale)
    shade, covered = render_mesh_shaded(skull.vertices_mm, skull.faces, camera, (w, h))
    rgba = np.zeros(covered.shape + (4,), dtype=np.uint8)
    rgba[..., :3] = np.clip(shade[..., None] * SKULL_RGB, 0, 255).astype(np.uint8)
    rgba[..., 3] = np.where(covered, 255, 0)
    contours, _ = cv2.findContours(
        covered.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE
    )
    cv2.drawContours(rgba, contours, -1, (*OUTLINE_RGB, 255), OUTLINE_PX, cv2.LINE_AA)
    return rgba


def view_box(size_wh, covered=None, mask=None, points_uv=()):
    """The region of the photo a report shows: skull, face mask and landmarks with a margin.

    Returns the whole photo when that region covers most of it anyway.

    Returns
    -------
    tuple (u0, v0, u1, v1), int
    """
    w, h = size_wh
    us, vs = [], []
    for region in (covered, mask):
        if region is not None and region.any():
            rows, cols = np.nonzero(region)
            us += [cols.min(), cols.max()]
            vs += [rows.min(), rows.max()]
    pts = np.asarray(points_uv, dtype=float).reshape(-1, 2)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    us += list(pts[:, 0])
    vs += list(pts[:, 1])
    if not us:
        return 0, 0, w, h
    margin = VIEW_MARGIN * max(max(us) - min(us), max(vs) - min(vs))
    u0, u1 = max(0, int(min(us) - margin)), min(w, int(np.ceil(max(us) + margin)) + 1)
    v0, v1 = max(0, int(min(vs) - margin)), min(h, int(np.ceil(max(vs) + margin)) + 1)
    if (u1 - u0) * (v1 - v0) > FULL_VIEW_FRACTION * w * h:
        return 0, 0, w, h
    return u0, v0, u1, v1


def _resize(array, size_wh):
    from PIL import Image

    if (array.shape[1], array.shape[0]) == tuple(size_wh):
        return array
    return np.asarray(Image.fromarray(array).resize(size_wh, Image.Resampling.LANCZOS))


def _data_uri(array, fmt):
    from PIL import Image

    buffer = io.BytesIO()
    if fmt == "jpeg":
        Image.fromarray(array).save(buffer, format="JPEG", quality=92)
    else:
        Image.fromarray(array).save(buffer, format="PNG", optimize=True)
    return f"data:image/{fmt};base64," + base64.b64encode(buffer.getvalue()).decode("ascii")


# --------------------------------------------------------------------------------------------
# Numbers


def landmark_rows(result, photo):
    """Photo landmark, projected estimate and error of every landmark the SFO used.

    Returns
    -------
    list of dict
        ``name``, ``photo_uv``, ``estimate_uv`` (NaN when the SFO failed), ``error_px``.
    """
    names = [n for n in result.facial_landmarks_mm if n in photo.landmarks_uv]
    photo_uv = np.array([photo.landmarks_uv[n] for n in names]).reshape(-1, 2)
    if result and names:
        est3d = np.array([result.facial_landmarks_mm[n] for n in names])
        est_uv = result.camera.project(est3d)
    else:
        est_uv = np.full_like(photo_uv, np.nan)
    errors = np.linalg.norm(est_uv - photo_uv, axis=1)
    return [
        {"name": n, "photo_uv": p, "estimate_uv": e, "error_px": float(d)}
        for n, p, e, d in zip(names, photo_uv, est_uv, errors, strict=True)
    ]


def camera_facts(result, photo):
    """Camera parameters of a successful SFO, for the report (degrees, mm, pixels)."""
    from scipy.spatial.transform import Rotation

    camera = result.camera
    T, R = camera.skull2cam, camera.R
    rotvec = matrix_to_rotvec(R)
    angle = float(np.degrees(np.linalg.norm(rotvec)))
    axis = rotvec / np.linalg.norm(rotvec) if angle > 0 else np.array([0.0, 0.0, 1.0])
    lms = result.facial_landmarks_mm
    centre = lms["nasion"] if "nasion" in lms else np.mean(list(lms.values()), axis=0)
    facts = {
        "focal_px": camera.focal_px,
        "principal_point_px": [float(x) for x in camera.principal_point_px],
        "scd_mm": float(camera.distance_mm(centre)),
        "scd_point": "facial nasion" if "nasion" in lms else "centroid of the facial landmarks",
        "rotation_angle_deg": angle,
        "rotation_axis": axis,
        "euler_xyz_deg": Rotation.from_matrix(R).as_euler("xyz", degrees=True),
        "translation_mm": T[:3, 3],
        "skull2cam": T,
        "head_deviation_deg": None,
    }
    prior = photo.priors.head_rotation_skull2cam
    if prior is not None:
        facts["head_deviation_deg"] = float(geodesic_angle_deg(R, prior))
    return facts


# --------------------------------------------------------------------------------------------
# HTML pieces

_e = html.escape


def _num(value, fmt="{:.2f}", none="&ndash;"):
    if value is None:
        return none
    try:
        value = float(value)
    except (TypeError, ValueError):
        return _e(str(value))
    return fmt.format(value) if np.isfinite(value) else none


def _table(header, rows, cls=""):
    head = "".join(f"<th>{h}</th>" for h in header) if any(header) else ""
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in rows)
    head = f"<thead><tr>{head}</tr></thead>" if head else ""
    return f'<table class="{cls}">{head}<tbody>{body}</tbody></table>'


def _marks_svg(rows, box):
    u0, v0, u1, v1 = box
    w, h = u1 - u0, v1 - v0
    r = max(w, h) / 160
    parts = []
    for k, row in enumerate(rows, start=1):
        (pu, pv), (eu, ev) = row["photo_uv"], row["estimate_uv"]
        name = _e(row["name"])
        g = [f"<g><title>{k}. {name}: error {_num(row['error_px'], '{:.1f}')} px</title>"]
        if np.isfinite(eu) and np.isfinite(ev):
            g.append(f'<line class="err" x1="{pu:.2f}" y1="{pv:.2f}" x2="{eu:.2f}" y2="{ev:.2f}"/>')
            g.append(f'<circle class="est" cx="{eu:.2f}" cy="{ev:.2f}" r="{0.45 * r:.2f}"/>')
        g.append(f'<circle class="lm" cx="{pu:.2f}" cy="{pv:.2f}" r="{r:.2f}"/>')
        g.append(
            f'<text class="lbl" x="{pu + 1.2 * r:.2f}" y="{pv - 1.2 * r:.2f}" '
            f'font-size="{2.2 * r:.1f}">{k}</text></g>'
        )
        parts.append("".join(g))
    return (
        f'<svg class="marks" viewBox="{u0 - 0.5} {v0 - 0.5} {w} {h}" preserveAspectRatio="none" '
        f'xmlns="http://www.w3.org/2000/svg">{"".join(parts)}</svg>'
    )


def _curve_svg(history):
    """Best fitness per generation, log scale, as an inline SVG."""
    y = np.asarray(history, dtype=float)
    y = y[np.isfinite(y)]
    if len(y) < 2:
        return "<p class='muted'>No fitness curve (the method has no generations).</p>"
    ly = np.log10(np.maximum(y, 1e-12))
    W, H, L, B, T, Rm = 640, 240, 64, 36, 12, 12
    lo, hi = float(ly.min()), float(ly.max())
    if hi - lo < 1e-9:
        lo, hi = lo - 0.5, hi + 0.5
    xs = L + (W - L - Rm) * np.arange(len(ly)) / (len(ly) - 1)
    ys = T + (H - T - B) * (hi - ly) / (hi - lo)
    points = " ".join(f"{a:.1f},{b:.1f}" for a, b in zip(xs, ys, strict=True))
    ticks = []
    for value in np.linspace(lo, hi, 4):
        ty = T + (H - T - B) * (hi - value) / (hi - lo)
        ticks.append(
            f'<line x1="{L - 4}" y1="{ty:.1f}" x2="{W - Rm}" y2="{ty:.1f}" class="grid"/>'
            f'<text x="{L - 6}" y="{ty + 4:.1f}" text-anchor="end">{10**value:.3g}</text>'
        )
    n = len(ly)
    for g in sorted({0, n // 2, n - 1}):
        tx = xs[g]
        ticks.append(f'<text x="{tx:.1f}" y="{H - B + 16}" text-anchor="middle">{g + 1}</text>')
    return (
        f'<svg class="curve" viewBox="0 0 {W} {H}" width="{W}" height="{H}" '
        f'xmlns="http://www.w3.org/2000/svg">{"".join(ticks)}'
        f'<polyline points="{points}" class="fit"/>'
        f'<text x="{(L + W) / 2}" y="{H - 4}" text-anchor="middle">generation</text>'
        f'<text x="14" y="{H / 2}" transform="rotate(-90 14 {H / 2})" text-anchor="middle">'
        "best fitness (log)</text></svg>"
    )


def _method_label(result):
    return result.method + (f" {result.variant}" if result.variant else "")


def _summary(entry, rows, outside):
    result, photo = entry.result, entry.photo
    errors = np.array([r["error_px"] for r in rows])
    mean_err = float(np.mean(errors)) if len(errors) and np.all(np.isfinite(errors)) else None
    scd = camera_facts(result, photo)["scd_mm"] if result else None
    return {
        "status": "ok" if result else f"failed: {result.error}",
        "focal_px": result.camera.focal_px if result else None,
        "scd_mm": scd,
        "mean_error_px": mean_err,
        "fitness": result.fitness,
        "outside_pct": outside[1] if outside else None,
    }


def _outside_mask(covered_full, photo):
    """(pixels, percent of the skull's pixels) of skull outside the face mask, or None."""
    if photo.face_mask is None or covered_full is None:
        return None
    n_skull = int(covered_full.sum())
    n_out = int((covered_full & ~photo.face_mask).sum())
    return n_out, (100.0 * n_out / n_skull if n_skull else 0.0)


def _section(index, entry, rows, box, layer, outside):
    result, photo, skull = entry.result, entry.photo, entry.skull
    size_wh = photo.image_size_wh
    u0, v0, u1, v1 = box
    box_wh = (u1 - u0, v1 - v0)
    small_wh = tuple(max(1, round(s * _scale_of(box_wh))) for s in box_wh)
    photo_uri = _data_uri(_resize(photo.image[v0:v1, u0:u1], small_wh), "jpeg")
    sid = f"sfo-{index}"
    title = f"{_e(photo.id)} &mdash; {_e(_method_label(result))}"
    out = [f'<section class="sfo" id="{sid}"><h2>{index}. {title}</h2>']
    out.append(
        f"<p class='muted'>Skull <b>{_e(skull.id)}</b>, photo <b>{_e(photo.id)}</b> "
        f"({size_wh[0]}&times;{size_wh[1]} px, {_e(photo.view)} view)"
        + (
            f"; shown: columns {u0}&ndash;{u1 - 1}, rows {v0}&ndash;{v1 - 1}"
            if box_wh != tuple(size_wh)
            else ""
        )
        + "</p>"
    )
    if not result:
        out.append(f"<p class='fail'>The SFO failed: {_e(result.error)}</p>")
    # --- the overlay
    layers = [f'<img class="photo" alt="photo {_e(photo.id)}" src="{photo_uri}">']
    if layer is not None:
        layers.append(
            f'<img class="skull-layer" alt="projected skull" src="{_data_uri(layer, "png")}" '
            f'style="opacity:{DEFAULT_OPACITY_PCT / 100}">'
        )
    outside_ctl = ""
    if layer is not None and outside is not None and outside[0] > 0:
        mask_crop = photo.face_mask[v0:v1, u0:u1].astype(np.uint8) * 255
        mask_small = _resize(mask_crop, layer.shape[1::-1]) > 127
        hot = (layer[..., 3] > 0) & ~mask_small
        rgba = np.zeros(hot.shape + (4,), dtype=np.uint8)
        rgba[hot] = OUTSIDE_RGBA
        layers.append(
            f'<img class="outside-layer" alt="skull outside the face" '
            f'src="{_data_uri(rgba, "png")}" style="display:none">'
        )
        outside_ctl = (
            '<label><input type="checkbox" class="show-outside"> skull outside the face mask '
            f"({outside[0]} px)</label>"
        )
    layers.append(_marks_svg(rows, box))
    layers.append('<div class="wipe-line" hidden></div>')
    out.append(
        '<div class="view"><div class="pic">'
        f'<div class="stage" data-box="{u0} {v0} {u1} {v1}" '
        f'style="aspect-ratio:{box_wh[0]}/{box_wh[1]};'
        f'width:min(100%, calc(82vh * {box_wh[0]} / {box_wh[1]}))">' + "".join(layers) + "</div>"
    )
    if layer is not None:
        out.append(
            '<div class="controls">'
            f'<label>skull opacity <input type="range" class="opacity" min="0" max="100" '
            f'value="{DEFAULT_OPACITY_PCT}"><output>{DEFAULT_OPACITY_PCT} %</output></label>'
            '<label>wipe (skull left of) <input type="range" class="wipe" min="0" max="100" '
            'value="100"><output>100 %</output></label>'
            '<label><input type="checkbox" class="show-marks" checked> landmarks</label>'
            f"{outside_ctl}</div>"
            "<p class='muted legend'><span class='sw lm'></span> landmark marked in the photo "
            "&nbsp; <span class='sw est'></span> projected estimate (skull + soft tissue) "
            "&nbsp; <span class='sw ol'></span> skull outline. Drag on the picture to move the "
            "wipe.</p>"
        )
    out.append("</div><div class='side'>")
    # --- landmarks
    out.append("<h3 style='margin-top:0'>Landmarks</h3>")
    table_rows = []
    for k, row in enumerate(rows, start=1):
        (pu, pv), (eu, ev) = row["photo_uv"], row["estimate_uv"]
        table_rows.append(
            [
                str(k),
                _e(row["name"]),
                f"{pu:.1f}, {pv:.1f}",
                f"{_num(eu, '{:.1f}')}, {_num(ev, '{:.1f}')}",
                _num(row["error_px"], "{:.2f}"),
            ]
        )
    errors = np.array([r["error_px"] for r in rows])
    if len(errors) and np.all(np.isfinite(errors)):
        table_rows.append(
            ["", "<b>mean</b>", "", "", f"<b>{np.mean(errors):.2f}</b>"],
        )
    out.append(
        _table(
            ["#", "facial landmark", "photo (u, v) px", "estimate (u, v) px", "error px"],
            table_rows,
            "num",
        )
    )
    out.append("</div></div>")
    # --- camera
    out.append("<h3>Camera</h3>")
    cam_rows = []
    priors = photo.priors
    if result:
        c = camera_facts(result, photo)
        in_prior = ""
        if priors.focal_px is not None:
            lo, hi = priors.focal_px
            ok = lo <= c["focal_px"] <= hi
            in_prior = f" (prior {lo:.0f}&ndash;{hi:.0f}: {'inside' if ok else 'OUTSIDE'})"
        cam_rows.append(["focal length", f"{c['focal_px']:.1f} px{in_prior}"])
        cam_rows.append(
            ["principal point", "{:.1f}, {:.1f} px (image centre)".format(*c["principal_point_px"])]
        )
        in_prior = ""
        if priors.scd_mm is not None:
            lo, hi = priors.scd_mm
            ok = lo <= c["scd_mm"] <= hi
            in_prior = f" (prior {lo:.0f}&ndash;{hi:.0f}: {'inside' if ok else 'OUTSIDE'})"
        cam_rows.append(
            [
                "subject-to-camera distance",
                f"{c['scd_mm']:.1f} mm to the {c['scd_point']}{in_prior}",
            ]
        )
        cam_rows.append(
            [
                "rotation skull&rarr;camera",
                "{:.2f}&deg; about ({:.3f}, {:.3f}, {:.3f})".format(
                    c["rotation_angle_deg"], *c["rotation_axis"]
                ),
            ]
        )
        cam_rows.append(
            [
                "Euler angles x, y, z (extrinsic)",
                "{:.2f}&deg;, {:.2f}&deg;, {:.2f}&deg;".format(*c["euler_xyz_deg"]),
            ]
        )
        if c["head_deviation_deg"] is not None:
            cam_rows.append(
                [
                    "deviation from the a-priori head orientation",
                    f"{c['head_deviation_deg']:.2f}&deg; (tolerance "
                    f"{priors.head_tolerance_deg:g}&deg;)",
                ]
            )
        cam_rows.append(["translation", "{:.1f}, {:.1f}, {:.1f} mm".format(*c["translation_mm"])])
        matrix = "<br>".join(
            " ".join(f"{x:+.5f}" if j < 3 else f"{x:+.2f}" for j, x in enumerate(r))
            for r in c["skull2cam"]
        )
        cam_rows.append(["skull2cam (mm)", f"<code>{matrix}</code>"])
    for key, value in entry.notes.items():
        cam_rows.append([_e(key), _e(str(value))])
    out.append(_table(["", ""], cam_rows, "kv"))
    # --- fitness
    out.append("<h3>Fitness</h3>")
    labels = {
        "mse_pix": "MSE<sub>pix</sub> (px&sup2;)",
        "p_cam": "P<sub>cam</sub> (camera priors)",
        "p_skof": "P<sub>skof</sub> (skull outside face)",
        "p_pll": "P<sub>pll</sub> (curve parallelism)",
    }
    term_rows = [
        [labels.get(k, _e(k)), _num(v, "{:.4g}", "off") if result else "&ndash;"]
        for k, v in result.terms.items()
    ]
    score = "fitness" if result.method != "posest-sfo" else "score (mean landmark error, px)"
    term_rows.append([f"<b>{score}</b>", f"<b>{_num(result.fitness, '{:.4g}')}</b>"])
    if outside is not None and result:
        term_rows.append(
            [
                "skull pixels outside the face mask",
                f"{outside[0]} px ({outside[1]:.2f} % of the skull)",
            ]
        )
    out.append(_table(["term", "value"], term_rows, "kv"))
    history = result.extra.get("history")
    out.append(_curve_svg(history) if history is not None else "")
    run = [
        ["method", _e(_method_label(result))],
        ["seed", _e(str(result.seed)) if result.seed is not None else "&ndash; (deterministic)"],
        ["time", f"{result.seconds:.2f} s"],
    ]
    for key in ("generations", "evaluations", "stop", "fallbacks"):
        if key in result.extra:
            run.append([key, _e(str(result.extra[key]))])
    out.append(_table(["run", ""], run, "kv"))
    # --- inputs
    out.append("<h3>Inputs and outputs</h3>")
    file_rows = []
    for label, path in entry.inputs.items():
        path = Path(path)
        digest = sha256_of(path) if path.is_file() else "missing"
        size = f"{path.stat().st_size:,} B" if path.is_file() else ""
        file_rows.append([_e(label), _e(str(path)), size, f"<code>{digest}</code>"])
    out.append(_table(["input", "file", "size", "SHA-256"], file_rows, "files"))
    if entry.outputs:
        links = " &middot; ".join(
            f'<a href="{_e(str(href))}">{_e(label)}</a>' for label, href in entry.outputs.items()
        )
        out.append(f"<p>Outputs: {links}</p>")
    out.append("</section>")
    return "".join(out)


_CSS = """
body{font:15px/1.45 system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:0 auto;
 max-width:1600px;padding:16px 24px;color:#1d232a;background:#fafafa}
h1{font-size:24px;margin:8px 0} h2{font-size:20px;margin:32px 0 8px;border-top:2px solid #ccd;
 padding-top:16px} h3{font-size:16px;margin:18px 0 6px}
table{border-collapse:collapse;margin:6px 0;background:#fff}
th,td{border:1px solid #d5d9de;padding:3px 8px;text-align:left;vertical-align:top}
th{background:#eef1f4} table.num td{font-variant-numeric:tabular-nums}
code{font:12px/1.35 ui-monospace,Menlo,Consolas,monospace}
.muted{color:#5b6670} .fail{color:#b00020;font-weight:600}
.view{display:grid;grid-template-columns:minmax(0,1fr) auto;gap:8px 20px;align-items:start}
@media (max-width:900px){.view{grid-template-columns:1fr}}
.stage{position:relative;width:100%;background:#000;overflow:hidden;
 touch-action:none;cursor:ew-resize;user-select:none}
.stage img,.stage svg{position:absolute;left:0;top:0;width:100%;height:100%;display:block}
.stage img.photo{position:relative;height:auto}
.stage .marks{pointer-events:none}
.marks .lm{fill:none;stroke:#00c8ff;stroke-width:2;vector-effect:non-scaling-stroke}
.marks .est{fill:#ff2828} .marks .err{stroke:#ff2828;stroke-width:1.5;
 vector-effect:non-scaling-stroke}
.marks .lbl{fill:#fff;stroke:#000;stroke-width:3;paint-order:stroke;
 vector-effect:non-scaling-stroke;font-family:sans-serif;font-weight:700}
.wipe-line{position:absolute;top:0;bottom:0;width:2px;margin-left:-1px;background:#fff;
 box-shadow:0 0 3px #000;pointer-events:none}
.controls{display:flex;flex-wrap:wrap;gap:8px 24px;margin:8px 0;align-items:center}
.controls input[type=range]{width:220px;vertical-align:middle}
.controls output{display:inline-block;width:48px;text-align:right}
.sw{display:inline-block;width:12px;height:12px;border-radius:50%;vertical-align:-1px}
.sw.lm{border:2px solid #00c8ff;box-sizing:border-box} .sw.est{background:#ff2828}
.sw.ol{background:#ffd600;border-radius:0;height:3px;vertical-align:3px}
svg.curve text{font:11px sans-serif;fill:#333} svg.curve .grid{stroke:#ddd}
svg.curve .fit{fill:none;stroke:#1f5fbf;stroke-width:2}
.note{background:#fff7e0;border:1px solid #f0d890;padding:8px 12px}
"""

_JS = """
(function(){
  for (const sec of document.querySelectorAll('section.sfo')) {
    const stage = sec.querySelector('.stage');
    const skull = sec.querySelector('.skull-layer');
    if (!skull) continue;
    const outside = sec.querySelector('.outside-layer');
    const marks = sec.querySelector('.marks');
    const line = sec.querySelector('.wipe-line');
    const opacity = sec.querySelector('input.opacity');
    const wipe = sec.querySelector('input.wipe');
    const showMarks = sec.querySelector('input.show-marks');
    const showOutside = sec.querySelector('input.show-outside');
    function update() {
      skull.style.opacity = String(opacity.value / 100);
      opacity.nextElementSibling.textContent = opacity.value + ' %';
      const clip = 'inset(0px ' + (100 - wipe.value) + '% 0px 0px)';
      skull.style.clipPath = clip;
      if (outside) {
        outside.style.clipPath = clip;
        outside.style.display = showOutside && showOutside.checked ? 'block' : 'none';
      }
      wipe.nextElementSibling.textContent = wipe.value + ' %';
      line.style.left = wipe.value + '%';
      line.hidden = Number(wipe.value) >= 100;
      marks.style.display = showMarks.checked ? 'block' : 'none';
    }
    for (const el of [opacity, wipe, showMarks, showOutside]) {
      if (el) el.addEventListener('input', update);
      if (el) el.addEventListener('change', update);
    }
    let dragging = false;
    function drag(ev) {
      const box = stage.getBoundingClientRect();
      const pct = 100 * (ev.clientX - box.left) / box.width;
      wipe.value = String(Math.round(Math.min(100, Math.max(0, pct))));
      update();
    }
    stage.addEventListener('pointerdown', function(ev) {
      dragging = true;
      try { stage.setPointerCapture(ev.pointerId); } catch (err) { /* synthetic event */ }
      drag(ev);
    });
    stage.addEventListener('pointermove', function(ev) { if (dragging) drag(ev); });
    stage.addEventListener('pointerup', function() { dragging = false; });
    update();
  }
})();
"""


def build_report(entries, title=None, command=None, date=None):
    """The report's HTML text.

    Parameters
    ----------
    entries : list of ReportEntry
        One per SFO; entries of the same photo (e.g. two methods) follow each other.
    title : str, optional
    command : str, optional
        The command line that produced the results, for the provenance.
    date : str, optional
        ISO date-time; now (UTC) by default.

    Returns
    -------
    str
    """
    if not entries:
        raise ValueError("a report needs at least one SFO result")
    date = date or _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    skull_ids = sorted({e.skull.id for e in entries})
    title = title or f"Skull-face overlay: skull {', '.join(skull_ids)}"
    sections, summary_rows = [], []
    for index, entry in enumerate(entries, start=1):
        result, photo = entry.result, entry.photo
        if photo.image is None:
            raise ValueError(f"photo {photo.id!r} was read without its image; read it with pixels")
        rows = landmark_rows(result, photo)
        layer, covered_full = None, None
        if result:
            _, covered_full = render_mesh_shaded(
                entry.skull.vertices_mm, entry.skull.faces, result.camera, photo.image_size_wh
            )
        points = [r["photo_uv"] for r in rows] + [r["estimate_uv"] for r in rows]
        box = view_box(photo.image_size_wh, covered_full, photo.face_mask, points)
        if result:
            box_wh = (box[2] - box[0], box[3] - box[1])
            # The skull is drawn (not photographed): render small regions finer than the photo.
            long_px = max(box_wh)
            scale = min(MAX_REPORT_PX, max(long_px, MIN_LAYER_PX)) / long_px
            layer = skull_layer_rgba(result, entry.skull, box, scale)
        outside = _outside_mask(covered_full, photo)
        s = _summary(entry, rows, outside)
        summary_rows.append(
            [
                f'<a href="#sfo-{index}">{index}</a>',
                _e(photo.id),
                _e(photo.view),
                _e(_method_label(result)),
                _e(s["status"]),
                _num(s["focal_px"], "{:.0f}"),
                _num(s["scd_mm"], "{:.0f}"),
                _num(s["mean_error_px"], "{:.2f}"),
                _num(s["fitness"], "{:.4g}"),
                _num(s["outside_pct"], "{:.2f}"),
                f"{result.seconds:.2f}",
            ]
        )
        sections.append(_section(index, entry, rows, box, layer, outside))
    versions = software_versions()
    prov_rows = [[_e(k), _e(v)] for k, v in versions.items()]
    prov_rows.append(["report date (UTC)", _e(date)])
    if command:
        prov_rows.append(["command", f"<code>{_e(command)}</code>"])
    summary = _table(
        [
            "#",
            "photo",
            "view",
            "method",
            "status",
            "focal px",
            "SCD mm",
            "mean landmark error px",
            "fitness / score",
            "skull outside face %",
            "time s",
        ],
        summary_rows,
        "num",
    )
    return (
        "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
        "<meta name='viewport' content='width=device-width, initial-scale=1'>"
        f"<title>{_e(title)}</title><style>{_CSS}</style></head><body>"
        f"<h1>{_e(title)}</h1>"
        f"<p class='muted'>Lilium {_e(versions['lilium'])}, {_e(date)}. "
        f"{len(entries)} superimposition(s) of skull {_e(', '.join(skull_ids))}.</p>"
        "<p class='note'>Each picture shows the skull projected with the estimated camera over "
        "the photo. Judge the anatomical consistency of the outline, the orbits, the nasal "
        "aperture, the dentition and the chin with the face; the landmark errors and the "
        "skull pixels outside the face support that judgement but do not replace it.</p>"
        f"<h2 style='border:0;margin-top:12px'>Summary</h2>{summary}"
        + "".join(sections)
        + f"<h2>Provenance</h2>{_table(['', ''], prov_rows, 'kv')}"
        f"<script>{_JS}</script></body></html>\n"
    )


def write_report(path, entries, **kwargs):
    """Write :func:`build_report` to ``path`` (UTF-8); returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(build_report(entries, **kwargs), encoding="utf-8")
    return path
