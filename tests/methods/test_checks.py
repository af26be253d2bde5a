"""docs/checks.md checks: left and right of skulls and photos, the skull-faces-camera rule, the
declared view, the priors' warnings and provenance, the landmark error, the focal cap."""

from dataclasses import replace

import numpy as np
import pytest

from lilium.casework.build import read_photo, read_skull
from lilium.geometry.camera import Camera, principal_point_of
from lilium.geometry.rotations import rotvec_to_matrix
from lilium.inputs import Photo, Priors
from lilium.methods import SfoOptions, run_sfo
from lilium.methods.checks import (
    check_inputs,
    check_photo_labels,
    check_skull_labels,
    facing_angle_deg,
    facing_check,
    label_handedness,
    landmark_error,
    skull_directions,
)
from lilium.methods.lilium import lilium_sfo
from lilium.methods.pairs import correspondences
from lilium.methods.posest_sfo import mean_depth_landmarks, posest_sfo
from lilium.methods.prior_checks import priors_record
from lilium.softtissue.landmarks import side, twin

MIRROR = np.diag([-1.0, 1.0, 1.0])


def _swapped(points):
    return {(twin(k) if side(k) else k): v for k, v in points.items()}


def _mirrored(points):
    return {k: MIRROR @ np.asarray(v, float) for k, v in points.items()}


@pytest.fixture
def standin(case):
    subject_dir, photo_dir = case
    skull = read_skull(subject_dir)
    skull = replace(skull, landmarks_file=str(subject_dir / "cranial_landmarks.json"))
    photo = read_photo(photo_dir, load_image=False)
    photo = replace(photo, landmarks_file=str(photo_dir / "photo.json"))
    return skull, photo


def test_skull_and_its_mirror_image(standin):
    skull, _ = standin
    assert label_handedness(skull.landmarks_mm, skull.vertices_mm) > 0.9
    check_skull_labels(skull)
    # The mirror image of the skull (mesh, landmarks, axes) with _l/_r swapped is a valid skull.
    mirror = replace(
        skull,
        vertices_mm=skull.vertices_mm @ MIRROR.T,
        faces=skull.faces[:, ::-1],
        landmarks_mm=_swapped(_mirrored(skull.landmarks_mm)),
        axes=_swapped(_mirrored(skull.axes)),
    )
    assert label_handedness(mirror.landmarks_mm, mirror.vertices_mm) > 0.9
    check_skull_labels(mirror)
    # Swapped labels only, or a mirrored mesh whose labels moved with it: an error naming the file.
    only_labels = replace(skull, landmarks_mm=_swapped(skull.landmarks_mm))
    only_mesh = replace(
        mirror, landmarks_mm=_mirrored(skull.landmarks_mm), axes=_mirrored(skull.axes)
    )
    for bad in (only_labels, only_mesh):
        assert label_handedness(bad.landmarks_mm, bad.vertices_mm) < -0.9
        with pytest.raises(ValueError, match=r"cranial_landmarks\.json: left and right are mirr"):
            check_skull_labels(bad)
    with pytest.raises(ValueError, match="swap every _l and _r name"):
        run_sfo("posest-sfo", only_labels, standin[1])


def test_photo_and_its_mirror_image(standin):
    skull, photo = standin
    check_photo_labels(photo)
    width = photo.image_size_wh[0]
    flipped = {k: np.array([width - 1 - uv[0], uv[1]]) for k, uv in photo.landmarks_uv.items()}
    # A mirrored photo (a selfie) with its labels on the anatomy: every pair reversed.
    selfie = replace(photo, landmarks_uv=flipped)
    with pytest.raises(ValueError, match=r"photo\.json: in this frontal photo every _l landmark"):
        check_inputs(skull, selfie)
    with pytest.raises(ValueError, match="flip the image"):
        run_sfo("posest-sfo", skull, selfie)
    # Its labels swapped too, it is a valid photo of the mirrored face.
    check_photo_labels(replace(photo, landmarks_uv=_swapped(flipped)))
    # Lateral views show one side only: not checked.
    check_photo_labels(replace(selfie, view="lateral_left"))


