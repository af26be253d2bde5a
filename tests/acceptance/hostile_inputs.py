"""Hostile-input probes of ``lilium photo``, ``lilium import-ct`` and ``lilium synth``, run by
the campaign (issue 28).

Every input is generated in the probe's set-up: photos from scikit-image's astronaut (a real,
public-domain face) with EXIF tags that lie, in every image mode, turned by each EXIF
orientation, doubled, cut or shrunk; CT volumes from the phantom of ``tests/ct_phantom.py`` as
DICOM series (missing, duplicated, mixed or inconsistent slices) and NIfTI files (singular or
non-finite affines, NaN voxels, no bone, a declared shape the file cannot hold); ``lilium
synth`` with one subject and one photo. Nothing is read from the shared data.
"""

import json
from functools import cache

import numpy as np
from hostile_machinery import Probe

# -- photos -----------------------------------------------------------------------------------


@cache
def _astronaut():
    from skimage import data

    return data.astronaut()  # 512 x 512 RGB, one frontal face


def _pil(array):
    from PIL import Image

    return Image.fromarray(np.ascontiguousarray(array))


def _in(ws, *parts):
    return ws.root.joinpath("in", *parts)


def _image(name, make, **save):
    """Set-up: ``in/<name>``, the PIL image ``make()`` saved with ``save`` (``exif`` a dict of
    Exif-IFD tags, or an ``Image.Exif``)."""

    def setup(ws):
        from PIL import Image

        options = dict(save)
        tags = options.pop("exif_ifd", None)
        if tags is not None:
            exif = Image.Exif()
            exif[0x8769] = tags
            options["exif"] = exif
        make().save(_in(ws, name), **options)

    return setup


def _face(mode=None):
    def make():
        im = _pil(_astronaut())
        return im.convert(mode) if mode else im

    return make


def _rational(num, den):
    from PIL.TiffImagePlugin import IFDRational

    return IFDRational(num, den)


def _photo(*extra, name="p.jpg", out=None):
    return lambda ws: ["photo", _in(ws, name), "--out", out(ws) if out else ws.out, *extra]


def _meta(ws):
    return json.loads((ws.out / "photo.json").read_text())


def _no_focal(ws):
    focal = _meta(ws)["priors"].get("focal_px")
    return None if focal is None else f"focal prior {focal} from absurd EXIF"


def _face_found(ws):
    n = len(_meta(ws)["landmarks"])
    return None if n >= 10 else f"only {n} landmarks"


def _no_landmarks(ws):
    meta = _meta(ws)
    return None if meta["landmarks"] == {} else f"{len(meta['landmarks'])} landmarks on no face"


def _landmarks_inside(ws):
    from lilium.io.images import image_size_wh

    folder = ws.out
    image = next(folder / n for n in ("image.png", "image.jpg") if (folder / n).exists())
    w, h = image_size_wh(image)
    bad = [k for k, (u, v) in _meta(ws)["landmarks"].items() if not (0 <= u < w and 0 <= v < h)]
    return f"landmarks outside the {w}x{h} image: {bad}" if bad else None


# EXIF orientation o: the stored pixels are the upright face transformed by the inverse of
# what a viewer applies (Pillow's exif_transpose), so that the viewed image is upright.
_STORED = {
    2: lambda a: a[:, ::-1],
    3: lambda a: a[::-1, ::-1],
    4: lambda a: a[::-1],
    5: lambda a: a.transpose(1, 0, 2),
    6: lambda a: np.rot90(a, 1),
    7: lambda a: np.rot90(a, 2).transpose(1, 0, 2),
    8: lambda a: np.rot90(a, -1),
}


def _oriented(orientation):
    def setup(ws):
        from PIL import Image

        stored = _pil(_STORED[orientation](_astronaut()))
        exif = Image.Exif()
        exif[0x0112] = orientation
        stored.save(_in(ws, "p.jpg"), exif=exif, quality=95)
        # The reference: the upright face, prepared in a folder of its own.
        _pil(_astronaut()).save(_in(ws, "upright.jpg"), quality=95)

    return setup


