"""A contact sheet of a generated dataset: photos with the true skull drawn over the skin.

For a visual check of the generator: each tile is a photo cropped around the head, the skull
projected with the ground-truth camera (shaded bone, semi-transparent), the face-mask outline
(magenta), the face curve (cyan), the visible landmarks (green) and the hidden ones (red). The
label gives the photo id, image size, focal, SCD and the % of skull pixels outside the mask.
"""

from pathlib import Path

import cv2
import numpy as np

from ..casework.build import read_photo
from ..evaluation.metrics import implausible_sfo
from ..imaging.raster import mesh_mask
from ..io.jsonio import read_json
from ..io.truth import read_ground_truth
from ..synthetic import render as _render

BONE_RGB = np.array([245.0, 245.0, 235.0])
SKULL_ALPHA = 0.5
_VIEW_ORDER = ("frontal", "lateral_left", "lateral_right")


def _load_mesh(subject_dir):
    from ..io.mesh import MESH_SUFFIXES, read_mesh

    for suffix in MESH_SUFFIXES:
        path = Path(subject_dir) / f"skull{suffix}"
        if path.is_file():
            return read_mesh(path)
    raise ValueError(f"{subject_dir}: no skull.ply/.obj/.stl")


def overlay_tile(
    image,
    face_mask,
    skull_vertices_mm,
    skull_faces,
    truth,
    landmarks_uv=None,
    face_curve=None,
    tile_px=400,
):
    """One contact-sheet tile.

    Parameters
    ----------
    image : ndarray of shape (H, W, 3), uint8 RGB
    face_mask : ndarray of shape (H, W)
    skull_vertices_mm : ndarray of shape (V, 3)
    skull_faces : ndarray of shape (F, 3)
    truth : GroundTruth
        Of the photo (:func:`lilium.io.truth.read_ground_truth`): the camera and the noise-free
        landmarks.
    landmarks_uv : dict of str -> ndarray of shape (2,), optional
        The landmarks given to the methods (the visible ones; ringed).
    face_curve : dict of str -> ndarray of shape (K, 2), optional
    tile_px : int

    Returns
    -------
    tile : ndarray of shape (tile_px, tile_px, 3), uint8 RGB
    implausible : lilium.evaluation.metrics.ImplausibleSFO
        For the ground-truth camera.
    """
    height, width = image.shape[:2]
    skull = _render.render_mesh(skull_vertices_mm, skull_faces, truth.camera, (width, height))
    bone = _render.shade(skull, albedo_rgb=BONE_RGB, smooth_px=1.0)
    # The silhouette (and its outside count) from the one mesh raster; the depth buffer shades.
    skull_mask = mesh_mask(skull_vertices_mm, skull_faces, truth.camera, (width, height))
    out = image.astype(np.float32)
    out[skull_mask] = (1 - SKULL_ALPHA) * out[skull_mask] + SKULL_ALPHA * bone[skull_mask]
    face = np.asarray(face_mask) != 0
    stats = implausible_sfo(skull_mask, face)
    out[skull_mask & ~face] = [255, 40, 40]  # skull outside the mask: bright red

    rows, cols = np.flatnonzero(face.any(axis=1)), np.flatnonzero(face.any(axis=0))
    if len(rows) == 0:
        rows, cols = np.arange(height), np.arange(width)
    cy, cx = (rows[0] + rows[-1]) / 2, (cols[0] + cols[-1]) / 2
    half = 0.6 * max(rows[-1] - rows[0], cols[-1] - cols[0]) + 2
    x0, y0 = int(max(0, cx - half)), int(max(0, cy - half))
    x1, y1 = int(min(width, cx + half)), int(min(height, cy + half))
    scale = tile_px / max(x1 - x0, y1 - y0)
    crop = cv2.resize(
        np.clip(out[y0:y1, x0:x1], 0, 255).astype(np.uint8),
        (max(1, round((x1 - x0) * scale)), max(1, round((y1 - y0) * scale))),
        interpolation=cv2.INTER_AREA,
    )
    tile = np.full((tile_px, tile_px, 3), 30, dtype=np.uint8)
    tile[: crop.shape[0], : crop.shape[1]] = crop

    def to_tile(uv):
        uv = (np.asarray(uv, dtype=float) - [x0, y0]) * scale
        return tuple(int(round(c)) for c in uv)

    small_mask = cv2.resize(
        face[y0:y1, x0:x1].astype(np.uint8), (crop.shape[1], crop.shape[0]), cv2.INTER_NEAREST
    )
    contours, _ = cv2.findContours(small_mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    cv2.drawContours(tile, contours, -1, (255, 0, 255), 1)
    for pts in (face_curve or {}).values():
        pts = np.array([to_tile(p) for p in pts], dtype=np.int32)
        if len(pts):
            cv2.polylines(tile, [pts], False, (0, 255, 255), 2)
    visible = landmarks_uv or {}
    for name, uv in truth.landmarks_noise_free.items():
        if not np.all(np.isfinite(uv)):
            continue
        colour = (40, 230, 40) if name in visible else (230, 30, 30)
        cv2.circle(tile, to_tile(uv), 3, colour, -1)
    for uv in visible.values():
        cv2.circle(tile, to_tile(uv), 5, (40, 230, 40), 1)
    return tile, stats


def contact_sheet(dataset_dir, path, n_subjects=4, experiment="A", tile_px=400):
    """Write a contact sheet PNG of a generated dataset; rows = subjects, one frontal, one
    lateral_left and one lateral_right photo each.

    Returns
    -------
    list of dict
        Per tile: photo id, view, % of GT-skull pixels outside the face mask.
    """
    dataset_dir = Path(dataset_dir)
    index = read_json(dataset_dir / "dataset.json")
    if experiment not in index["experiments"]:
        raise ValueError(f"experiment {experiment!r} is not in this dataset")
    subjects = [s["id"] for s in index["subjects"]][:n_subjects]
    rows, report = [], []
    for sid in subjects:
        vertices, faces = _load_mesh(dataset_dir / "subjects" / sid)
        tiles = []
        for view in _VIEW_ORDER:
            entry = next(
                (p for p in index["photos"] if p["subject"] == sid and p["view"] == view), None
            )
            if entry is None:
                tiles.append(np.full((tile_px, tile_px, 3), 30, dtype=np.uint8))
                continue
            folder = dataset_dir / entry["paths"][experiment]
            photo = read_photo(folder)
            truth = read_ground_truth(folder)
            curve = None
            if photo.face_curve_uv is not None:
                curve = {"chin_jaw" if view == "frontal" else "forehead": photo.face_curve_uv}
            tile, stats = overlay_tile(
                photo.image,
                photo.face_mask,
                vertices,
                faces,
                truth,
                photo.landmarks_uv,
                curve,
                tile_px,
            )
            w, h = truth.image_size_wh
            label = f"{entry['id']} {w}x{h} f{truth.camera.focal_px:.0f} d{truth.scd_mm:.0f}"
            label2 = f"{view} out {stats.percent_outside:.2f}%"
            for k, text in enumerate((label, label2)):
                cv2.putText(
                    tile, text, (6, 18 + 18 * k), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (255, 255, 255), 1
                )
            tiles.append(tile)
            report.append(
                {"photo": entry["id"], "view": view, "percent_outside": stats.percent_outside}
            )
        rows.append(np.hstack(tiles))
    sheet = np.vstack(rows)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(path), sheet[..., ::-1])
    return report
