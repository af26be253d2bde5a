"""A real-anatomy benchmark case from the headsq CT (issue 27): subject folders and photos.

A script and a module: other benchmarks import :func:`build_headsq_dataset` (a stand-alone
dataset of the headsq subjects) or :func:`add_headsq_subjects` (the headsq subjects appended
to an existing generated dataset); both return None when the CT is absent. Run::

    PYTHONPATH=src .venv/bin/python benchmarks/headsq_case.py --out headsq-case --photos 3

Data: ``../shared/data/headsq`` beside the repository (override with ``--data`` or the
environment variable ``LILIUM_HEADSQ``): VTK's quarter-resolution head CT, 64 x 64 x 93 int16
slices of 3.2 x 3.2 x 1.5 mm, from the eyebrows to the neck (the vault is cut off above the
orbits), skin at 500, bone at 1150.

What is built, all through the project's own code:

1. Volume edits before meshing (the only hand-made step, voxel index boxes written below):
   the cervical spine is cut away (bone at rows >= 34 and slices >= 33 lowered to soft tissue:
   it is attached to the skull base at this resolution, ``import_ct`` warns so); the plastic
   tube hanging from the mouth in front of the chin is removed from the skin (what a 2D opening
   of radius 2 voxels takes off the skin mask below slice 64, in front of row 22, columns 20-43);
   for the mandible-less variant the mandible's bone is lowered to soft tissue (the bone
   component that holds the chin after a one-voxel erosion, grown back to every bone voxel
   nearer to it than to another component).
2. ``lilium.ct.import_ct`` (skull at 1150, skin at 500, LPS) into the subject folder, then the
   meshes and landmarks turned into the generator's skull frame (x = the subject's left, y = up,
   z = anterior; ``lilium.synthetic.subjects``): ``(x, y, z) = (L, S, -P)`` minus the centre of
   the complete skull's bounding box (a proper rotation, no mirroring).
3. Landmarks placed on the meshes by the rules of :func:`place_landmarks` (each one a vertex of
   its mesh); the true soft tissue of each pair is ``F - C``: ``soft_tissue_axes.json`` holds its
   direction (like the generator's true axes), ``subject.json`` its depth.
4. Photos with the generator's own code (``lilium.synthetic.dataset``: cameras drawn from
   ``CameraRanges``, the render, visibility, face mask, chin-jaw curve, Exp. B/C noise and the
   five perturbed axes sets), the same for the complete and the mandible-less variant (the same
   person and seed: identical photos), so each headsq photo is solved against both skulls.

Subjects: ``hq`` (complete skull) and ``hq_nm`` (the same head, skull without its mandible;
``"mandible": false`` in ``dataset.json`` and ``subject.json``, the mandible's landmarks under
``removed_landmarks``). Both are one person: in an identification run keep one of them
(``variants``), or the photos of one count as negative pairs of the other.

Landmark placement rules (frame above; "frontal height map": the skull rendered by the
project's rasteriser from straight in front, 1 mm per pixel, the height of a pixel the z of the
triangle seen there; "depth": how far a pixel lies behind a grey closing of the height map with
a disk of radius 20 mm, so orbits and the nasal aperture are the connected regions deeper than
8 mm; a chosen pixel gives the vertex of its triangle nearest to it in x, y):

- orbits: the largest deep region on each side (|x| > 12 mm from the bounding-box centre)
  in the upper half; the midline is x = the mean of their centroids' x (the frame is shifted
  so that it is x = 0); an orbit's transverse axis is the row of its centroid;
- ``ectoconchion``: the first bone pixel lateral of the orbit on its transverse axis;
- ``dacryon``: the first bone pixel medial of the orbit on its transverse axis (the medial
  margin: the true dacryon lies a few mm behind it on the medial wall, which the coarse mesh
  does not resolve);
- ``orbitale``: the first bone pixel below the orbit's lowest pixel, in its centroid column;
- nasal aperture: the deep region crossing the midline column nearest below the orbits;
  ``alare``: the first bone pixel lateral of the aperture on its widest row, each side;
- midsagittal profile: vertices within 2.5 mm of the midline, the front-most one per 1.5 mm
  of height (the slice spacing); the cranium's (no mandible vertex) and the mandible's apart
  (mandible vertices: those of the complete skull more than 2 mm from the mandible-less one);
- ``nasion``: the most posterior cranium profile point between the orbits' transverse axis and
  3 mm below the top cut; ``glabella`` (the profile is a plateau up to the cut), ``metopion``,
  ``bregma``, ``frontotemporale``, ``porion`` and ``mental_foramen`` are not placed;
- ``prosthion``: the most anterior cranium profile point below the aperture (at 3.2 mm the
  incisors and the alveolar bone are one surface); ``subspinale``: the most posterior cranium
  profile point between the aperture's lowest row and ``prosthion``;
- ``infradentale``: the most anterior mandible profile point in the mandible's top 12 mm;
  menton (not written): the lowest mandible profile point; ``pogonion``: the mandible profile
  point (more than 3 mm above menton) farthest in front of the chord infradentale-menton (this
  chin recedes, so "most anterior" alone would give infradentale); ``gnathion``: the profile
  point midway (in profile steps) between pogonion and menton;
- ``gonion``: among the mandible vertices of that side in the posterior 35 % of the mandible's
  depth, those within 3 mm of the largest ``-y - z`` (the posterior-inferior corner), the most
  lateral one (the outer surface of the angle);
- ``zygion``: the cranium vertex of largest |x| at most 20 mm below and 5 mm above
  ``orbitale``, 5-50 mm behind ``ectoconchion``.

Facial (skin) landmarks; "over C along d": the skin vertex within 2 mm of the ray
``C + t d``, ``0 < t < 35 mm`` (the radius grows by 1 mm until there is one), the first one
(smallest ``t``) for rays from the bone surface outwards, the outermost one (largest ``t``)
for rays from inside the face, which cross airway surfaces first:

- ``nasion``, ``pogonion``, ``gnathion``: first over the cranial one along its bone normal
  (``surface_normals_at``) with the x component removed (in the midsagittal plane);
- ``zygion``: first over the cranial one along its bone normal; ``gonion``: first over it
  along the bisector of its bone normal and the lateral direction (the normal alone points
  down and back into the neck, where the skin is more than 35 mm away);
- ``alare``: outermost over the cranial one along +z (the ala in front of the aperture
  margin);
- ``exocanthion``: outermost along +z from 5 mm medial of and 15 mm behind ``ectoconchion``;
  ``endocanthion``: the same from 3 mm lateral of and 15 mm behind ``dacryon`` (the eyes are
  closed in this CT: these are the lid line's ends, about);
- skin profile: skin vertices within 2 mm of the midline, the front-most per 1.5 mm of height;
  ``subnasale``: its most posterior point from 5 mm above ``subspinale`` down to 5 mm above
  ``prosthion`` (the columella-lip junction; the nose of this head is short and flat);
  ``labiale_superius``: its most anterior point 3-20 mm below ``subnasale``; stomion (not
  written): its most posterior point 3-15 mm below ``labiale_superius``;
- ``cheilion``: outermost along +z (up to 60 mm) from 30 mm behind stomion at x = +-0.4 x
  (|x| of exocanthion + |x| of endocanthion), about the pupils' columns (an estimate: the mouth
  corners do not show on a 3.2 mm skin; used only to cut the chin-jaw region). On the
  pictures they fall on the mouth corners.
"""