def test_a_photo_with_some_pairs_swapped_or_upside_down(standin):
    skull, photo = standin
    lm = dict(photo.landmarks_uv)
    # One slip: zygion's _l and _r exchanged (the others right): a camera 68 px off and a
    # confident exclusion of the true person, before this check.
    slip = {**lm, "zygion_l": lm["zygion_r"], "zygion_r": lm["zygion_l"]}
    with pytest.raises(ValueError, match=r"zygion_l lie left of their _r twins.*swap _l and _r"):
        check_inputs(skull, replace(photo, landmarks_uv=slip))
    # Turned 180 degrees with its landmarks: every pair reversed, and the forehead below the
    # chin: upside down, not mirrored.
    w, h = photo.image_size_wh
    turned = {k: np.array([w - 1 - uv[0], h - 1 - uv[1]]) for k, uv in lm.items()}
    with pytest.raises(ValueError, match="upside down"):
        check_inputs(skull, replace(photo, landmarks_uv=turned))
    flipped = {k: np.array([uv[0], h - 1 - uv[1]]) for k, uv in lm.items()}  # top to bottom
    for view in ("frontal", "lateral_left"):
        with pytest.raises(ValueError, match="upside down or flipped top to bottom"):
            check_photo_labels(replace(photo, landmarks_uv=flipped, view=view))


def test_skull_faces_camera_rule(standin):
    skull, photo = standin
    truth = read_ground_truth_camera(photo)
    directions = skull_directions(skull.landmarks_mm, skull.vertices_mm)
    assert directions.origin_source == "mesh centroid"  # the stand-in has no porion
    assert facing_angle_deg(directions, truth.R, truth.t)[0] < 20
    check = facing_check(skull)
    # The same camera turned 180 deg about the skull's vertical axis looks at the back.
    behind = truth.R @ rotvec_to_matrix([0.0, np.pi, 0.0])
    angles = facing_angle_deg(directions, np.stack([truth.R, behind]), np.stack([truth.t] * 2))
    assert angles[1] > 160
    assert check(np.stack([truth.R, behind]), np.stack([truth.t] * 2)).tolist() == [True, False]


def read_ground_truth_camera(photo):
    from lilium.io.truth import read_ground_truth

    return read_ground_truth(photo.landmarks_file.rsplit("/", 1)[0]).camera


def test_lilium_refuses_a_camera_behind_the_skull(standin):
    skull, photo = standin
    mirrored = replace(
        skull,
        landmarks_mm=_swapped(skull.landmarks_mm),
        axes=_swapped(skull.axes),
        landmarks_file="skull/cranial_landmarks.json",
    )
    options = SfoOptions(variant="base").with_de(max_generations=5, population_size=10)
    # Bypassing the checks before the SFO (run_sfo would stop it there): no camera from behind.
    result = lilium_sfo(mirrored, photo, options, seed=0)
    directions = skull_directions(mirrored.landmarks_mm, mirrored.vertices_mm)
    if result:  # when no member had a camera, each took its own POSEST, which sees the front
        assert result.extra["no_camera_evaluations"] >= 1
        assert facing_angle_deg(directions, result.camera.R, result.camera.t)[0] <= 110
    else:
        assert "behind the skull" in result.error
        assert "left and right swapped in skull/cranial_landmarks.json" in result.error
    pose = posest_sfo(mirrored, photo)
    if pose:  # any camera POSEST-SFO returns sees the front of the skull
        assert facing_angle_deg(directions, pose.camera.R, pose.camera.t)[0] <= 120


def test_wrong_view_gives_view_mismatch(standin):
    skull, photo = standin
    right = run_sfo("posest-sfo", skull, photo)
    assert "view_mismatch" not in [w.code for w in right.warnings]
    wrong = run_sfo("posest-sfo", skull, replace(photo, view="lateral_left"))
    mismatch = [w for w in wrong.warnings if w.code == "view_mismatch"]
    assert len(mismatch) == 1
    assert "declares the view 'lateral_left'" in mismatch[0].message
    assert "in front of the face" in mismatch[0].message
    assert wrong.to_dict()["warnings"][-1]["code"] == "view_mismatch"


def test_no_priors_warn_and_say_none(standin):
    skull, photo = standin
    bare = replace(photo, priors=Priors())
    result = run_sfo("posest-sfo", skull, bare)
    codes = [w.code for w in result.warnings]
    assert codes == ["no_focal_prior", "no_scd_prior"]
    data = result.to_dict()
    assert data["priors"]["focal_px"] == {"range": None, "source": "none"}
    assert data["priors"]["scd_mm"] == {"range": None, "source": "none"}
    assert data["priors"]["head_rotation"]["source"] == "none"
    given = priors_record(replace(photo, prior_sources={"focal_px": "command line"}))
    assert given["focal_px"]["source"] == "command line"
    assert given["scd_mm"]["source"] == "photo.json"
    assert given["focal_px"]["range"] == pytest.approx([0.95 * 2600, 1.05 * 2600])


