"""Every bad input gives a ValueError naming the file, the field and the fix."""

import json

import numpy as np
import pytest

from lilium.casework.build import read_photo, read_skull
from lilium.io.case import read_depth_table
from lilium.io.mesh import write_mesh
from lilium.methods.pairs import correspondences


def _edit_json(path, change):
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data))


def test_reads_a_valid_case(case):
    subject_dir, photo_dir = case
    skull = read_skull(subject_dir)
    photo = read_photo(photo_dir)
    assert skull.id == "standin" and len(skull.landmarks_mm) == 20
    assert photo.view == "frontal" and photo.image_size_wh == (1200, 900)
    assert photo.face_mask.shape == (900, 1200) and photo.face_mask.any()
    assert photo.priors.focal_px[0] < photo.priors.focal_px[1]
    corr = correspondences(skull, photo)
    assert len(corr.cranial_names) == 20
    assert corr.facial_names[corr.cranial_names.index("prosthion")] == "labiale_superius"


def test_missing_axes_default_to_surface_normals(case):
    subject_dir, _ = case
    given = read_skull(subject_dir).axes
    (subject_dir / "soft_tissue_axes.json").unlink()
    derived = read_skull(subject_dir).axes
    for name in given:  # the stand-in's axes are its exact ellipsoid normals
        assert np.dot(given[name], derived[name]) > 0.99


def test_missing_folder_and_files(case, tmp_path):
    subject_dir, photo_dir = case
    with pytest.raises(ValueError, match="subject folder not found"):
        read_skull(tmp_path / "nope")
    (subject_dir / "skull.ply").unlink()
    with pytest.raises(ValueError, match=r"no skull mesh \(skull.ply"):
        read_skull(subject_dir)
    (photo_dir / "photo.json").unlink()
    with pytest.raises(ValueError, match=r"photo.json: file not found"):
        read_photo(photo_dir)


def test_unknown_landmark_name_suggests_the_right_one(case):
    subject_dir, photo_dir = case
    _edit_json(
        subject_dir / "cranial_landmarks.json",
        lambda d: d["landmarks"].update(nasoin=d["landmarks"].pop("nasion")),
    )
    with pytest.raises(
        ValueError,
        match=r"cranial_landmarks.json: landmarks: unknown cranial landmark "
        r"'nasoin'; did you mean 'nasion'\?",
    ):
        read_skull(subject_dir)
    _edit_json(photo_dir / "photo.json", lambda d: d["landmarks"].update(chin=[1, 2]))
    with pytest.raises(ValueError, match=r"photo.json: landmarks: unknown facial landmark 'chin'"):
        read_photo(photo_dir)


def test_nan_landmark(case):
    subject_dir, photo_dir = case
    text = (photo_dir / "photo.json").read_text()
    data = json.loads(text)
    data["landmarks"]["nasion"] = [float("nan"), 3.0]
    (photo_dir / "photo.json").write_text(json.dumps(data))  # json writes NaN
    with pytest.raises(
        ValueError, match=r"photo.json: landmarks: 'nasion' has NaN or infinite coordinates; give"
    ):
        read_photo(photo_dir)


def test_spec_files_accept_the_aliases_of_the_other_formats(case):
    subject_dir, photo_dir = case
    before = read_skull(subject_dir).landmarks_mm["nasion"]
    _edit_json(
        subject_dir / "cranial_landmarks.json",
        lambda d: d["landmarks"].update(N=d["landmarks"].pop("nasion")),
    )
    _edit_json(
        photo_dir / "photo.json",
        lambda d: d["landmarks"].update(exR=d["landmarks"].pop("exocanthion_r")),
    )
    np.testing.assert_array_equal(read_skull(subject_dir).landmarks_mm["nasion"], before)
    assert "exocanthion_r" in read_photo(photo_dir).landmarks_uv


def test_a_landmark_given_twice_is_an_error(case):
    subject_dir, photo_dir = case
    path = subject_dir / "cranial_landmarks.json"
    _edit_json(path, lambda d: d["landmarks"].update(n=d["landmarks"]["nasion"]))
    with pytest.raises(
        ValueError,
        match=r"cranial_landmarks.json: landmarks: 'n' and 'nasion' are both nasion; keep one",
    ):
        read_skull(subject_dir)
    # The same JSON key twice: json.loads would keep the last one silently.
    text = (photo_dir / "photo.json").read_text()
    (photo_dir / "photo.json").write_text(
        text.replace('"landmarks": {', '"landmarks": {"nasion": [1.0, 2.0], ', 1)
    )
    with pytest.raises(
        ValueError, match=r"photo.json: the key 'nasion' appears twice in one JSON object"
    ):
        read_photo(photo_dir)


def test_duplicate_keys_are_an_error_in_every_json_read(tmp_path):
    from lilium.io.jsonio import read_json

    path = tmp_path / "dataset.json"
    path.write_text('{"subjects": [{"id": "a", "id": "b"}]}')
    with pytest.raises(ValueError, match=r"dataset.json: the key 'id' appears twice"):
        read_json(path)


def test_too_few_usable_correspondences(case):
    subject_dir, photo_dir = case
    keep = ["nasion", "glabella", "pogonion"]
    _edit_json(
        photo_dir / "photo.json",
        lambda d: d.update(landmarks={k: d["landmarks"][k] for k in keep}),
    )
    with pytest.raises(ValueError, match="only 3 usable landmark pairs .* at least 4 are needed"):
        correspondences(read_skull(subject_dir), read_photo(photo_dir))