import argparse
import os
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

#: The CT beside the repository (``../shared/data/headsq``); ``LILIUM_HEADSQ`` overrides it.
DEFAULT_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "headsq"
HEADER = "quarter.nhdr"
BONE_ISO = 1150.0
SKIN_ISO = 500.0
SOFT_TISSUE_VALUE = 1000  # between skin and bone: what removed bone becomes
AIR_VALUE = 100

#: Voxel boxes of the volume edits (slice k, row j, column i; see the module notes).
SPINE_ROWS_FROM = 34
SPINE_SLICES_FROM = 33
SPINE_COLUMNS = (21, 44)
CHIN_SLICES_FROM = 75  # the vertebrae, medial of the mandible's rami
TUBE_SLICES_FROM = 64
TUBE_ROWS_BEFORE = 22
TUBE_COLUMNS = (20, 44)

#: Subject ids and whether the skull keeps its mandible.
VARIANTS = {"hq": True, "hq_nm": False}

#: LPS -> generator skull frame (x = left, y = up, z = anterior): a proper rotation.
LPS_TO_SKULL = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])

HEIGHT_MAP_PX_MM = 1.0
CLOSING_RADIUS_MM = 20.0
DEEP_MM = 8.0


def data_dir(path=None):
    """The headsq folder (argument, ``LILIUM_HEADSQ``, or the default), or None if absent."""
    path = Path(path or os.environ.get("LILIUM_HEADSQ") or DEFAULT_DATA)
    return path if (path / HEADER).is_file() else None


# -- volume -----------------------------------------------------------------------------------
def _with_data(volume, data):
    return replace(volume, data=data)


