"""Semantic probes, tested (docs/checks.md): valid files that do not
belong together. Every file passes its own checks (names, sizes, ranges); what is wrong is
their relation: a landmark file of another photo, the mask of another photo or an inverted
one, a lateral photo declared frontal (or the other side), the cranial landmarks of another
skull or in centimetres, a mirrored skull, some bilateral labels swapped, an upside-down photo,
priors that exclude the truth by a factor 2 or 10, an image rescaled without its landmarks, an
implausible soft-tissue depth, an EXIF focal that contradicts ``photo.json``.

The standard: "A missing piece switches off what needs it and says so; an inconsistency is
caught and named, never answered with a confident wrong camera." Each probe therefore expects
an error naming the file, a warning naming the inconsistency (``warn`` with its needles), or a
result that is right; a result is compared with the known camera of the stand-in or of a
generated photo (``ground_truth`` in ``photo.json``) or with the SFO of the clean input, and a
wrong camera without a warning is ``silently wrong``.

Inputs: the stand-in case of the campaign and the generated dataset of
``hostile_fixtures.py`` (``_syn``: two subjects with one frontal and one lateral photo
each, experiment A, made once per campaign, about 5 s). Budgets: POSEST-SFO, or Lilium with
5 x 2 where the check does not need a converged SFO.
"""

import shutil

import numpy as np
from hostile_casework import TINY, _quiet_main
from hostile_fixtures import (
    _codes,
    _dump,
    _edit_json,
    _edit_landmarks,
    _image_op,
    _in,
    _json,
    _photo,
    _result,
    _rot_err_deg,
    _size,
    _standin_photo,
    _standin_skull,
    _subject,
    _syn,
)
from hostile_machinery import Probe, _then

# -- checks -----------------------------------------------------------------------------------


#: Warnings of the clean inputs (POSEST-SFO's focal is loose: ``outside_prior`` on clean
#: photos), which say nothing of the inconsistency a probe plants.
CLEAN_CODES = {"outside_prior", "no_focal_prior", "no_scd_prior", "focal_cap"}


def _right_camera(truth, max_rot_deg=5.0, max_err_px=None, rel=None, named=()):
    """Check: the result's camera is within ``max_rot_deg`` of the true head rotation of
    ``truth(ws)/photo.json`` (the unedited one, in ``ws.base`` or the generated dataset) and its
    mean landmark error at most ``max_err_px``; else a warning beyond :data:`CLEAN_CODES` (or
    one of ``named``) must say something is wrong."""

    def check(ws):
        result = _result(ws, rel)
        if result is None:
            return "no result.json"
        if not result.get("camera"):
            return None  # a failed SFO says why on its own
        gt = _json(truth(ws) / "photo.json")["ground_truth"]
        rot = _rot_err_deg(result["camera"]["skull2cam"], gt["skull2cam"])
        err = (result.get("landmark_error") or {}).get("mean_px", float("nan"))
        focal = result["camera"]["focal_px"] / gt["focal_px"]
        wrong = rot > max_rot_deg or (max_err_px is not None and not err <= max_err_px)
        codes = _codes(result)
        flagged = [c for c in codes if c not in CLEAN_CODES or c in named]
        if wrong and not flagged:
            idn = result.get("identification") or {}
            return (
                f"camera {rot:.1f} deg from the truth, focal x{focal:.2f}, landmark error "
                f"{err:.1f} px, warnings {codes}, conclusion {idn.get('conclusion')!r} "
                f"(log10 LR {idn.get('log10_lr')})"
            )
        return None

    return check


# -- set-ups: photos --------------------------------------------------------------------------


def _rescale_image(where, factor):
    """The image and mask resized by ``factor``; the landmarks (and priors) left as they were."""

    def op(im):
        return im.resize((round(im.width * factor), round(im.height * factor)))

    return _image_op(where, op)


