"""The transformations of the metamorphic probes (``hostile_metamorphic.py``): set-ups
that change a case without changing its answer. Photos: resampled with their landmarks, mask,
focal prior and ground truth, a canvas padded or cropped, the landmark entries permuted or
renamed by their aliases, the mask in another PNG mode, a JPEG with or without an EXIF focal,
the ground-truth files removed, the landmarks written as CSV, TSV or JSON beside a plain
image. Skulls: moved rigidly (with their landmarks, axes, priors and ground truth), vertices
and faces reordered, written as STL/OBJ or with split vertices, scaled to other units, the
cranial landmarks in another format (CSV, 3D Slicer's FCSV and .mrk.json, MeshLab's .pp).
Tables and priors: the built-in depth table as a CSV, a copy of the axes, the priors moved to
the command line.
"""

import json
import re
import shutil

import numpy as np
from hostile_fixtures import _dump, _in, _json

# -- transformations: photos -------------------------------------------------------------------


def _standin_photo(ws):
    return ws.photo


def _standin_skull(ws):
    return ws.skull


def _sp(name):
    return lambda ws: _in(ws, "syn", "photos", "A", name)


def _ss(name):
    return lambda ws: _in(ws, "syn", "subjects", name)


def _map_uv_json(path, fn):
    """Every ``[u, v]`` of ``photo.json``'s landmarks and ground truth, or of a
    ``face_curve.json``, through ``fn``."""
    if not path.is_file():
        return
    data = _json(path)
    if path.name == "face_curve.json":
        data = {k: [list(fn(p)) for p in v] if isinstance(v, list) else v for k, v in data.items()}
    else:
        data["landmarks"] = {k: list(fn(p)) for k, p in data["landmarks"].items()}
        gt = data.get("ground_truth")
        if gt and "landmarks_noise_free" in gt:
            gt["landmarks_noise_free"] = {
                k: list(fn(p)) for k, p in gt["landmarks_noise_free"].items()
            }  # noqa: E501
    _dump(path, data)


def _edit_photo_json(where, change):
    def setup(ws):
        path = where(ws) / "photo.json"
        data = _json(path)
        change(data)
        _dump(path, data)

    return setup


def _rescale(where, factor):
    """Image (Lanczos) and mask (nearest) resized by ``factor``; landmarks, face curve, focal
    prior and ground truth scaled with them (the same photo at another resolution)."""

    def setup(ws):
        from PIL import Image

        folder = where(ws)
        for name, resample in (
            ("image.png", Image.Resampling.LANCZOS),
            ("face_mask.png", Image.Resampling.NEAREST),
        ):  # noqa: E501
            path = folder / name
            if path.is_file():
                with Image.open(path) as im:
                    im.load()
                    im.resize((round(im.width * factor), round(im.height * factor)), resample).save(
                        path
                    )  # noqa: E501
        fn = lambda p: [(p[0] + 0.5) * factor - 0.5, (p[1] + 0.5) * factor - 0.5]  # noqa: E731
        _map_uv_json(folder / "photo.json", fn)
        _map_uv_json(folder / "face_curve.json", fn)

        def priors(d):
            pr = d.get("priors", {})
            if "focal_px" in pr:
                pr["focal_px"] = [x * factor for x in pr["focal_px"]]
            gt = d.get("ground_truth")
            if gt:
                gt["focal_px"] *= factor
                gt.pop("principal_point_px", None)
                gt.pop("image_size", None)

        _edit_photo_json(where, priors)(ws)

    return setup


def _canvas(where, left, top, right, bottom, fill=40):
    """The canvas extended (positive) or cropped (negative) on each side; landmarks and curve
    shifted by ``(left, top)``; the image extended with a grey border, the mask with 0."""

    def setup(ws):
        from PIL import Image

        folder = where(ws)
        for name in ("image.png", "face_mask.png"):
            path = folder / name
            if not path.is_file():
                continue
            with Image.open(path) as im:
                im.load()
                w, h = im.size
                value = fill if name == "image.png" else 0
                bands = len(im.getbands())
                canvas = Image.new(
                    im.mode,
                    (w + left + right, h + top + bottom),
                    (value,) * bands if bands > 1 else value,
                )  # noqa: E501
                canvas.paste(im, (left, top))
                canvas.save(path)
        fn = lambda p: [p[0] + left, p[1] + top]  # noqa: E731
        _map_uv_json(folder / "photo.json", fn)
        _map_uv_json(folder / "face_curve.json", fn)
        _edit_photo_json(
            where, lambda d: d.get("ground_truth", {}).pop("principal_point_px", None)
        )(ws)  # noqa: E501

    return setup