def edited_volumes(path=None):
    """The CT with the spine and the tube removed, and the same without the mandible.

    Returns
    -------
    complete, no_mandible : lilium.ct.Volume
    """
    from scipy import ndimage as ndi

    from lilium.ct import read_volume

    folder = data_dir(path)
    if folder is None:
        raise FileNotFoundError(f"no headsq CT at {path or DEFAULT_DATA}")
    volume = read_volume(folder / HEADER)
    data = volume.data.copy()
    spine = data[SPINE_SLICES_FROM:, SPINE_ROWS_FROM:, SPINE_COLUMNS[0] : SPINE_COLUMNS[1]]
    spine[spine >= BONE_ISO] = SOFT_TISSUE_VALUE
    skin = data >= SKIN_ISO
    disk = np.zeros((1, 5, 5), bool)
    disk[0] = np.hypot(*np.mgrid[-2:3, -2:3]) <= 2.1
    thin = skin & ~ndi.binary_opening(skin, structure=disk)
    region = np.zeros_like(skin)
    region[TUBE_SLICES_FROM:, :TUBE_ROWS_BEFORE, TUBE_COLUMNS[0] : TUBE_COLUMNS[1]] = True
    data[thin & region] = AIR_VALUE
    bone = data >= BONE_ISO
    apart = bone.copy()  # for the labels only: the whole width behind the rami cut away
    apart[SPINE_SLICES_FROM:, SPINE_ROWS_FROM:, :] = False
    labels, _ = ndi.label(ndi.binary_erosion(apart))
    k, j, i = np.nonzero(labels[CHIN_SLICES_FROM:])
    front = np.argmin(j)  # the chin: the most anterior bone of the lowest slices
    mandible_label = labels[CHIN_SLICES_FROM + k[front], j[front], i[front]]
    _, nearest = ndi.distance_transform_edt(labels == 0, return_indices=True)
    mandible = bone & (labels[tuple(nearest)] == mandible_label)
    no_mandible = data.copy()
    no_mandible[mandible] = SOFT_TISSUE_VALUE
    return _with_data(volume, data), _with_data(volume, no_mandible)


def _import(volume, folder):
    """``import_ct`` into ``folder``; skull and skin in LPS."""
    from lilium.ct import import_ct

    result = import_ct(volume, folder, bone_iso=BONE_ISO, skin_iso=SKIN_ISO)
    return result["skull"], result["skin"], result["record"]


# -- landmarks ----------------------------------------------------------------------------------
def _height_map(vertices, faces):
    """Frontal height map of a mesh: (z per pixel or NaN, triangle per pixel, pixel -> x, y)."""
    from lilium.geometry.camera import Camera
    from lilium.synthetic import photos, render

    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    centre = 0.5 * (lo + hi)
    size = np.ceil((hi[:2] - lo[:2]) / HEIGHT_MAP_PX_MM).astype(int) + 21
    distance = 1e6
    focal = distance / HEIGHT_MAP_PX_MM
    R = photos.R_FRONTAL
    t = np.array([0.0, 0.0, distance]) - R @ centre
    pp = 0.5 * (size - 1)
    camera = Camera.from_rt(R, t, focal, pp)
    faces_index = render.render_mesh(vertices, faces, camera, tuple(int(s) for s in size))
    index = faces_index.face_index
    z_tri = vertices[faces].mean(axis=1)[:, 2]
    height = np.where(index >= 0, z_tri[np.maximum(index, 0)], np.nan)

    def xy(u, v):
        return np.array(
            [centre[0] + (u - pp[0]) * HEIGHT_MAP_PX_MM, centre[1] - (v - pp[1]) * HEIGHT_MAP_PX_MM]
        )

    return height, index, xy


def _pixel_vertex(vertices, faces, index, xy, u, v):
    """The vertex of the triangle at pixel (u, v) nearest to it in x, y."""
    tri = faces[index[v, u]]
    d = np.linalg.norm(vertices[tri, :2] - xy(u, v), axis=1)
    return vertices[tri[int(np.argmin(d))]].copy()


def _deep_regions(height):
    import cv2
    from scipy import ndimage as ndi

    inside = np.isfinite(height)
    floor = np.nanmin(height) - 1.0
    h = np.where(inside, height, floor).astype(np.float32)
    r = int(round(CLOSING_RADIUS_MM / HEIGHT_MAP_PX_MM))
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1, 2 * r + 1))
    closed = cv2.morphologyEx(h, cv2.MORPH_CLOSE, kernel)
    hull = cv2.morphologyEx(inside.astype(np.uint8), cv2.MORPH_CLOSE, kernel).astype(bool)
    deep = hull & ((closed - h) > DEEP_MM)
    labels, n = ndi.label(deep)
    return labels, n


