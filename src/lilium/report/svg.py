"""Inline SVG of the report: the landmark marks over a picture and the fitness curve.

Pure formatting: numbers in, SVG markup (``str``) out.
"""

import html

import numpy as np

#: Fitness-curve plot size and margins (SVG user units = CSS pixels).
CURVE_WIDTH, CURVE_HEIGHT = 640, 240
CURVE_LEFT, CURVE_BOTTOM, CURVE_TOP, CURVE_RIGHT = 64, 36, 12, 12

#: Mark radius as a fraction of the pictured region's longest side.
MARK_RADIUS_FRACTION = 1 / 160

#: Floor of the fitness before its logarithm is plotted.
CURVE_FLOOR = 1e-12


def marks_svg(rows, box):
    """The landmarks as an SVG layer over the pictured region, in photo pixels.

    Photo landmark: ring; estimate: dot, joined to the ring by a line; each numbered as in the
    landmark table and titled with its name and error.

    Parameters
    ----------
    rows : sequence of LandmarkRow
        ``photo_uv``, ``estimate_uv`` (NaN when the SFO failed), ``name``, ``error_px``.
    box : tuple (u0, v0, u1, v1), int
        The pictured region (its ``viewBox``; pixel centres at integer ``uv``).

    Returns
    -------
    str
    """
    u0, v0, u1, v1 = box
    w, h = u1 - u0, v1 - v0
    r = max(w, h) * MARK_RADIUS_FRACTION
    parts = []
    for k, row in enumerate(rows, start=1):
        (pu, pv), (eu, ev) = row.photo_uv, row.estimate_uv
        error = f"{row.error_px:.1f}" if np.isfinite(row.error_px) else "&ndash;"
        g = [f"<g><title>{k}. {html.escape(row.name)}: error {error} px</title>"]
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


def curve_svg(history):
    """Best fitness per generation, log scale, as an inline SVG.

    Parameters
    ----------
    history : sequence of float or None
        One value per generation; non-finite values are dropped.

    Returns
    -------
    str
        The SVG, or a short note when there are fewer than two generations.
    """
    y = np.asarray([] if history is None else history, dtype=float)
    y = y[np.isfinite(y)]
    if len(y) < 2:
        return "<p class='muted'>No fitness curve (the method has no generations).</p>"
    ly = np.log10(np.maximum(y, CURVE_FLOOR))
    W, H = CURVE_WIDTH, CURVE_HEIGHT
    L, B, T, Rm = CURVE_LEFT, CURVE_BOTTOM, CURVE_TOP, CURVE_RIGHT
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


#: Skull-alone views: width of each label column (SVG units = picture pixels), label spacing,
#: font size and mark radius.
LABEL_COLUMN = 185
LABEL_SPACING = 17
LABEL_FONT = 14
SKULL_MARK_RADIUS = 4.5

#: Colour classes of a cranial landmark by side (``_l``, ``_r``, midline).
SIDE_CLASS = {"l": "side-l", "r": "side-r", None: "side-m"}

#: Captions of the skull-alone views: title, and the words at the picture's left and right.
VIEW_CAPTIONS = {
    "frontal": ("frontal view", "subject's right", "subject's left"),
    "lateral_left": ("left lateral view", "anterior", "posterior"),
    "lateral_right": ("right lateral view", "posterior", "anterior"),
}


def _side(name):
    return name[-1] if name.endswith(("_l", "_r")) else None


def _spread(targets, spacing, low, high):
    """Label positions near ``targets`` (sorted), at least ``spacing`` apart, in [low, high]."""
    out = []
    for y in targets:
        out.append(max(y, low, out[-1] + spacing if out else low))
    overflow = out[-1] - high if out else 0
    if overflow > 0:  # push back up from the bottom
        out[-1] -= overflow
        for k in range(len(out) - 2, -1, -1):
            out[k] = min(out[k], out[k + 1] - spacing)
    return out


def skull_view_defs(pictures, data_uri):
    """The skull-alone pictures of a page, embedded once as SVG ``<image>`` definitions.

    Parameters
    ----------
    pictures : iterable of SkullViewPicture
    data_uri : callable
        ``data_uri(bytes, "jpeg") -> str``.

    Returns
    -------
    str
        An invisible ``<svg>`` whose ``<image id=key>`` elements :func:`skull_view_svg` uses.
    """
    images = "".join(
        f'<image id="{html.escape(p.key)}" width="{p.size_wh[0]}" height="{p.size_wh[1]}" '
        f'href="{data_uri(p.jpeg, "jpeg")}"/>'
        for p in pictures
    )
    if not images:
        return ""
    return (
        '<svg class="defs" width="0" height="0" aria-hidden="true" '
        f'xmlns="http://www.w3.org/2000/svg"><defs>{images}</defs></svg>'
    )


