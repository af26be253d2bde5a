"""Geometric degeneracy probes of ``lilium sfo``, ``lilium case`` and ``lilium lineup``: valid-
looking files whose geometry is degenerate or damaged, as real scans and real hand annotations
are. Every file passes its own format checks; what is wrong is its shape: a stray fragment or a
second copy of the skull in the mesh, inward or mixed face winding, zero-area and duplicate
faces, a holey mesh (a CT cut), a mesh of a few faces, a skull a kilometre from the origin, a
mesh of the mandible alone; landmark sets on one plane (the midline), two landmarks at one place
(on the photo or on the skull), 4 or 5 landmarks only, a cranial landmark off the bone; a face
mask of one pixel, one line, the full frame but a pixel, or of several components.

The standard: "A missing piece switches off what needs it and says so; an inconsistency is
caught and named, never answered with a confident wrong camera." Each probe therefore expects an
error naming the file, or a result that is right (the camera of the clean input or the known
truth, the same conclusion) unless a warning names the damage; a result that differs from the
clean one without a word is ``silently wrong``.

Inputs: the stand-in case of the campaign (an ellipsoidal skull without porion or
mandible landmarks; its photo's head-rotation prior is dropped where a probe tests what the
landmarks alone determine) and the generated dataset of ``hostile_fixtures.py`` (``_syn``,
with mandible landmarks and face curves, for P_pll and the lineup). Budgets: POSEST-SFO, or
Lilium at 5 x 2 with a fixed seed (a probe compares it with the clean input's SFO at the same
seed and budget, so the DE need not converge).

Here: the command lines, the checks (against the clean input's SFO at the same seed, or the
known truth of a generated photo) and the probes; the set-ups that damage the meshes, the
landmark sets and the masks are in ``hostile_geometry_damage.py``. ::

    python -m pytest -m slow tests/acceptance/test_hostile_geometry.py [-k TEXT]
"""

import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from hostile_casework import TINY, _quiet_main  # noqa: E402
from hostile_fixtures import (  # noqa: E402
    _codes,
    _edit_json,
    _in,
    _json,
    _result,
    _rot_err_deg,
    _syn,
)
from hostile_geometry_damage import (  # noqa: E402
    MIDLINE_FACE,
    MIDLINE_SKULL,
    _all_but_corner,
    _blob_below_chin,
    _blob_in_corner,
    _coarse_skull,
    _compact,
    _copy_beside,
    _copy_cranial_lm,
    _copy_photo_lm,
    _cut_below,
    _degenerate_faces,
    _flip_faces,
    _fragment,
    _holes,
    _keep_cranial,
    _keep_photo,
    _mask,
    _mesh_op,
    _no_curve,
    _no_priors,
    _no_rotation_prior,
    _offset_subject,
    _one_pixel,
    _one_row,
    _only_below,
    _push_cranial,
    _stray_triangle,
    _unreferenced_vertex,
)
from hostile_machinery import Probe, _then  # noqa: E402

SEED = ("--seed", "1")
#: Warnings of the clean inputs (see hostile_semantic.CLEAN_CODES).
CLEAN_CODES = {"outside_prior", "no_focal_prior", "no_scd_prior", "focal_cap"}

# -- where things are -------------------------------------------------------------------------


def _S(ws):
    return ws.skull


def _P(ws):
    return ws.photo


def _S0(ws):
    return ws.base / "subjects" / "standin"


def _P0(ws):
    return ws.base / "photos" / "standin_frontal"


def _syn_subject(name, clean=False):
    if clean:
        return lambda ws: ws.root.parent / "semantic-dataset" / "subjects" / name
    return lambda ws: _in(ws, "syn", "subjects", name)


def _syn_photo(name, clean=False):
    if clean:
        return lambda ws: ws.root.parent / "semantic-dataset" / "photos" / "A" / name
    return lambda ws: _in(ws, "syn", "photos", "A", name)


S1, S1c = _syn_subject("s01"), _syn_subject("s01", True)
F1, F1c = _syn_photo("s01_f00"), _syn_photo("s01_f00", True)
F2, F2c = _syn_photo("s02_f00"), _syn_photo("s02_f00", True)

# -- command lines ----------------------------------------------------------------------------


