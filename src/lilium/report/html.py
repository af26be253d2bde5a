"""A self-contained HTML report of one case: one skull, one or more photos, one or more methods.

Formats the plain records of :mod:`lilium.report.records` into the templates shipped in
``lilium/report/templates/`` (``report.html``, ``sfo.html``, ``controls.html``,
``skull_views.html``, ``report.css``, ``pictures.css``, ``report.js``), filled with
:class:`string.Template`. Each SFO gets a section with

- the overlay as two stacked pictures (the photo, and the shaded skull as an RGBA layer that is
  transparent off the skull), an opacity slider for the skull layer and a wipe (slider, or drag
  on the picture) that shows the skull only left of a position, by CSS ``clip-path``; the
  landmarks as an SVG layer (photo landmark: ring, estimate: dot, joined by a line) and, with a
  face mask, the skull pixels outside it;
- the skull alone in a frontal and a lateral view with its cranial landmarks marked and
  labelled (numbered as in the landmark table where the SFO used them), so a misplaced or
  mislabelled landmark shows; each view's picture is embedded once per page (an SVG
  ``<image>`` that every SFO's view ``<use>``-s);
- above the landmark table, where the landmarks came from when ``lilium photo`` placed them
  ("facial landmarks automatic, unreviewed: ...", with a link to the review page), which the
  summary repeats; the table then gives each landmark's source (``automatic, tracked``);
- the landmark table (photo point, projected estimate, error in pixels), the camera (focal
  length, subject-to-camera distance, rotation, ``skull2cam``), each fitness term, the fitness
  curve (inline SVG);
- the inputs' provenance (SHA-256 of each file, software versions, seed, method, date).

A summary table on top lists every SFO of the page: the landmark error in pixels and in
millimetres at the landmarks' depth for every method side by side (comparable), each method's
own score in a column of its own (not comparable across methods), "implausible" for any camera
that puts skull pixels beyond the head mask's edge band whatever its method (the
identification's ``skull_outside_head``), and the docs/checks.md warnings,
which each SFO's section lists in full. Nothing is fetched from the network: the
pictures are base64 ``data:`` URIs, styles and script are inline.
"""

import base64
import functools
import html
import urllib.parse
from importlib import resources
from string import Template

import numpy as np

from ..io.results import write_page
from .conclusion_html import conclusion_section
from .records import ReportEntry, report_record
from .svg import curve_svg, marks_svg, skull_view_defs, skull_view_svg

#: How the report names facial landmarks found by ``lilium photo`` that nobody confirmed
#: (the same words as :data:`lilium.casework.prepared.UNREVIEWED`).
UNREVIEWED = "automatic, unreviewed"

#: Initial skull-layer opacity (percent).
DEFAULT_OPACITY_PCT = 60

#: Labels of the fitness terms (HTML).
TERM_LABELS = {
    "mse_pix": "MSE<sub>pix</sub> (px&sup2;)",
    "p_cam": "P<sub>cam</sub> (camera priors)",
    "p_skof": "P<sub>skof</sub> (skull outside face)",
    "p_pll": "P<sub>pll</sub> (curve parallelism)",
}

#: Columns of the summary table.
SUMMARY_HEADER = (
    "#",
    "photo",
    "view",
    "method",
    "status",
    "focal px",
    "SCD mm",
    "mean error px",
    "mean error mm",
    "method's own score: the paper's alignment score (not comparable across methods)",
    "skull outside face %",
    "warnings",
    "time s",
)

_e = html.escape


@functools.cache
def template_text(name):
    """The text of a template file shipped with the package (``templates/<name>``)."""
    return resources.files(__package__).joinpath("templates", name).read_text(encoding="utf-8")


def _fill(name, **values):
    return Template(template_text(name)).substitute(values)


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


def _data_uri(data, fmt):
    return f"data:image/{fmt};base64," + base64.b64encode(data).decode("ascii")


def _warning_codes(warnings):
    return " ".join(
        f'<span class="warn" title="{_e(message)}">{_e(code)}</span>' for code, message in warnings
    )


