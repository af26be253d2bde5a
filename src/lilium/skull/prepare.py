"""``lilium skull``'s folder: a bare skull mesh to a subject folder (I/O; the maths is in
:func:`lilium.skull.locate.locate_skull_landmarks`).

Written in ``out`` (and nowhere else): ``skull.ply`` (the mesh in its own frame and units, welded
and checked as ``lilium case`` reads it), ``cranial_landmarks.json`` (docs/contract.md:
``landmarks``, ``landmark_sources``, ``parts``, ``prepared_by``) and ``soft_tissue_axes.json``
(:func:`lilium.softtissue.normals.fitted_axes` in the fitted frame: the outward surface
normals, ``lilium case``'s default, but beside the eye corners and the alae)
and ``review.html`` (the skull in 3D, each landmark draggable along the bone:
:mod:`lilium.report.skull_review`).
"""

from pathlib import Path

import numpy as np

from .locate import (
    FOREIGN_PART_MM,
    GIVEN,
    TEMPLATE,
    locate_skull_landmarks,
    orientation_dependent,
)

#: ``prepared_by`` of the files written here.
PREPARED_BY = "lilium skull"

#: The ``flag`` of an automatic point of :data:`~lilium.skull.locate.ORIENTATION_DEPENDENT`:
#: check it first in review.html.
FLAG = "orientation_dependent"


def _reviewed(landmarks_path):
    """The points of a landmark file to keep: all of them, but those a ``landmark_sources``
    entry marks as automatic and not confirmed (they are placed again)."""
    from ..io.case import parse_cranial_landmarks
    from ..io.jsonio import read_json

    points = parse_cranial_landmarks(landmarks_path)
    sources = {}
    if Path(landmarks_path).suffix.lower() == ".json":
        data = read_json(landmarks_path)
        sources = data.get("landmark_sources", {}) if isinstance(data, dict) else {}
    keep = {}
    for name, p in points.items():
        entry = sources.get(name) if isinstance(sources, dict) else None
        automatic = isinstance(entry, dict) and entry.get("source") == "automatic"
        if not automatic or entry.get("confirmed") is True:
            keep[name] = p
    return keep


def landmark_sources(result):
    """``{name: {"source", "quality"[, "confirmed"][, "flag"]}}`` of the contract for a
    :class:`~lilium.skull.locate.SkullLandmarks`: an automatic point of
    :data:`~lilium.skull.locate.ORIENTATION_DEPENDENT` is flagged for review, ``"flag":
    "orientation_dependent"``."""
    out = {}
    for name, quality in result.quality.items():
        if quality == GIVEN:
            out[name] = {"source": "reviewed", "quality": "manual", "confirmed": True}
        else:
            out[name] = {"source": "automatic", "quality": quality}
            if orientation_dependent(name):
                out[name]["flag"] = FLAG
    return out


def parts_left_out_sentence(face_counts):
    """What ``lilium skull`` says of the mesh's parts it took for no part of the skull
    (:func:`~lilium.skull.locate.locate_skull_landmarks`; ``face_counts`` per part, largest
    first)."""
    n, faces = len(face_counts), sum(face_counts)
    largest = f"; the largest {face_counts[0]}" if n > 1 else ""
    return (
        f"{n} part(s) of the mesh left out of skull.ply ({faces} faces{largest}): apart from "
        f"the skull, or farther than {FOREIGN_PART_MM:g} mm from the fitted skull (a stand, a "
        "label, a mandible not in place?); if one is this skull's bone, put it in place"
    )


def flagged(sources):
    """The names ``sources`` (``landmark_sources``) flags for review, in its order."""
    return [name for name, entry in sources.items() if entry.get("flag") == FLAG]


def _review_page(vertices, faces, result, sources, title):
    """The HTML of ``review.html``: the skull in 3D, every landmark draggable along the bone
    (:mod:`lilium.report.skull_review`), opened in a frontal view of the fitted skull frame."""
    from ..report.skull_review import skull_review_page

    parts = {"cranium": True, "mandible": result.mandible}
    template = [n for n, q in result.quality.items() if q == TEMPLATE]
    message = "automatic landmarks, unreviewed: check each, drag it where it belongs, Save"
    if template:
        message += f"; template points (off until confirmed): {', '.join(template)}"
    for name, why in result.doubtful.items():
        message += f"; {name} not located: {why}"
    if result.parts_left_out:
        message += f"; {parts_left_out_sentence(result.parts_left_out)}"
    check = flagged(sources)
    if check:
        message += (
            "; check first (extremes whose place depends on the head's orientation): "
            + ", ".join(check)
        )
    return skull_review_page(
        vertices, faces, result.landmarks, sources, title=title, parts=parts, message=message,
        skull_axes=result.mesh2skull[:3, :3],
    )


