"""The report's first section: the identification's conclusions (docs/method/identification.md).

One row per decision (each SFO, each joint SFO, and a person's photos taken together): the
conclusion on the verbal scale, the calibrated log10 LR, what capped it (the material, a
consistency failure) and the calibration model it comes from. The fitness stays in each SFO's
section as the paper's score.
"""

from html import escape

from ..identification.conclusion import NO_SUPPORT_CAPS, SCALE

#: CSS class of a conclusion by its side of the scale.
_SIDE = {label: ("support" if k > 3 else "exclusion" if k < 3 else "undetermined")
         for k, (label, _) in enumerate(SCALE)}


def _lr_text(record):
    lr = record.get("log10_lr")
    if lr is None:
        return "&ndash;"
    return f"{lr:+.2f} <span class='muted'>(LR {10 ** lr:.3g})</span>"


def _why(record):
    caps = dict(record.get("caps") or {})
    # Outside the calibration first: the LR beside it is an extrapolation.
    first = {k: caps.pop(k) for k in NO_SUPPORT_CAPS if k in caps}
    parts = [
        f"<b>{escape(code)}</b>: {escape(text)}"
        for code, text in (first | (record.get("inconsistent") or {})).items()
    ]
    parts += [f"{escape(code)}: {escape(text)}" for code, text in caps.items()]
    if record.get("note"):
        parts.append(f"<i>{escape(record['note'])}</i>")
    worst = record.get("worst_landmark")
    if worst:
        parts.append(
            f"<span class='muted'>worst-fitting landmark: {escape(str(worst['name']))} (misfit "
            f"{worst['misfit']:.1f} per coordinate; a misplaced landmark lowers the LR)</span>"
        )
    return "<br>".join(parts) or "&ndash;"


def _error_rates(provenance):
    """The model's known error rates (cross-validated on its calibration data), when its
    calibration file states them."""
    rates = [provenance.get(f"cv_wrong_conclusion_{side}") for side in ("same", "diff")]
    if None in rates:
        return ""
    same, diff = (100 * r for r in rates)
    n = provenance.get("pairs_same"), provenance.get("pairs_different")
    pairs = f" on {n[0]} same- and {n[1]} different-person pairs" if None not in n else ""
    return (
        f"<br><span class='muted'>known error rate (cross-validated{escape(pairs)}): a wrong "
        f"conclusion for {same:.1f} % of same-person and {diff:.1f} % of different-person "
        "pairs</span>"
    )


def conclusion_section(decisions):
    """HTML of the conclusions (empty when the page has none).

    Parameters
    ----------
    decisions : sequence of (str, str, dict)
        ``ReportRecord.decisions``.
    """
    if not decisions:
        return ""
    rows = []
    for label, anchor, record in decisions:
        name = escape(label)
        if anchor:
            name = f"<a href='#{escape(anchor)}'>{name}</a>"
        conclusion = record.get("conclusion", "undetermined")
        capped = ""
        if record.get("conclusion_uncapped") not in (None, conclusion):
            alone = escape(record["conclusion_uncapped"])
            capped = f"<br><span class='muted'>(LR alone: {alone})</span>"
        calibration = record.get("calibration") or {}
        model = f"<code>{escape(calibration.get('model', ''))}</code>"
        model += _error_rates(calibration.get("provenance") or {})
        rows.append(
            f"<tr><td>{name}</td><td class='conclusion {_SIDE.get(conclusion, '')}'>"
            f"<b>{escape(conclusion)}</b>{capped}</td><td>{_lr_text(record)}</td>"
            f"<td>{_why(record)}</td><td>{model}</td></tr>"
        )
    head = ("<tr><th>decision</th><th>conclusion</th><th>log10 LR</th>"
            "<th>caps and consistency</th><th>calibration</th></tr>")
    return (
        "<h2 style='border:0;margin-top:12px'>Identification</h2>\n"
        "<p class='note'>Is this the person? The likelihood ratio compares the observations "
        "under \"this skull is the person in the photo\" with \"a random other person\", "
        "calibrated on generated subjects (docs/method/identification.md says where it holds). The "
        "conclusion follows a verbal scale, capped by the material. A decision whose features "
        "lie outside the range its calibration was fitted on (<b>outside_calibration</b>) gets "
        "no support: its LR would be an extrapolation. A skull outside the head, a camera whose "
        "perspective contradicts the photo's distance prior or whose focal length or distance "
        "lies beyond 1.5 x its prior is never support; a camera that contradicts the declared "
        "view or turns the head more than three tolerances from its prior is neither support "
        "nor exclusion. The fitness in each SFO's "
        "section is the paper's alignment score, not an identification.</p>\n"
        f"<table class='conclusions'><thead>{head}</thead><tbody>{''.join(rows)}</tbody></table>\n"
    )
