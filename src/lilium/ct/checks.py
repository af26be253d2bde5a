"""What the CT importer measures and warns about: intensity units and default levels, a skull
cut by the volume's border, coarse or anisotropic voxels, an attached spine.

Default levels (iso-values), measured on a phantom (a 72 mm bone sphere in a 80 mm head of soft
tissue, 1 mm voxels with partial volume, Gaussian blur sigma 0.7 mm, noise 15 HU):

- **Hounsfield units**: bone 300 HU puts the outer bone surface 0.4-0.6 mm outside the truth
  and keeps plates 0.8 mm thin closed (400 HU starts to open them, 500 HU loses them: thin
  orbital and maxillary walls); skin -400 HU is within 0.2 mm of the air/skin boundary (-500 HU
  is the half-way level, -200 HU sits 0.6 mm inside). ``tests/ct/test_ct_frame.py`` checks both.
- **Scanner units** (air near 0, water near 1000; VTK's ``headsq``): bone 1150, skin 500, the
  classic levels of VTK's head example.

Units are "HU" where the file says so (DICOM, after the rescale) or where at least 1 % of the
voxels lie at or below -500 (air is -1000 HU; scanner units start at 0); otherwise scanner units.
"""

import numpy as np

from .frame import side_name

#: Default (bone, skin) levels per unit.
DEFAULT_LEVELS = {"HU": (300.0, -400.0), "scanner": (1150.0, 500.0)}

#: Coarsest voxel edge (mm) and largest ratio of voxel edges before a warning.
MAX_VOXEL_MM = 1.5
MAX_ANISOTROPY = 2.0

#: Cut cross-section (mm^2) of the skull at a border before the cut is reported.
MIN_CUT_AREA_MM2 = 100.0

#: Spine criterion: the bone in the posterior half of the skull reaches within this distance
#: (mm) of the lowest bone of its anterior half, or the skull is taller than
#: :data:`MAX_SKULL_HEIGHT_MM`.
SPINE_MARGIN_MM = 10.0
MAX_SKULL_HEIGHT_MM = 260.0


def detect_units(volume, override=None):
    """``("HU" | "scanner", how)`` for a volume.

    Parameters
    ----------
    volume : Volume
    override : {"hu", "scanner", "auto", None}
        The user's choice (``--units``); auto/None: detect.
    """
    if override not in (None, "auto"):
        key = str(override).lower()
        if key not in ("hu", "scanner"):
            raise ValueError(f"--units must be auto, hu or scanner, got {override!r}")
        return ("HU" if key == "hu" else "scanner"), "given (--units)"
    if volume.units == "HU":
        return "HU", "stated by the file (DICOM rescale)"
    sample = volume.data[::2, ::2, ::2]
    low = np.count_nonzero(sample <= -500) / max(sample.size, 1)
    if low >= 0.01:
        return "HU", f"detected: {100 * low:.0f} % of voxels at or below -500 (air)"
    return "scanner", "detected: no air below -500, so not Hounsfield units"


def voxel_warnings(spacing_mm):
    """Warnings about coarse or anisotropic voxels, as ``[(code, message)]``."""
    spacing = np.asarray(spacing_mm, dtype=float)
    text = " x ".join(f"{s:g}" for s in spacing)
    out = []
    if spacing.max() > MAX_VOXEL_MM:
        out.append(
            (
                "coarse_voxels",
                f"voxels of {text} mm are coarser than {MAX_VOXEL_MM} mm: thin bone (orbits, "
                "nasal bones) is lost or thickened; use the scan's thinnest reconstruction",
            )
        )
    if spacing.max() / spacing.min() > MAX_ANISOTROPY:
        out.append(
            (
                "anisotropic_voxels",
                f"voxels of {text} mm are anisotropic beyond {MAX_ANISOTROPY:g}:1 "
                f"({spacing.max() / spacing.min():.1f}:1): surfaces are staircased along the "
                "coarse axis",
            )
        )
    return out


