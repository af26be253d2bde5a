"""The InVesalius "Cranium" CT: where to find it, how to read it, its volume edits, its meshes
and its subject in the skull frame.

:func:`cranium_subject` gives the subject ``cr`` of ``benchmarks/datasets/cranium_case.py`` (which
renders its photos and writes the dataset); :func:`data_path` finds the CT, :func:`fetch` gets
it.

Data: ``Cranium.inv3`` of the Debian package ``invesalius-examples`` (InVesalius' example
project, GPL-2; installed as ``/usr/share/doc/invesalius-examples/examples/Cranium.inv3``).
Looked for at the ``--data`` argument, the environment variable ``LILIUM_CRANIUM``,
``../shared/data/cranium/Cranium.inv3`` beside the repository, then the installed path.
``python benchmarks/datasets/cranium_ct.py --fetch CACHE_DIR`` runs ``apt-get download
invesalius-examples`` in ``CACHE_DIR`` and extracts ``Cranium.inv3`` there (a development
step: the project's tests skip without the file and never download it).

The file: a gzip tar holding ``main.plist`` (an Apple plist: ``matrix`` shape 108 x 256 x 256
(slice, row, column), dtype int16, ``spacing`` 0.957 x 0.957 x 1.5 mm (column, row, slice),
modality CT) and ``matrix.dat`` (little-endian int16 Hounsfield units, -1024 to 2986). A living
adult's head from the upper teeth (slice 0 cuts the crowns of the upper dentition) to the vertex,
eyes closed; the mandible is not scanned but for its rami (coronoid processes, condyles), which
reach up into the lowest 25 slices, with the atlas and the dens. The vault has a large defect of
the right frontal bone (roughly 25 x 50 mm in front view) above an irregular supraorbital
margin; the right zygoma and arch are irregular (healed trauma or surgery). A plastic head-rest
shell (up to about 600 HU) and its foam (about -550 HU) lie behind the head, apart from it.

Orientation, checked on renders of the meshes (not in the file): slice index k runs from the teeth
to the vertex (superior), row index j from the occiput to the face (anterior); column index i
runs to the subject's left, as InVesalius stores an axial DICOM series (its reader reverses the
rows of each image and keeps the columns, whose DICOM direction is the patient's left). So
``(i, j, k) -> (L, A, S)``: the voxel grid is left-handed and its direction matrix in LPS is
``diag(1, -1, 1)``; the meshes are not mirrored. The left/right call rests on the column
convention only (nothing in the anatomy of a head decides it).

What is built here, all through the project's own code:

1. Volume edits before meshing: the mandible's rami and the cervical vertebrae (atlas, dens) are
   lowered to soft tissue (:data:`SOFT_TISSUE_HU`). They touch the skull at the joints, so they
   are split off by a watershed of the bone mask (bone at :data:`BONE_ISO` and above, its largest
   component) on the smoothed CT number, which cuts along the joint spaces (the darkest seams):
   seeds are the bone of the two lowest slices in the voxel boxes :data:`RAMUS_BOXES` (one each
   side) and :data:`VERTEBRA_BOX`, against the bone of the dental arch box :data:`TEETH_BOX` and
   every bone voxel from slice :data:`CRANIUM_SLICES_FROM` up (the cranium). Measured: 4923 +
   5212 voxels of the rami (slices 0-25: coronoid processes, necks and condyles), 5860 of the
   atlas and dens (slices 0-9); checked on sections and renders (the clivus and the occipital
   condyles stay with the skull; a watershed on the distance to the bone's surface instead took
   the thin clivus with the atlas). The head-rest shell is a separate bone component, dropped by
   the importer's largest-component rule; no other edit.
2. ``lilium.ct.import_ct`` (skull at :data:`BONE_ISO`, skin at :data:`SKIN_ISO`, LPS, decimated
   to :data:`TARGET_FACES` faces each) into a work folder, then the meshes and landmarks turned
   into the generator's skull frame (x = the subject's left, y = up, z = anterior;
   ``lilium.synthetic.subjects``): ``(x, y, z) = (L, S, -P)`` minus the centre of the skull's
   bounding box, then shifted in x so that the midline (between the orbits) is x = 0 (a proper
   rotation and a translation, no mirroring). The head lies about level in the scanner (the
   hard palate is horizontal within about 4 degrees: slices 11-16 from row 170 to 195), so the
   axes are not turned to the Frankfurt plane (the porion is not placed, see the landmarks).
   The importer warns ``skull_cut`` (the teeth at slice 0) and ``spine_attached``: the latter
   is its height rule misled by the cut, as the occiput reaches down to the lowest slices too;
   the vertebrae are removed.
3. Landmarks placed on the meshes by :func:`cranium_landmarks.place_landmarks` (its rules and
   its sanity figures in that module's docstring; each one a vertex of its mesh); the true soft
   tissue of each pair is ``F - C`` (direction in ``soft_tissue_axes.json``, depth in
   ``subject.json``). The subject has ``mandible=False``: the mandible was never in the scan,
   so there are no true mandible landmarks to keep (``removed_landmarks`` is empty).

Iso-values (HU): bone 300, the importer's default for HU. Soft tissue is 0-80 HU here and
cortical bone peaks at 1500-1800 HU, so 300 keeps the surface clear of muscle and vessels while
keeping the thin edges that partial volume at 1 x 1 x 1.5 mm lowers to 300-900 HU (orbital
rims and roofs, nasal bones, the aperture's margins, the zygomatic arches): at 450 the orbital
roofs and the nasal region break into holes, at 200 the orbits fill with the streaks of the
1.5 mm slices. The lacrimal bone and the lamina papyracea (100-150 HU) are lost at any level
clear of soft tissue. InVesalius' own bone mask of this file starts at 226. Skin -400, the
importer's default: half-way between air (-1000) and fat (-100 to 0), above the head-rest
foam (its 99th percentile is -535), so the skin is the head's own.
"""

