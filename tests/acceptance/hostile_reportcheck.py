"""The checks of the report probes (``hostile_report.py``): one report page against the
``result.json`` files it links and the console of its command, from the files alone (read by
``hostile_reportpage.py``):

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
  report's row of that decision) says.

:func:`_report_consistent` makes a probe's check of all this (a command's own checks added,
as the lineup's of ``hostile_report.py``).
"""

import re
from pathlib import Path

import numpy as np
from hostile_fixtures import _json
from hostile_reportpage import (
    _box_close,
    _console,
    _cranial_points,
    _decode,
    _fmt4,
    _fmt_lr,
    _inputs_of,
    _kv,
    _norm,
    _project,
    _Report,
    _resolve,
    _rows,
    _section_facts,
    _skull_box,
    _skull_vertices,
)

# -- one SFO section ---------------------------------------------------------------------------


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

# -- conclusion rows, the console, the whole page ----------------------------------------------


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
        # "fitness" is its weighted share (docs/method/joint.md), the section shows its own,
        # unweighted.
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