def _follows_exif(ws):
    """The landmarks of an EXIF-oriented photo are those of the upright photo (viewed pixels)."""
    import contextlib
    import io

    from lilium.cli.main import main

    ref = ws.root / "ref"
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        main(["photo", str(_in(ws, "upright.jpg")), "--out", str(ref)])
    want = json.loads((ref / "photo.json").read_text())["landmarks"]
    got = _meta(ws)["landmarks"]
    if sorted(got) != sorted(want):
        return f"landmarks {sorted(set(got) ^ set(want))} differ from the upright photo's"
    worst = max(float(np.hypot(*np.subtract(got[k], want[k]))) for k in want)
    return None if worst < 4.0 else f"landmarks {worst:.0f} px from the upright photo's"


def _two_faces():
    a = _astronaut()[:300, 100:420]
    return _pil(np.concatenate([a, np.zeros((300, 40, 3), np.uint8), a], axis=1))


def _right_face(ws):
    u = float(np.mean([uv[0] for uv in _meta(ws)["landmarks"].values()] or [0]))
    return None if u > 360 else f"--face 2 gave the face at u = {u:.0f} (the left one)"


def _border_face():
    return _pil(_astronaut()[:, 150:])  # the face's right half cut by the image's left edge


def _tiny_face():
    canvas = np.full((2400, 3200, 3), 90, np.uint8)
    canvas[1000:1128, 1500:1628] = np.asarray(_pil(_astronaut()).resize((128, 128)))
    return _pil(canvas)


def _noise():
    return _pil(np.random.default_rng(0).integers(0, 256, (400, 300, 3), np.uint8))


def _inputs_kept(ws):
    return None if _in(ws, "p.jpg").is_file() else "the photograph was removed"


def _out_under_input(ws):
    _image("p.jpg", _face())(ws)
    ws.out = _in(ws, "sub", "p")


def _out_is_input_folder(ws):
    _image("p.jpg", _face())(ws)
    ws.out = _in(ws)


def _foreign_folder(name, content):
    def setup(ws):
        _image("p.jpg", _face())(ws)
        ws.out.mkdir()
        path = ws.out / name
        if content is None:
            path.mkdir()
        else:
            path.write_text(content)

    return setup


def _landmark_file(points):
    def setup(ws):
        _image("p.jpg", _face())(ws)
        _in(ws, "lm.json").write_text(json.dumps({"landmarks": points}))  # NaN as JSON's NaN

    return setup


# fmt: off