def _swap_pairs(*bases):
    """The ``_l``/``_r`` labels of the bilateral pairs ``bases`` swapped (the others kept)."""

    def change(lm, ws):
        out = dict(lm)
        for b in bases:
            left, right = f"{b}_l", f"{b}_r"
            if left in lm and right in lm:
                out[left], out[right] = lm[right], lm[left]
        return out

    return change


def _rotate180(where):
    """The photo turned upside down: image, mask, landmarks and face curve."""

    def setup(ws):
        from PIL import Image

        w, h = _size(where)(ws)
        _image_op(where, lambda im: im.transpose(Image.Transpose.ROTATE_180))(ws)
        turn = lambda p: [w - 1 - p[0], h - 1 - p[1]]  # noqa: E731
        _edit_landmarks(where, lambda lm, ws: {k: turn(p) for k, p in lm.items()})(ws)
        curve = where(ws) / "face_curve.json"
        if curve.is_file():
            data = _json(curve)
            _dump(
                curve,
                {k: [turn(p) for p in v] if isinstance(v, list) else v for k, v in data.items()},
            )

    return setup


def _invert_mask(where):
    def op(im):
        from PIL import Image

        a = np.asarray(im.convert("L")) > 0
        return Image.fromarray(((~a) * 255).astype(np.uint8))

    return _image_op(where, op, names=("face_mask.png",))


def _shift_mask(where, dx):
    """The mask of another photo of the same size: the head ``dx`` pixels to the side."""

    def op(im):
        a = np.asarray(im.convert("L")) > 0
        out = np.zeros_like(a)
        if dx >= 0:
            out[:, dx:] = a[:, : a.shape[1] - dx]
        else:
            out[:, :dx] = a[:, -dx:]
        from PIL import Image

        return Image.fromarray((out * 255).astype(np.uint8))

    return _image_op(where, op, names=("face_mask.png",))


def _view(where, view):
    return _edit_json(where, "photo.json", lambda d: d.update(view=view))


def _landmarks_of(where, other):
    """``where``'s photo.json takes the landmarks of ``other``'s (a file swapped)."""

    def setup(ws):
        lm = _json(other(ws) / "photo.json")["landmarks"]
        _edit_json(where, "photo.json", lambda d: d.update(landmarks=lm))(ws)

    return setup


def _half_photo(ws):
    """``in/photos/half``: the stand-in at half size, its landmarks and priors scaled."""
    from standin_case import scaled_photo

    if not _in(ws, "photos", "half").exists():
        scaled_photo(ws.photo, _in(ws, "photos", "half"), 0.5)


def _half(ws):
    return _in(ws, "photos", "half")


def _no_priors(where, *keys):
    def change(d):
        for k in keys or ("focal_px", "scd_mm", "head_rotation_skull2cam", "head_tolerance_deg"):
            d.get("priors", {}).pop(k, None)

    return _edit_json(where, "photo.json", change)


# -- set-ups: skulls --------------------------------------------------------------------------


def _cranial_of(where, other):
    def setup(ws):
        shutil.copy(other(ws) / "cranial_landmarks.json", where(ws) / "cranial_landmarks.json")

    return setup


def _cranial_map(where, fn):
    """Every cranial landmark ``p`` becomes ``fn(p)``."""
    return _edit_json(
        where,
        "cranial_landmarks.json",
        lambda d: d.update(
            landmarks={k: list(fn(np.asarray(p, float))) for k, p in d["landmarks"].items()}
        ),
    )


def _mirror_mesh(where, names=("skull.ply", "face.ply")):
    """The subject's meshes mirrored x -> -x (faces reversed so normals still point out)."""

    def setup(ws):
        from lilium.io.mesh import read_mesh, write_mesh

        for name in names:
            path = where(ws) / name
            if path.is_file():
                v, f = read_mesh(path)
                v = np.asarray(v, float).copy()
                v[:, 0] *= -1
                write_mesh(path, v, np.asarray(f)[:, ::-1])

    return setup


