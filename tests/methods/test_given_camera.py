"""Scoring a given camera without search (an examiner's, ``--camera``): ``run_sfo(camera=...)``,
``lilium sfo --camera`` and ``lilium case --camera PHOTO=FILE``."""

import json
from dataclasses import replace

import numpy as np
import pytest

from cli_helpers import _one_line_error, _run, _sfo
from lilium.casework.build import read_photo, read_skull
from lilium.geometry.camera import Camera
from lilium.geometry.rotations import geodesic_angle_deg, rotvec_to_matrix
from lilium.inputs import GivenCamera
from lilium.methods import SfoOptions, run_sfo

FAST = SfoOptions(variant="skof+pll").with_de(max_generations=60, population_size=16)


def _inputs(case):
    subject_dir, photo_dir = case
    return read_skull(subject_dir), read_photo(photo_dir)


def _turned(camera, skull, yaw_deg):
    """``camera`` with the skull turned by ``yaw_deg`` about the camera's vertical axis through
    the skull's landmarks' centre."""
    centre = np.mean(list(skull.landmarks_mm.values()), axis=0)
    turn = rotvec_to_matrix(np.radians([0.0, yaw_deg, 0.0]))
    R = turn @ camera.R
    t = camera.R @ centre + camera.t - R @ centre
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return Camera(T, camera.focal_px, camera.principal_point_px)


def test_posest_sfo_reproduces_its_own_camera(case):
    skull, photo = _inputs(case)
    searched = run_sfo("posest-sfo", skull, photo)
    scored = run_sfo("posest-sfo", skull, photo, camera=GivenCamera(searched.camera))
    assert scored.camera_source == "examiner" and searched.camera_source == "search"
    assert scored.fitness == pytest.approx(searched.fitness, rel=1e-9)
    assert scored.terms["mse_pix"] == pytest.approx(searched.terms["mse_pix"], rel=1e-9)
    assert scored.landmark_error["mean_px"] == pytest.approx(
        searched.landmark_error["mean_px"], rel=1e-9
    )


def test_a_turned_camera_scores_worse(case):
    skull, photo = _inputs(case)
    searched = run_sfo("posest-sfo", skull, photo)
    turned = _turned(searched.camera, skull, 5.0)
    assert geodesic_angle_deg(turned.R, searched.camera.R) == pytest.approx(5.0, abs=1e-9)
    scored = run_sfo("posest-sfo", skull, photo, camera=GivenCamera(turned))
    assert scored.fitness > 2 * searched.fitness
    assert scored.landmark_error["mean_px"] > searched.landmark_error["mean_px"]


def test_lilium_scores_the_given_soft_tissue_or_fits_one(case):
    """With the soft tissue the camera came with (the SFO's own), its fitness and terms come
    back; a bare camera gets the best soft tissue under it (the DE over the cones only): the
    same camera and image terms, a reprojection error no larger, and the same seed gives the
    same result."""
    skull, photo = _inputs(case)
    searched = run_sfo("lilium", skull, photo, FAST, seed=3)
    own = GivenCamera(searched.camera, searched.facial_landmarks_mm)
    scored = run_sfo("lilium", skull, photo, FAST, seed=3, camera=own)
    assert scored.extra["soft_tissue"] == "given"
    assert scored.fitness == pytest.approx(searched.fitness, rel=1e-9)
    for term, value in searched.terms.items():
        assert scored.terms[term] == (
            None if value is None else pytest.approx(value, rel=1e-9, abs=1e-12)
        )
    bare = GivenCamera(searched.camera)
    fitted = run_sfo("lilium", skull, photo, FAST, seed=3, camera=bare)
    again = run_sfo("lilium", skull, photo, FAST, seed=3, camera=bare)
    assert fitted.extra["soft_tissue"] == "fitted" and fitted.fitness == again.fitness
    np.testing.assert_array_equal(fitted.camera.skull2cam, searched.camera.skull2cam)
    assert searched.terms["p_skof"] is not None
    for term in ("p_skof", "p_pll", "p_cam"):
        if searched.terms[term] is None:
            assert fitted.terms[term] is None
        else:
            assert fitted.terms[term] == pytest.approx(searched.terms[term], rel=1e-9, abs=1e-12)
    assert fitted.terms["mse_pix"] <= searched.terms["mse_pix"] + 1e-9
    turned = _turned(searched.camera, skull, 5.0)
    moved = run_sfo("lilium", skull, photo, FAST, seed=3, camera=replace(own, camera=turned))
    assert moved.landmark_error["mean_px"] > scored.landmark_error["mean_px"]
    assert moved.fitness > scored.fitness


def _camera_file(path, camera):
    path.write_text(json.dumps(camera.to_dict()))
    return path