def photo_probes():
    """``lilium photo``: lying EXIF, EXIF orientations, image modes, faces, --out, options."""
    F = "exif_focal_unusable"
    ifd = lambda **tags: {int(k[1:], 16): v for k, v in tags.items()}  # noqa: E731
    jpg = lambda **tags: _image("p.jpg", _face(), exif_ifd=ifd(**tags))  # noqa: E731
    png = lambda make, name="p.png": _image(name, make)  # noqa: E731
    P = "photo"
    probes = [
        Probe("photo EXIF FocalLength 0", _photo(), "ok", (), jpg(x920A=_rational(0, 1)), P, _no_focal),  # noqa: E501
        Probe("photo EXIF FocalLength 0/0", _photo(), "ok", (), jpg(x920A=_rational(0, 0)), P, _no_focal),  # noqa: E501
        Probe("photo EXIF FocalLength negative", _photo(), "ok", (), jpg(x920A=_rational(-50, 1)), P, _no_focal),  # noqa: E501
        Probe("photo EXIF 35 mm equivalent 5000 mm", _photo(), "warn", (F, "FocalLengthIn35mmFilm"), jpg(xA405=5000), P, _no_focal),  # noqa: E501
        Probe("photo EXIF focal 0.01 mm", _photo(), "warn", (F, "FocalLength"), jpg(x920A=_rational(1, 100)), P, _no_focal),  # noqa: E501
        Probe("photo EXIF pixel pitch of a 0.5 mm sensor", _photo(), "warn", (F, "FocalPlaneXResolution"), jpg(x920A=_rational(50, 1), xA20E=_rational(1024, 1), xA210=4), P, _no_focal),  # noqa: E501
        Probe("photo EXIF PixelXDimension not the file's", _photo(), "warn", (F, "PixelXDimension"), jpg(xA405=50, xA002=4000, xA003=3000), P, _no_focal),  # noqa: E501
        Probe("photo --sensor-width-mm contradicts EXIF", _photo("--sensor-width-mm", "36"), "warn", (F, "--sensor-width-mm"), jpg(x920A=_rational(50, 1), xA20E=_rational(100, 1), xA210=4), P, _no_focal),  # noqa: E501
        Probe("photo --sensor-width-mm 1000", _photo("--sensor-width-mm", "1000"), "error", ("--sensor-width-mm",), jpg(x920A=_rational(50, 1)), P),  # noqa: E501
        Probe("photo --sensor-width-mm nan", _photo("--sensor-width-mm", "nan"), "error", ("--sensor-width-mm",), jpg(x920A=_rational(50, 1)), P),  # noqa: E501
    ]
    probes += [
        Probe(f"photo EXIF orientation {o}", _photo(), "ok", (), _oriented(o), P, _follows_exif)
        for o in range(2, 9)
    ]
    probes += [
        Probe("photo grey (L)", _photo(name="p.png"), "ok", (), png(_face("L")), P, _face_found),
        Probe("photo 16-bit grey", _photo(name="p.png"), "ok", (), png(lambda: _pil(np.asarray(_face("L")()).astype(np.uint16) * 257)), P, _face_found),  # noqa: E501
        Probe("photo RGBA", _photo(name="p.png"), "ok", (), png(_face("RGBA")), P, _face_found),
        Probe("photo palette (P)", _photo(name="p.png"), "ok", (), png(_face("P")), P, _face_found),  # noqa: E501
        Probe("photo CMYK JPEG", _photo(), "ok", (), _image("p.jpg", _face("CMYK")), P, _face_found),  # noqa: E501
        Probe("photo blank image", _photo(name="p.png"), "ok", (), png(lambda: _pil(np.full((300, 400, 3), 200, np.uint8))), P, _no_landmarks, code=3),  # noqa: E501
        Probe("photo noise image", _photo(name="p.png"), "ok", (), png(_noise), P, _no_landmarks, code=3),  # noqa: E501
        Probe("photo two faces", _photo(name="p.png"), "warn", ("several_faces",), png(_two_faces), P, _face_found),  # noqa: E501
        Probe("photo two faces --face 2", _photo("--face", "2", name="p.png"), "ok", (), png(_two_faces), P, _right_face),  # noqa: E501
        Probe("photo two faces --face 3", _photo("--face", "3", name="p.png"), "error", ("--face",), png(_two_faces), P),  # noqa: E501
        Probe("photo --face 0", _photo("--face", "0"), "error", ("--face",), jpg(), P),
        Probe("photo face cut by the border", _photo(name="p.png"), "ok", (), png(_border_face), P, _landmarks_inside),  # noqa: E501
        # A 128 px face in 3200 px is under the detector's reach: exit 3, a folder to mark by hand.
        Probe("photo tiny face in 7.7 MP", _photo(name="p.png"), "ok", (), png(_tiny_face), P, _no_landmarks, code=3),  # noqa: E501
        Probe("photo --out inside the input folder", _photo(), "ok", (), _out_under_input, P, _face_found),  # noqa: E501
        Probe("photo --out is the input folder", _photo(), "ok", (), _out_is_input_folder, P, _inputs_kept),  # noqa: E501
        Probe("photo --out holds a hand-made photo.json", _photo(), "error", ("photo.json", "--out"), _foreign_folder("photo.json", '{"view": "frontal", "landmarks": {}}'), P),  # noqa: E501
        Probe("photo --out holds a folder named face_mask.png", _photo(), "error", ("face_mask.png", "--out"), _foreign_folder("face_mask.png", None), P),  # noqa: E501
        Probe("photo --landmarks outside the image", _photo("--landmarks", "in/lm.json"), "error", ("lm.json", "outside"), _landmark_file({"subnasale": [900, 10]}), P),  # noqa: E501
        Probe("photo --landmarks NaN", _photo("--landmarks", "in/lm.json"), "error", ("lm.json",), _landmark_file({"subnasale": [float("nan"), 10]}), P),  # noqa: E501
        Probe("photo --landmarks a folder", _photo("--landmarks", "in/photos"), "error", ("in/photos", "folder"), jpg(), P),  # noqa: E501
    ]
    return probes