def _command(name):
    """``lilium sfo`` or ``lilium case`` of one skull and one photo (paths of the workspace)."""

    def command(skull, photo, *extra, method="posest-sfo", out=None):
        def argv(ws):
            o = out(ws) if out else ws.out
            rest = [e(ws) if callable(e) else e for e in extra]
            return [name, "--skull", skull(ws), "--photo", photo(ws), "--out", o,
                    "--method", method, *rest]  # fmt: skip

        return argv

    return command


_sfo, _case = _command("sfo"), _command("case")


def _lineup(skull, candidates, *extra, method="posest-sfo", out=None):
    def argv(ws):
        o = out(ws) if out else ws.out
        cmd = ["lineup", "--no-progress", "--skull", skull(ws), "--out", o, "--method", method]
        for name, photo in candidates:
            cmd += ["--candidate", name, photo(ws)]
        return cmd + list(extra)

    return argv


# -- checks -----------------------------------------------------------------------------------


def _summary(r):
    cam = r.get("camera") or {}
    idn = r.get("identification") or {}
    return (
        f"focal {cam.get('focal_px', float('nan')):.0f} px, landmark error "
        f"{(r.get('landmark_error') or {}).get('mean_px', float('nan')):.2f} px, "
        f"score {r.get('fitness', float('nan')):.4g}, warnings {_codes(r)}, conclusion "
        f"{idn.get('conclusion')!r} (log10 LR {idn.get('log10_lr')})"
    )


def _messages(r):
    out = [w.get("message", "") for w in r.get("warnings", []) or []]
    for photo in r.get("photos", []) or []:
        out += [w.get("message", "") for w in photo.get("warnings", []) or []]
    return out


def _flagged(r, clean, words, strict=False):
    """A warning of ``r`` not in ``clean``'s codes (or naming one of ``words``); ``strict``:
    only a warning naming one of ``words`` (a warning that blames something else, e.g. the
    declared view for a damaged mesh, is no flag)."""
    codes = [] if strict else _codes(r)
    new = [c for c in codes if c not in CLEAN_CODES and c not in _codes(clean)]
    named = [m for m in _messages(r) if any(w in m for w in words)]
    return new or named


def _like_clean(clean_argv, max_rot_deg=2.0, max_focal=0.03, max_err_px=1.0, words=(),
                same_conclusion=True, overlay=True, strict=False):  # fmt: skip
    """Check: the result agrees with the clean input's (``clean_argv(ws)``, run here into
    ``ws.root/clean``): head rotation within ``max_rot_deg``, focal within ``max_focal``,
    landmark error within ``max_err_px`` of the clean one, the same conclusion; else a warning
    beyond the clean ones (or naming one of ``words``) must say something is wrong. And an
    ``overlay.png`` beside ``result.json`` when ``overlay``."""

    def check(ws):
        r = _result(ws)
        if r is None:
            return "no result.json"
        if overlay:
            found = sorted(ws.out.rglob("result.json"))
            if found and not (found[0].parent / "overlay.png").is_file():
                return f"no overlay.png beside {found[0].relative_to(ws.out)}"
        if _quiet_main(clean_argv(ws)) != 0:
            return "the clean SFO failed"
        c = _result(type("W", (), {"out": ws.root / "clean"})())
        if not r.get("camera") or not c.get("camera"):
            return None if not r.get("camera") else "the clean SFO has no camera"
        rot = _rot_err_deg(r["camera"]["skull2cam"], c["camera"]["skull2cam"])
        focal = r["camera"]["focal_px"] / c["camera"]["focal_px"]
        er = (r.get("landmark_error") or {}).get("mean_px", float("nan"))
        ec = (c.get("landmark_error") or {}).get("mean_px", float("nan"))
        cr = (r.get("identification") or {}).get("conclusion")
        cc = (c.get("identification") or {}).get("conclusion")
        diffs = []
        if rot > max_rot_deg:
            diffs.append(f"head rotation {rot:.1f} deg from the clean SFO's")
        if abs(focal - 1) > max_focal:
            diffs.append(f"focal x{focal:.3f} of the clean one")
        if not er <= ec + max_err_px:
            diffs.append(f"landmark error {er:.2f} px (clean {ec:.2f})")
        if same_conclusion and cr != cc:
            diffs.append(f"conclusion {cr!r} (clean {cc!r})")
        if diffs and not _flagged(r, c, words, strict):
            return "; ".join(diffs) + f" -- result: {_summary(r)}; clean: {_summary(c)}"
        return None

    return check