def _permute_landmarks(where, seed=0):
    """``photo.json``'s landmark entries in another order (same names and points)."""

    def change(d):
        items = list(d["landmarks"].items())
        order = np.random.default_rng(seed).permutation(len(items))
        d["landmarks"] = dict(items[k] for k in order)

    return _edit_photo_json(where, change)


#: Aliases the README promises (``n``, ``gn``, ``Pog``, ``ex_l``, ``Zygion R``).
ALIASES = {
    "nasion": "n",
    "gnathion": "gn",
    "pogonion": "Pog",
    "exocanthion_l": "ex_l",
    "zygion_r": "Zygion R",
}  # noqa: E501


def _alias_names(where):
    return _edit_photo_json(
        where,
        lambda d: d.update(landmarks={ALIASES.get(k, k): p for k, p in d["landmarks"].items()}),  # noqa: E501
    )


def _mask_mode(where, mode):
    """The face mask saved in another PNG mode, the same pixels non-zero."""

    def setup(ws):
        from PIL import Image

        path = where(ws) / "face_mask.png"
        with Image.open(path) as im:
            on = np.asarray(im.convert("L")) > 0
        if mode == "1":
            Image.fromarray(on).convert("1").save(path)
        elif mode == "L":
            Image.fromarray((on * 255).astype(np.uint8)).save(path)
        elif mode == "L1":  # the value 1, not 255: "non-zero = face"
            Image.fromarray(on.astype(np.uint8)).save(path)
        elif mode == "RGBA":
            a = np.zeros(on.shape + (4,), np.uint8)
            a[on] = 255
            a[..., 3] = 255
            Image.fromarray(a).save(path)
        elif mode == "P":
            Image.fromarray((on * 255).astype(np.uint8)).convert("P").save(path)
        elif mode == "I;16":
            Image.fromarray((on * 65535).astype(np.uint16)).save(path)

    return setup


def _to_jpeg(where, exif_f35=None, quality=95):
    """``image.png`` -> ``image.jpg`` (the same JPEG bytes apart from an EXIF block with a
    35 mm focal ``exif_f35``, full-frame tags)."""

    def setup(ws):
        from PIL import Image

        folder = where(ws)
        image = Image.open(folder / "image.png").convert("RGB")
        kwargs = {"quality": quality}
        if exif_f35 is not None:
            exif = Image.Exif()
            exif[0x8769] = {0x920A: (exif_f35, 1), 0xA405: exif_f35}
            kwargs["exif"] = exif
        image.save(folder / "image.jpg", **kwargs)
        (folder / "image.png").unlink()

    return setup


def _strip_truth(subject, photo):
    """The ground-truth files the methods must ignore removed (``face.ply``,
    ``facial_landmarks.json``, ``subject.json``, ``photo.json``'s ``ground_truth``)."""

    def setup(ws):
        for name in ("face.ply", "facial_landmarks.json", "subject.json"):
            (subject(ws) / name).unlink(missing_ok=True)
        _edit_photo_json(photo, lambda d: d.pop("ground_truth", None))(ws)

    return setup


# -- transformations: skulls -------------------------------------------------------------------


def _rigid(angle_deg=35.0, axis=(0.3, -0.8, 0.5), shift=(120.0, -340.0, 515.0)):
    from lilium.geometry.rotations import rotvec_to_matrix

    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    M = np.eye(4)
    M[:3, :3] = rotvec_to_matrix(np.radians(angle_deg) * axis)
    M[:3, 3] = shift
    return M


MOTION = _rigid()