# fmt: on

# -- CT volumes -------------------------------------------------------------------------------


def _phantom():
    from ct_phantom import head

    return head(hu=True)


def _dicom(change=None, folder="dcm", data=None):
    """Set-up: ``in/<folder>``, the phantom as a DICOM series; ``change(files)`` edits it
    (``files`` the paths in slice order of their file names)."""

    def setup(ws):
        from ct_phantom import write_dicom

        write_dicom(_in(ws, folder), _phantom() if data is None else data)
        if change:
            change(sorted(_in(ws, folder).iterdir()))

    return setup


def _edit_dicom(path, **values):
    import pydicom

    ds = pydicom.dcmread(path)
    for key, value in values.items():
        setattr(ds, key, value)
    ds.save_as(path, enforce_file_format=True)


def _second_series(files):
    import pydicom
    from pydicom.uid import generate_uid

    _edit_dicom(files[3], SeriesInstanceUID=generate_uid())
    assert pydicom.dcmread(files[3]).SeriesInstanceUID


def _duplicate(files):
    import shutil

    shutil.copyfile(files[5], files[5].with_name("copy.dcm"))


def _tilt_one(files):
    _edit_dicom(files[7], ImageOrientationPatient=[0, 1, 0, 1, 0, 0])


def _spacing_one(files):
    _edit_dicom(files[7], PixelSpacing=[3.0, 3.0])


def _nifti(data=None, affine=None, name="v.nii", sform=1, qform=0):
    """Set-up: ``in/<name>``, ``data`` (``[k, j, i]``, default the phantom) as NIfTI-1."""

    def setup(ws):
        import nibabel

        volume = _phantom() if data is None else data
        a = np.diag([1.5, 1.5, 1.5, 1.0]) if affine is None else np.asarray(affine, float)
        image = nibabel.Nifti1Image(np.asarray(volume).transpose(2, 1, 0), None)
        image.set_sform(a, code=sform)
        image.set_qform(a if qform else None, code=qform)
        nibabel.save(image, _in(ws, name))

    return setup


def _nan_phantom():
    data = _phantom().astype(np.float32)
    data[40, 30, 20] = np.nan
    return data


def _tiny():
    data = np.full((3, 3, 3), -1000, np.int16)
    data[1, 1, 1] = 1000
    return data


def _huge_header(ws):
    import nibabel

    header = nibabel.Nifti1Header()
    header.set_data_dtype(np.int16)
    header.set_data_shape((4000, 4000, 4000))
    header.set_zooms((1.0, 1.0, 1.0))
    _in(ws, "v.nii").write_bytes(header.binaryblock + b"\0" * 4 + b"\1" * 1000)


def _sheared_check(ws):
    record = json.loads((ws.out / "ct_import.json").read_text())
    m = np.asarray(record["index_to_frame"])[:3, :3]
    return None if abs(m[0, 2]) > 0.1 else "the shear of the affine was dropped"


def _skull_written(ws):
    return None if (ws.out / "skull.ply").stat().st_size > 1000 else "no skull mesh"


# fmt: off