def skull_view_svg(picture, numbers=None):
    """The skull alone in one view with its cranial landmarks marked and labelled.

    Labels stand in two columns beside the picture, each joined to its landmark by a leader
    line; a landmark goes to the column of the side of the picture it lies on (frontal: of the
    midline landmarks' median column; midline landmarks fill the shorter column), so a label
    on the wrong side (``_l`` among the subject's right) shows a swap. Colour by the name's side
    (``_l``, ``_r``, midline); filled: used by the SFO (prefixed with its number in the
    landmark table), hollow: not used. A landmark hidden behind bone in this view (the far
    side in a lateral view) is a faded dashed ring without a label (its name on hover): the
    other view shows it.

    Parameters
    ----------
    picture : SkullViewPicture
    numbers : dict of str -> int, optional
        Cranial landmark -> its row number in the SFO's landmark table.

    Returns
    -------
    str
    """
    numbers = numbers or {}
    w, h = picture.size_wh
    col = LABEL_COLUMN
    title, left_word, right_word = VIEW_CAPTIONS.get(picture.view, (picture.view, "", ""))
    top, bottom = 2 * LABEL_SPACING, h - 1.2 * LABEL_SPACING
    items = []
    for name, (u, v), seen in zip(picture.names, picture.uv, picture.visible, strict=True):
        if np.isfinite(u) and np.isfinite(v):
            items.append((name, float(np.clip(u, 0, w - 1)), float(np.clip(v, 0, h - 1)), seen))
    # Frontal: split at the midline (the landmarks' own, not the picture's centre); lateral:
    # at the picture's centre (face half and vault half).
    midline = [u for n, u, _, _ in items if _side(n) is None]
    midline_u = np.median(midline) if picture.view == "frontal" and midline else w / 2
    columns = {"left": [], "right": []}
    for item in sorted(items, key=lambda it: it[2]):
        name, u = item[0], item[1]
        if abs(u - midline_u) < 1.0 and _side(name) is None:
            where = "left" if len(columns["left"]) <= len(columns["right"]) else "right"
        else:
            where = "left" if u < midline_u else "right"
        columns[where].append(item)
    parts = [
        f'<rect x="{-col}" y="0" width="{w + 2 * col}" height="{h}" class="bg"/>',
        f'<use href="#{html.escape(picture.key)}"/>',
    ]
    for where, column in columns.items():
        labelled = [it for it in column if it[3]]
        ys = _spread([it[2] for it in labelled], LABEL_SPACING, top, bottom)
        for (name, u, v, _), y in zip(labelled, ys, strict=True):
            number = numbers.get(name)
            label = html.escape(name if number is None else f"{number} {name}")
            x_end = -6 if where == "left" else w + 6
            x_text = x_end - 3 if where == "left" else x_end + 3
            anchor = "end" if where == "left" else "start"
            fill = "used" if number is not None else "unused"
            parts.append(
                f'<g class="{SIDE_CLASS[_side(name)]}"><title>{html.escape(name)}</title>'
                f'<polyline class="leader" points="{u:.1f},{v:.1f} {x_end:.1f},{y:.1f}"/>'
                f'<circle class="{fill}" cx="{u:.1f}" cy="{v:.1f}" r="{SKULL_MARK_RADIUS}"/>'
                f'<text x="{x_text:.1f}" y="{y + LABEL_FONT / 3:.1f}" text-anchor="{anchor}">'
                f"{label}</text></g>"
            )
        for name, u, v, _ in (it for it in column if not it[3]):
            number = numbers.get(name)
            tip = name if number is None else f"{number} {name}"
            parts.append(
                f'<g class="{SIDE_CLASS[_side(name)]} hidden"><title>{html.escape(tip)} '
                "(hidden behind bone in this view)</title>"
                f'<circle class="unused" cx="{u:.1f}" cy="{v:.1f}" r="{SKULL_MARK_RADIUS}"/></g>'
            )
    parts.append(
        f'<text class="caption" x="{w / 2}" y="{LABEL_SPACING}" text-anchor="middle">'
        f"{html.escape(title)}</text>"
        f'<text class="caption" x="6" y="{h - 6}">{html.escape(left_word)}</text>'
        f'<text class="caption" x="{w - 6}" y="{h - 6}" text-anchor="end">'
        f"{html.escape(right_word)}</text>"
    )
    return (
        f'<svg class="skull-view" viewBox="{-col} 0 {w + 2 * col} {h}" '
        f'font-size="{LABEL_FONT}" xmlns="http://www.w3.org/2000/svg">{"".join(parts)}</svg>'
    )