def test_sfo_camera_option_reproduces_lilium_from_its_result(case, tmp_path, capsys):
    fast = ["--method", "lilium", "--generations", "40", "--population", "12"]
    assert _run(_sfo(case, tmp_path / "search", *fast), capsys)[0] == 0
    result = json.loads((tmp_path / "search" / "result.json").read_text())
    given = tmp_path / "search" / "result.json"
    assert _run(_sfo(case, tmp_path / "own", *fast, "--camera", given), capsys)[0] == 0
    own = json.loads((tmp_path / "own" / "result.json").read_text())
    assert own["camera_source"] == "examiner" and own["soft_tissue"] == "given"
    assert own["fitness"] == pytest.approx(result["fitness"], rel=1e-9)
    assert own["identification"]["log10_lr"] == pytest.approx(
        result["identification"]["log10_lr"], rel=1e-9
    )
    # A chosen camera's LR is for comparison: it concludes nothing.
    assert "examiner_camera" in own["identification"]["caps"]
    assert own["identification"]["conclusion"] == "undetermined"
    assert "examiner_camera" not in result["identification"]["caps"]


def test_sfo_camera_option(case, tmp_path, capsys):
    code, _, err = _run(_sfo(case, tmp_path / "search"), capsys)
    assert code == 0, err
    result = json.loads((tmp_path / "search" / "result.json").read_text())
    camera = Camera.from_dict(result["camera"])
    good = _camera_file(tmp_path / "camera.json", camera)
    for given in (good, tmp_path / "search" / "result.json"):  # camera.json or result.json
        out = tmp_path / f"scored-{given.stem}"
        code, stdout, err = _run(_sfo(case, out, "--camera", given), capsys)
        assert code == 0, err
        scored = json.loads((out / "result.json").read_text())
        assert scored["camera_source"] == "examiner"
        assert scored["fitness"] == pytest.approx(result["fitness"], rel=1e-9)
        assert "the given camera scored" in stdout
    assert result["camera_source"] == "search"
    # A camera turned half a turn about the vertical: the skull lies behind it.
    behind = np.eye(4)
    behind[:3, :3] = rotvec_to_matrix([0.0, np.pi, 0.0]) @ camera.R
    behind[:3, 3] = -camera.t
    bad = _camera_file(tmp_path / "behind.json", Camera(behind, camera.focal_px,
                                                        camera.principal_point_px))
    _one_line_error(capsys, _sfo(case, tmp_path / "b", "--camera", bad), "behind.json", "behind")
    malformed = tmp_path / "malformed.json"
    malformed.write_text('{"focal_px": 1000, "skull2cam": [[1, 0]]}')
    _one_line_error(capsys, _sfo(case, tmp_path / "m", "--camera", malformed), "malformed.json")
    _one_line_error(
        capsys, _sfo(case, tmp_path / "n", "--camera", tmp_path / "none.json"), "none.json"
    )
    assert not (tmp_path / "b").exists() or not (tmp_path / "b" / "result.json").exists()


def test_case_scores_the_examiner_camera_beside_the_search(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    searched = run_sfo("posest-sfo", *_inputs(case))
    turned = _turned(searched.camera, read_skull(subject_dir), 3.0)
    camera = _camera_file(tmp_path / "camera.json", turned)
    out = tmp_path / "out"
    argv = ["case", "--skull", subject_dir, "--photo", photo_dir, "--method", "posest-sfo",
            "--camera", f"{photo_dir.name}={camera}", "--out", out]
    code, stdout, err = _run(argv, capsys)
    assert code == 0, err
    folder = out / photo_dir.name / "posest-sfo"
    automatic = json.loads((folder / "result.json").read_text())
    examiner = json.loads((folder / "examiner" / "result.json").read_text())
    assert automatic["camera_source"] == "search" and examiner["camera_source"] == "examiner"
    np.testing.assert_allclose(examiner["camera"]["skull2cam"], turned.skull2cam)
    assert examiner["fitness"] > automatic["fitness"]
    report = (out / "report.html").read_text()
    assert "examiner&#x27;s camera" in report or "examiner's camera" in report
    assert "search&#x27;s camera, scored the same way" in report or "scored the same way" in report
    _one_line_error(
        capsys, [*argv[:-2], "--camera", f"nophoto={camera}", "--out", tmp_path / "o2"],
        "--camera", "nophoto",
    )


def test_case_scores_a_workbench_camera_with_its_soft_tissue(case, tmp_path, capsys):
    """A camera saved by the workbench carries the search's soft tissue: Lilium scores it as
    given (the search's own figures compare, so no re-scored search line)."""
    subject_dir, photo_dir = case
    out = tmp_path / "out"
    argv = ["case", "--skull", subject_dir, "--photo", photo_dir, "--method", "lilium",
            "--generations", "30", "--population", "12", "--out", out]
    assert _run(argv, capsys)[0] == 0
    folder = out / photo_dir.name / "lilium-skof+pll"
    searched = json.loads((folder / "result.json").read_text())
    saved = {**searched["camera"], "facial_landmarks_3d": searched["facial_landmarks_3d"]}
    camera = tmp_path / "camera.json"
    camera.write_text(json.dumps(saved))
    assert _run([*argv, "--camera", f"{photo_dir.name}={camera}"], capsys)[0] == 0
    examiner = json.loads((folder / "examiner" / "result.json").read_text())
    assert examiner["soft_tissue"] == "given" and examiner["camera_source"] == "examiner"
    assert examiner["fitness"] == pytest.approx(searched["fitness"], rel=1e-9)
    assert "scored the same way" not in (out / "report.html").read_text()
