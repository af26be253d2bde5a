"""Metamorphic probes (docs/checks.md, docs/method/photo.md, docs/method/identification.md): one
case under a transformation that must not
change the answer, beyond the DE's own seed noise. A photo resampled 0.5x/2x with its
landmarks, mask and pixel priors, a canvas padded or cropped off-centre, the landmark rows
permuted or written with other names or in another format, the skull moved rigidly, its
vertices and faces reordered or written as STL/OBJ, the priors moved from ``photo.json`` to the
command line, an EXIF block added or stripped while the priors are explicit, the ground-truth
files removed, the photos of ``lilium case`` or the candidates of ``lilium lineup`` listed in
another order. A change beyond the tolerance is a silently wrong answer (``silently wrong``):
the same evidence gives another camera or another identification.

How the answers are compared, the tolerances and the probe factory are in
``hostile_metamorphic_compare.py``; the transformations in
``hostile_metamorphic_transforms.py``; here are the checks of multi-photo and lineup
results, the probes, and the seed spread the tolerances come from (``--spread``).

Inputs: the stand-in case of the campaign and the generated dataset of
``hostile_fixtures.py`` (``_syn``: subjects s01, s02, frontal and lateral photos).
83 probes, about 4 minutes on a loaded 2-core machine (most of it the Lilium probes' eight
seeds a side). Run alone::

    python -m pytest -m slow tests/acceptance/test_hostile_metamorphic.py [-k TEXT]
"""

import re
import shutil
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from hostile_fixtures import _dump, _in, _json, _syn  # noqa: E402
from hostile_machinery import ROOT, Probe, Workspace, _then  # noqa: E402
from hostile_metamorphic_compare import (  # noqa: E402
    IDENTITY,
    LIL,
    LIL_FLOOR,
    NOTES,
    SEEDS,
    Frame,
    Run,
    _dataset,
    _quiet,
    _results_of,
    _rot_spread,
    _scalars,
    _sd,
    _standin_truth,
    _syn_truth,
    metamorphic,
    metrics,
    tolerances,
)
from hostile_metamorphic_transforms import (  # noqa: E402
    MOTION,
    _alias_names,
    _axes_copy,
    _canvas,
    _cranial_file,
    _depth_csv,
    _edit_photo_json,
    _mask_mode,
    _mesh_as,
    _move_skull,
    _permute_landmarks,
    _photo_file,
    _plain,
    _priors_to_cli,
    _reorder_mesh,
    _rescale,
    _skull_units,
    _sp,
    _ss,
    _standin_photo,
    _standin_skull,
    _strip_truth,
    _to_jpeg,
)

sys.path.insert(0, str(ROOT / "tests"))


# -- checks of multi-photo and lineup results --------------------------------------------------

_TOGETHER = re.compile(r"together, (\S+): identification: (.+?), log10 LR ([+-][0-9.]+)")


def _together(text):
    """The 'photos ... together' decisions a ``lilium case`` printed: ``{tag: (concl, lr)}``."""
    return {m.group(1): (m.group(2), float(m.group(3))) for m in _TOGETHER.finditer(text)}


def _case_order(photos, method="posest-sfo", extra=()):
    """Check: ``lilium case`` with the photos in the other order gives each photo the same
    result and the same decision taken together (each order run here, stdout captured)."""

    def check(ws):
        outs, decisions, per_photo = [], [], []
        for k, order in enumerate((photos, photos[::-1])):
            run = Run(
                "case",
                _standin_skull if photos[0] in (_standin_photo, _half) else _ss("s01"),
                tuple(order),
                method,
                extra,
            )  # noqa: E501
            out = ws.root / f"order{k}"
            code, text, err = _quiet(run.argv(ws, SEEDS[0], out))
            if code != 0:
                return f"order {k}: exit {code}: {err.strip().splitlines()[-1:]}"
            outs.append(out)
            decisions.append(_together(text + err))
            per_photo.append({
                p.parent.parent.name: (r["identification"]["log10_lr"], r["identification"]["conclusion"], r["camera"]["focal_px"])  # noqa: E501
                for p in out.rglob("result.json") for r in [_json(p)] if r.get("camera")
            })  # fmt: skip
        problems = []
        if decisions[0] != decisions[1]:
            problems.append(f"together: {decisions[0]} -> {decisions[1]}")
        for photo, (lr, concl, f) in per_photo[0].items():
            lr2, concl2, f2 = per_photo[1].get(photo, (None, None, None))
            if lr2 is None or abs(lr - lr2) > 0.05 or concl != concl2 or abs(f / f2 - 1) > 0.005:
                problems.append(
                    f"{photo}: LR {lr:+.2f} {concl!r} f {f:.0f} -> {lr2} {concl2!r} f {f2}"
                )  # noqa: E501
        if not decisions[0]:
            problems.append("no 'together' decision printed")
        NOTES["last"] = f"together {decisions[0]} -> {decisions[1]}; per photo {per_photo[0]}"
        return "; ".join(problems) or None

    return check