def _prepared(out, mesh_sha256):
    """Whether the subject folder ``out`` is whole and was written for the mesh of this sha256
    (its ``cranial_landmarks.json`` names it, written last, and ``skull.ply`` is there)."""
    from ..io.jsonio import read_json

    try:
        stored = read_json(out / "cranial_landmarks.json").get("mesh_sha256")
    except (ValueError, AttributeError):
        return False
    return stored == mesh_sha256 and (out / "skull.ply").is_file()


def prepare_skull(mesh_path, out, landmarks_path=None, rng=0, reuse=False):
    """Place the cranial landmarks of a skull mesh and write the subject folder ``out``.

    Parameters
    ----------
    mesh_path : str or Path
        PLY, OBJ or STL, millimetres, any pose.
    out : str or Path
        The subject folder (created; only files inside it are written).
    landmarks_path : str or Path, optional
        Reviewed landmarks (any cranial landmark file ``lilium case`` reads): kept as they are;
        the rest are placed.
    rng : anything :func:`numpy.random.default_rng` accepts
    reuse : bool
        Keep the folder ``out`` as it is when ``lilium skull`` already wrote it for this mesh
        (the same bytes; ``lilium case --skull MESH``): nothing placed, ``result`` None.

    Returns
    -------
    dict
        ``folder``, ``reused``, ``result`` (:class:`~lilium.skull.locate.SkullLandmarks`),
        ``faces``.

    Raises
    ------
    ValueError
        An unreadable mesh, a mesh that is not a skull in millimetres, a bad landmark file.
    """
    from ..geometry.mesh import check_landmarks_on_mesh, clean_mesh, compact
    from ..io.jsonio import write_json
    from ..io.mesh import parse_mesh, write_mesh
    from ..io.provenance import sha256_of
    from ..io.results import write_page
    from ..methods.checks import check_cranial_labels

    mesh_path, out = Path(mesh_path), Path(out)
    digest = sha256_of(mesh_path)
    if reuse and _prepared(out, digest):
        return {"folder": out, "reused": True, "result": None, "faces": None}
    if (out / "skull.ply").resolve() == mesh_path.resolve():
        raise ValueError(
            f"{mesh_path}: --out {out} would write skull.ply over the input mesh; give another "
            "output folder"
        )
    vertices, faces = compact(*clean_mesh(*parse_mesh(mesh_path), source=str(mesh_path)))
    keep = _reviewed(landmarks_path) if landmarks_path is not None else None
    if keep:
        check_landmarks_on_mesh(keep, vertices, faces, landmarks_path)
        check_cranial_labels(keep, vertices, landmarks_path)
    result = locate_skull_landmarks(vertices, faces, keep=keep, rng=rng, source=str(mesh_path))
    # The skull without the parts that are not its bone (a stand, a far fragment): what the
    # landmarks were placed on, and what an SFO is to draw.
    vertices, faces = compact(vertices, faces[result.faces_kept])
    sources = landmark_sources(result)
    page = _review_page(vertices, faces, result, sources, mesh_path.name)
    out.mkdir(parents=True, exist_ok=True)
    write_page(out / "review.html", page)
    write_mesh(out / "skull.ply", vertices, faces)
    write_json(out / "soft_tissue_axes.json", {"axes": result.axes, "prepared_by": PREPARED_BY})
    write_json(  # last: a folder holding it is whole (_prepared)
        out / "cranial_landmarks.json",
        {
            "landmarks": result.landmarks,
            "landmark_sources": sources,
            "parts": {"cranium": True, "mandible": result.mandible},
            "prepared_by": PREPARED_BY,
            "mesh": mesh_path.name,
            "mesh_sha256": digest,
            "mesh2skull": np.round(result.mesh2skull, 9),
        },
    )
    return {"folder": out, "reused": False, "result": result, "faces": len(faces)}
