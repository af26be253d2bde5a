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
    from lilium.casework.build import read_photo
    from lilium.evaluation.metrics import outside_face
    from lilium.identification.decision import skull_outside_head
    from lilium.identification.score import head_overlap, outside_fraction, skull_beyond_head

    skull, camera, folder = _face_only_folder(case, tmp_path, is_head)
    photo = read_photo(folder)
    beyond, skull_px, _ = skull_beyond_head(skull, photo, camera)
    codes = [w.code for w in photo.warnings]
    sentence = skull_outside_head([photo], [head_overlap(skull, photo, camera)])
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


def test_lilium_photo_says_when_the_mask_misses_the_head_top(tmp_path, monkeypatch, capsys):
    """A head mask with hair and ears but cut 0.4 face heights above the nasion (as the whole
    Hopper portrait's scanned print lost her dark cap before the crown pass, issue 55) is more
    than the face outline, yet misses the head's top: photo.json marks it
    ``face_mask_is_head: false`` with ``head_mask_face_only``, saying the mask stops below the
    head's top."""
    pytest.importorskip("ai_edge_litert")
    from skimage import data

    from lilium.photo import analysis, mask

    Image.fromarray(data.astronaut()).save(tmp_path / "a.png")
    real = analysis.segmented_head_mask

    def cut_top(image, mesh_xyz):
        head = real(image, mesh_xyz)
        nasion, chin = mesh_xyz[168, :2], mesh_xyz[152, :2]
        top = nasion[1] - 0.4 * np.linalg.norm(chin - nasion)
        head[: int(np.ceil(top))] = False
        assert mask.head_share_beyond_face(head, mesh_xyz) >= mask.HEAD_BEYOND_FACE
        return head

    monkeypatch.setattr(analysis, "segmented_head_mask", cut_top)
    out = tmp_path / "photo"
    assert main(["photo", str(tmp_path / "a.png"), "--out", str(out)]) == 0
    meta = json.loads((out / "photo.json").read_text())
    assert meta["face_mask_is_head"] is False
    (warning,) = [w for w in meta["warnings"] if w["code"] == "head_mask_face_only"]
    assert "stops below the head's top" in warning["message"]
    assert "warning head_mask_face_only" in capsys.readouterr().err


def test_reaches_head_top_where_the_frame_cuts_the_head():
    """A mask that reaches the photo's top edge reaches the head's top as seen, however near the
    nasion the edge is; one that stops short of both does not."""
    from lilium.photo.mask import HEAD_TOP_ABOVE_NASION, reaches_head_top

    mesh = np.zeros((468, 2))
    mesh[168], mesh[152] = (50.0, 30.0), (50.0, 130.0)  # nasion, gnathion: face height 100 px
    head = np.zeros((200, 100), bool)
    head[0:140, 20:80] = True  # up to the top edge, 30 px above the nasion
    assert reaches_head_top(head, mesh)
    head[:2] = False
    assert not reaches_head_top(head, mesh)
    mesh[:, 1] += 100  # nasion at row 130: the edge is 1.3 face heights up
    head[:] = False
    head[130 - int(HEAD_TOP_ABOVE_NASION * 100) : 240, 20:80] = True
    assert reaches_head_top(head, mesh)
    head[: 130 - int(HEAD_TOP_ABOVE_NASION * 100) + 5] = False
    assert not reaches_head_top(head, mesh)