def test_camera_outside_a_prior(standin):
    skull, photo = standin
    far = replace(photo, priors=replace(photo.priors, focal_px=(5000.0, 5200.0)))
    result = run_sfo("posest-sfo", skull, far)  # POSEST-SFO does not use the priors
    outside = [w.message for w in result.warnings if w.code == "outside_prior"]
    assert any("focal length" in m and "5000-5200 px" in m for m in outside)


def test_landmark_error_in_mm_at_each_depth():
    camera = Camera.from_rt(np.eye(3), [0.0, 0.0, 0.0], 1000.0, [0.0, 0.0])
    facial = {"nasion": [0.0, 0.0, 500.0], "pogonion": [0.0, 0.0, 2000.0]}
    photo = Photo("p", (10, 10), "frontal", {"nasion": [3.0, 4.0], "pogonion": [0.0, 2.0]})
    error = landmark_error(Camera(camera.skull2cam, 1000.0, [0.0, 0.0]), facial, photo)
    assert error["per_landmark_px"] == pytest.approx({"nasion": 5.0, "pogonion": 2.0})
    assert error["mean_px"] == pytest.approx(3.5)
    # 5 px at 500 mm with f = 1000 px is 2.5 mm; 2 px at 2000 mm is 4 mm.
    assert error["mean_mm"] == pytest.approx((2.5 + 4.0) / 2)


def test_every_method_reports_a_landmark_error(standin):
    skull, photo = standin
    options = SfoOptions(variant="base").with_de(max_generations=3, population_size=8)
    for method in ("posest-sfo", "lilium"):
        data = run_sfo(method, skull, photo, options).to_dict()
        error = data["landmark_error"]
        assert set(error) == {"mean_px", "mean_mm", "per_landmark_px"}
        assert 0 < error["mean_mm"] < error["mean_px"]  # ~0.35 mm per px at 900 mm, 2600 px
        assert len(error["per_landmark_px"]) == len(data["facial_landmarks_3d"])


def _long_lens_photo(skull, photo, focal_px=33_000.0, size_wh=(6000, 4000)):
    """The stand-in seen through a 200 mm full-frame lens on a 6,000 px photo (f = 33,000 px),
    its landmarks exactly where POSEST-SFO's facial landmarks project."""
    corr = correspondences(skull, photo)
    facial = mean_depth_landmarks(corr)
    truth = read_ground_truth_camera(photo)
    R = truth.R
    distance_mm = 900.0 * focal_px / 2600.0
    t = np.array([0.0, 0.0, distance_mm]) - R @ facial[corr.facial_names.index("nasion")]
    camera = Camera.from_rt(R, t, focal_px, principal_point_of(size_wh))
    uv = camera.project(facial)
    return Photo(
        "long_lens",
        size_wh,
        "frontal",
        dict(zip(corr.facial_names, uv, strict=True)),
        landmarks_file="long_lens/photo.json",
    )


def test_focal_cap_with_and_without_a_prior(standin):
    skull, photo = standin
    bare = _long_lens_photo(skull, photo)
    with_prior = replace(bare, priors=Priors(focal_px=(31_350.0, 34_650.0)))
    # With the prior the cap is 2 x 34,650 px: POSEST-SFO finds the camera.
    found = run_sfo("posest-sfo", skull, with_prior)
    assert found.camera.focal_px == pytest.approx(33_000.0, rel=1e-6)
    assert [w.code for w in found.warnings] == ["no_scd_prior"]
    # Without it the 10,000 px cap refuses that camera, and says how to lift it.
    capped = run_sfo("posest-sfo", skull, bare)
    assert not capped
    assert "exceeds the 10000 px limit" in capped.error
    assert "give the focal prior (a photo with EXIF, or --focal-px LO HI)" in capped.error
    # Lilium: the same, through P_cam's cap.
    options = SfoOptions(variant="base").with_de(max_generations=20, population_size=10)
    lifted = lilium_sfo(skull, with_prior, options, seed=0)
    assert lifted and lifted.camera.focal_px > 25_000.0  # above the 10,000 px default cap
    assert lifted.terms["p_cam"] < 1e8
    stuck = lilium_sfo(skull, bare, options, seed=0)
    message = stuck.error if not stuck else " ".join(w.message for w in stuck.warnings)
    assert "give the focal prior (a photo with EXIF, or --focal-px LO HI)" in message