def border_cuts(vertices_index, faces, vertices_lps, shape_zyx, to_lps):
    """Borders of the volume the mesh is cut by, with the cut area and the side of the patient.

    The mesh was extracted from the volume padded with background, so where the structure
    reaches a border it is closed by a cap lying outside the index range; a cap of at least
    :data:`MIN_CUT_AREA_MM2` counts.

    Parameters
    ----------
    vertices_index : ndarray of shape (V, 3)
        Vertices as (i, j, k) voxel indices of the (cropped) volume.
    faces : ndarray of shape (F, 3)
    vertices_lps : ndarray of shape (V, 3)
        The same vertices in the output frame, mm (for the areas).
    shape_zyx : tuple of 3 ints
        The (cropped) volume's shape.
    to_lps : ndarray of shape (3, 3)
        Columns: the i, j, k index directions in LPS (for naming the side).

    Returns
    -------
    list of dict
        ``{"axis": "i"|"j"|"k", "end": "first"|"last", "side": "superior", ..., "area_mm2"}``.
    """
    tri = vertices_lps[faces]
    areas = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    cuts = []
    for axis, n in enumerate(shape_zyx[::-1]):
        coord = vertices_index[:, axis][faces]
        for end, outside, sign in (("first", coord < 0, -1.0), ("last", coord > n - 1, 1.0)):
            area = float(areas[outside.all(axis=1)].sum())
            if area >= MIN_CUT_AREA_MM2:
                cuts.append(
                    {
                        "axis": "ijk"[axis],
                        "end": end,
                        "side": side_name(sign * to_lps[:, axis]),
                        "area_mm2": round(area, 1),
                    }
                )
    return cuts


def cut_warnings(cuts):
    """``[(code, message)]`` for the cuts of :func:`border_cuts`."""
    what = {
        "superior": "the vault is cut",
        "inferior": "the jaw or neck is cut",
        "anterior": "the face is cut",
        "posterior": "the occiput is cut",
        "left": "the left side is cut",
        "right": "the right side is cut",
    }
    out = []
    for cut in cuts:
        out.append(
            (
                "skull_cut",
                f"the skull touches the volume's {cut['side']} border ({cut['axis']} index "
                f"{cut['end']}; {cut['area_mm2']:.0f} mm^2 cut): {what[cut['side']]}, so "
                "landmarks and the silhouette there are missing",
            )
        )
    return out


def spine_check(vertices_lps):
    """Whether the largest bone component looks like it includes the cervical spine.

    Criterion (LPS frame, z superior, y posterior): split the component at the middle of its
    antero-posterior extent. A skull's posterior half (occiput, mastoids, condyles) ends 20-30
    mm above the lowest point of its anterior half without the mandible (teeth) and 50-70 mm
    above it with it (the chin); vertebrae under the skull base put posterior bone as low as the
    chin or lower. So: spine when the posterior half reaches within :data:`SPINE_MARGIN_MM` of
    the anterior half's lowest point, or when the component is taller than
    :data:`MAX_SKULL_HEIGHT_MM` (no adult skull is). Needs the patient axes: where the file
    names none, the assumed axes of :mod:`lilium.ct.frame` are used.

    Returns
    -------
    attached : bool
    measures : dict
        ``height_mm``, ``posterior_low_mm`` and ``anterior_low_mm`` (lowest z of each half).
    """
    v = np.asarray(vertices_lps, dtype=float)
    y_mid = 0.5 * (v[:, 1].min() + v[:, 1].max())
    posterior = v[v[:, 1] > y_mid, 2]
    anterior = v[v[:, 1] <= y_mid, 2]
    height = float(np.ptp(v[:, 2]))
    measures = {
        "height_mm": round(height, 1),
        "posterior_low_mm": round(float(posterior.min()), 1) if len(posterior) else None,
        "anterior_low_mm": round(float(anterior.min()), 1) if len(anterior) else None,
    }
    if not len(posterior) or not len(anterior):
        return False, measures
    attached = bool(
        posterior.min() < anterior.min() + SPINE_MARGIN_MM or height > MAX_SKULL_HEIGHT_MM
    )
    return attached, measures


def spine_warning(measures):
    """The ``(code, message)`` of an attached spine."""
    return (
        "spine_attached",
        f"the skull mesh seems to include the cervical spine (its posterior half reaches "
        f"z = {measures['posterior_low_mm']:g} mm, its anterior half z = "
        f"{measures['anterior_low_mm']:g} mm; height {measures['height_mm']:g} mm): crop the "
        "volume above the vertebrae (--crop) or raise --bone-iso, or the spine counts in the "
        "skull's silhouette",
    )