def ct_probes():
    """``lilium import-ct``: DICOM series, NIfTI affines and voxels, orientation options."""
    imp = lambda name, *extra: lambda ws: ["import-ct", _in(ws, name), "--out", ws.out, *extra]  # noqa: E501, E731
    C = "ct"
    shear = np.diag([1.5, 1.5, 1.5, 1.0])
    shear[0, 2] = 0.5
    flat = np.diag([1.5, 1.5, 1.5, 1.0])
    flat[:3, 2] = flat[:3, 0]  # the slice axis along the columns: a rank-2 affine
    nan_affine = np.diag([1.5, 1.5, 1.5, 1.0])
    nan_affine[1, 3] = np.nan
    return [
        Probe("import-ct DICOM series", imp("dcm"), "ok", (), _dicom(), C, _skull_written),
        Probe("import-ct DICOM missing slice", imp("dcm"), "error", ("dcm", "evenly spaced"), _dicom(lambda f: f[10].unlink()), C),  # noqa: E501
        Probe("import-ct DICOM duplicated slice", imp("dcm"), "error", ("dcm", "duplicate"), _dicom(_duplicate), C),  # noqa: E501
        Probe("import-ct DICOM two series in one folder", imp("dcm"), "error", ("dcm", "series"), _dicom(_second_series), C),  # noqa: E501
        Probe("import-ct DICOM one slice turned", imp("dcm"), "error", ("ImageOrientationPatient",), _dicom(_tilt_one), C),  # noqa: E501
        Probe("import-ct DICOM one slice of other PixelSpacing", imp("dcm"), "error", ("PixelSpacing",), _dicom(_spacing_one), C),  # noqa: E501
        Probe("import-ct DICOM a single slice", imp("dcm"), "error", ("dcm",), _dicom(data=_phantom()[40:41]), C),  # noqa: E501
        Probe("import-ct DICOM with --orientation", imp("dcm", "--orientation", "LPS"), "error", ("--orientation",), _dicom(), C),  # noqa: E501
        Probe("import-ct NIfTI sheared affine", imp("v.nii"), "ok", (), _nifti(affine=shear), C, _sheared_check),  # noqa: E501
        Probe("import-ct NIfTI rank-2 affine", imp("v.nii"), "error", ("v.nii", "singular"), _nifti(affine=flat), C),  # noqa: E501
        Probe("import-ct NIfTI NaN in the affine", imp("v.nii"), "error", ("v.nii",), _nifti(affine=nan_affine), C),  # noqa: E501
        Probe("import-ct NIfTI NaN voxel", imp("v.nii"), "error", ("v.nii", "NaN", "--crop"), _nifti(_nan_phantom()), C),  # noqa: E501
        Probe("import-ct NIfTI all zero", imp("v.nii"), "error", ("v.nii", "--bone-iso"), _nifti(np.zeros((8, 8, 8), np.int16)), C),  # noqa: E501
        Probe("import-ct NIfTI constant bone", imp("v.nii", "--units", "hu"), "error", ("v.nii", "--bone-iso"), _nifti(np.full((8, 8, 8), 1500, np.int16)), C),  # noqa: E501
        Probe("import-ct NIfTI 3x3x3 with one bone voxel", imp("v.nii", "--units", "hu"), "ok", (), _nifti(_tiny()), C),  # noqa: E501
        Probe("import-ct NIfTI one slice thick", imp("v.nii"), "error", ("v.nii", "2 voxels"), _nifti(_phantom()[40:41]), C),  # noqa: E501
        Probe("import-ct NIfTI 64 G voxels declared, 1 kB file", imp("v.nii"), "error", ("v.nii",), _huge_header, C),  # noqa: E501
        Probe("import-ct NIfTI with sform and --orientation", imp("v.nii", "--orientation", "LPI"), "error", ("--orientation",), _nifti(), C),  # noqa: E501
        Probe("import-ct --orientation LLS", imp("v.nii", "--orientation", "LLS"), "error", ("--orientation",), _nifti(sform=0), C),  # noqa: E501
        Probe("import-ct --orientation XYZ", imp("v.nii", "--orientation", "XYZ"), "error", ("--orientation",), _nifti(sform=0), C),  # noqa: E501
        Probe("import-ct --orientation 4 letters", imp("v.nii", "--orientation", "LPSI"), "error", ("--orientation",), _nifti(sform=0), C),  # noqa: E501
        Probe("import-ct --bone-iso below --skin-iso", imp("v.nii", "--bone-iso", "-500"), "error", ("--bone-iso", "--skin-iso"), _nifti(), C),  # noqa: E501
        Probe("import-ct --bone-iso nan", imp("v.nii", "--bone-iso", "nan"), "error", ("--bone-iso",), _nifti(), C),  # noqa: E501
        Probe("import-ct --skin-iso inf", imp("v.nii", "--skin-iso", "inf"), "error", ("--skin-iso",), _nifti(), C),  # noqa: E501
        Probe("import-ct --crop reversed", imp("v.nii", "--crop", "40:10,0:76,0:80"), "error", ("crop",), _nifti(), C),  # noqa: E501
        Probe("import-ct --target-faces 0", imp("v.nii", "--target-faces", "0"), "error", ("--target-faces",), _nifti(), C),  # noqa: E501
        Probe("import-ct --out is the volume file", lambda ws: ["import-ct", _in(ws, "v.nii"), "--out", _in(ws, "v.nii")], "error", ("--out",), _nifti(), C),  # noqa: E501
        Probe("import-ct raw --raw-dtype bogus", imp("v.raw", "--raw-shape", "8,8,8", "--raw-dtype", "int17", "--spacing", "1,1,1"), "error", ("--raw-dtype",), lambda ws: _in(ws, "v.raw").write_bytes(bytes(1024)), C),  # noqa: E501
        Probe("import-ct raw --header-bytes -5", imp("v.raw", "--raw-shape", "8,8,8", "--raw-dtype", "int16", "--spacing", "1,1,1", "--header-bytes", "-5"), "error", ("--header-bytes",), lambda ws: _in(ws, "v.raw").write_bytes(bytes(1024)), C),  # noqa: E501
    ]