import argparse
import os
import plistlib
import shutil
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

import numpy as np

from cranium_landmarks import place_landmarks, sanity_figures
from headsq_ct import true_soft_tissue

#: The CT beside the repository; ``LILIUM_CRANIUM`` (a file or its folder) overrides it.
FILE_NAME = "Cranium.inv3"
DEFAULT_DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "cranium"
INSTALLED = Path("/usr/share/doc/invesalius-examples/examples") / FILE_NAME
PACKAGE = "invesalius-examples"

BONE_ISO = 300.0
SKIN_ISO = -400.0
SOFT_TISSUE_HU = 40  # what removed bone becomes
TARGET_FACES = 150_000

#: (i, j, k) -> LPS of the voxel grid (see the module notes): left, anterior, superior.
INDEX_TO_LPS = np.diag([1.0, -1.0, 1.0])
#: LPS -> generator skull frame (x = left, y = up, z = anterior): a proper rotation.
LPS_TO_SKULL = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])

#: Watershed seeds (voxel boxes: rows j, columns i; seeds are bone in slices < SEED_SLICES).
SEED_SLICES = 2
RAMUS_BOXES = {"right": ((125, 175), (60, 105)), "left": ((125, 175), (155, 200))}
VERTEBRA_BOX = ((95, 135), (100, 160))
TEETH_BOX = ((175, 256), (95, 165))
CRANIUM_SLICES_FROM = 26
SMOOTH_VOXELS = 0.7


def data_path(path=None):
    """``Cranium.inv3`` (the argument, ``LILIUM_CRANIUM``, the default or the installed path;
    each a file or a folder holding it), or None if absent."""
    given = path or os.environ.get("LILIUM_CRANIUM")
    candidates = [Path(given)] if given else [DEFAULT_DATA, INSTALLED]
    for candidate in candidates:
        candidate = candidate / FILE_NAME if candidate.is_dir() else candidate
        if candidate.is_file():
            return candidate
    return None


