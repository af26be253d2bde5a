"""Lilium finds a camera wherever POSEST-SFO does (issue 25, item 3): frontal photos of skulls
without the mandible, with focal, distance and head priors.

On such photos the least-squares camera over all landmarks of a random soft tissue often runs
off towards an infinite focal length (near-coplanar midface landmarks); when every member of the
initial population did, every warm start after it did too and the SFO failed with a message
blaming the labels. The tests reproduce that by making every fit run off."""

from dataclasses import replace

import numpy as np
import pytest

from lilium.cli.main import main
from lilium.io.jsonio import read_json
from lilium.methods import lilium
from lilium.pose.posest import failure
from lilium.synthetic import dataset as ds
from lilium.synthetic.photos import CameraRanges
from lilium.synthetic.toyhead import make_toy_subject, write_toy_subject

DE = ["--generations", "3", "--population", "8"]


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    """A generated skull without the mandible and a frontal photo of the person, with priors."""
    root = tmp_path_factory.mktemp("no_mandible")
    ds.generate_dataset(
        root,
        1,
        1,
        seed=5,
        experiments=("C",),
        workers=1,
        ranges=CameraRanges(image_sizes=((640, 480),)),
        subject_factory=make_toy_subject,
        subject_writer=write_toy_subject,
        no_mandible_share=1.0,
    )
    entry = next(p for p in read_json(root / "dataset.json")["photos"] if p["view"] == "frontal")
    photo_dir = root / entry["paths"]["C"]
    priors = read_json(photo_dir / "photo.json")["priors"]
    assert {"focal_px", "scd_mm", "head_rotation_skull2cam"} <= set(priors)
    subject_dir = root / "subjects" / entry["subject"]
    assert "pogonion" not in read_json(subject_dir / "cranial_landmarks.json")["landmarks"]
    return subject_dir, photo_dir


def _sfo(case, out, method, *extra):
    subject_dir, photo_dir = case
    argv = ["sfo", "--skull", subject_dir, "--photo", photo_dir, "--out", out, "--method", method]
    code = main([str(a) for a in argv + ["--no-overlay", *extra]])
    return code, read_json(out / "result.json")


def _runs_off(monkeypatch, own_posest=False):
    """Every warm-started least-squares fit runs off towards an infinite focal length (as on the
    real photo of issue 25; no point behind the camera); without ``own_posest`` a member's own
    POSEST finds nothing either."""
    refine = lilium.refine_batch

    def run_off(*args, **kwargs):
        fit = refine(*args, **kwargs)
        finite = np.zeros_like(fit.sq_err_px2)
        return replace(
            fit,
            focal_px=np.full_like(fit.focal_px, 2.28e267),
            sq_err_px2=finite,
            cost=np.zeros_like(fit.cost),
        )

    monkeypatch.setattr(lilium, "refine_batch", run_off)
    # The compiled camera stage refines inside its kernel: take the steps one by one (the same
    # numbers, tests/test_kernels_camera.py) so that the patched refinement applies.
    monkeypatch.setattr(
        lilium,
        "camera_terms_compiled",
        lambda problem, genes, members: problem.camera_terms(
            problem.facial_landmarks(genes), members
        ),
    )
    if not own_posest:
        monkeypatch.setattr(lilium.LiliumProblem, "_posest", lambda self, facial_mm: None)


def test_lilium_finds_a_camera_on_a_mandible_less_frontal_photo(case, tmp_path):
    code, posest_sfo = _sfo(case, tmp_path / "posest", "posest-sfo")
    assert code == 0 and posest_sfo["camera"] is not None
    code, result = _sfo(case, tmp_path / "lilium", "lilium", *DE)
    assert code == 0 and result["camera"] is not None and not result["rescued"]
    assert "p_pll" in result["terms_off"]  # no mandible: no chin-jaw curve on the skull


def test_a_population_without_any_camera_gets_posest_sfo_s(case, tmp_path, monkeypatch):
    code, posest_sfo = _sfo(case, tmp_path / "posest", "posest-sfo")
    assert code == 0
    _runs_off(monkeypatch)
    code, result = _sfo(case, tmp_path / "lilium", "lilium", *DE)
    assert code == 0 and result["rescued"] and result["camera"] is not None
    assert result["no_camera_evaluations"] >= 1
    # Every trial ran off, so the best member is POSEST-SFO's soft tissue under its camera.
    assert result["camera"]["focal_px"] == pytest.approx(posest_sfo["camera"]["focal_px"])
    np.testing.assert_allclose(
        result["camera"]["skull2cam"], posest_sfo["camera"]["skull2cam"], atol=1e-9
    )
    for name, xyz in posest_sfo["facial_landmarks_3d"].items():
        np.testing.assert_allclose(result["facial_landmarks_3d"][name], xyz, atol=1e-9)
    assert result["terms"]["mse_pix"] == pytest.approx(posest_sfo["terms"]["mse_pix"])


def test_run_off_members_of_the_first_population_take_their_own_posest(case, tmp_path, monkeypatch):
    _runs_off(monkeypatch, own_posest=True)
    code, result = _sfo(case, tmp_path / "lilium", "lilium", *DE)
    assert code == 0 and result["camera"] is not None
    assert not result["rescued"] and result["fallbacks"] >= 8 and result["no_camera_evaluations"]


def test_no_camera_at_all_does_not_blame_correct_labels(case, tmp_path, monkeypatch):
    _runs_off(monkeypatch)
    monkeypatch.setattr(lilium, "posest", lambda *args, **kwargs: failure("no real sample"))
    # The camera of a fit from the 1 m guess may see the skull from any side: no facing rule.
    monkeypatch.setattr(lilium, "facing_check", lambda skull: None)
    code, result = _sfo(case, tmp_path / "lilium", "lilium", *DE)
    assert code == 1 and result["camera"] is None and not result["rescued"]
    assert "swapped" not in result["error"]
    assert "infinite focal length (2.28e+267 px)" in result["error"]
    assert "landmark pairs lie nearly in one plane" in result["error"]
    assert "mean soft tissue has no camera either" in result["error"]