def _lineup_run(candidates, method="posest-sfo"):
    def argv(ws, out=None):
        a = [
            "lineup",
            "--no-progress",
            "--skull",
            _ss("s01")(ws),
            "--out",
            out or ws.out,
            "--method",
            method,
        ]  # noqa: E501
        if method == "lilium":
            a += [*LIL, "--seed", "1"]
        for name, *photos in candidates:
            a += ["--candidate", name, *(p(ws) for p in photos)]
        return a

    return argv


def _ranking(folder):
    data = _json(folder / "lineup.json")
    return [
        (r["candidate"], r["identification"]["log10_lr"], r["identification"]["conclusion"])
        for r in data["ranking"]
    ]  # noqa: E501


def _lineup_same(other, lr_tol=0.05):
    """Check: the lineup in ``other`` order ranks the candidates the same, with the same LRs."""

    def check(ws):
        out = ws.root / "other"
        code, _, err = _quiet(other(ws, out))
        if code != 0:
            return f"other order: exit {code}: {err.strip().splitlines()[-1:]}"
        a, b = _ranking(ws.out), _ranking(out)
        NOTES["last"] = (
            f"{[(n, round(lr, 3), c) for n, lr, c in a]} -> {[(n, round(lr, 3), c) for n, lr, c in b]}"  # noqa: E501
        )
        if [x[0] for x in a] != [x[0] for x in b]:
            return f"ranking {a} -> {b}"
        for (n, lr, c), (_, lr2, c2) in zip(a, b, strict=True):
            if abs(lr - lr2) > lr_tol or c != c2:
                return f"{n}: log10 LR {lr:+.3f} {c!r} -> {lr2:+.3f} {c2!r}"
        return None

    return check


def _joint_photo(photo_id):
    """``pick`` of a joint SFO's result: photo ``photo_id``'s camera, landmark error and
    warnings, with the joint identification."""

    def pick(data):
        entry = next(p for p in data["photos"] if p["photo"] == photo_id)
        return {
            "camera": entry.get("camera"),
            "landmark_error": entry.get("landmark_error"),
            "warnings": (data.get("warnings") or []) + (entry.get("warnings") or []),
            "identification": data.get("identification"),
        }

    return pick


def _half(ws):
    return _in(ws, "photos", "half")


def _half_photo(ws):
    from standin_case import scaled_photo

    if not _half(ws).exists():
        scaled_photo(ws.photo, _half(ws), 0.5, moved=0.0)  # a resized copy of the photo


# -- the probes --------------------------------------------------------------------------------
# fmt: off