def _same_run(clean_argv, rel_tol=1e-6, words=(), strict=False):
    """Check: the fitness and terms equal the clean input's at the same seed (a change that must
    not matter, e.g. face winding), else a warning naming it."""

    def check(ws):
        r = _result(ws)
        if r is None:
            return "no result.json"
        if _quiet_main(clean_argv(ws)) != 0:
            return "the clean SFO failed"
        c = _result(type("W", (), {"out": ws.root / "clean"})())
        fr, fc = r.get("fitness"), c.get("fitness")
        terms_r, terms_c = r.get("terms") or {}, c.get("terms") or {}
        bad = []
        if not (isinstance(fr, float) and isinstance(fc, float)) or abs(fr - fc) > rel_tol * max(
            1.0, abs(fc)
        ):
            bad.append(f"fitness {fr} (clean {fc})")
        for k in sorted(set(terms_r) | set(terms_c)):
            a, b = terms_r.get(k), terms_c.get(k)
            if isinstance(a, (int, float)) and isinstance(b, (int, float)):
                if abs(a - b) > 1e-6 * max(1.0, abs(b)) + 1e-9:
                    bad.append(f"{k} {a:.6g} (clean {b:.6g})")
            elif a != b:
                bad.append(f"{k} {a!r} (clean {b!r})")
        cr = (r.get("identification") or {}).get("conclusion")
        cc = (c.get("identification") or {}).get("conclusion")
        if cr != cc:
            bad.append(f"conclusion {cr!r} (clean {cc!r})")
        if bad and not _flagged(r, c, words, strict):
            return "; ".join(bad) + f" -- result: {_summary(r)}; clean: {_summary(c)}"
        return None

    return check


def _right_camera(truth, max_rot_deg=5.0, max_err_px=None, words=(), need_cap=None):
    """Check: the camera within ``max_rot_deg`` of ``truth(ws)/photo.json``'s ground truth (and
    a mean landmark error at most ``max_err_px``), else a warning beyond the clean ones (or
    naming one of ``words``); ``need_cap``: a text the identification's caps must hold."""

    def check(ws):
        r = _result(ws)
        if r is None:
            return "no result.json"
        idn = r.get("identification") or {}
        if need_cap and not any(need_cap in str(v) for v in (idn.get("caps") or {}).values()):
            if idn.get("conclusion") not in (None, "undetermined"):
                return f"no cap naming {need_cap!r}: caps {idn.get('caps')}, {_summary(r)}"
        if not r.get("camera"):
            return None
        gt = _json(truth(ws) / "photo.json")["ground_truth"]
        rot = _rot_err_deg(r["camera"]["skull2cam"], gt["skull2cam"])
        err = (r.get("landmark_error") or {}).get("mean_px", float("nan"))
        focal = r["camera"]["focal_px"] / gt["focal_px"]
        wrong = rot > max_rot_deg or (max_err_px is not None and not err <= max_err_px)
        flagged = [c for c in _codes(r) if c not in CLEAN_CODES]
        flagged += [m for m in _messages(r) if any(w in m for w in words)]
        if wrong and not flagged:
            return f"camera {rot:.1f} deg from the truth, focal x{focal:.2f}; {_summary(r)}"
        return None

    return check


def _lineup_like_clean(clean_argv, words=()):
    """Check: a lineup's ranking and conclusions equal the clean skull's, else a warning."""

    def read(folder):
        data = _json(folder / "lineup.json")
        rows = data.get("candidates") or data.get("ranking") or []
        return data, [
            (c.get("candidate"), (c.get("identification") or {}).get("conclusion")) for c in rows
        ]

    def check(ws):
        if not (ws.out / "lineup.json").is_file():
            return "no lineup.json"
        if _quiet_main(clean_argv(ws)) != 0:
            return "the clean lineup failed"
        (dr, rr), (_, rc) = read(ws.out), read(ws.root / "clean")
        if rr != rc:
            text = json.dumps(dr)
            if not any(w in text for w in words):
                return f"ranking/conclusions {rr} (clean {rc}), no warning naming the mesh"
        return None

    return check


