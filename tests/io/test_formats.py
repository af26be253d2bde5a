"""Landmark files users already have (Slicer, MeshLab, CSV, JSON) and literature aliases."""

import json

import numpy as np
import pytest

from lilium.casework.build import read_skull
from lilium.io.formats import canonical_name, find_landmark_file, read_landmarks

POINTS = {"nasion": [1.0, 2.0, 3.0], "zygion_l": [4.0, 5.0, 6.0], "subspinale": [7, 8, 9.5]}


@pytest.mark.parametrize(
    ("written", "kind", "canonical"),
    [
        ("n", "cranial", "nasion"),
        ("Nasion", "facial", "nasion"),
        ("N", "cranial", "nasion"),
        ("gn", "cranial", "gnathion"),
        ("Pog", "cranial", "pogonion"),
        ("pg'", "facial", "pogonion"),
        ("soft tissue pogonion", "facial", "pogonion"),
        ("g", "facial", "glabella"),
        ("ex_l", "facial", "exocanthion_l"),
        ("exR", "facial", "exocanthion_r"),
        ("Ex (L)", "facial", "exocanthion_l"),
        ("left ex", "facial", "exocanthion_l"),
        ("R. Zygion", "cranial", "zygion_r"),
        ("zy-right", "cranial", "zygion_r"),
        ("ZygionL", "cranial", "zygion_l"),
        ("GoR", "cranial", "gonion_r"),
        ("al_l", "facial", "alare_l"),
        ("ftR", "cranial", "frontotemporale_r"),
        ("sn", "facial", "subnasale"),
        ("ls", "facial", "labiale_superius"),
        ("Labrale superius", "facial", "labiale_superius"),
        ("ch_r", "facial", "cheilion_r"),
        ("en l", "facial", "endocanthion_l"),
        ("Lateral canthus R", "facial", "exocanthion_r"),
        ("ec_l", "cranial", "ectoconchion_l"),
        ("dR", "cranial", "dacryon_r"),
        ("pr", "cranial", "prosthion"),
        ("ss", "cranial", "subspinale"),
        ("A point", "cranial", "subspinale"),
        ("id", "cranial", "infradentale"),
        ("PoL", "cranial", "porion_l"),
        ("po_r", "cranial", "porion_r"),
        ("Or-L", "cranial", "orbitale_l"),
        ("mf r", "cranial", "mental_foramen_r"),
        ("mental_foramen_l", "cranial", "mental_foramen_l"),
        ("frontotemporale_l", "facial", "frontotemporale_l"),
    ],
)
def test_aliases_map_to_canonical_names(written, kind, canonical):
    assert canonical_name(written, kind) == canonical


@pytest.mark.parametrize(
    ("written", "kind"),
    [
        ("sn", "cranial"),  # subnasale is on the skin; the bone has subspinale
        ("ss", "facial"),
        ("ex_l", "cranial"),  # exocanthion is facial; the bone has ectoconchion
        ("ec_l", "facial"),
        ("pr", "facial"),
        ("ls", "cranial"),
        ("pg'", "cranial"),
        ("zygion", "cranial"),  # no side
        ("F-1", "cranial"),
    ],
)
def test_names_are_per_set_and_sides_required(written, kind):
    assert canonical_name(written, kind) is None


def _write(path, text):
    path.write_text(text)
    return path


def _check(points):
    assert set(points) == set(POINTS)
    for name, value in POINTS.items():
        np.testing.assert_allclose(points[name], value)