def fetch(cache_dir):
    """``apt-get download invesalius-examples`` into ``cache_dir`` (unless a .deb is already
    there) and extract ``Cranium.inv3`` beside it.

    Returns
    -------
    Path
        ``cache_dir/Cranium.inv3``.
    """
    cache = Path(cache_dir).resolve()
    cache.mkdir(parents=True, exist_ok=True)
    target = cache / FILE_NAME
    if target.is_file():
        return target
    debs = sorted(cache.glob(f"{PACKAGE}_*.deb"))
    if not debs:
        subprocess.run(["apt-get", "download", PACKAGE], cwd=cache, check=True)
        debs = sorted(cache.glob(f"{PACKAGE}_*.deb"))
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run(["dpkg-deb", "-x", str(debs[-1]), tmp], check=True)
        found = list(Path(tmp).rglob(FILE_NAME))
        if not found:
            raise FileNotFoundError(f"{debs[-1]} holds no {FILE_NAME}")
        shutil.copyfile(found[0], target)
    return target


def read_inv3(path):
    """The CT of an InVesalius project file as a ``lilium.ct.Volume`` in LPS (HU).

    Parameters
    ----------
    path : path
        An ``.inv3`` file (gzip tar with ``main.plist`` and the matrix it names).

    Returns
    -------
    lilium.ct.Volume
    """
    from lilium.ct.volume import Volume

    path = Path(path)
    with tarfile.open(path, "r:gz") as tar:
        members = {Path(m.name).name: m for m in tar.getmembers() if m.isfile()}
        main = plistlib.loads(tar.extractfile(members["main.plist"]).read())
        matrix = main["matrix"]
        blob = tar.extractfile(members[matrix["filename"]]).read()
    dtype = np.dtype(matrix["dtype"]).newbyteorder("<")
    data = np.frombuffer(blob, dtype=dtype).reshape(matrix["shape"]).astype(np.int16)
    return Volume(
        data,
        np.asarray(main["spacing"], dtype=float),  # column, row, slice
        direction=INDEX_TO_LPS,
        source=str(path),
        space="LPS",
        space_known=True,
        units="HU",
    )


# -- volume -----------------------------------------------------------------------------------
def _box_seeds(bone, box):
    (j0, j1), (i0, i1) = box
    seeds = np.zeros_like(bone)
    seeds[:SEED_SLICES, j0:j1, i0:i1] = bone[:SEED_SLICES, j0:j1, i0:i1]
    return seeds


def removed_bone(volume):
    """The voxels of the mandible's rami and of the vertebrae (see the module notes).

    Returns
    -------
    dict of str -> ndarray of shape (Z, Y, X), bool
        ``ramus_right``, ``ramus_left``, ``vertebrae``.
    """
    from scipy import ndimage as ndi
    from skimage.segmentation import watershed

    data = volume.data
    bone = data >= BONE_ISO
    labels, _ = ndi.label(bone)
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    bone = labels == np.argmax(sizes)  # the head; the head-rest shell is apart
    markers = np.zeros(data.shape, np.int32)
    markers[CRANIUM_SLICES_FROM:][bone[CRANIUM_SLICES_FROM:]] = 1
    markers[_box_seeds(bone, TEETH_BOX)] = 1
    parts = {"ramus_right": RAMUS_BOXES["right"], "ramus_left": RAMUS_BOXES["left"]}
    parts["vertebrae"] = VERTEBRA_BOX
    for n, box in enumerate(parts.values(), start=2):
        markers[_box_seeds(bone, box)] = n
    elevation = -ndi.gaussian_filter(data.astype(np.float32), SMOOTH_VOXELS)
    regions = watershed(elevation, markers, mask=bone)
    out = {name: regions == n for n, name in enumerate(parts, start=2)}
    for name, mask in out.items():
        if not mask.any():
            raise ValueError(f"{volume.source}: no bone seeds for the {name} (not this CT?)")
    return out


def edited_volume(path=None):
    """The CT without the mandible's rami and the vertebrae, and the removed voxel counts.

    Returns
    -------
    volume : lilium.ct.Volume
    removed : dict of str -> int
    """
    from dataclasses import replace

    found = data_path(path)
    if found is None:
        raise FileNotFoundError(f"no {FILE_NAME} at {path or DEFAULT_DATA}")
    volume = read_inv3(found)
    data = volume.data.copy()
    removed = {}
    for name, mask in removed_bone(volume).items():
        data[mask] = SOFT_TISSUE_HU
        removed[name] = int(mask.sum())
    return replace(volume, data=data), removed


