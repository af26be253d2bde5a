"""The headsq real-anatomy case (benchmarks/datasets/headsq_case.py, issue 27).

Skips where ``../shared/data/headsq`` (the CT beside the repository) is absent.
"""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks" / "datasets"))
import headsq_case  # noqa: E402
import headsq_ct  # noqa: E402

pytestmark = pytest.mark.skipif(
    headsq_ct.data_dir() is None, reason="no headsq CT in ../shared/data/headsq"
)

#: Landmarks the rules place (module notes of headsq_landmarks): 18 cranial, 17 facial; without
#: the mandible 5 cranial ones fewer.
N_CRANIAL = 18
N_FACIAL = 17
MANDIBLE = {"infradentale", "pogonion", "gnathion", "gonion_l", "gonion_r"}

#: POSEST-SFO on the Exp. A frontal photo hq_f00 of seed 0 (true axes, mean depths): BPE
#: measured 2.63 mm (frontal photos of the complete skull, Exp. A and B: 0.9-2.6 mm); the
#: tolerance leaves room for another platform's numerics, not for a misplaced landmark or a
#: mirrored frame (those give 5 mm and more).
FRONTAL_BPE_MM = 3.5


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    out = tmp_path_factory.mktemp("headsq")
    root = headsq_case.build_headsq_dataset(out, n_photos=1, seed=0, experiments=("A",))
    assert root == out
    return root


def _landmarks(path):
    return json.loads(path.read_text())["landmarks"]


def test_dataset_index_lists_both_variants(case):
    from lilium.experiments.dataset import check_index

    index = json.loads((case / "dataset.json").read_text())
    check_index(index, case / "dataset.json")
    assert [s["id"] for s in index["subjects"]] == ["hq", "hq_nm"]
    assert index["subjects"][1]["mandible"] is False
    views = sorted(p["view"] for p in index["photos"] if p["subject"] == "hq")
    assert views[0] == "frontal" and views[1].startswith("lateral")


@pytest.mark.parametrize("subject", ["hq", "hq_nm"])
def test_landmarks_are_mesh_vertices(case, subject):
    from lilium.io.mesh import read_mesh

    folder = case / "subjects" / subject
    cranial = _landmarks(folder / "cranial_landmarks.json")
    facial = _landmarks(folder / "facial_landmarks.json")
    expected = N_CRANIAL - (len(MANDIBLE) if subject == "hq_nm" else 0)
    assert len(cranial) == expected
    assert len(facial) == N_FACIAL
    assert not (MANDIBLE & set(cranial)) if subject == "hq_nm" else MANDIBLE <= set(cranial)
    for mesh, points in (("skull.ply", cranial), ("face.ply", facial)):
        vertices = read_mesh(folder / mesh)[0]
        for name, p in points.items():
            gap = np.min(np.linalg.norm(vertices - np.asarray(p), axis=1))
            assert gap < 1e-3, f"{subject} {name} is {gap:.3f} mm from every vertex of {mesh}"


def test_landmarks_are_anatomically_ordered(case):
    """Coarse sanity of the placement: midline at x = 0, left at +x, eyes above the mouth."""
    cranial = _landmarks(case / "subjects" / "hq" / "cranial_landmarks.json")
    facial = _landmarks(case / "subjects" / "hq" / "facial_landmarks.json")
    for name in ("nasion", "subspinale", "prosthion", "pogonion", "gnathion"):
        assert abs(cranial[name][0]) < 4.0, name
    for base in ("ectoconchion", "zygion", "gonion", "alare", "dacryon"):
        assert cranial[f"{base}_l"][0] > 5.0 > -5.0 > cranial[f"{base}_r"][0], base
    heights = [cranial[n][1] for n in ("nasion", "subspinale", "prosthion", "pogonion")]
    assert heights == sorted(heights, reverse=True)
    assert facial["exocanthion_l"][1] > facial["subnasale"][1] > facial["labiale_superius"][1]
    for name, p in facial.items():  # the skin lies in front of / outside the bone
        c = cranial.get(name)
        if c is not None and name in ("nasion", "pogonion", "gnathion"):
            assert p[2] > c[2], name


def test_photos_show_a_whole_head(case):
    """The CT's cut above the orbits is domed over in the skin (headsq_ct, module notes 4): the
    skin rises DOME_MM above the cut skull at its top, and its rim stays where the cut was."""
    from lilium.io.mesh import read_mesh

    folder = case / "subjects" / "hq"
    skull = read_mesh(folder / "skull.ply")[0]
    skin = read_mesh(folder / "face.ply")[0]
    rise = skin[:, 1].max() - skull[:, 1].max()
    assert headsq_ct.DOME_MM - 2.0 < rise < headsq_ct.DOME_MM + 2.0
    # the cut skull's rim lies inside the skin's outline seen from the front and the side
    top = skull[skull[:, 1] > skull[:, 1].max() - 2.0]
    near = skin[np.abs(skin[:, 1] - top[:, 1].mean()) < 3.0]
    assert np.abs(top[:, 0]).max() < np.abs(near[:, 0]).max()
    assert near[:, 2].min() < top[:, 2].min() and top[:, 2].max() < near[:, 2].max()


def test_posest_sfo_recovers_the_frontal_camera(case, tmp_path, capsys):
    from lilium.cli.main import main
    from lilium.evaluation.metrics import back_projection_error_from_dicts
    from lilium.geometry.camera import Camera

    photo = case / "photos" / "A" / "hq_f00"
    subject = case / "subjects" / "hq"
    out = tmp_path / "sfo"
    argv = ["sfo", "--skull", str(subject), "--photo", str(photo), "--method", "posest-sfo"]
    code = main(argv + ["--out", str(out), "--no-overlay"])
    capsys.readouterr()
    assert code == 0
    result = json.loads((out / "result.json").read_text())
    assert result["camera"] is not None, result.get("error")
    truth = json.loads((photo / "photo.json").read_text())["ground_truth"]
    facial = _landmarks(subject / "facial_landmarks.json")
    bpe = back_projection_error_from_dicts(
        facial, truth["landmarks_noise_free"], Camera.from_dict(result["camera"])
    )
    assert bpe < FRONTAL_BPE_MM


def test_absent_data_builds_nothing(tmp_path):
    assert headsq_ct.data_dir(tmp_path / "nowhere") is None
    assert headsq_case.build_headsq_dataset(tmp_path / "x", data=tmp_path / "nowhere") is None
    assert not (tmp_path / "x").exists()