def test_slicer_mrk_json(tmp_path):
    labels = {"nasion": "n", "zygion_l": "Zy_L", "subspinale": "A point"}
    doc = {
        "@schema": "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/"
        "Markups/Resources/Schema/markups-schema-v1.0.3.json#",
        "markups": [
            {
                "type": "Fiducial",
                "coordinateSystem": "LPS",
                "coordinateUnits": "mm",
                "controlPoints": [
                    {"id": str(k), "label": labels[n], "position": p, "positionStatus": "defined"}
                    for k, (n, p) in enumerate(POINTS.items())
                ]
                + [{"id": "9", "label": "gn", "positionStatus": "undefined"}],
            }
        ],
    }
    _check(read_landmarks(_write(tmp_path / "s.mrk.json", json.dumps(doc)), "cranial"))
    # RAS points come back in LPS (Slicer's mesh frame): x and y negated.
    doc["markups"][0]["coordinateSystem"] = "RAS"
    ras = read_landmarks(_write(tmp_path / "ras.mrk.json", json.dumps(doc)), "cranial")
    np.testing.assert_allclose(ras["nasion"], [-1, -2, 3])


def test_slicer_fcsv(tmp_path):
    lines = [
        "# Markups fiducial file version = 4.11",
        "# CoordinateSystem = LPS",
        "# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,associatedNodeID",
    ]
    for k, (name, (x, y, z)) in enumerate(POINTS.items()):
        lines.append(f"vtkMRMLMarkupsFiducialNode_{k},{x},{y},{z},0,0,0,1,1,1,0,{name},,")
    _check(read_landmarks(_write(tmp_path / "s.fcsv", "\n".join(lines)), "cranial"))


def test_meshlab_pp(tmp_path):
    names = {"nasion": "N", "zygion_l": "zyL", "subspinale": "ss"}
    points = "".join(
        f'<point x="{x}" y="{y}" z="{z}" active="1" name="{names[n]}"/>'
        for n, (x, y, z) in POINTS.items()
    )
    text = (
        "<!DOCTYPE PickedPoints><PickedPoints><DocumentData><DataFileName name='s.ply'/>"
        f'</DocumentData>{points}<point x="0" y="0" z="0" active="0" name="gn"/></PickedPoints>'
    )
    _check(read_landmarks(_write(tmp_path / "s.pp", text), "cranial"))


@pytest.mark.parametrize(
    "text",
    [
        "name,x,y,z\nnasion,1,2,3\nzygion_l,4,5,6\nsubspinale,7,8,9.5\n",
        "nasion,1,2,3\nZy L,4,5,6\nss,7,8,9.5\n",
        "x;y;z;label\n1;2;3;N\n4;5;6;zygion_l\n7;8;9.5;subspinale\n",
    ],
)
def test_csv(tmp_path, text):
    _check(read_landmarks(_write(tmp_path / "s.csv", text), "cranial"))


def test_facial_csv_and_json(tmp_path):
    csv_points = read_landmarks(
        _write(tmp_path / "f.csv", "name,u,v\nn,10,20\nexR,30,40\n"), "facial"
    )
    assert set(csv_points) == {"nasion", "exocanthion_r"}
    np.testing.assert_allclose(csv_points["exocanthion_r"], [30, 40])
    flat = read_landmarks(_write(tmp_path / "f.json", '{"sn": [1, 2], "ls": [3, 4]}'), "facial")
    assert set(flat) == {"subnasale", "labiale_superius"}
    spec = read_landmarks(
        _write(tmp_path / "g.json", '{"landmarks": {"nasion": [1, 2, 3]}}'), "cranial"
    )
    np.testing.assert_allclose(spec["nasion"], [1, 2, 3])