def _mirror_side_files(where):
    """The other per-landmark files of the subject mirrored too (axes x -> -x)."""

    def setup(ws):
        for name in ("soft_tissue_axes.json", "facial_landmarks.json"):
            path = where(ws) / name
            if path.is_file():
                data = _json(path)
                key = "axes" if "axes" in data else "landmarks"
                data[key] = {k: [-p[0], p[1], p[2]] for k, p in data[key].items()}
                _dump(path, data)

    return setup


def _write_in(name, text):
    def setup(ws):
        _in(ws, name).write_text(text)

    return setup


# -- command lines ----------------------------------------------------------------------------


def _photos_command(command, skull, photos, extra, method):
    """``lilium <command> --skull S --photo P ... --out OUT --method M EXTRA`` of a probe."""

    def argv(ws):
        out = [command, "--skull", skull(ws)]
        for p in photos:
            out += ["--photo", p(ws)]
        rest = (e(ws) if callable(e) else e for e in extra)
        return [*out, "--out", ws.out, "--method", method, *rest]

    return argv


def _sfo(skull, photo, *extra, method="posest-sfo"):
    photos = photo if isinstance(photo, (list, tuple)) else [photo]
    return _photos_command("sfo", skull, photos, extra, method)


def _case(skull, photos, *extra, method="posest-sfo"):
    return _photos_command("case", skull, photos, extra, method)


def _lineup(skull, candidates, *extra, method="posest-sfo"):
    def argv(ws):
        out = ["lineup", "--no-progress", "--skull", skull(ws), "--out", ws.out, "--method", method]
        for name, *photos in candidates:
            out += ["--candidate", name, *(p(ws) for p in photos)]
        return out + list(extra)

    return argv


S, P = _standin_skull, _standin_photo
F1, L1, F2, L2 = _photo("s01_f00"), _photo("s01_l00"), _photo("s02_f00"), _photo("s02_l00")
S1, S2 = _subject("s01"), _subject("s02")


def _base(ws):
    return ws.base / "photos" / "standin_frontal"


def _orig(name):
    """The unedited generated photo (for its ground truth)."""
    return lambda ws: ws.root.parent / "semantic-dataset" / "photos" / "A" / name


def _warned(*needles, rel=None):
    """Check: a warning of the result (``result.json``'s ``warnings``, a joint result's per
    photo too) holds every text of ``needles``; else the numbers that show the miss."""

    def check(ws):
        result = _result(ws, rel)
        if result is None:
            return "no result.json"
        messages = [w["message"] for w in result.get("warnings", [])]
        for photo in result.get("photos", []) or []:
            messages += [w["message"] for w in photo.get("warnings", [])]
        if any(all(n in m for n in needles) for m in messages):
            return None
        idn = result.get("identification") or {}
        err = (result.get("landmark_error") or {}).get("mean_px")
        focal = (result.get("camera") or {}).get("focal_px")
        lr = idn.get("log10_lr")
        return (
            f"no warning naming {needles}: warnings {_codes(result)}, focal "
            f"{focal and round(focal)} px, landmark error {err and round(err, 1)} px, conclusion "
            f"{idn.get('conclusion')!r} (log10 LR {lr and round(lr, 2)})"
        )

    return check


def _same_as_clean(max_focal_ratio=0.02, max_err_px=1.0):
    """Check: the camera of a photo turned or otherwise transformed consistently has the
    clean stand-in's focal (POSEST-SFO: 2435 px) and landmark error."""

    def check(ws):
        clean = ws.root / "clean"
        if (
            _quiet_main(
                [
                    "sfo",
                    "--skull",
                    ws.skull,
                    "--photo",
                    _base(ws),
                    "--out",
                    clean,
                    "--method",
                    "posest-sfo",
                    "--no-overlay",
                ]
            )
            != 0
        ):
            return "the clean SFO failed"
        a, b = _result(ws), _json(clean / "result.json")
        fa, fb = a["camera"]["focal_px"], b["camera"]["focal_px"]
        ea = a["landmark_error"]["mean_px"]
        if abs(fa / fb - 1) > max_focal_ratio or ea > max_err_px:
            return f"focal {fa:.0f} px (clean {fb:.0f}), landmark error {ea:.2f} px"
        return None

    return check