def _profile(vertices, band_mm, bin_mm, x0=0.0):
    """Front-most vertex per height bin within ``band_mm`` of x = x0: (K, 3) sorted top-down."""
    near = vertices[np.abs(vertices[:, 0] - x0) < band_mm]
    bins = np.round((near[:, 1] - vertices[:, 1].max()) / bin_mm).astype(int)
    out = []
    for b in np.unique(bins):
        sel = near[bins == b]
        out.append(sel[np.argmax(sel[:, 2])])
    out = np.array(out)
    return out[np.argsort(-out[:, 1])]


def _over(skin, point, direction, radius_mm=2.0, max_t_mm=35.0, outermost=True):
    """The outermost (or first) skin vertex within ``radius_mm`` of the ray
    ``point + t direction``, ``0 < t < max_t_mm`` (outermost: the outer skin, not the airway
    surfaces a ray from inside the face crosses first)."""
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    rel = skin - point
    t = rel @ d
    perp = np.linalg.norm(rel - t[:, None] * d, axis=1)
    for radius in radius_mm + np.arange(8.0):
        ok = (t > 0) & (t < max_t_mm) & (perp < radius)
        if ok.any():
            k = np.flatnonzero(ok)
            return skin[k[np.argmax(t[k]) if outermost else np.argmin(t[k])]].copy()
    raise ValueError(f"no skin over {point} along {d}")