@pytest.mark.parametrize(
    ("name", "text", "match"),
    [
        ("a.csv", "nasoin,1,2,3\n", r"a.csv: line 1: unknown cranial landmark 'nasoin'; did you "),
        ("a.csv", "zygion,1,2,3\n", r"'zygion' \(zygion\) needs a side; write zygion_l"),
        ("a.csv", "sn,1,2,3\n", r"'sn' is a facial landmark \(subnasale\) but this file holds"),
        ("a.csv", "nasion,1,nan,3\n", r"a.csv: line 1: 'nasion' has NaN"),
        ("a.csv", "nasion,1,2\n", r"a.csv: line 1: expected a name and 3 coordinates"),
        ("a.csv", "nasion,1,x,3\n", r"'nasion' must have 3 numeric coordinates"),
        ("a.csv", "n,1,2,3\nnasion,1,2,3\n", r"'nasion' and 'n' are both nasion; keep one"),
        ("a.csv", "", r"a.csv: no landmarks found"),
        ("a.pp", "<PickedPoints><point", r"not a valid MeshLab .pp file"),
        ("a.mrk.json", "{", r"not valid JSON"),
        ("a.json", '{"n": [1, 2, 3], "n": [1, 2, 4]}', r"a.json: the key 'n' appears twice"),
        (
            "a.json",
            '{"landmarks": {"g": [1, 2, 3], "glabella": [1, 2, 3]}}',
            r"a.json: landmarks: "
            r"'glabella' and 'g' are both glabella",
        ),
        ("a.mrk.json", '{"markups": []}', r"no 'markups' list"),
        ("a.xyz", "n 1 2 3", r"unknown landmark file type; use .mrk.json"),
    ],
)
def test_bad_files_name_the_file_the_field_and_the_fix(tmp_path, name, text, match):
    with pytest.raises(ValueError, match=match):
        read_landmarks(_write(tmp_path / name, text), "cranial")


def test_missing_file(tmp_path):
    with pytest.raises(ValueError, match=r"nope.fcsv: file not found"):
        read_landmarks(tmp_path / "nope.fcsv", "cranial")


def test_subject_folder_with_a_slicer_file_instead_of_the_json(case):
    subject_dir, _ = case
    spec = json.loads((subject_dir / "cranial_landmarks.json").read_text())["landmarks"]
    (subject_dir / "cranial_landmarks.json").unlink()
    lines = ["# CoordinateSystem = LPS"]
    lines += [
        f"p{k},{x},{y},{z},0,0,0,1,1,1,0,{n},," for k, (n, (x, y, z)) in enumerate(spec.items())
    ]
    (subject_dir / "skull.fcsv").write_text("\n".join(lines))
    assert find_landmark_file(subject_dir, ["cranial_landmarks", "skull"]).name == "skull.fcsv"
    skull = read_skull(subject_dir)
    assert set(skull.landmarks_mm) == set(spec)
    (subject_dir / "other.pp").write_text("<PickedPoints/>")
    (subject_dir / "skull.fcsv").rename(subject_dir / "mine.fcsv")
    with pytest.raises(ValueError, match=r"several landmark files \(mine.fcsv, other.pp\)"):
        read_skull(subject_dir)


def _fcsv(path, system_line, points):
    lines = ["# Markups fiducial file version = 4.11"] + ([system_line] if system_line else [])
    lines.append("# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,associatedNodeID")
    for k, (name, (x, y, z)) in enumerate(points.items()):
        lines.append(f"vtkMRMLMarkupsFiducialNode_{k},{x},{y},{z},0,0,0,1,1,1,0,{name},,")
    return _write(path, "\n".join(lines) + "\n")


def _mrk(path, *systems):
    """A ``.mrk.json`` with one point list per system (None: no ``coordinateSystem`` key)."""
    markups = []
    for system in systems:
        markup = {"type": "Fiducial", "coordinateUnits": "mm", "controlPoints": []}
        if system is not None:
            markup["coordinateSystem"] = system
        markups.append(markup)
    names = list(POINTS)
    for k, name in enumerate(names):
        point = {"label": name, "position": POINTS[name], "positionStatus": "defined"}
        markups[k % len(markups)]["controlPoints"].append(point)
    return _write(path, json.dumps({"markups": markups}))