def _depth_csv(depth_mm, names=None):
    names = names or (
        "nasion",
        "glabella",
        "metopion",
        "bregma",
        "subspinale",
        "prosthion",
        "pogonion",
        "gnathion",
        "ectoconchion",
        "dacryon",
        "zygion",
        "gonion",
        "alare",
        "frontotemporale",
    )
    rows = "".join(f"{n},{depth_mm},5,{max(0, depth_mm - 10)},{depth_mm + 10}\n" for n in names)
    return _write_in("d.csv", "landmark,mean,sd,min,max\n" + rows)


def _exif_jpg(f35_mm, keep_prior=True):
    """The stand-in photo as ``image.jpg`` with a full-frame EXIF focal ``f35_mm`` (78 mm is
    the true 2600 px on its 1200 px width); ``photo.json``'s focal prior kept or dropped."""

    def setup(ws):
        from PIL import Image

        image = Image.open(ws.photo / "image.png").convert("RGB")
        exif = Image.Exif()
        exif[0x8769] = {0x920A: (f35_mm, 1), 0xA405: f35_mm}
        image.save(ws.photo / "image.jpg", exif=exif, quality=95)
        (ws.photo / "image.png").unlink()
        if not keep_prior:
            ws.edit(ws.photo / "photo.json", lambda d: d["priors"].pop("focal_px", None))

    return setup


def _vflip(where):
    """The photo mirrored top to bottom, landmarks with it (what "flip it" makes of an
    upside-down photo)."""

    def setup(ws):
        from PIL import Image

        w, h = _size(where)(ws)
        _image_op(where, lambda im: im.transpose(Image.Transpose.FLIP_TOP_BOTTOM))(ws)
        _edit_landmarks(where, lambda lm, ws: {k: [u, h - 1 - v] for k, (u, v) in lm.items()})(ws)  # noqa: E501

    return setup


def _rot90(where):
    """The photo turned 90 degrees (counter-clockwise), landmarks with it, priors dropped."""

    def setup(ws):
        from PIL import Image

        w, h = _size(where)(ws)
        _image_op(where, lambda im: im.transpose(Image.Transpose.ROTATE_90))(ws)
        _edit_landmarks(where, lambda lm, ws: {k: [v, w - 1 - u] for k, (u, v) in lm.items()})(ws)  # noqa: E501
        _edit_json(where, "photo.json", lambda d: d.pop("priors"))(ws)

    return setup


def _photo_prior(key, factor):
    """The stand-in's ``priors.<key>`` in ``photo.json`` times ``factor`` (excludes the truth)."""
    return lambda ws: ws.edit(
        ws.photo / "photo.json",
        lambda d: d["priors"].update({key: [x * factor for x in d["priors"][key]]}),
    )


def _no_curve(where):
    return lambda ws: (where(ws) / "face_curve.json").unlink()


def _swap_files(a, b):
    """The landmark lists of photos ``a`` and ``b`` swapped."""

    def setup(ws):
        la, lb = (_json(x(ws) / "photo.json")["landmarks"] for x in (a, b))
        _edit_json(a, "photo.json", lambda d: d.update(landmarks=lb))(ws)
        _edit_json(b, "photo.json", lambda d: d.update(landmarks=la))(ws)

    return setup