def place_landmarks(skull, skull_faces, skin, mandible_mask):
    """Cranial and facial landmarks by the rules of the module notes (skull frame, mm).

    Parameters
    ----------
    skull : ndarray (V, 3), skull_faces : ndarray (F, 3)
        The complete skull.
    skin : ndarray (V', 3)
    mandible_mask : ndarray (V,), bool
        Which skull vertices are the mandible's.

    Returns
    -------
    cranial, facial : dict of str -> ndarray (3,)
    """
    from lilium.softtissue.normals import surface_normals_at

    height, index, xy = _height_map(skull, skull_faces)
    labels, n = _deep_regions(height)
    H, W = height.shape
    centre_u = int(np.argmin([abs(xy(u, 0)[0]) for u in range(W)]))
    rows_in = np.flatnonzero(np.isfinite(height).any(axis=1))
    top_row, mid_row = rows_in[0], 0.5 * (rows_in[0] + rows_in[-1])
    regions = []
    for lab in range(1, n + 1):
        v, u = np.nonzero(labels == lab)
        if v.min() > top_row + 2:  # not the open bowl of the cut vault
            regions.append((lab, u, v))
    orbits = {}
    for side, sign in (("l", 1.0), ("r", -1.0)):
        cands = [
            r for r in regions if sign * xy(r[1].mean(), 0)[0] > 12.0 and r[2].mean() < mid_row
        ]
        orbits[side] = max(cands, key=lambda r: len(r[1]))
    orbit_v = max(o[2].mean() for o in orbits.values())
    x_mid = float(np.mean([xy(o[1].mean(), 0)[0] for o in orbits.values()]))
    centre_u = int(np.argmin([abs(xy(u, 0)[0] - x_mid) for u in range(W)]))
    crossing = [r for r in regions if (r[1] == centre_u).any() and r[2].mean() > orbit_v]
    aperture = min(crossing, key=lambda r: r[2].mean())
    cranial = {}

    def vertex(u, v):
        return _pixel_vertex(skull, skull_faces, index, xy, int(u), int(v))

    for side, sign in (("l", 1.0), ("r", -1.0)):
        lab, u, v = orbits[side]
        row = int(round(v.mean()))
        on_row = u[v == row]
        outer = on_row.max() if sign * (xy(1, 0)[0] - xy(0, 0)[0]) > 0 else on_row.min()
        inner = on_row.min() if outer == on_row.max() else on_row.max()
        step = 1 if outer == on_row.max() else -1
        cranial[f"ectoconchion_{side}"] = vertex(outer + step, row)
        cranial[f"dacryon_{side}"] = vertex(inner - step, row)
        col = int(round(u.mean()))
        bottom = v[u == col].max()
        cranial[f"orbitale_{side}"] = vertex(col, bottom + 1)
        # aperture margin on its widest row
        au, av = aperture[1], aperture[2]
        rows = np.unique(av)
        widths = [np.ptp(au[av == r]) for r in rows]
        wrow = int(rows[int(np.argmax(widths))])
        line = au[av == wrow]
        edge = line.max() if step == 1 else line.min()
        cranial[f"alare_{side}"] = vertex(edge + step, wrow)
    ap_bottom_y = xy(0, aperture[2].max())[1]
    orbit_axis_y = 0.5 * (cranial["ectoconchion_l"][1] + cranial["ectoconchion_r"][1])

    cranium = skull[~mandible_mask]
    mandible = skull[mandible_mask]
    prof = _profile(cranium, 2.5, 1.5, x_mid)
    upper = prof[(prof[:, 1] > orbit_axis_y) & (prof[:, 1] < skull[:, 1].max() - 3.0)]
    cranial["nasion"] = upper[np.argmin(upper[:, 2])]
    below = prof[prof[:, 1] < ap_bottom_y]
    cranial["prosthion"] = below[np.argmax(below[:, 2])]
    between = prof[(prof[:, 1] < ap_bottom_y) & (prof[:, 1] > cranial["prosthion"][1])]
    cranial["subspinale"] = between[np.argmin(between[:, 2])]
    mprof = _profile(mandible, 2.5, 1.5, x_mid)
    top = mprof[mprof[:, 1] > mprof[:, 1].max() - 12.0]
    cranial["infradentale"] = top[np.argmax(top[:, 2])]
    menton = mprof[np.argmin(mprof[:, 1])]
    chord = cranial["infradentale"][1:] - menton[1:]
    normal = np.array([-chord[1], chord[0]]) / np.linalg.norm(chord)
    normal *= np.sign(normal[1])  # anterior
    chin = mprof[mprof[:, 1] > menton[1] + 3.0]
    cranial["pogonion"] = chin[np.argmax((chin[:, 1:] - menton[1:]) @ normal)]
    arc = mprof[(mprof[:, 1] < cranial["pogonion"][1]) & (mprof[:, 1] >= menton[1])]
    cranial["gnathion"] = arc[len(arc) // 2]  # midway (in profile steps) to menton
    z_lo, z_hi = mandible[:, 2].min(), mandible[:, 2].max()
    for side, sign in (("l", 1.0), ("r", -1.0)):
        m = mandible[
            (sign * (mandible[:, 0] - x_mid) > 0) & (mandible[:, 2] < z_lo + 0.35 * (z_hi - z_lo))
        ]
        corner = -m[:, 2] - m[:, 1]
        m = m[corner > corner.max() - 3.0]  # the angle; its outer (lateral) surface
        cranial[f"gonion_{side}"] = m[np.argmax(sign * (m[:, 0] - x_mid))]
        o, e = cranial[f"orbitale_{side}"], cranial[f"ectoconchion_{side}"]
        c = cranium[
            (cranium[:, 1] > o[1] - 20.0)
            & (cranium[:, 1] < o[1] + 5.0)
            & (cranium[:, 2] < e[2] - 5.0)
            & (cranium[:, 2] > e[2] - 50.0)
        ]
        cranial[f"zygion_{side}"] = c[np.argmax(sign * c[:, 0])]

    # facial
    names = list(cranial)
    normals = dict(
        zip(
            names,
            surface_normals_at(skull, skull_faces, np.array([cranial[k] for k in names])),
            strict=True,
        )
    )
    facial = {}
    z_axis = np.array([0.0, 0.0, 1.0])
    for name in ("nasion", "pogonion", "gnathion"):
        d = normals[name] * np.array([0.0, 1.0, 1.0])
        facial[name] = _over(skin, cranial[name], d, outermost=False)
    for side, sign in (("l", 1.0), ("r", -1.0)):
        key = f"zygion_{side}"
        facial[key] = _over(skin, cranial[key], normals[key], outermost=False)
        key = f"gonion_{side}"
        d = normals[key] + np.array([sign, 0.0, 0.0])  # bisector of the normal and lateral
        facial[key] = _over(skin, cranial[key], d, outermost=False)
        facial[f"alare_{side}"] = _over(skin, cranial[f"alare_{side}"], z_axis)
        e = cranial[f"ectoconchion_{side}"] - np.array([sign * 5.0, 0.0, -15.0])
        facial[f"exocanthion_{side}"] = _over(skin, e, z_axis)
        d = cranial[f"dacryon_{side}"] + np.array([sign * 3.0, 0.0, -15.0])
        facial[f"endocanthion_{side}"] = _over(skin, d, z_axis)
    sprof = _profile(skin, 2.0, 1.5, x_mid)
    window = (sprof[:, 1] < cranial["subspinale"][1] + 5.0) & (
        sprof[:, 1] > cranial["prosthion"][1] + 5.0
    )
    facial["subnasale"] = sprof[window][np.argmin(sprof[window][:, 2])]
    sn = facial["subnasale"]
    lip = sprof[(sprof[:, 1] < sn[1] - 3.0) & (sprof[:, 1] > sn[1] - 20.0)]
    facial["labiale_superius"] = lip[np.argmax(lip[:, 2])]
    ls = facial["labiale_superius"]
    gap = sprof[(sprof[:, 1] < ls[1] - 3.0) & (sprof[:, 1] > ls[1] - 15.0)]
    stomion = gap[np.argmin(gap[:, 2])]
    for side, sign in (("l", 1.0), ("r", -1.0)):
        half = 0.4 * sum(
            abs(facial[f"{n}_{side}"][0] - x_mid) for n in ("exocanthion", "endocanthion")
        )
        start = np.array([x_mid + sign * half, stomion[1], stomion[2] - 30.0])
        facial[f"cheilion_{side}"] = _over(skin, start, z_axis, max_t_mm=60.0)
    return cranial, facial, x_mid


# -- subjects ---------------------------------------------------------------------------------
_CACHE = {}


def headsq_subjects(path=None, work_dir=None):
    """The two headsq subjects (``lilium.synthetic.subjects.SyntheticSubject``), keyed by id.

    Meshes come from ``import_ct`` (written under ``work_dir``, a temporary folder by default)
    and are turned into the skull frame; see the module notes.
    """
    from scipy.spatial import cKDTree

    from lilium.softtissue.landmarks import CORRESPONDENCES, MIDLINE_CRANIAL
    from lilium.softtissue.normals import surface_normals_at
    from lilium.synthetic.subjects import MANDIBLE_LANDMARKS, SyntheticSubject

    key = str(data_dir(path))
    if key in _CACHE:
        return _CACHE[key]
    complete, cranium = edited_volumes(path)
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(work_dir or tmp)
        (skull, skull_f), (skin, skin_f), record = _import(complete, base / "ct_complete")
        (nm, nm_f), _, _ = _import(cranium, base / "ct_no_mandible")
    origin = 0.5 * (skull.min(axis=0) + skull.max(axis=0)) @ LPS_TO_SKULL.T

    def frame(v):
        return v @ LPS_TO_SKULL.T - origin

    skull, skin, nm = frame(skull), frame(skin), frame(nm)
    # mandible vertices: complete-skull vertices with no cranium vertex within 2 mm
    mandible_mask = cKDTree(nm).query(skull)[0] > 2.0
    mandible_mask &= skull[:, 1] < np.percentile(skull[:, 1], 60)
    cranial, facial, x_mid = place_landmarks(skull, skull_f, skin, mandible_mask)
    shift = np.array([x_mid, 0.0, 0.0])  # x = 0 on the midline (between the orbits)
    skull, skin, nm = skull - shift, skin - shift, nm - shift
    cranial = {k: v - shift for k, v in cranial.items()}
    facial = {k: v - shift for k, v in facial.items()}
    origin = origin + shift
    for name in MIDLINE_CRANIAL:
        if name in cranial:
            assert abs(cranial[name][0]) < 3.0, name
    pairs = [(c, f) for c, f in CORRESPONDENCES if c in cranial and f in facial]
    axes = {c: (facial[f] - cranial[c]) / np.linalg.norm(facial[f] - cranial[c]) for c, f in pairs}
    depths = {c: float(np.linalg.norm(facial[f] - cranial[c])) for c, f in pairs}
    names = list(cranial)
    normals = dict(
        zip(
            names,
            surface_normals_at(skull, skull_f, np.array([cranial[n] for n in names])),
            strict=True,
        )
    )
    out = {
        "hq": SyntheticSubject(
            "hq", skull, skull_f, skin, skin_f, cranial, facial, axes, depths, normals
        )
    }
    kept = {n: v for n, v in cranial.items() if n not in MANDIBLE_LANDMARKS}
    removed = {n: v for n, v in cranial.items() if n in MANDIBLE_LANDMARKS}
    off = cKDTree(nm).query(np.array(list(kept.values())))[0]
    # cranium landmarks are vertices of the complete skull; snap to the mandible-less mesh
    kept = {n: nm[cKDTree(nm).query(v)[1]].copy() for n, v in kept.items()}
    assert off.max() < 1.0, off
    out["hq_nm"] = SyntheticSubject(
        "hq_nm",
        nm,
        nm_f,
        skin,
        skin_f,
        kept,
        facial,
        {c: a for c, a in axes.items() if c in kept},
        depths,
        {n: v for n, v in normals.items() if n in kept},
        mandible=False,
        removed_landmarks=removed,
        head_skull_vertices_mm=skull,
    )
    out["_record"] = record
    out["_origin_lps"] = origin @ LPS_TO_SKULL
    _CACHE[key] = out
    return out


# -- dataset ----------------------------------------------------------------------------------
#: ``SeedSequence(seed, spawn_key=(HEADSQ_SPAWN_KEY,))`` draws the headsq photos: apart from the
#: generated subjects' streams, and the same for both variants (identical photos).
HEADSQ_SPAWN_KEY = 2700


def _factory(subjects):
    def factory(subject_id, rng=None, mandible=True):
        del rng
        subject = subjects[subject_id]
        assert subject.mandible == mandible
        return subject

    return factory


def _write_subjects(root, n_photos, seed, experiments, variants, path):
    """Subject folders and photos of the headsq variants under ``root``; index entries."""
    from lilium.io.jsonio import write_json
    from lilium.synthetic import dataset as _dataset
    from lilium.synthetic.photos import CameraRanges
    from lilium.synthetic.subjects import write_subject

    subjects = headsq_subjects(path)
    factory = _factory(subjects)
    entries, photos = [], []
    for sid in variants:
        seq = np.random.SeedSequence(seed, spawn_key=(HEADSQ_SPAWN_KEY,))
        task = (str(root), sid, seq, n_photos, tuple(experiments), CameraRanges(), factory)
        task += (write_subject, VARIANTS[sid], 0.0)
        entry, photo_entries = _dataset._generate_subject(task)
        entry["source"] = "headsq CT (benchmarks/headsq_case.py)"
        write_json(
            Path(root) / entry["path"] / "headsq.json",
            {
                "source": "headsq CT, benchmarks/headsq_case.py (rules in its docstring)",
                "frame": "mm; x = subject's left, y = up, z = anterior",
                "skull_frame_from_lps": {
                    "rotation": LPS_TO_SKULL,
                    "origin_lps_mm": subjects["_origin_lps"],
                },
                "ct_import": subjects["_record"],
            },
        )
        entries.append(entry)
        photos.extend(photo_entries)
    return entries, photos


def build_headsq_dataset(
    out_dir, n_photos=3, seed=0, experiments=("A", "B", "C"), variants=tuple(VARIANTS), data=None
):
    """A dataset of the headsq subjects only (``dataset.json`` in the generator's format).

    Parameters
    ----------
    out_dir : path
    n_photos : int
        Frontal photos per subject, as many lateral ones (left/right alternating).
    seed : int
    experiments : sequence of {"A", "B", "C"}
    variants : sequence of {"hq", "hq_nm"}
        ``hq`` complete skull, ``hq_nm`` without the mandible (same photos).
    data : path, optional
        The headsq folder (default ``LILIUM_HEADSQ`` or ``../shared/data/headsq``).

    Returns
    -------
    Path or None
        ``out_dir``; None when the CT is absent (nothing written).
    """
    from lilium.io.jsonio import write_json
    from lilium.synthetic import noise, photos
    from lilium.synthetic.photos import CameraRanges

    if data_dir(data) is None:
        return None
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    subjects, photo_entries = _write_subjects(out, n_photos, seed, experiments, variants, data)
    index = {
        "format": "lilium-synthetic-dataset",
        "version": 1,
        "seed": seed,
        "n_subjects": len(subjects),
        "n_photos_per_view": n_photos,
        "experiments": list(experiments),
        "camera_ranges": CameraRanges().as_dict(),
        "min_visible_landmarks": photos.MIN_VISIBLE_LANDMARKS,
        "priors": {
            "focal_fraction": photos.PRIOR_FOCAL_FRACTION,
            "scd_fraction": photos.PRIOR_SCD_FRACTION,
            "head_rotation": "true rotation",
            "head_tolerance_deg": photos.PRIOR_HEAD_TOLERANCE_DEG,
        },
        "noise": {
            "landmark_px": noise.LANDMARK_NOISE_PX,
            "axis_deg": noise.AXIS_NOISE_DEG,
            "n_axes_sets": noise.N_AXES_SETS,
        },
        "subjects": subjects,
        "photos": photo_entries,
        "headsq": _index_note(variants),
    }
    if "hq_nm" in variants:
        index["incomplete"] = {
            "no_mandible_share": sum(not VARIANTS[v] for v in variants) / len(variants),
            "subjects_without_mandible": [v for v in variants if not VARIANTS[v]],
            "drop_landmark_rate": 0.0,
        }
    write_json(out / "dataset.json", index)
    return out


def _index_note(variants):
    return {
        "subjects": list(variants),
        "note": "real-anatomy case from the headsq CT (benchmarks/headsq_case.py); hq and hq_nm "
        "are one person (same photos), so one is a negative pair of the other's photos",
    }


def add_headsq_subjects(dataset_dir, n_photos=None, seed=None, variants=("hq",), data=None):
    """Append headsq subjects and their photos to an existing generated dataset.

    ``n_photos``, ``seed`` and the experiments default to the dataset's own. The index gains
    the subjects, their photos and a ``"headsq"`` note; subjects already there are replaced.

    Returns
    -------
    Path or None
        ``dataset_dir``; None when the CT is absent (nothing changed).
    """
    from lilium.io.jsonio import read_json, write_json

    if data_dir(data) is None:
        return None
    root = Path(dataset_dir)
    index = read_json(root / "dataset.json")
    n_photos = index.get("n_photos_per_view", 3) if n_photos is None else n_photos
    seed = index.get("seed", 0) if seed is None else seed
    experiments = index.get("experiments", ["A", "B", "C"])
    subjects, photo_entries = _write_subjects(root, n_photos, seed, experiments, variants, data)
    index["subjects"] = [s for s in index["subjects"] if s["id"] not in variants] + subjects
    index["photos"] = [p for p in index["photos"] if p["subject"] not in variants]
    index["photos"] += photo_entries
    index["n_subjects"] = len(index["subjects"])
    index["headsq"] = _index_note(variants)
    if any(not VARIANTS[v] for v in variants):
        inc = index.setdefault(
            "incomplete", {"no_mandible_share": 0.0, "subjects_without_mandible": []}
        )
        inc.setdefault("drop_landmark_rate", 0.0)
        lost = set(inc["subjects_without_mandible"]) | {v for v in variants if not VARIANTS[v]}
        inc["subjects_without_mandible"] = sorted(lost)
        inc["no_mandible_share"] = len(lost) / len(index["subjects"])
    write_json(root / "dataset.json", index)
    return root


def sfo_problems_from_dataset(root, experiment="C", axes_set=1, subjects=None):
    """POSEST-SFO problems of the positive pairs of a dataset on disk (``bench_posest --sfo``).

    What POSEST-SFO hands POSEST for each photo of ``subjects`` (default all) against its own
    skull: the photo's marked landmarks of ``experiment`` and the cranial landmarks pushed by the
    mean depths along the axes set ``axes_set`` (Exp. C; the folder's true axes for A/B), as
    ``sfo_problems.SfoProblem`` (scored by BPE over every true facial landmark).

    Returns
    -------
    list of sfo_problems.SfoProblem
    """
    from lilium.geometry.camera import Camera
    from lilium.inputs import correspondences
    from lilium.io.case import read_photo, read_skull
    from lilium.io.jsonio import read_json
    from lilium.methods.posest_sfo import mean_depth_landmarks
    from sfo_problems import SfoProblem

    root = Path(root)
    index = read_json(root / "dataset.json")
    entries = {s["id"]: s for s in index["subjects"]}
    problems = []
    for photo_entry in index["photos"]:
        sid = photo_entry["subject"]
        if subjects is not None and sid not in subjects:
            continue
        folder = root / entries[sid]["path"]
        axes = None
        if experiment == "C":
            axes = folder / entries[sid]["axes_C"][axes_set - 1]
        skull = read_skull(folder, axes_path=axes)
        photo_dir = root / photo_entry["paths"][experiment]
        photo = read_photo(photo_dir, load_image=False)
        truth = read_json(photo_dir / "photo.json")["ground_truth"]
        facial = read_json(folder / "facial_landmarks.json")["landmarks"]
        names = sorted(set(facial) & set(truth["landmarks_noise_free"]))
        corr = correspondences(skull, photo)
        camera = Camera.from_rt(
            np.asarray(truth["skull2cam"])[:3, :3],
            np.asarray(truth["skull2cam"])[:3, 3],
            truth["focal_px"],
            truth["principal_point_px"],
        )
        problems.append(
            SfoProblem(
                photo_id=photo_entry["id"],
                view="frontal" if photo_entry["view"] == "frontal" else "lateral",
                image_size_wh=tuple(photo.image_size_wh),
                uv_px=corr.uv_px,
                points_mm=mean_depth_landmarks(corr),
                facial_true_mm=np.array([facial[n] for n in names]),
                uv_true_px=np.array([truth["landmarks_noise_free"][n] for n in names]),
                camera=camera,
            )
        )
    return problems


def ensure_dataset(folder, n_photos=6, seed=0, data=None):
    """The headsq dataset at ``folder``, built there first if it has no ``dataset.json``
    (:func:`build_headsq_dataset`); None when the CT is absent."""
    folder = Path(folder)
    if (folder / "dataset.json").is_file():
        return folder
    return build_headsq_dataset(folder, n_photos=n_photos, seed=seed, data=data)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="headsq-case", help="dataset folder to write")
    parser.add_argument("--add-to", help="append to this generated dataset instead")
    parser.add_argument("--photos", type=int, default=3, help="frontal (and lateral) per subject")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS))
    parser.add_argument("--data", help="headsq folder (default ../shared/data/headsq)")
    args = parser.parse_args(argv)
    if args.add_to:
        out = add_headsq_subjects(args.add_to, args.photos, args.seed, args.variants, args.data)
    else:
        out = build_headsq_dataset(
            args.out, args.photos, args.seed, variants=args.variants, data=args.data
        )
    if out is None:
        print(f"no headsq CT at {args.data or DEFAULT_DATA}: nothing built", file=sys.stderr)
        return 0
    print(f"headsq dataset -> {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