def _summary_row(sfo):
    s = sfo.summary
    status = _e(s.status)
    if s.implausible:
        status = (
            '<span class="fail" title="skull pixels outside the face mask">'
            "implausible</span>"
        )
    return [
        f'<a href="#sfo-{sfo.index}">{sfo.index}</a>',
        _e(sfo.photo_id),
        _e(sfo.view),
        _e(sfo.method_label),
        status,
        _num(s.focal_px, "{:.0f}"),
        _num(s.scd_mm, "{:.0f}"),
        _num(s.mean_error_px, "{:.2f}"),
        _num(s.mean_error_mm, "{:.2f}"),
        f"{_num(s.fitness, '{:.4g}')} <span class='muted'>({_e(s.score_label)})</span>",
        _num(s.outside_pct, "{:.2f}"),
        _warning_codes(s.warnings) + _unreviewed_mark(sfo),
        f"{s.seconds:.2f}",
    ]


def _unreviewed_mark(sfo):
    if not sfo.landmarks_unreviewed:
        return ""
    return f' <span class="warn" title="{_e(sfo.landmarks_note)}">landmarks {UNREVIEWED}</span>'


def _review_link(sfo):
    if not sfo.review_href:
        return ""
    return f' (<a href="{_e(relative_href(sfo.review_href))}">review page</a>)'


def _landmarks_note(sfo):
    """The line on the landmarks' origin, above the landmark table ("" when placed by hand)."""
    if not sfo.landmarks_note:
        return ""
    cls = "warnings" if sfo.landmarks_unreviewed else "muted"
    return f"<p class='{cls} landmarks-origin'>{_e(sfo.landmarks_note)}{_review_link(sfo)}</p>"


def _summary_notes(page):
    """One line under the summary per photo whose landmarks are automatic and unreviewed."""
    lines = {}
    for sfo in page.sfos:
        if sfo.landmarks_unreviewed and sfo.photo_id not in lines:
            lines[sfo.photo_id] = (
                f"<p class='warnings landmarks-origin'>Photo <b>{_e(sfo.photo_id)}</b>: "
                f"{_e(sfo.landmarks_note)}{_review_link(sfo)}</p>"
            )
    return "\n".join(lines.values())


def _alerts(sfo):
    """The failure, the implausible mark and every warning of an SFO, above its pictures."""
    out = []
    if not sfo.ok:
        out.append(f"<p class='fail'>The SFO failed: {_e(sfo.error)}</p>")
    if sfo.summary.implausible:
        out.append(
            f"<p class='fail'>Implausible: {sfo.outside.outside_px} skull pixels "
            f"({sfo.outside.percent_outside:.2f} %) lie outside the face mask.</p>"
        )
    if sfo.warnings:
        items = "".join(
            f"<li><code>{_e(code)}</code>: {_e(message)}</li>" for code, message in sfo.warnings
        )
        out.append(f"<div class='warnings'><b>Warnings</b><ul>{items}</ul></div>")
    return "\n".join(out)


def _layers(sfo):
    pics = sfo.pictures
    out = [
        f'<img class="photo" alt="photo {_e(sfo.photo_id)}" '
        f'src="{_data_uri(pics.photo_jpeg, "jpeg")}">'
    ]
    if pics.skull_png is not None:
        out.append(
            f'<img class="skull-layer" alt="projected skull" '
            f'src="{_data_uri(pics.skull_png, "png")}" style="opacity:{DEFAULT_OPACITY_PCT / 100}">'
        )
    if pics.outside_png is not None:
        out.append(
            f'<img class="outside-layer" alt="skull outside the face" '
            f'src="{_data_uri(pics.outside_png, "png")}" style="display:none">'
        )
    out.append(marks_svg(sfo.landmarks, pics.box))
    return "".join(out)


def _skull_views(sfo):
    if not sfo.skull_views:
        return (
            "<p class='muted'>No skull-alone views: the cranial landmarks cannot orient the "
            "skull (give porion_l, porion_r and an orbitale, or upper and lower midline "
            "landmarks).</p>"
        )
    numbers = dict(sfo.cranial_numbers)
    figures = "".join(f"<figure>{skull_view_svg(p, numbers)}</figure>" for p in sfo.skull_views)
    return _fill("skull_views.html", figures=figures)