def hu_sampler(volume, origin):
    """``hu_at(points (N, 3)) -> (N,)``: the CT number (linear interpolation) at skull-frame
    points, for the frame ``skull = lps @ LPS_TO_SKULL.T - origin`` (mm)."""
    from scipy.ndimage import map_coordinates

    def hu_at(points):
        lps = (np.asarray(points, dtype=float) + origin) @ LPS_TO_SKULL
        ijk = (lps - volume.origin_mm) @ volume.direction / volume.spacing_mm
        return map_coordinates(volume.data.astype(np.float32), ijk[:, ::-1].T, order=1)

    return hu_at


# -- subject ----------------------------------------------------------------------------------
_CACHE = {}


def cranium_subject(path=None, work_dir=None):
    """The Cranium subject ``cr`` (``SyntheticSubject``, ``mandible=False``) and its records.

    Meshes come from ``import_ct`` (written under ``work_dir``, a temporary folder by default)
    and are turned into the skull frame; see the module notes.

    Returns
    -------
    dict
        ``"cr"``: the subject; ``"_record"``: what ``ct_import.json`` holds; ``"_origin_lps"``:
        the skull frame's origin in LPS (mm); ``"_removed_voxels"``; ``"_sanity"``: the
        craniometric figures of :func:`cranium_landmarks.sanity_figures`.
    """
    from lilium.ct import import_ct
    from lilium.synthetic.subjects import SyntheticSubject

    key = str(data_path(path))
    if key in _CACHE:
        return _CACHE[key]
    volume, removed = edited_volume(path)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(work_dir or tmp) / "ct_import"
        result = import_ct(
            volume, folder, bone_iso=BONE_ISO, skin_iso=SKIN_ISO, target_faces=TARGET_FACES
        )
    (skull, skull_f), (skin, skin_f) = result["skull"], result["skin"]
    origin = 0.5 * (skull.min(axis=0) + skull.max(axis=0)) @ LPS_TO_SKULL.T
    skull = skull @ LPS_TO_SKULL.T - origin
    skin = skin @ LPS_TO_SKULL.T - origin
    hu_at = hu_sampler(volume, origin)
    cranial, facial, x_mid = place_landmarks(skull, skull_f, skin, skin_f, hu_at)
    shift = np.array([x_mid, 0.0, 0.0])  # x = 0 on the midline
    skull, skin, origin = skull - shift, skin - shift, origin + shift
    cranial = {k: v - shift for k, v in cranial.items()}
    facial = {k: v - shift for k, v in facial.items()}
    axes, depths, normals = true_soft_tissue(skull, skull_f, cranial, facial)
    subject = SyntheticSubject(
        "cr",
        skull,
        skull_f,
        skin,
        skin_f,
        cranial,
        facial,
        axes,
        depths,
        normals,
        mandible=False,
        removed_landmarks={},
    )
    out = {
        "cr": subject,
        "_record": result["record"],
        "_origin_lps": origin @ LPS_TO_SKULL,
        "_removed_voxels": removed,
        "_sanity": sanity_figures(cranial),
    }
    _CACHE[key] = out
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", help=f"{FILE_NAME} or its folder")
    parser.add_argument("--fetch", metavar="CACHE_DIR", help="apt-get download and extract")
    args = parser.parse_args(argv)
    if args.fetch:
        print(f"{FILE_NAME} -> {fetch(args.fetch)}")
        return 0
    found = data_path(args.data)
    if found is None:
        print(f"no {FILE_NAME} (--data, LILIUM_CRANIUM, {DEFAULT_DATA}, {INSTALLED})")
        return 1
    subjects = cranium_subject(found)
    subject = subjects["cr"]
    print(f"{found}: skull {len(subject.skull_faces)} faces, skin {len(subject.skin_faces)}")
    print(f"removed voxels: {subjects['_removed_voxels']}")
    for name, (value, lo, hi) in subjects["_sanity"].items():
        flag = "" if lo <= value <= hi else "  (outside the adult range)"
        print(f"{name:>24}: {value:6.1f} mm  (adult {lo:g}-{hi:g}){flag}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