# -- synth ------------------------------------------------------------------------------------


def _synth(*extra):
    return lambda ws: ["synth", "--out", ws.out, "--subjects", "1", "--photos", "1", "--no-progress", *extra]  # noqa: E501


def _notes_kept(ws):
    ok = (ws.out / "notes.txt").read_text() == "mine" and (ws.out / "dataset.json").is_file()
    return None if ok else "the user's notes.txt was lost or no dataset.json"


def _experiments(*want):
    def check(ws):
        got = json.loads((ws.out / "dataset.json").read_text())["experiments"]
        return None if got == list(want) else f"experiments {got}"
    return check


def _user_notes(ws):
    ws.out.mkdir()
    (ws.out / "notes.txt").write_text("mine")


def synth_probes():
    """``lilium synth``: counts, seeds, experiment letters, output folder, contact sheet."""
    return [
        Probe("synth --subjects 0", _synth("--subjects", "0"), "error", ("--subjects",)),
        Probe("synth --subjects -3", _synth("--subjects", "-3"), "error", ("--subjects",)),
        Probe("synth --subjects 10^9", _synth("--subjects", "1000000000"), "error", ("--subjects",)),  # noqa: E501
        Probe("synth --photos 2.5", _synth("--photos", "2.5"), "error", ("--photos",)),
        Probe("synth --seed -1", _synth("--seed", "-1"), "error", ("--seed",)),
        Probe("synth --seed 2^64", _synth("--seed", str(2**64)), "error", ("--seed",)),
        Probe("synth --workers -1", _synth("--workers", "-1"), "error", ("--workers",)),
        # 0: one worker per core, as lilium experiment's --workers (cli.options)
        Probe("synth --workers 0", _synth("--workers", "0"), "ok", ()),
        Probe("synth --experiments X", _synth("--experiments", "X"), "error", ("--experiments", "X")),  # noqa: E501
        Probe("synth --experiments empty", _synth("--experiments", ","), "error", ("--experiments",)),  # noqa: E501
        Probe("synth --experiments A,A", _synth("--experiments", "A,A"), "error", ("--experiments", "twice")),  # noqa: E501
        Probe("synth --experiments b", _synth("--experiments", "b", "--workers", "1"), "ok", (), check=_experiments("B")),  # noqa: E501
        Probe("synth --out a file", lambda ws: ["synth", "--out", ws.skull / "skull.ply"], "error", ("--out",)),  # noqa: E501
        Probe("synth --out a folder with the user's notes", _synth("--experiments", "A", "--workers", "1"), "ok", (), _user_notes, check=_notes_kept),  # noqa: E501
        Probe("synth --contact-sheet a folder", lambda ws: [*_synth()(ws), "--contact-sheet", ws.out], "error", ("--contact-sheet",)),  # noqa: E501
        Probe("synth --contact-sheet sheet.txt", lambda ws: [*_synth()(ws), "--contact-sheet", ws.out / "sheet.txt"], "error", ("--contact-sheet", ".png")),  # noqa: E501
    ]


# fmt: on


def input_probes():
    return photo_probes() + ct_probes() + synth_probes()