def _controls(sfo):
    if sfo.pictures.skull_png is None:
        return ""
    outside = ""
    if sfo.pictures.outside_png is not None:
        outside = (
            '<label><input type="checkbox" class="show-outside"> skull outside the face mask '
            f"({sfo.outside.outside_px} px)</label>"
        )
    return _fill("controls.html", opacity=DEFAULT_OPACITY_PCT, outside_control=outside)


def _landmark_table(sfo):
    tags = dict(sfo.landmark_tags)
    rows = []
    for k, row in enumerate(sfo.landmarks, start=1):
        (pu, pv), (eu, ev) = row.photo_uv, row.estimate_uv
        rows.append(
            [
                str(k),
                _e(row.name),
                f"{pu:.1f}, {pv:.1f}",
                f"{_num(eu, '{:.1f}')}, {_num(ev, '{:.1f}')}",
                _num(row.error_px, "{:.2f}"),
            ]
            + ([_e(tags.get(row.name, ""))] if tags else [])
        )
    if sfo.mean_error_px is not None:
        mean = ["", "<b>mean</b>", "", "", f"<b>{sfo.mean_error_px:.2f}</b>"]
        rows.append(mean + ([""] if tags else []))
    header = ["#", "facial landmark", "photo (u, v) px", "estimate (u, v) px", "error px"]
    return _table(header + (["source"] if tags else []), rows, "num")


def _in_prior(bounds, inside):
    if bounds is None:
        return ""
    lo, hi = bounds
    return f" (prior {lo:.0f}&ndash;{hi:.0f}: {'inside' if inside else 'OUTSIDE'})"


def _camera_table(sfo):
    rows = []
    c = sfo.camera
    if c is not None:
        rows.append(
            ["focal length", f"{c.focal_px:.1f} px{_in_prior(c.focal_prior_px, c.focal_in_prior)}"]
        )
        rows.append(
            ["principal point", "{:.1f}, {:.1f} px (image centre)".format(*c.principal_point_px)]
        )
        rows.append(
            [
                "subject-to-camera distance",
                f"{c.scd_mm:.1f} mm to the {c.scd_point}"
                + _in_prior(c.scd_prior_mm, c.scd_in_prior),
            ]
        )
        rows.append(
            [
                "rotation skull&rarr;camera",
                "{:.2f}&deg; about ({:.3f}, {:.3f}, {:.3f})".format(
                    c.rotation_angle_deg, *c.rotation_axis
                ),
            ]
        )
        rows.append(
            [
                "Euler angles x, y, z (extrinsic)",
                "{:.2f}&deg;, {:.2f}&deg;, {:.2f}&deg;".format(*c.euler_xyz_deg),
            ]
        )
        if c.head_deviation_deg is not None:
            rows.append(
                [
                    "deviation from the a-priori head orientation",
                    f"{c.head_deviation_deg:.2f}&deg; (tolerance {c.head_tolerance_deg:g}&deg;)",
                ]
            )
        rows.append(["translation", "{:.1f}, {:.1f}, {:.1f} mm".format(*c.translation_mm)])
        matrix = "<br>".join(
            " ".join(f"{x:+.5f}" if j < 3 else f"{x:+.2f}" for j, x in enumerate(r))
            for r in c.skull2cam
        )
        rows.append(["skull2cam (mm)", f"<code>{matrix}</code>"])
    rows += [[_e(key), _e(value)] for key, value in sfo.notes]
    rows += [
        [f"prior: {_e(name)}", f"{_e(value)} (source: {_e(source)})"]
        for name, value, source in sfo.priors
    ]
    return _table(["", ""], rows, "kv")