def _csv_photo(dup=None):
    """``in/plain/front.png`` with ``front_mask.png`` and ``front.csv`` (name,u,v) of the
    stand-in; ``dup`` a landmark written twice, the second time 200 px away."""

    def setup(ws):
        d = _in(ws, "plain")
        d.mkdir()
        shutil.copy(ws.photo / "image.png", d / "front.png")
        shutil.copy(ws.photo / "face_mask.png", d / "front_mask.png")
        lm = _json(ws.photo / "photo.json")["landmarks"]
        rows = ["name,u,v"] + [f"{k},{u},{v}" for k, (u, v) in lm.items()]
        if dup:
            u, v = lm[dup]
            rows.append(f"{dup},{u + 200},{v + 100}")
        (d / "front.csv").write_text("\n".join(rows) + "\n")

    return setup


def _plain(ws):
    return _in(ws, "plain", "front.png")


def _mirrored_skull(where):
    return _then(
        _mirror_mesh(where),
        _cranial_map(where, lambda p: p * [-1, 1, 1]),
        _mirror_side_files(where),
    )


# fmt: off


def semantic_probes():
    """Valid files that do not belong together (module docstring)."""
    D = lambda ws: ws.root / "in" / "d.csv"  # noqa: E731
    depth = lambda *extra: _sfo(S, P, "--depth-table", D, *extra)  # noqa: E731
    swap2 = _edit_landmarks(P, _swap_pairs("zygion", "gonion"))
    syn = lambda *setups: _then(_syn, *setups)  # noqa: E731
    return [
        # photos and their landmark files, masks and curves
        Probe("semantic sfo landmark file of the half-size photo, priors kept", _sfo(S, P), "error", ("photo.json", "of another photo"), _then(_half_photo, _landmarks_of(P, _half))),  # noqa: E501
        Probe("semantic sfo landmark file of the half-size photo, no priors", _sfo(S, P), "error", ("photo.json", "of another photo"), _then(_half_photo, _landmarks_of(P, _half), _no_priors(P))),  # noqa: E501
        Probe("semantic case landmark files swapped between a photo and its half-size copy", _case(S, [P, _half]), "error", ("photo.json", "of another photo"), _then(_half_photo, _swap_files(P, _half))),  # noqa: E501
        Probe("semantic sfo image and mask downscaled to 0.8, landmarks not", _sfo(S, P), "error", ("mask", "rescaled"), _rescale_image(P, 0.8)),  # noqa: E501
        Probe("semantic sfo inverted face mask", _sfo(S, P), "ok", (), _invert_mask(P), check=_warned("mask")),  # noqa: E501
        Probe("semantic sfo lilium inverted face mask", _sfo(S, P, "--generations", "30", method="lilium"), "ok", (), _invert_mask(P), check=_warned("mask")),  # noqa: E501
        Probe("semantic sfo lilium mask of another photo (head 400 px aside)", _sfo(S, P, "--generations", "30", method="lilium"), "error", ("mask", "of another photo"), _shift_mask(P, 400)),  # noqa: E501
        Probe("semantic case csv landmark twice at two places", _case(S, [_plain]), "error", ("front.csv", "zygion_l"), _csv_photo("zygion_l")),  # noqa: E501
        Probe("semantic case csv photo (control)", _case(S, [_plain]), "ok", (), _csv_photo(), check=_right_camera(_base)),  # noqa: E501
        # views
        Probe("semantic sfo lateral_left photo declared lateral_right", _sfo(S1, L1), "warn", ("view_mismatch", "lateral_right"), syn(_view(L1, "lateral_right"))),  # noqa: E501
        Probe("semantic sfo lilium lateral_left photo declared lateral_right", _sfo(S1, L1, *TINY, method="lilium"), "warn", ("view_mismatch",), syn(_view(L1, "lateral_right"))),  # noqa: E501
        Probe("semantic sfo lateral photo declared frontal, no curve file", _sfo(S1, L1), "warn", ("view_mismatch",), syn(_view(L1, "frontal"), _no_curve(L1))),  # noqa: E501
        Probe("semantic sfo frontal photo declared lateral_left, no curve file", _sfo(S1, F1), "warn", ("view_mismatch",), syn(_view(F1, "lateral_left"), _no_curve(F1))),  # noqa: E501
        Probe("semantic sfo lateral photo declared frontal, its forehead curve kept", _sfo(S1, L1), "error", ("face_curve.json", "view"), syn(_view(L1, "frontal"))),  # noqa: E501
        # turned and mirrored photos
        Probe("semantic sfo photo turned 90 deg with its landmarks", _sfo(S, P), "ok", (), _rot90(P), check=_same_as_clean()),  # noqa: E501
        Probe("semantic sfo photo upside down with its landmarks", _sfo(S, P), "error", ("photo.json", "upside down"), _rotate180(P)),  # noqa: E501
        Probe("semantic sfo upside-down photo flipped as told (top-bottom mirror)", _sfo(S, P), "error", ("photo.json", "upside down"), _vflip(P)),  # noqa: E501
        # some bilateral labels swapped
        Probe("semantic sfo zygion and gonion _l/_r swapped", _sfo(S, P), "error", ("zygion", "swap _l and _r"), swap2),  # noqa: E501
        Probe("semantic sfo lilium zygion and gonion _l/_r swapped", _sfo(S, P, "--generations", "30", method="lilium"), "error", ("zygion", "swap _l and _r"), swap2),  # noqa: E501
        Probe("semantic lineup true candidate's photo with zygion and gonion swapped", _lineup(S1, [("A", F1), ("B", F2)]), "error", ("zygion", "swap _l and _r"), syn(_edit_landmarks(F1, _swap_pairs("zygion", "gonion")))),  # noqa: E501
        Probe("semantic case --joint one photo with zygion and gonion swapped", _case(S1, [F1, L1], "--joint", *TINY, method="lilium"), "error", ("zygion", "swap _l and _r"), syn(_edit_landmarks(F1, _swap_pairs("zygion", "gonion")))),  # noqa: E501
        # skulls
        Probe("semantic sfo cranial landmarks in centimetres", _sfo(S1, F1), "error", ("cranial_landmarks.json", "mm from the skull mesh"), syn(_cranial_map(S1, lambda p: p / 10))),  # noqa: E501
        Probe("semantic sfo mirrored skull with its landmarks (a consistent mirror image)", _sfo(S1, F1), "error", ("cranial_landmarks.json", "mirrored"), syn(_mirrored_skull(S1))),  # noqa: E501
        # priors and tables
        Probe("semantic case --focal-px a tenth of the truth", _case(S, [P], "--focal-px", "250", "270"), "ok", (), check=_warned("focal length", "outside its prior")),  # noqa: E501
        Probe("semantic case lilium --focal-px twice the truth", _case(S, [P], "--focal-px", "5000", "5400", *TINY, method="lilium"), "ok", (), check=_warned("outside its prior")),  # noqa: E501
        Probe("semantic case --scd-mm ten times the truth", _case(S, [P], "--scd-mm", "8000", "10000"), "ok", (), check=_warned("distance", "outside its prior")),  # noqa: E501
        Probe("semantic sfo photo.json focal prior twice the truth, lilium", _sfo(S, P, *TINY, method="lilium"), "warn", ("outside_prior",), _photo_prior("focal_px", 2.0)),  # noqa: E501
        Probe("semantic sfo EXIF focal twice photo.json's focal prior", _sfo(S, P), "ok", (), _exif_jpg(156), check=_warned("EXIF")),  # noqa: E501
        Probe("semantic sfo EXIF focal alone (control)", _sfo(S, P), "ok", (), _exif_jpg(78, keep_prior=False), check=_right_camera(_base)),  # noqa: E501
        Probe("semantic sfo --depth-table nasion 80 mm", depth(), "ok", (), _depth_csv(80, ("nasion",)), check=_right_camera(_base)),  # noqa: E501
        Probe("semantic sfo --depth-table 80 mm at every landmark", depth(), "error", ("d.csv",), _depth_csv(80)),  # noqa: E501
    ]


# fmt: on