def metamorphic_probes():
    """The same case under transformations that must not change the answer."""
    S, P = _standin_skull, _standin_photo
    ST = _standin_truth
    S1, F1, L1, F2, L2 = _ss("s01"), _sp("s01_f00"), _sp("s01_l00"), _sp("s02_f00"), _sp("s02_l00")
    T1F, T1L = _syn_truth("s01", "s01_f00"), _syn_truth("s01", "s01_l00")
    pos = Run("sfo", S, (P,))
    lil = Run("sfo", S, (P,), "lilium")
    pF1, lF1 = Run("sfo", S1, (F1,)), Run("sfo", S1, (F1,), "lilium")
    lL1 = Run("sfo", S1, (L1,), "lilium")
    pF2 = Run("sfo", S1, (F2,))  # another person: an LR that is not at its cap
    p = []
    # resampled photos
    for f in (0.5, 2.0):
        fr = Frame(scale=f)
        p.append(metamorphic(f"standin photo resampled x{f} (landmarks, mask, focal prior scaled)", pos, _rescale(P, f), fr, ST, key="standin posest"))  # noqa: E501
        p.append(metamorphic(f"standin photo resampled x{f}, lilium", lil, _rescale(P, f), fr, ST, key="standin lilium"))  # noqa: E501
        p.append(metamorphic(f"s01 frontal resampled x{f}", pF1, _rescale(F1, f), fr, T1F, key="F1 posest", common=_syn))  # noqa: E501
        p.append(metamorphic(f"s01 frontal resampled x{f}, lilium", lF1, _rescale(F1, f), fr, T1F, key="F1 lilium", common=_syn))  # noqa: E501
        p.append(metamorphic(f"s01 lateral resampled x{f}, lilium", lL1, _rescale(L1, f), fr, T1L, key="L1 lilium", common=_syn))  # noqa: E501
        p.append(metamorphic(f"s02 frontal vs s01 skull resampled x{f}", pF2, _rescale(F2, f), fr, None, key="F2 posest", common=_syn))  # noqa: E501
    full = ("--generations", "750", "--population", "30")  # the calibration's own budget
    p.append(metamorphic("s01 lateral resampled x0.5, lilium at the calibrated budget (750 x 30)", lL1.with_(budget=full), _rescale(L1, 0.5), Frame(scale=0.5), T1L, key="L1 lilium full", common=_syn))  # noqa: E501
    # padded and cropped canvases
    canv = {"padded 400 px on the right": (0, 0, 400, 0),
            "padded 400 px on the left": (400, 0, 0, 0),
            "padded 300 px top and left": (300, 300, 0, 0), "cropped off-centre (250 px left, 120 px top)": (-250, -120, 0, 0)}  # noqa: E501
    for label, box in canv.items():
        fr = Frame(offset=(box[0], box[1]), shift_rot=True)
        p.append(metamorphic(f"standin canvas {label}", pos, _canvas(P, *box), fr, ST, key="standin posest"))  # noqa: E501
        p.append(metamorphic(f"standin canvas {label}, lilium", lil, _canvas(P, *box), fr, ST, key="standin lilium"))  # noqa: E501
        p.append(metamorphic(f"s01 lateral canvas {label}, lilium", lL1, _canvas(L1, *box), fr, T1L, key="L1 lilium", common=_syn))  # noqa: E501
    p.append(metamorphic("s01 frontal canvas padded 400 px on the right", pF1, _canvas(F1, 0, 0, 400, 0), Frame(shift_rot=True), T1F, key="F1 posest", common=_syn))  # noqa: E501
    p.append(metamorphic("s01 frontal canvas padded 400 px on the right, lilium", lF1, _canvas(F1, 0, 0, 400, 0), Frame(shift_rot=True), T1F, key="F1 lilium", common=_syn))  # noqa: E501
    # landmark files: order, names, formats
    p.append(metamorphic("standin photo.json landmarks permuted", pos, _permute_landmarks(P), IDENTITY, ST, key="standin posest"))  # noqa: E501
    p.append(metamorphic("standin photo.json landmarks permuted, lilium", lil, _permute_landmarks(P), IDENTITY, ST, key="standin lilium"))  # noqa: E501
    p.append(metamorphic("s01 lateral photo.json landmarks permuted, lilium", lL1, _permute_landmarks(L1), IDENTITY, T1L, key="L1 lilium", common=_syn))  # noqa: E501
    p.append(metamorphic("standin photo.json landmark names as aliases (n, gn, Pog, ex_l, Zygion R)", pos, _alias_names(P), IDENTITY, ST, key="standin posest"))  # noqa: E501
    ext = {"json": "json", "tsv-xy": "tsv"}
    plain = lambda fmt: Run("case", S, (_plain,), extra=("--photo-landmarks", lambda ws: _in(ws, "plain", f"front.{ext[fmt]}"), "--view", "frontal"), rel="front/posest-sfo/result.json")  # noqa: E501, E731
    plain_ref = Run("case", S, (_plain,), rel="front/posest-sfo/result.json", extra=("--view", "frontal"))  # noqa: E501
    for fmt in ("json", "tsv-xy"):
        p.append(metamorphic(f"standin case photo landmarks as {fmt} instead of a permuted CSV", plain_ref, _photo_file(P, fmt), IDENTITY, ST, key="standin case plain csv", common=_photo_file(P, "csv"), new_run=plain(fmt)))  # noqa: E501
    # the mesh alone has no axes file beside it: the folder's own given with --axes (without
    # them the case would rightly warn normal_axes), so that only the landmark file differs
    case_lm = lambda name: Run("case", lambda ws: ws.skull / "skull.ply", (P,), landmarks=lambda ws: _in(ws, name), rel="standin_frontal/posest-sfo/result.json", extra=("--axes", lambda ws: ws.skull / "soft_tissue_axes.json"))  # noqa: E501, E731
    case_ref = Run("case", S, (P,), rel="standin_frontal/posest-sfo/result.json")
    for fmt, name in (("csv", "lm.csv"), ("fcsv", "lm.fcsv"), ("fcsv-ras", "lm.fcsv"), ("mrk.json", "lm.mrk.json"), ("pp", "lm.pp")):  # noqa: E501
        p.append(metamorphic(f"standin case cranial landmarks as {fmt} (reversed order) with the mesh", case_ref, _cranial_file(S, fmt), IDENTITY, ST, key="standin case posest", new_run=case_lm(name)))  # noqa: E501
    # skulls: rigid motion, order, formats, units
    p.append(metamorphic("standin skull moved rigidly (35 deg, 630 mm) with landmarks, axes, prior", pos, _move_skull(S, [P]), Frame(motion=MOTION), ST, key="standin posest"))  # noqa: E501
    p.append(metamorphic("standin skull moved rigidly, lilium", lil, _move_skull(S, [P]), Frame(motion=MOTION), ST, key="standin lilium"))  # noqa: E501
    p.append(metamorphic("s01 skull moved rigidly (frontal photo)", pF1, _move_skull(S1, [F1]), Frame(motion=MOTION), T1F, key="F1 posest", common=_syn))  # noqa: E501
    p.append(metamorphic("s01 skull moved rigidly (frontal photo), lilium", lF1, _move_skull(S1, [F1]), Frame(motion=MOTION), T1F, key="F1 lilium", common=_syn))  # noqa: E501
    p.append(metamorphic("s01 skull moved rigidly (lateral photo), lilium", lL1, _move_skull(S1, [L1]), Frame(motion=MOTION), T1L, key="L1 lilium", common=_syn))  # noqa: E501
    p.append(metamorphic("s01 skull vertices and faces reordered, lilium", lF1, _reorder_mesh(S1), IDENTITY, T1F, key="F1 lilium", common=_syn))  # noqa: E501
    p.append(metamorphic("s01 skull vertices and faces reordered (lateral), lilium", lL1, _reorder_mesh(S1), IDENTITY, T1L, key="L1 lilium", common=_syn))  # noqa: E501
    for suffix, split in ((".stl", False), (".obj", False), (".ply", True)):
        what = f"as {suffix[1:].upper()}" + (" with every face's vertices split" if split else "")
        p.append(metamorphic(f"s01 skull written {what}, lilium", lF1, _mesh_as(S1, suffix, split), IDENTITY, T1F, key="F1 lilium", common=_syn))  # noqa: E501
        p.append(metamorphic(f"s01 skull written {what} (lateral), lilium", lL1, _mesh_as(S1, suffix, split), IDENTITY, T1L, key="L1 lilium", common=_syn))  # noqa: E501
    p.append(metamorphic("s01 skull written as STL (posest-sfo, identification)", pF1, _mesh_as(S1, ".stl"), IDENTITY, T1F, key="F1 posest", common=_syn))  # noqa: E501
    p.append(Probe("metamorphic s01 skull and landmarks in centimetres (no unit can be declared)", lambda ws: pF1.argv(ws), "error", ("skull.ply", "millimetres"), _then(_syn, _skull_units(S1, 0.1))))  # noqa: E501
    p.append(Probe("metamorphic s01 skull and landmarks in centimetres, no priors, lilium", lambda ws: lF1.argv(ws), "error", ("skull.ply", "millimetres"), _then(_syn, _skull_units(S1, 0.1), _edit_photo_json(F1, lambda d: d.pop("priors")))))  # noqa: E501
    def mrk_cm(ws):  # the only unit a supported format declares: 3D Slicer's coordinateUnits
        _cranial_file(S, "mrk.json")(ws)
        path = _in(ws, "lm.mrk.json")
        data = _json(path)
        for point in data["markups"][0]["controlPoints"]:
            point["position"] = [x / 10 for x in point["position"]]
        data["markups"][0]["coordinateUnits"] = "cm"
        _dump(path, data)

    p.append(Probe("metamorphic standin cranial landmarks in a .mrk.json declared in cm", lambda ws: case_lm("lm.mrk.json").argv(ws), "error", ("lm.mrk.json", "mm"), mrk_cm))  # noqa: E501
    # priors, masks, EXIF, tables, ground truth
    p.append(metamorphic("standin focal and distance priors on the command line instead of photo.json", case_ref, _priors_to_cli(P), IDENTITY, ST, key="standin case posest",  # noqa: E501
                         new_run=case_ref.with_(extra=("--focal-px", "2470", "2730", "--scd-mm", "810", "990.0000000000001"))))  # noqa: E501
    p.append(metamorphic("s01 lateral priors on the command line instead of photo.json, lilium", Run("case", S1, (L1,), "lilium", rel="s01_l00/lilium-skof+pll/result.json"), _priors_to_cli(L1), IDENTITY, T1L, key="L1 case lilium", common=_syn,  # noqa: E501
                         new_run=Run("case", S1, (L1,), "lilium", rel="s01_l00/lilium-skof+pll/result.json", extra=(lambda ws: "--focal-px", *[lambda ws, i=i: repr(_json(_dataset(ws) / "photos/A/s01_l00/photo.json")["priors"]["focal_px"][i]) for i in (0, 1)], "--scd-mm", *[lambda ws, i=i: repr(_json(_dataset(ws) / "photos/A/s01_l00/photo.json")["priors"]["scd_mm"][i]) for i in (0, 1)]))))  # noqa: E501
    for mode in ("1", "L", "L1", "RGBA", "P", "I;16"):
        p.append(metamorphic(f"standin face mask saved as PNG mode {mode}", pos, _mask_mode(P, mode), IDENTITY, ST, key="standin posest"))  # noqa: E501
    p.append(metamorphic("standin face mask saved as PNG mode 1, lilium", lil, _mask_mode(P, "1"), IDENTITY, ST, key="standin lilium"))  # noqa: E501
    p.append(metamorphic("standin JPEG with a matching EXIF focal (78 mm) vs stripped, priors in photo.json", pos, _to_jpeg(P, 78), IDENTITY, ST, key="standin posest jpeg", ref_only=_to_jpeg(P)))  # noqa: E501
    p.append(metamorphic("standin JPEG with a matching EXIF focal (78 mm) vs stripped, priors in photo.json, lilium", lil, _to_jpeg(P, 78), IDENTITY, ST, key="standin lilium jpeg", ref_only=_to_jpeg(P)))  # noqa: E501
    cL1 = Run("case", S1, (L1,), rel="s01_l00/posest-sfo/result.json", extra=("--focal-px", "3500", "3900"))  # noqa: E501
    p.append(metamorphic("s01 lateral JPEG with a matching EXIF focal (65 mm) vs stripped, case --focal-px given", cL1, _to_jpeg(L1, 65), IDENTITY, T1L, key="L1 case posest jpeg focal", common=_syn, ref_only=_to_jpeg(L1)))  # noqa: E501
    p.append(metamorphic("s01 lateral JPEG with a matching EXIF focal (65 mm) vs stripped, case --focal-px given, lilium", cL1.with_(method="lilium", rel="s01_l00/lilium-skof+pll/result.json"), _to_jpeg(L1, 65), IDENTITY, T1L, key="L1 case lilium jpeg focal", common=_syn, ref_only=_to_jpeg(L1)))  # noqa: E501
    p.append(metamorphic("standin --depth-table = the built-in table", pos, _depth_csv(), IDENTITY, ST, key="standin posest", new_run=pos.with_(extra=("--depth-table", lambda ws: _in(ws, "d.csv")))))  # noqa: E501
    p.append(metamorphic("standin --depth-table = the built-in table, rows named by facial landmark", pos, _depth_csv(True), IDENTITY, ST, key="standin posest", new_run=pos.with_(extra=("--depth-table", lambda ws: _in(ws, "d.csv")))))  # noqa: E501
    p.append(metamorphic("s01 --depth-table = the built-in table, lilium", lL1, _depth_csv(), IDENTITY, T1L, key="L1 lilium", common=_syn, new_run=lL1.with_(extra=("--depth-table", lambda ws: _in(ws, "d.csv")))))  # noqa: E501
    p.append(metamorphic("s01 --axes = its own axes x10 (not unit length), lilium", lL1, _axes_copy(S1, 10.0), IDENTITY, T1L, key="L1 lilium", common=_syn, new_run=lL1.with_(extra=("--axes", lambda ws: _in(ws, "axes.json")))))  # noqa: E501
    p.append(metamorphic("standin ground-truth files removed", pos, _strip_truth(S, P), IDENTITY, ST, key="standin posest"))  # noqa: E501
    p.append(metamorphic("s01 ground-truth files removed, lilium", lL1, _strip_truth(S1, L1), IDENTITY, T1L, key="L1 lilium", common=_syn))  # noqa: E501
    # commands: sfo vs case, photo order, lineup order
    p.append(metamorphic("standin lilium case = sfo (same inputs and seed)", lil, None, IDENTITY, ST, key="standin lilium", new_run=Run("case", S, (P,), "lilium", rel="standin_frontal/lilium-skof+pll/result.json")))  # noqa: E501
    p.append(Probe("metamorphic case photos in the other order (s01 frontal, lateral)", lambda ws: Run("case", S1, (F1, L1)).argv(ws), "ok", (), _syn, check=_case_order((F1, L1))))  # noqa: E501
    # A photo and its own half-size copy are one photo: counted as two views they lifted the
    # single-photo cap ("strong support" from two copies of a "moderate" photo).
    p.append(Probe("metamorphic case with a photo and its own half-size copy", lambda ws: Run("case", S, (P, _half)).argv(ws), "error", ("half/photo.json", "one photo"), _half_photo))  # noqa: E501
    p.append(Probe("metamorphic case photos in the other order, lilium", lambda ws: Run("case", S1, (F1, L1), "lilium").argv(ws), "ok", (), _syn, check=_case_order((F1, L1), "lilium")))  # noqa: E501
    for pid, truth in (("s01_f00", T1F), ("s01_l00", T1L)):
        joint = Run("sfo", S1, (F1, L1), "lilium", pick=_joint_photo(pid))
        p.append(metamorphic(f"joint sfo photos in the other order ({pid}'s camera), lilium", joint, None, IDENTITY, truth, key=f"joint {pid}", common=_syn, new_run=joint.with_(photos=(L1, F1))))  # noqa: E501
    order = [("A", F1), ("B", F2, L2), ("C", L1)]
    p.append(Probe("metamorphic lineup candidates in the other order", _lineup_run(order), "ok", (), _syn, check=_lineup_same(_lineup_run(order[::-1]))))  # noqa: E501
    p.append(Probe("metamorphic lineup a candidate's photos in the other order", _lineup_run(order), "ok", (), _syn, check=_lineup_same(_lineup_run([("A", F1), ("B", L2, F2), ("C", L1)]))))  # noqa: E501
    p.append(Probe("metamorphic lineup candidates in the other order, lilium", _lineup_run(order, "lilium"), "ok", (), _syn, check=_lineup_same(_lineup_run(order[::-1], "lilium"), lr_tol=0.3)))  # noqa: E501
    return p