def _terms_table(sfo):
    off = dict(sfo.terms_off)  # asked for but without their inputs: say why (docs/method/lilium.md)
    rows = [
        [
            TERM_LABELS.get(k, _e(k)),
            f"switched off: {_e(off[k])}"
            if k in off
            else (_num(v, "{:.4g}", "off") if sfo.ok else "&ndash;"),
        ]
        for k, v in sfo.terms
    ]
    rows += [
        [f"{TERM_LABELS['p_cam']}, {_e(k[len('p_cam_') :])} part", f"switched off: {_e(why)}"]
        for k, why in sfo.terms_off
        if k.startswith("p_cam_")
    ]
    score = f"method's own score ({_e(sfo.summary.score_label)})"
    if sfo.method_label.endswith(" joint"):
        # result.json's photos[k]: "fitness" is the weighted share, this the unweighted one
        score += " of this photo alone (result.json: <code>fitness_unweighted</code>)"
    rows.append([f"<b>{score}</b>", f"<b>{_num(sfo.fitness, '{:.4g}')}</b>"])
    s = sfo.summary
    if s.mean_error_px is not None:
        rows.append(
            [
                "mean landmark error (comparable across methods)",
                f"{s.mean_error_px:.2f} px = {_num(s.mean_error_mm, '{:.2f}')} mm at the "
                "landmarks' depth",
            ]
        )
    if sfo.outside is not None:
        o = sfo.outside
        rows.append(
            [
                "skull pixels outside the face mask",
                f"{o.outside_px} px ({o.percent_outside:.2f} % of the skull)",
            ]
        )
    return _table(["term", "value"], rows, "kv")


def _run_table(sfo):
    seed = _e(str(sfo.seed)) if sfo.seed is not None else "&ndash; (deterministic)"
    rows = [["method", _e(sfo.method_label)], ["seed", seed], ["time", f"{sfo.seconds:.2f} s"]]
    rows += [[key, _e(value)] for key, value in sfo.run_extra]
    return _table(["run", ""], rows, "kv")


def _files_table(sfo):
    rows = [
        [
            _e(f.label),
            _e(f.path),
            "" if f.size_bytes is None else f"{f.size_bytes:,} B",
            f"<code>{f.sha256 or 'missing'}</code>",
        ]
        for f in sfo.inputs
    ]
    return _table(["input", "file", "size", "SHA-256"], rows, "files")


def relative_href(path):
    """A link to a file beside the report: the path percent-encoded, so it can only be relative.

    A folder named ``javascript:alert(1)`` or ``https:x`` must stay a folder, not become a
    scheme: ``:`` and every other reserved character are encoded (``/`` kept between parts), and
    leading slashes are dropped (no absolute or ``//host`` links).
    """
    return urllib.parse.quote(str(path).replace("\\", "/").lstrip("/"), safe="/")


def _outputs(sfo):
    if not sfo.outputs:
        return ""
    links = " &middot; ".join(
        f'<a href="{_e(relative_href(href))}">{_e(label)}</a>' for label, href in sfo.outputs
    )
    return f"<p>Outputs: {links}</p>"


def format_sfo(sfo):
    """The ``<section>`` of one SFO.

    Parameters
    ----------
    sfo : SfoRecord

    Returns
    -------
    str
    """
    u0, v0, u1, v1 = sfo.pictures.box
    box_w, box_h = u1 - u0, v1 - v0
    width, height = sfo.image_size_wh
    shown = ""
    if (box_w, box_h) != (width, height):
        shown = f"; shown: columns {u0}&ndash;{u1 - 1}, rows {v0}&ndash;{v1 - 1}"
    failure = _alerts(sfo)
    return _fill(
        "sfo.html",
        anchor=f"sfo-{sfo.index}",
        index=sfo.index,
        photo_id=_e(sfo.photo_id),
        method=_e(sfo.method_label),
        skull_id=_e(sfo.skull_id),
        width=width,
        height=height,
        view=_e(sfo.view),
        shown=shown,
        failure=failure,
        u0=u0,
        v0=v0,
        u1=u1,
        v1=v1,
        box_w=box_w,
        box_h=box_h,
        layers=_layers(sfo),
        controls=_controls(sfo),
        skull_views=_skull_views(sfo),
        landmarks=_landmarks_note(sfo) + _landmark_table(sfo),
        camera=_camera_table(sfo),
        terms=_terms_table(sfo),
        curve="" if sfo.history is None else curve_svg(sfo.history),
        run=_run_table(sfo),
        files=_files_table(sfo),
        outputs=_outputs(sfo),
    )