# -- the probes -------------------------------------------------------------------------------
# fmt: off


def geometry_probes():
    """Degenerate or damaged geometry (module docstring)."""
    p = []
    lil = dict(method="lilium")
    clean_out = lambda ws: ws.root / "clean"  # noqa: E731
    sfo = lambda *e, **k: _sfo(_S, _P, *e, **k)  # noqa: E731
    sfo0 = lambda *e, **k: _sfo(_S0, _P0, *e, out=clean_out, **k)  # noqa: E731
    mesh = lambda op: _mesh_op(_S, op)  # noqa: E731
    MESHW = ("skull.ply", "fragment", "component", "disconnected")  # a warning naming the damage
    # -- skull meshes: stray parts ---------------------------------------------------------
    p += [
        Probe("geometry sfo stray triangle 1 m beside the skull", sfo(), "ok", (), mesh(_stray_triangle([-1000, 0, 0])), check=_like_clean(sfo0(), words=MESHW, strict=True)),  # noqa: E501
        Probe("geometry sfo stray triangle 400 mm beside the skull", sfo(), "ok", (), mesh(_stray_triangle([-400, 0, 0])), check=_like_clean(sfo0(), words=MESHW, strict=True)),  # noqa: E501
        Probe("geometry sfo fragment (642 vertices) 400 mm beside the skull", sfo(), "ok", (), mesh(_fragment([-400, 0, 0])), check=_like_clean(sfo0(), words=MESHW, strict=True)),  # noqa: E501
        Probe("geometry sfo fragment (642 vertices) 300 mm behind the skull", sfo(), "ok", (), mesh(_fragment([0, 0, -300])), check=_like_clean(sfo0(), words=MESHW, strict=True)),  # noqa: E501
        Probe("geometry sfo lilium fragment 150 mm beside the skull (inside the photo)", sfo(*TINY, *SEED, **lil), "ok", (), mesh(_fragment([-150, 0, 0])), check=_like_clean(sfo0(*TINY, *SEED, **lil), max_rot_deg=3, max_focal=0.05, words=MESHW, strict=True)),  # noqa: E501
        Probe("geometry sfo second copy of the skull 200 mm beside it", sfo(), "ok", (), mesh(_copy_beside([-200, 0, 0])), check=_like_clean(sfo0(), words=MESHW, strict=True)),  # noqa: E501
        Probe("geometry sfo lilium second copy of the skull 200 mm beside it", sfo(*TINY, *SEED, **lil), "ok", (), mesh(_copy_beside([-200, 0, 0])), check=_like_clean(sfo0(*TINY, *SEED, **lil), max_rot_deg=3, max_focal=0.05, words=MESHW, strict=True)),  # noqa: E501
        Probe("geometry sfo second copy of the skull overlapping (5 mm aside)", sfo(), "ok", (), mesh(_copy_beside([5, 0, 0])), check=_like_clean(sfo0(), words=MESHW, strict=True)),  # noqa: E501
    ]
    # -- skull meshes: winding, degenerate faces, holes, few faces, offset ------------------
    p += [
        Probe("geometry sfo lilium every face flipped (normals inward)", sfo(*TINY, *SEED, **lil), "ok", (), mesh(_flip_faces(1.0)), check=_same_run(sfo0(*TINY, *SEED, **lil), words=("skull.ply", "normal", "winding"))),  # noqa: E501
        Probe("geometry sfo lilium half the faces flipped", sfo(*TINY, *SEED, **lil), "ok", (), mesh(_flip_faces(0.5)), check=_same_run(sfo0(*TINY, *SEED, **lil), words=("skull.ply", "normal", "winding"))),  # noqa: E501
        Probe("geometry sfo every face flipped (posest, facing/view tests)", sfo(), "ok", (), mesh(_flip_faces(1.0)), check=_like_clean(sfo0(), max_rot_deg=0.01, max_focal=1e-4, max_err_px=0.01)),  # noqa: E501
        Probe("geometry sfo lilium duplicate and zero-area faces", sfo(*TINY, *SEED, **lil), "ok", (), mesh(_degenerate_faces), check=_same_run(sfo0(*TINY, *SEED, **lil))),  # noqa: E501
        Probe("geometry sfo lilium 40 % of the faces missing (holey, non-manifold)", sfo(*TINY, *SEED, **lil), "ok", (), mesh(_holes(0.4)), check=_like_clean(sfo0(*TINY, *SEED, **lil), max_rot_deg=3, max_focal=0.05)),  # noqa: E501
        Probe("geometry sfo mesh cut below the orbits (no jaw, landmarks kept)", sfo(), "error", ("cranial_landmarks.json",), mesh(_compact(_cut_below(-5)))),  # noqa: E501
        Probe("geometry sfo mesh of the jaw alone", sfo(), "error", ("cranial_landmarks.json",), mesh(_compact(_only_below(-40)))),  # noqa: E501
        Probe("geometry sfo mesh cut below the orbits, cut vertices kept unreferenced", sfo(), "error", ("cranial_landmarks.json",), mesh(_cut_below(-5))),  # noqa: E501
        Probe("geometry sfo mesh of the jaw alone, the cranium's vertices kept unreferenced", sfo(), "error", ("cranial_landmarks.json",), mesh(_only_below(-40))),  # noqa: E501
        Probe("geometry sfo unreferenced vertex 3 m away, cranial landmarks in centimetres", sfo(), "error", ("cranial_landmarks.json",), _then(mesh(_unreferenced_vertex([3000, 0, 0])), _edit_json(_S, "cranial_landmarks.json", lambda d: d.update(landmarks={k: [x / 10 for x in q] for k, q in d["landmarks"].items()})))),  # noqa: E501
        Probe("geometry sfo unreferenced vertex 3 m away, nasion 60 mm off the bone", sfo(), "error", ("cranial_landmarks.json", "nasion"), _then(mesh(_unreferenced_vertex([3000, 0, 0])), _push_cranial(_S, "nasion", 60))),  # noqa: E501
        Probe("geometry sfo unreferenced vertex 1 m away (clean otherwise)", sfo(), "ok", (), mesh(_unreferenced_vertex([-1000, 0, 0])), check=_like_clean(sfo0())),  # noqa: E501
        Probe("geometry sfo skull of 80 faces", sfo(), "ok", (), mesh(_coarse_skull(1)), check=_like_clean(sfo0(), max_rot_deg=1)),  # noqa: E501
        Probe("geometry sfo lilium skull of 20 faces (landmarks 16 mm off its facets)", sfo(*TINY, *SEED, **lil), "error", ("cranial_landmarks.json", "from the skull mesh"), mesh(_coarse_skull(0))),  # noqa: E501
        Probe("geometry sfo whole subject 1 km from the origin (x + 1e6 mm)", sfo(), "ok", (), _offset_subject(_S, [1e6, 0, 0]), check=_like_clean(sfo0(), max_rot_deg=0.5, max_focal=0.01, max_err_px=0.1)),  # noqa: E501
        Probe("geometry sfo lilium whole subject 1 km from the origin (x + 1e6 mm)", sfo(*TINY, *SEED, **lil), "ok", (), _offset_subject(_S, [1e6, 0, 0]), check=_like_clean(sfo0(*TINY, *SEED, **lil), max_rot_deg=1, max_focal=0.02, max_err_px=0.5)),  # noqa: E501
        Probe("geometry sfo whole subject 100 km from the origin (x + 1e8 mm)", sfo(), "ok", (), _offset_subject(_S, [1e8, 0, 0]), check=_like_clean(sfo0(), max_rot_deg=0.5, max_focal=0.01, max_err_px=0.5)),  # noqa: E501
    ]
    # -- landmark sets ------------------------------------------------------------------------
    norot = _no_rotation_prior(_P)
    nopri = _no_priors(_P)
    p += [
        Probe("geometry sfo photo midline landmarks only (8, coplanar in 3D), no rotation prior", sfo(), "warn", ("landmark pairs", "photo.json", "cranial_landmarks.json", "off the midline"), _then(norot, _keep_photo(_P, MIDLINE_FACE)), code=1),  # noqa: E501
        Probe("geometry sfo skull midline landmarks only (8, coplanar), no priors", sfo(), "warn", ("landmark pairs", "photo.json", "cranial_landmarks.json", "off the midline"), _then(nopri, _keep_cranial(_S, MIDLINE_SKULL)), code=1),  # noqa: E501
        Probe("geometry sfo lilium photo midline landmarks only, no priors", sfo(*TINY, *SEED, **lil), "ok", (), _then(nopri, _keep_photo(_P, MIDLINE_FACE)), check=_right_camera(_P0)),  # noqa: E501
        Probe("geometry sfo midline plus one eye corner (nearly coplanar), no priors", sfo(), "ok", (), _then(nopri, _keep_photo(_P, MIDLINE_FACE + ("exocanthion_l",))), check=_right_camera(_P0)),  # noqa: E501
        Probe("geometry sfo 4 landmarks only, no priors (POSEST: no real camera; a failure naming the files)", sfo(), "warn", ("landmark pairs", "photo.json", "cranial_landmarks.json", "off the midline"), _then(nopri, _keep_photo(_P, ("nasion", "gnathion", "exocanthion_l", "exocanthion_r"))), code=1),  # noqa: E501
        Probe("geometry sfo 5 landmarks only, no rotation prior", sfo(), "ok", (), _then(norot, _keep_photo(_P, ("nasion", "gnathion", "exocanthion_l", "exocanthion_r", "subnasale"))), check=_right_camera(_P0, need_cap="8")),  # noqa: E501
        Probe("geometry sfo 4 landmarks only, priors kept (POSEST: no real camera; a failure naming the files)", sfo(), "warn", ("landmark pairs", "photo.json", "cranial_landmarks.json", "off the midline"), _keep_photo(_P, ("nasion", "gnathion", "zygion_l", "gonion_r")), code=1),  # noqa: E501
        Probe("geometry sfo lilium 4 landmarks only, priors kept", sfo(*TINY, *SEED, **lil), "ok", (), _keep_photo(_P, ("nasion", "gnathion", "zygion_l", "gonion_r")), check=_right_camera(_P0, need_cap="8")),  # noqa: E501
        Probe("geometry sfo 3 landmarks only", sfo(), "error", ("standin_frontal", "at least 4"), _keep_photo(_P, ("nasion", "exocanthion_l", "exocanthion_r"))),  # noqa: E501
        Probe("geometry sfo exocanthion_r at exocanthion_l's pixel (copy-paste)", sfo(), "error", ("photo.json", "exocanthion_l and exocanthion_r lie at one place"), _then(norot, _copy_photo_lm(_P, "exocanthion_l", "exocanthion_r"))),  # noqa: E501
        Probe("geometry sfo zygion_r at zygion_l's pixel + 0.001 px", sfo(), "error", ("photo.json", "zygion_l and zygion_r lie at one place"), _then(norot, _copy_photo_lm(_P, "zygion_l", "zygion_r", (0.001, 0.0)))),  # noqa: E501
        Probe("geometry sfo lilium zygion_r at zygion_l's pixel, no priors", sfo(*TINY, *SEED, **lil), "error", ("photo.json", "zygion_l and zygion_r lie at one place"), _then(nopri, _copy_photo_lm(_P, "zygion_l", "zygion_r"))),  # noqa: E501
        Probe("geometry sfo cranial zygion_r at zygion_l's point", sfo(), "error", ("cranial_landmarks.json", "zygion_l and zygion_r lie at one place"), _then(norot, _copy_cranial_lm(_S, "zygion_l", "zygion_r"))),  # noqa: E501
        Probe("geometry sfo cranial gnathion at pogonion's point", sfo(), "ok", (), _copy_cranial_lm(_S, "pogonion", "gnathion"), check=_right_camera(_P0, max_err_px=5, words=("gnathion",))),  # noqa: E501
        Probe("geometry sfo cranial nasion 30 mm off the bone", sfo(), "error", ("cranial_landmarks.json", "nasion"), _push_cranial(_S, "nasion", 30)),  # noqa: E501
        Probe("geometry sfo cranial nasion 30 mm inside the skull", sfo(), "error", ("cranial_landmarks.json", "nasion"), _push_cranial(_S, "nasion", -30)),  # noqa: E501
        Probe("geometry sfo cranial nasion 15 mm off the bone, no priors", sfo(), "ok", (), _then(nopri, _push_cranial(_S, "nasion", 15)), check=_right_camera(_P0, max_err_px=5, words=("nasion",))),  # noqa: E501
        Probe("geometry case cranial pogonion 15 mm off the bone", _case(_S, _P), "ok", (), _push_cranial(_S, "pogonion", 15), check=_right_camera(_P0, max_err_px=5, words=("pogonion",))),  # noqa: E501
        Probe("geometry sfo cranial landmarks all 12 mm outward (a skin surface picked)", sfo(), "ok", (), _edit_json(_S, "cranial_landmarks.json", lambda d: d.update(landmarks={k: list(np.asarray(q) * (1 + 12 / np.linalg.norm(q))) for k, q in d["landmarks"].items()})), check=_right_camera(_P0, words=("cranial_landmarks.json",))),  # noqa: E501
    ]
    # -- face masks ---------------------------------------------------------------------------
    p += [
        Probe("geometry sfo lilium mask a single pixel", sfo(*TINY, *SEED, **lil), "error", ("face_mask.png",), _mask(_P, _one_pixel)),  # noqa: E501
        Probe("geometry sfo lilium mask one row across the photo", sfo(*TINY, *SEED, **lil), "error", ("face_mask.png",), _mask(_P, _one_row)),  # noqa: E501
        Probe("geometry sfo lilium mask the full frame but one pixel", sfo(*TINY, *SEED, **lil), "error", ("face_mask.png", "no background"), _mask(_P, _all_but_corner)),  # noqa: E501
        Probe("geometry sfo lilium mask with a second blob in a corner", sfo(*TINY, *SEED, **lil), "ok", (), _mask(_P, _blob_in_corner), check=_same_run(sfo0(*TINY, *SEED, **lil), words=("face_mask.png", "component"))),  # noqa: E501
    ]
    # generated subject: P_pll's curve from the mask
    syn = lambda *s: _then(_syn, *s)  # noqa: E731
    sfo_syn = _sfo(S1, F1, *TINY, *SEED, method="lilium")
    sfo_syn0 = _sfo(S1c, F1c, *TINY, *SEED, method="lilium", out=clean_out)
    p += [
        Probe("geometry sfo lilium mask with a blob under the chin, curve from the mask", sfo_syn, "ok", (), syn(_no_curve(F1), _mask(F1, _blob_below_chin)), check=_same_run(_sfo(S1c, F1, *TINY, *SEED, method="lilium", out=clean_out), words=("face_mask.png", "component", "curve"))),  # noqa: E501
        Probe("geometry sfo lilium generated skull every face flipped", sfo_syn, "ok", (), syn(_mesh_op(S1, _flip_faces(1.0))), check=_same_run(sfo_syn0, words=("skull.ply", "normal", "winding"))),  # noqa: E501
        Probe("geometry sfo lilium generated skull with a fragment 120 mm below the chin", sfo_syn, "ok", (), syn(_mesh_op(S1, _fragment([0, -200, 60], 12))), check=_like_clean(sfo_syn0, max_rot_deg=3, max_focal=0.05, words=MESHW, strict=True)),  # noqa: E501
    ]
    # -- lineup and case ----------------------------------------------------------------------
    lineup = _lineup(S1, [("A", F1), ("B", F2)])
    lineup0 = _lineup(S1c, [("A", F1c), ("B", F2c)], out=clean_out)
    p += [
        Probe("geometry lineup skull with a second copy 200 mm beside it", lineup, "ok", (), syn(_mesh_op(S1, _copy_beside([-200, 0, 0]))), check=_lineup_like_clean(lineup0, words=MESHW)),  # noqa: E501
        Probe("geometry lineup skull fragment 400 mm aside", lineup, "ok", (), syn(_mesh_op(S1, _fragment([-400, 0, 0])), ), check=_lineup_like_clean(lineup0, words=MESHW)),  # noqa: E501
        Probe("geometry case skull with a second copy 200 mm beside it", _case(_S, _P), "ok", (), mesh(_copy_beside([-200, 0, 0])), check=_like_clean(_case(_S0, _P0, out=clean_out), words=MESHW, strict=True)),  # noqa: E501
        Probe("geometry case whole subject at x + 1e6 mm", _case(_S, _P), "ok", (), _offset_subject(_S, [1e6, 0, 0]), check=_like_clean(_case(_S0, _P0, out=clean_out), max_rot_deg=0.5, max_focal=0.01, max_err_px=0.1)),  # noqa: E501
    ]
    return p


# fmt: on