def _move_skull(subject, photos, M=MOTION):
    """The skull mesh, its cranial landmarks, axes and ground-truth face moved by ``M``; each
    photo's head-rotation prior (skull frame) and ground-truth camera follow."""

    def setup(ws):
        from lilium.io.mesh import read_mesh, write_mesh

        folder = subject(ws)
        R, t = M[:3, :3], M[:3, 3]
        for name in ("skull.ply", "face.ply"):
            if (folder / name).is_file():
                v, f = read_mesh(folder / name)
                write_mesh(folder / name, v @ R.T + t, f)
        for name, key, point in (
            ("cranial_landmarks.json", "landmarks", True),
            ("facial_landmarks.json", "landmarks", True),
            ("soft_tissue_axes.json", "axes", False),
        ):  # noqa: E501
            path = folder / name
            if path.is_file():
                data = _json(path)
                data[key] = {
                    k: list(R @ np.asarray(p) + (t if point else 0)) for k, p in data[key].items()
                }  # noqa: E501
                _dump(path, data)
        Minv = np.linalg.inv(M)
        for photo in photos:

            def change(d):
                pr = d.get("priors", {})
                if "head_rotation_skull2cam" in pr:
                    pr["head_rotation_skull2cam"] = (
                        np.asarray(pr["head_rotation_skull2cam"]) @ R.T
                    ).tolist()  # noqa: E501
                gt = d.get("ground_truth")
                if gt and "skull2cam" in gt:
                    gt["skull2cam"] = (np.asarray(gt["skull2cam"]) @ Minv).tolist()

            _edit_photo_json(photo, change)(ws)

    return setup


def _reorder_mesh(subject, seed=0, roll=True):
    """The skull's vertices and faces in another order (each face's corners rolled, the winding
    kept): the same surface."""

    def setup(ws):
        from lilium.io.mesh import read_mesh, write_mesh

        path = subject(ws) / "skull.ply"
        v, f = read_mesh(path)
        rng = np.random.default_rng(seed)
        perm = rng.permutation(len(v))
        inv = np.empty_like(perm)
        inv[perm] = np.arange(len(v))
        f = inv[np.asarray(f)][rng.permutation(len(f))]
        if roll:
            f = np.roll(f, 1, axis=1)
        write_mesh(path, v[perm], f)

    return setup


def _mesh_as(subject, suffix, split=False):
    """``skull.ply`` rewritten as ``skull<suffix>`` (trimesh's writer), optionally with every
    face's vertices split (no shared vertex, as STL stores them)."""

    def setup(ws):
        from lilium.io.mesh import read_mesh, write_mesh

        path = subject(ws) / "skull.ply"
        v, f = read_mesh(path)
        f = np.asarray(f)
        if split:
            v, f = v[f.reshape(-1)], np.arange(f.size).reshape(-1, 3)
        path.unlink()
        write_mesh(path.with_suffix(suffix), v, f)

    return setup


def _skull_units(subject, factor):
    """Mesh and cranial landmarks multiplied by ``factor`` (0.1: centimetres)."""

    def setup(ws):
        from lilium.io.mesh import read_mesh, write_mesh

        folder = subject(ws)
        v, f = read_mesh(folder / "skull.ply")
        write_mesh(folder / "skull.ply", v * factor, f)
        data = _json(folder / "cranial_landmarks.json")
        data["landmarks"] = {k: [x * factor for x in p] for k, p in data["landmarks"].items()}
        _dump(folder / "cranial_landmarks.json", data)

    return setup


