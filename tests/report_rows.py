"""A hand-made results database with known answers: rows of the ``sfo`` table (``report_row``)
and the set the report tables are tested on (``make_rows``), shared by the tests of
``lilium report``, the identification metrics and the hostile-input probes."""

SKULLS = ("s1", "s2", "s3")
#: 6 photos: two per subject, frontal and lateral.
PHOTOS = [(f"{s}_{v[0]}", s, v) for s in SKULLS for v in ("frontal", "lateral_left")]


def report_row(method, variant, rep, photo, subject, score, **extra):
    pid, true, view = photo
    row = {
        "experiment": "A",
        "method": method,
        "variant": variant,
        "axes_set": 0,
        "repetition": rep,
        "seed": rep,
        "photo": pid,
        "subject": subject,
        "view": view,
        "true_subject": true,
        "positive": int(subject == true),
        "success": int(score is not None),
        "score": score,
        "seconds": 0.5 if method == "lilium" else 0.01,
        "outside_px": 0,
        "skull_px": 100,
        "percent_outside": 0.0,
    }
    row.update(extra)
    return row


def make_rows():
    """POSEST-SFO: true skull best (rank 1), BPE 1 mm. Lilium base: rep 0 ties the true skull
    with one other (rank 1.5), rep 1 puts it last (rank 3); BPE 2 and 4 mm. Lilium+P_pll: the
    true SFO fails on the frontal photos (rank 3). Implausible: POSEST-SFO 2 SFOs (one positive,
    one negative, 10 % and 20 % outside), Lilium base rep 1: 3 negative SFOs at 30 %."""
    rows = []
    for photo in PHOTOS:
        true = photo[1]
        others = [s for s in SKULLS if s != true]
        for s in SKULLS:
            pos = s == true
            bad = {}
            if photo[0] == "s1_f" and s in ("s1", "s2"):
                bad = {"outside_px": 10 if pos else 20, "percent_outside": 10.0 if pos else 20.0}
            rows.append(
                report_row(
                    "posest-sfo",
                    "",
                    0,
                    photo,
                    s,
                    1.0 if pos else 5.0,
                    bpe_mm=1.0 if pos else None,
                    **bad,
                )
            )
            score0 = 2.0 if s in (true, others[0]) else 3.0
            rows.append(
                report_row("lilium", "base", 0, photo, s, score0, bpe_mm=2.0 if pos else None)
            )
            bad1 = {}
            if photo[0] in ("s2_f", "s2_l", "s3_f") and not pos:
                if s == others[0]:
                    bad1 = {"outside_px": 30, "percent_outside": 30.0}
            rows.append(
                report_row(
                    "lilium",
                    "base",
                    1,
                    photo,
                    s,
                    9.0 if pos else 1.0,
                    bpe_mm=4.0 if pos else None,
                    **bad1,
                )
            )
            fail = pos and photo[2] == "frontal"
            rows.append(
                report_row(
                    "lilium",
                    "pll",
                    0,
                    photo,
                    s,
                    None if fail else (1.0 if pos else 2.0),
                    bpe_mm=None if (fail or not pos) else 1.5,
                )
            )
    # An incomplete photo group (one skull missing) is left out of the ranks.
    rows.append(report_row("lilium", "base", 2, PHOTOS[0], "s1", 1.0, bpe_mm=2.0))
    return rows