def test_degenerate_and_badly_scaled_meshes(case):
    subject_dir, _ = case
    flat = np.array([[0, 0, 0], [100, 0, 0], [0, 100, 0], [100, 100, 0]], float)
    write_mesh(subject_dir / "skull.ply", flat, np.array([[0, 1, 2], [1, 3, 2]]))
    with pytest.raises(ValueError, match="skull.ply: degenerate mesh"):
        read_skull(subject_dir)
    import trimesh

    metres = trimesh.creation.icosphere(radius=0.09)
    write_mesh(subject_dir / "skull.ply", metres.vertices, metres.faces)
    with pytest.raises(ValueError, match="rescale it to millimetres"):
        read_skull(subject_dir)


def test_landmark_off_the_mesh(case):
    subject_dir, _ = case
    _edit_json(
        subject_dir / "cranial_landmarks.json",
        lambda d: d["landmarks"].update(nasion=[0, 0, 900]),
    )
    with pytest.raises(ValueError, match="landmarks.nasion lies .* mm from the skull mesh"):
        read_skull(subject_dir)


def test_landmark_outside_the_image(case):
    _, photo_dir = case
    _edit_json(photo_dir / "photo.json", lambda d: d["landmarks"].update(nasion=[1500, 10]))
    with pytest.raises(
        ValueError,
        match=r"landmarks.nasion = \(1500, 10\) lies outside the "
        r"1200x900 image",
    ):
        read_photo(photo_dir)


def test_mask_wrong_size_empty_and_corrupt_image(case):
    from PIL import Image

    _, photo_dir = case
    Image.new("L", (100, 100), 255).save(photo_dir / "face_mask.png")
    with pytest.raises(ValueError, match="face_mask.png: the mask is 100x100 px but the photo is"):
        read_photo(photo_dir)
    Image.new("L", (1200, 900), 0).save(photo_dir / "face_mask.png")
    with pytest.raises(ValueError, match="face_mask.png: the face mask is empty"):
        read_photo(photo_dir)
    (photo_dir / "image.png").write_bytes(b"not a png")
    with pytest.raises(ValueError, match="image.png: cannot read the image"):
        read_photo(photo_dir)


def test_bad_view_and_priors(case):
    _, photo_dir = case
    path = photo_dir / "photo.json"
    _edit_json(path, lambda d: d.update(view="profile"))
    with pytest.raises(ValueError, match="view must be one of frontal, lateral_left"):
        read_photo(photo_dir)
    _edit_json(path, lambda d: d.update(view="frontal"))
    _edit_json(path, lambda d: d["priors"].update(focal_px=[3000, 1000]))
    with pytest.raises(
        ValueError, match=r"photo.json: priors.focal_px must be a finite interval \[lo, hi\]"
    ):
        read_photo(photo_dir)
    for bad in ([0, 1000], [1000, "2000"], [1000], [1000, 1e400]):
        _edit_json(path, lambda d, bad=bad: d["priors"].update(scd_mm=bad, focal_px=None))
        with pytest.raises(
            ValueError, match=r"photo.json: priors.scd_mm must be a finite interval"
        ):
            read_photo(photo_dir)


def test_user_depth_table(tmp_path):
    path = tmp_path / "depths.csv"
    path.write_text("landmark,mean,sd,min,max\nnasion,7,1,4,11\nexocanthion,11,2,6,16\n")
    table = read_depth_table(path)
    assert table["nasion"].max_mm == 11 and table["ectoconchion"].mean_mm == 11
    path.write_text("landmark,mean,sd,min,max\nnasion,seven,1,4,11\n")
    with pytest.raises(ValueError, match="line 2: mean, sd, min and max must be numbers"):
        read_depth_table(path)


def test_exif_orientation_is_applied(tmp_path):
    """A JPEG stored landscape with 'rotate 90 CW' in EXIF is read upright (portrait)."""
    from PIL import Image

    from lilium.io.case import read_image

    stored = Image.new("RGB", (40, 20), (200, 10, 10))
    stored.paste((10, 10, 200), (0, 0, 10, 20))  # blue band on the stored image's left
    exif = Image.Exif()
    exif[0x0112] = 6  # Orientation: rotate 90 CW to display
    stored.save(tmp_path / "phone.jpg", exif=exif, quality=95)
    upright = read_image(tmp_path / "phone.jpg")
    assert upright.shape == (40, 20, 3)
    assert upright[2, 10, 2] > 150 and upright[-3, 10, 0] > 150  # blue band now on top


def test_face_curve_of_a_photo_folder(case):
    _, photo_dir = case
    curve = [[500.0, 600.0], [600.0, 640.0], [700.0, 600.0]]
    (photo_dir / "face_curve.json").write_text(json.dumps({"chin_jaw": curve}))
    read = read_photo(photo_dir).face_curve_uv  # whole pixels along the curve (issue 28)
    assert len(read) == 201 and all(p in read.tolist() for p in curve)
    # A curve for the other view is an error naming the file, not silently ignored.
    (photo_dir / "face_curve.json").write_text(json.dumps({"forehead": curve}))
    with pytest.raises(ValueError, match=r"face_curve.json: no 'chin_jaw' curve .*forehead"):
        read_photo(photo_dir)
    (photo_dir / "face_curve.json").write_text(json.dumps({"chin_jaw": [[1, "a"]]}))
    with pytest.raises(ValueError, match="chin_jaw must be a list of at least two"):
        read_photo(photo_dir)
    (photo_dir / "face_curve.json").write_text(json.dumps({"chin_jaw": [[1, 2]]}))
    with pytest.raises(ValueError, match="chin_jaw must be a list of at least two"):
        read_photo(photo_dir)