@pytest.mark.parametrize(
    ("system_line", "sign"),
    [
        (None, 1),  # states none: LPS, Slicer's default (as lilium import-ct reads it)
        ("# CoordinateSystem = LPS", 1),
        ("# CoordinateSystem = 1", 1),
        ("# CoordinateSystem = RAS", -1),
        ("# CoordinateSystem = 0", -1),
    ],
)
def test_slicer_fcsv_frames(tmp_path, system_line, sign):
    points = read_landmarks(_fcsv(tmp_path / "s.fcsv", system_line, POINTS), "cranial")
    for name, value in POINTS.items():
        np.testing.assert_allclose(points[name], np.array(value) * [sign, sign, 1])


@pytest.mark.parametrize("system", [None, "", "LPS", "RAS"])
def test_slicer_mrk_json_frames(tmp_path, system):
    points = read_landmarks(_mrk(tmp_path / "s.mrk.json", system), "cranial")
    sign = -1 if system == "RAS" else 1  # no key or "": LPS, the schema's default
    np.testing.assert_allclose(points["nasion"], np.array(POINTS["nasion"]) * [sign, sign, 1])


def test_a_slicer_frame_slicer_does_not_write_is_refused(tmp_path):
    fcsv = _fcsv(tmp_path / "s.fcsv", "# CoordinateSystem = XYZ", POINTS)
    with pytest.raises(ValueError, match=r"s\.fcsv: coordinate system 'XYZ' is not one 3D Slicer"):
        read_landmarks(fcsv, "cranial")
    mrk = _mrk(tmp_path / "s.mrk.json", "IJK")
    with pytest.raises(ValueError, match=r"'IJK' .* e\.g\. \"coordinateSystem\": \"LPS\""):
        read_landmarks(mrk, "cranial")
    mixed = _mrk(tmp_path / "m.mrk.json", "LPS", "RAS")
    with pytest.raises(ValueError, match=r"markups\[0\] is in LPS and markups\[1\] in RAS"):
        read_landmarks(mixed, "cranial")
    broken = _write(tmp_path / "b.mrk.json", json.dumps({"markups": [{"controlPoints": {"x": 1}}]}))
    with pytest.raises(ValueError, match=r"controlPoints is not a list of points"):
        read_landmarks(broken, "cranial")


def test_lilium_case_reads_slicer_frames_as_import_ct_does(case, tmp_path, capsys):
    """Issue 25: an unknown CoordinateSystem was read as LPS by ``lilium case``; now it is
    refused in one line (as ``lilium import-ct`` refuses it), an absent one is LPS and RAS is
    converted."""
    from cli_helpers import _one_line_error, _run

    subject_dir, photo_dir = case
    cranial = json.loads((subject_dir / "cranial_landmarks.json").read_text())["landmarks"]
    ras = {k: [-v[0], -v[1], v[2]] for k, v in cranial.items()}

    def argv(landmarks, out):
        files = ["--skull", subject_dir / "skull.ply", "--landmarks", landmarks]
        return [
            "case",
            *files,
            "--photo",
            photo_dir,
            "--method",
            "posest-sfo",
            "--out",
            tmp_path / out,
        ]

    bad = _fcsv(tmp_path / "skull.fcsv", "# CoordinateSystem = XYZ", cranial)
    _one_line_error(capsys, argv(bad, "o1"), bad, "coordinate system 'XYZ'", "LPS or RAS")
    for name, system, points in [("none", None, cranial), ("ras", "# CoordinateSystem = RAS", ras)]:
        landmarks = _fcsv(tmp_path / f"{name}.fcsv", system, points)
        code, _, err = _run(argv(landmarks, name), capsys)
        assert code == 0, err
        result = json.loads(
            (tmp_path / name / "standin_frontal" / "posest-sfo" / "result.json").read_text()
        )
        assert result["camera"] is not None and result["landmark_error"]["mean_px"] < 5


def test_a_landmark_folder_is_not_reported_missing(tmp_path):
    with pytest.raises(ValueError, match="is a folder, not a landmark file"):
        read_landmarks(tmp_path, "facial")