def format_joint(joint):
    """The ``<section>`` of a joint SFO's shared soft tissue: its photos and the estimated 3D
    facial landmarks (each photo's own section shows its overlay and terms).

    Parameters
    ----------
    joint : JointRecord

    Returns
    -------
    str
    """
    weights = joint.weights or (1.0,) * len(joint.photo_ids)
    parts = " + ".join(
        f"{w:.3g} &times; {_num(f, '{:.4g}')} ({_e(pid)})"
        for pid, f, w in zip(joint.photo_ids, joint.photo_fitness, weights, strict=True)
    )
    rows = [
        [str(k), _e(r.name), *(f"{x:.2f}" for x in r.position_mm), _e(", ".join(r.photos))]
        for k, r in enumerate(joint.landmarks, start=1)
    ]
    header = ["#", "facial landmark", "x mm", "y mm", "z mm", "seen in"]
    status = "" if joint.ok else " <span class='fail'>(a photo has no camera)</span>"
    return (
        f"<section><h2>Joint SFO: {_e(joint.method_label)}, skull {_e(joint.skull_id)}, "
        f"photos {_e(', '.join(joint.photo_ids))}{status}</h2>\n"
        "<p>One soft tissue shared by every photo, one camera per photo (docs/method/joint.md). "
        f"Joint fitness {_num(joint.fitness, '{:.4g}')} = {parts}: each photo's fitness "
        "weighted by its scale (pixels per mm at the face) so that photos of different sizes "
        "count alike. Each photo's section below shows its overlay and terms from this soft "
        "tissue.</p>\n"
        "<p>Estimated 3D facial landmarks (skull frame, mm):</p>\n"
        + _table(header, rows, "num")
        + "</section>\n"
    )


def _skull_view_defs(page):
    """The page's skull-alone pictures, embedded once (each SFO's views refer to them)."""
    unique = {p.key: p for sfo in page.sfos for p in sfo.skull_views}
    return skull_view_defs(unique.values(), _data_uri)


def format_report(page):
    """The report's HTML text from its record.

    Parameters
    ----------
    page : ReportRecord

    Returns
    -------
    str
    """
    provenance = [[_e(k), _e(v)] for k, v in page.versions]
    provenance.append(["report date (UTC)", _e(page.date)])
    if page.command:
        provenance.append(["command", f"<code>{_e(page.command)}</code>"])
    if page.request:
        provenance.append(["request", f"<code>{_e(page.request)}</code>"])
    return _fill(
        "report.html",
        title=_e(page.title),
        css=template_text("report.css") + template_text("pictures.css"),
        js=template_text("report.js"),
        version=_e(page.lilium_version),
        date=_e(page.date),
        count=len(page.sfos),
        skulls=_e(", ".join(page.skull_ids)),
        summary=conclusion_section(page.decisions)
        + "<h2 style='border:0;margin-top:12px'>Summary</h2>\n"
        + _table(SUMMARY_HEADER, [_summary_row(s) for s in page.sfos], "num")
        + _summary_notes(page),
        sections=_skull_view_defs(page)
        + "".join(format_joint(j) for j in page.joints)
        + "\n".join(format_sfo(s) for s in page.sfos),
        provenance=_table(["", ""], provenance, "kv"),
    )


def build_report(entries, title=None, command=None, date=None, decisions=(), request=None):
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
    decisions : sequence of (str, dict), optional
        Identifications of several photos taken together (:func:`report_record`).
    request : dict, optional
        The run's request, for the provenance (:func:`report_record`).

    Returns
    -------
    str
    """
    return format_report(
        report_record(
            entries, title=title, command=command, date=date, decisions=decisions,
            request=request,
        )
    )


def write_report(path, entries, **kwargs):
    """Write :func:`build_report` to ``path`` (UTF-8); returns the path.

    A file name that is not UTF-8 (held by Python as lone surrogates) is shown with U+FFFD in
    place of its bad bytes; the report is written all the same
    (:func:`~lilium.io.results.write_page`).
    """
    return write_page(path, build_report(entries, **kwargs))


__all__ = [
    "ReportEntry",
    "build_report",
    "format_joint",
    "format_report",
    "format_sfo",
    "write_report",
]