# fmt: on


# -- running alone -----------------------------------------------------------------------------


def spread(work, base):
    """Print the seed spread of the references (Lilium, seeds 1-3, the unchanged cases): how the
    tolerances of the metamorphic checks were set (``work`` a scratch folder, ``base`` the
    stand-in case)."""
    ws = Workspace(work / "spread", base)
    _syn(ws)
    S, P = _standin_skull, _standin_photo
    cases = {
        "standin": (Run("sfo", S, (P,), "lilium"), _standin_truth),
        "s01 frontal": (
            Run("sfo", _ss("s01"), (_sp("s01_f00"),), "lilium"),
            _syn_truth("s01", "s01_f00"),
        ),  # noqa: E501
        "s01 lateral": (
            Run("sfo", _ss("s01"), (_sp("s01_l00"),), "lilium"),
            _syn_truth("s01", "s01_l00"),
        ),  # noqa: E501
    }
    for name, (run, truth) in cases.items():
        ms = [metrics(r, IDENTITY, truth(ws)) for r in _results_of(run, ws)]
        sc = _scalars(ms)
        print(
            f"{name}: seeds {SEEDS[0]}-{SEEDS[-1]} at {' '.join(LIL)}, SD per seed: rotation "
            f"{_rot_spread(ms):.2f} deg, focal {_sd(sc['focal']):.3f} (log), landmark error "
            f"{_sd(sc['err_px']):.2f} px, BPE {_sd(sc.get('bpe_mm', [0])):.2f} mm, log10 LR "
            f"{_sd(sc['lr']):.3f}; conclusions {[m['conclusion'] for m in ms]}; tolerance of a "
            f"mean of {len(ms)} against another: {tolerances(ms, ms, LIL_FLOOR)}"
        )
        for s in ws.root.glob("seed*"):
            shutil.rmtree(s)
