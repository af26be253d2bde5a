"""A photo folder whose mask is the face outline alone (``"face_mask_is_head": false``, warning
``head_mask_face_only``; docs/method/photo.md): a case does not read the vault as outside the
head, and ``lilium photo`` says when it could find only the face."""

import json

import numpy as np
import pytest
from PIL import Image

from lilium.cli.main import main


def _face_only_folder(case, tmp_path, is_head, landmarks=None):
    """The stand-in photo folder with a face-only mask: the skull's raster grown, cut a little
    above the eye corners (no vault), marked ``face_mask_is_head``."""
    import shutil

    from scipy import ndimage as ndi

    from lilium.casework.build import read_skull
    from lilium.imaging.raster import mesh_mask
    from lilium.io.truth import read_ground_truth

    subject_dir, photo_dir = case
    folder = tmp_path / f"face_only_{is_head}"
    shutil.copytree(photo_dir, folder)
    skull, camera = read_skull(subject_dir), read_ground_truth(photo_dir).camera
    meta = json.loads((folder / "photo.json").read_text())
    w, h = 1200, 900
    raster = mesh_mask(skull.vertices_mm, skull.faces, camera, (w, h)) != 0
    eye_v = (meta["landmarks"]["exocanthion_r"][1] + meta["landmarks"]["exocanthion_l"][1]) / 2
    face = ndi.binary_dilation(raster, iterations=8)
    face[: int(eye_v - 40)] = False
    Image.fromarray(face.astype(np.uint8) * 255).save(folder / "face_mask.png")
    meta["face_mask_is_head"] = is_head
    if landmarks is not None:
        meta["landmarks"] = landmarks
    (folder / "photo.json").write_text(json.dumps(meta))
    return skull, camera, folder


@pytest.mark.parametrize("is_head", [True, False])
def test_a_face_only_mask_does_not_read_the_vault_as_outside(case, tmp_path, is_head):
    """Marked a head mask, the cut mask puts the vault outside the head; marked face-only
    (``face_mask_is_head: false``), the skull above the eye-corner line counts as inside, so
    skull_beyond_head, outside_fraction and P_skof's count see none of it; the photo says why."""
    from types import SimpleNamespace

    from lilium.casework.build import read_photo
    from lilium.evaluation.metrics import outside_face
    from lilium.identification.decision import skull_outside_head
    from lilium.identification.score import outside_fraction, skull_beyond_head

    skull, camera, folder = _face_only_folder(case, tmp_path, is_head)
    photo = read_photo(folder)
    beyond, skull_px, _ = skull_beyond_head(skull, photo, camera)
    codes = [w.code for w in photo.warnings]
    sentence = skull_outside_head(skull, [photo], [SimpleNamespace(camera=camera)])
    counts = outside_face(camera, skull.vertices_mm, skull.faces, photo.face_mask)
    if is_head:
        assert beyond > 0.1 * skull_px and sentence is not None
        assert "head_mask_face_only" not in codes
    else:
        assert beyond == 0 and sentence is None
        assert counts.outside_px == 0 and outside_fraction(skull, photo, camera) == 0
        assert codes == ["head_mask_face_only"]
        assert "eye-corner line" in photo.warnings[0].message


def test_a_face_only_mask_without_eye_corners_is_not_used(case, tmp_path):
    from lilium.casework.build import read_photo

    meta = json.loads((case[1] / "photo.json").read_text())
    kept = {k: v for k, v in meta["landmarks"].items() if "canthion" not in k}
    _, _, folder = _face_only_folder(case, tmp_path, False, landmarks=kept)
    photo = read_photo(folder)
    assert photo.face_mask is None
    assert "mask is not used" in photo.warnings[-1].message


def test_lilium_photo_says_when_it_found_only_the_face(tmp_path, monkeypatch, capsys):
    """A segmentation that finds no person (as on a washed-out print before issue 55) leaves the
    face outline: photo.json says ``face_mask_is_head: false`` with the warning, the console
    prints it; the review page's outline then replaces it (``head_outline_px``)."""
    pytest.importorskip("ai_edge_litert")
    from skimage import data

    from lilium.photo import runtime

    Image.fromarray(data.astronaut()).save(tmp_path / "a.png")
    real = runtime.person_mask
    monkeypatch.setattr(runtime, "person_mask", lambda image: np.zeros(image.shape[:2]))
    out = tmp_path / "photo"
    assert main(["photo", str(tmp_path / "a.png"), "--out", str(out)]) == 0
    meta = json.loads((out / "photo.json").read_text())
    assert meta["face_mask_is_head"] is False
    # (the 512 px astronaut is also below the resolution minimum: low_resolution)
    assert "head_mask_face_only" in [w["code"] for w in meta["warnings"]]
    assert "warning head_mask_face_only" in capsys.readouterr().err
    monkeypatch.setattr(runtime, "person_mask", real)
    assert main(["photo", str(tmp_path / "a.png"), "--out", str(out)]) == 0
    meta = json.loads((out / "photo.json").read_text())
    assert meta["face_mask_is_head"] is True
    assert "head_mask_face_only" not in [w["code"] for w in meta.get("warnings", ())]