def _cranial_file(subject, fmt):
    """``in/lm.<fmt>``: the skull's cranial landmarks in another format, points as in the mesh
    (3D Slicer files in the frame they state: ``fcsv-ras`` writes RAS, x and y negated)."""

    def setup(ws):
        lm = _json(subject(ws) / "cranial_landmarks.json")["landmarks"]
        items = list(lm.items())[::-1]  # another order too
        if fmt == "csv":
            text = "name,x,y,z\n" + "".join(f"{k},{x!r},{y!r},{z!r}\n" for k, (x, y, z) in items)
            name = "lm.csv"
        elif fmt in ("fcsv", "fcsv-ras"):
            ras = fmt == "fcsv-ras"
            head = f"# Markups fiducial file version = 4.11\n# CoordinateSystem = {'RAS' if ras else 'LPS'}\n# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,associatedNodeID\n"  # noqa: E501
            sx = -1 if ras else 1
            rows = [
                f"{i},{sx * x!r},{sx * y!r},{z!r},0,0,0,1,1,1,0,{k},,"
                for i, (k, (x, y, z)) in enumerate(items)
            ]  # noqa: E501
            text, name = head + "\n".join(rows) + "\n", "lm.fcsv"
        elif fmt == "mrk.json":
            pts = [{"label": k, "position": p, "positionStatus": "defined"} for k, p in items]
            text = json.dumps(
                {
                    "markups": [
                        {
                            "type": "Fiducial",
                            "coordinateSystem": "LPS",
                            "coordinateUnits": "mm",
                            "controlPoints": pts,
                        }
                    ]
                }
            )  # noqa: E501
            name = "lm.mrk.json"
        elif fmt == "pp":
            pts = "".join(
                f'<point x="{x!r}" y="{y!r}" z="{z!r}" name="{k}" active="1"/>\n'
                for k, (x, y, z) in items
            )  # noqa: E501
            text, name = f"<!DOCTYPE PickedPoints>\n<PickedPoints>\n{pts}</PickedPoints>\n", "lm.pp"
        else:
            raise ValueError(fmt)
        _in(ws, name).write_text(text)

    return setup


def _photo_file(where, fmt, permute=True):
    """``in/plain/front.png`` (the image), ``front_mask.png``, ``front_face_curve.json`` when
    the folder has one, and the landmarks as ``front.<fmt>`` (``csv`` name,u,v; ``tsv-xy``
    tab-separated with x,y columns; ``json``)."""

    def setup(ws):
        src, d = where(ws), _in(ws, "plain")
        d.mkdir(exist_ok=True)
        shutil.copy(src / "image.png", d / "front.png")
        shutil.copy(src / "face_mask.png", d / "front_mask.png")
        if (src / "face_curve.json").is_file():
            shutil.copy(src / "face_curve.json", d / "front_face_curve.json")
        lm = list(_json(src / "photo.json")["landmarks"].items())
        if permute:
            lm = [lm[k] for k in np.random.default_rng(1).permutation(len(lm))]
        if fmt == "csv":
            text = "name,u,v\n" + "".join(f"{k},{u!r},{v!r}\n" for k, (u, v) in lm)
            (d / "front.csv").write_text(text)
        elif fmt == "tsv-xy":
            text = "label\tx\ty\n" + "".join(f"{k}\t{u!r}\t{v!r}\n" for k, (u, v) in lm)
            (d / "front.tsv").write_text(text)
        elif fmt == "json":
            _dump(d / "front.json", {"landmarks": dict(lm)})

    return setup


def _plain(ws):
    return _in(ws, "plain", "front.png")


# -- transformations: tables and priors ------------------------------------------------------


def _depth_csv(facial=False):
    def setup(ws):
        from lilium.softtissue.depths import BUILTIN_DEPTHS
        from lilium.softtissue.landmarks import CRANIAL_TO_FACIAL

        def label(name):
            if not facial:
                return name
            for c, f in CRANIAL_TO_FACIAL.items():
                if re.sub(r"_[lr]$", "", c) == name:
                    return re.sub(r"_[lr]$", "", f)
            return name

        rows = "".join(
            f"{label(k)},{s.mean_mm!r},{s.sd_mm!r},{s.min_mm!r},{s.max_mm!r}\n"
            for k, s in BUILTIN_DEPTHS.items()
        )
        _in(ws, "d.csv").write_text("landmark,mean,sd,min,max\n" + rows)

    return setup


def _axes_copy(subject, factor=1.0):
    def setup(ws):
        data = _json(subject(ws) / "soft_tissue_axes.json")
        data["axes"] = {k: [x * factor for x in a] for k, a in data["axes"].items()}
        _dump(_in(ws, "axes.json"), data)

    return setup


def _priors_to_cli(where):
    """``photo.json``'s focal and distance priors removed (given on the command line instead)."""
    return _edit_photo_json(where, lambda d: [d["priors"].pop(k) for k in ("focal_px", "scd_mm")])
