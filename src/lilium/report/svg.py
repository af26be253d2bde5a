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
