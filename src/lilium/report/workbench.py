"""``workbench.html``: the overlay workbench, one self-contained page beside an SFO's result.

The skull is drawn with WebGL through the result's camera (the pinhole of
:mod:`lilium.geometry.camera`, in the shared ``web/meshgl.js``) over the photo, with the photo's
landmarks, the projected soft-tissue estimate and cranial landmarks, and a table of each
landmark's error in pixels (:func:`lilium.methods.checks.landmark_error`'s definition), live.
The examiner turns the skull about its anatomical axes through its centre, moves it in the
image plane, changes its distance and the focal length (:func:`adjusted_camera` is the page's
pose model in Python), and saves the camera as ``camera.json`` (``Camera.to_dict``'s object,
which :meth:`lilium.geometry.camera.Camera.from_dict` reads). Every number the page shows or
saves is in the original photo's pixels, whatever the size of the picture it embeds.

Nothing is fetched: the scripts (``lilium/report/web/*.js``) and styles are inline, the mesh is
base64 (float32 vertices relative to the skull's centre, uint32 faces, little-endian), the photo
a JPEG ``data:`` URI at most :data:`PAGE_SIDE_PX` on its long side. A mesh above ``max_faces``
is decimated (:func:`lilium.geometry.mesh.decimate`, quadric).

Opened as ``workbench.html?test[&yaw=D][&pitch=D][&roll=D]`` the page turns the skull, draws it
and writes ``<pre id="skull-box">u0 v0 u1 v1</pre>`` (the drawn skull's box, photo pixels, read
back from the framebuffer), ``<pre id="camera">`` (its camera), ``<pre id="pick">`` (a surface
pick at the projected nasion) and ``<pre id="timing">``, and presses Save, which only fills the
download link (for the headless-browser tests).
"""

import base64
import html
import io

import numpy as np

from ..fitness.regions import AnatomicalFrame, anatomical_frame
from ..geometry.camera import Camera
from ..geometry.mesh import decimate
from ..geometry.rotations import rotvec_to_matrix
from ..io.results import write_page
from ..photo.review import script_json
from ..softtissue.landmarks import CORRESPONDENCES
from .html import DEFAULT_OPACITY_PCT
from .pictures import view_box
from .records import method_label
from .web_pages import base64_array, web_page

#: Faces of the mesh the page draws (more are decimated): about 7 MB of base64 at 300,000.
DEFAULT_MAX_FACES = 300_000

#: Long side (pixels) of the photo embedded in the page; the page's numbers stay in the
#: original photo's pixels.
PAGE_SIDE_PX = 4000

#: JPEG quality of the embedded photo.
JPEG_QUALITY = 90

def skull_centre(vertices_mm):
    """The point the workbench turns the skull about: its bounding box's centre (mm, (3,))."""
    v = np.asarray(vertices_mm, dtype=float)
    return (v.min(axis=0) + v.max(axis=0)) / 2


def workbench_axes(landmarks_mm, camera):
    """The axes the workbench turns the skull about, skull frame.

    The anatomical frame of :func:`lilium.fitness.regions.anatomical_frame` (Frankfurt plane,
    or its documented fallback); without the landmarks it needs, the SFO camera's axes seen from
    the skull: ``up`` = image up, ``left`` = image right (the subject's left in a frontal photo),
    ``anterior`` = towards the camera (``source="camera"``).

    Parameters
    ----------
    landmarks_mm : dict of str -> array_like of shape (3,)
        Cranial landmarks.
    camera : Camera

    Returns
    -------
    AnatomicalFrame
        Unit ``left``, ``up``, ``anterior`` with ``anterior = left x up``.
    """
    try:
        return anatomical_frame(landmarks_mm)
    except ValueError:
        R = camera.R
        left, up = R.T @ [1.0, 0.0, 0.0], R.T @ [0.0, -1.0, 0.0]
        return AnatomicalFrame(np.zeros(3), left, up, np.cross(left, up), "camera")


def adjusted_camera(
    camera,
    axes,
    pivot_mm,
    *,
    yaw_deg=0.0,
    pitch_deg=0.0,
    roll_deg=0.0,
    shift_px=(0.0, 0.0),
    distance_mm=None,
    focal_px=None,
):
    """The camera of the workbench's pose fields: the page's model, in Python.

    ``Ra = Rot(up, yaw) Rot(left, pitch) Rot(anterior, roll)`` turns the skull about ``pivot_mm``;
    ``R = R_sfo Ra``; the pivot's camera-frame position is ``distance_mm`` along the ray through
    its SFO image point shifted by ``shift_px`` (with the new focal length), so a new focal
    length zooms about that point.

    Parameters
    ----------
    camera : Camera
        The SFO's camera.
    axes : AnatomicalFrame
        :func:`workbench_axes`.
    pivot_mm : array_like of shape (3,)
        :func:`skull_centre`.
    yaw_deg, pitch_deg, roll_deg : float
        About ``axes.up``, ``axes.left``, ``axes.anterior`` (right hand), in that order of
        composition (roll first).
    shift_px : (du, dv)
        Image shift of the pivot (pixels).
    distance_mm : float, optional
        Camera centre to pivot; default the SFO's.
    focal_px : float, optional
        Default the SFO's.

    Returns
    -------
    Camera
    """
    pivot = np.asarray(pivot_mm, dtype=float)
    Ra = (
        rotvec_to_matrix(np.radians(yaw_deg) * np.asarray(axes.up))
        @ rotvec_to_matrix(np.radians(pitch_deg) * np.asarray(axes.left))
        @ rotvec_to_matrix(np.radians(roll_deg) * np.asarray(axes.anterior))
    )
    R = camera.R @ Ra
    pivot_cam = camera.to_camera_frame(pivot[None])[0]
    pivot_uv = camera.project(pivot[None])[0]
    distance = np.linalg.norm(pivot_cam) if distance_mm is None else float(distance_mm)
    focal = camera.focal_px if focal_px is None else float(focal_px)
    ray = np.append((pivot_uv + shift_px - camera.principal_point_px) / focal, 1.0)
    centre = distance * ray / np.linalg.norm(ray)
    return Camera.from_rt(R, centre - R @ pivot, focal, camera.principal_point_px)


def _photo_data_url(image, side_px=PAGE_SIDE_PX):
    """``image`` (H, W, 3) as a JPEG ``data:`` URI, at most ``side_px`` on its long side."""
    from PIL import Image

    picture = Image.fromarray(np.asarray(image, dtype=np.uint8))
    if max(picture.size) > side_px:
        picture.thumbnail((side_px, side_px), Image.LANCZOS)
    buffer = io.BytesIO()
    picture.save(buffer, format="JPEG", quality=JPEG_QUALITY)
    return "data:image/jpeg;base64," + base64.b64encode(buffer.getvalue()).decode("ascii")


def _points(named):
    return {str(k): [float(x) for x in v] for k, v in named.items()}


#: The last skull's decimated mesh (a case draws one skull in every page): (key, the skull's
#: vertex array, held so that its id stays its own, (vertices, faces)).
_LAST_MESH = []


def page_mesh(skull, max_faces=DEFAULT_MAX_FACES):
    """The skull's mesh as the page draws it: ``(vertices (V', 3), faces (F', 3))``, decimated
    to about ``max_faces`` (:func:`lilium.geometry.mesh.decimate`); the last skull's is kept,
    so the pages of one case decimate it once."""
    key = (id(skull.vertices_mm), id(skull.faces), int(max_faces))
    if _LAST_MESH and _LAST_MESH[0][0] == key and _LAST_MESH[0][1] is skull.vertices_mm:
        return _LAST_MESH[0][2]
    mesh = decimate(skull.vertices_mm, skull.faces, max_faces)
    _LAST_MESH[:] = [(key, skull.vertices_mm, mesh)]
    return mesh


def workbench_page(skull, photo, result, *, max_faces=DEFAULT_MAX_FACES, title=""):
    """The workbench page of one SFO, as HTML text.

    Parameters
    ----------
    skull : lilium.inputs.Skull
        Mesh (``vertices_mm`` (V, 3), ``faces`` (F, 3)) and cranial landmarks (skull frame).
    photo : lilium.inputs.Photo
        ``image`` (H, W, 3) uint8 or None (a grey stage), ``image_size_wh``, ``landmarks_uv``.
    result : lilium.methods.result.SfoResult
        Needs ``camera``; uses ``facial_landmarks_mm`` (facial name -> (3,), skull frame) and
        ``landmark_error`` (the SFO's errors, shown beside the live ones).
    max_faces : int
        Faces drawn; a larger mesh is decimated to about this many.
    title : str
        Default ``"<skull> / <photo> / <method and variant>"``, saying "examiner's camera" for
        an examiner's result (:func:`~lilium.report.records.method_label`).

    Returns
    -------
    str

    Raises
    ------
    ValueError
        A failed SFO (no camera).
    """
    if result.camera is None:
        raise ValueError(
            f"no workbench for a failed SFO ({result.skull_id} / {result.photo_id}: "
            f"{result.error or 'no camera'}); rerun the SFO first"
        )
    camera = result.camera
    vertices, faces = page_mesh(skull, max_faces)
    pivot = skull_centre(skull.vertices_mm)
    axes = workbench_axes(skull.landmarks_mm, camera)
    size_wh = tuple(int(s) for s in photo.image_size_wh)
    photo_uv = _points(photo.landmarks_uv)
    points = np.vstack([camera.project(vertices), np.reshape(list(photo_uv.values()), (-1, 2))])
    facial = _points(result.facial_landmarks_mm)
    cranial = _points(skull.landmarks_mm)
    errors = result.landmark_error or {}
    data = {
        "camera": camera.to_dict(),
        "image_size_wh": list(size_wh),
        "has_image": photo.image is not None,
        "view_box": [int(x) for x in view_box(size_wh, mask=photo.face_mask, points_uv=points)],
        "mesh_origin_mm": [float(x) for x in pivot],
        "pivot_mm": [float(x) for x in pivot],
        "axes": {k: [float(x) for x in getattr(axes, k)] for k in ("left", "up", "anterior")},
        "axes_source": axes.source,
        "cranial_mm": cranial,
        "facial_mm": facial,
        "photo_uv": photo_uv,
        "pairs": [[c, f] for c, f in CORRESPONDENCES if c in cranial and f in facial],
        "sfo_error_px": errors.get("per_landmark_px") or {},
        "faces": {"drawn": len(faces), "of": len(skull.faces)},
    }
    mean = errors.get("mean_px")
    axes_source = {
        "frankfurt": "anatomical (Frankfurt plane)",
        "fallback": "anatomical (midline landmarks; no Frankfurt plane)",
        "camera": "the SFO camera's (too few cranial landmarks for anatomical ones)",
    }[axes.source]
    title = title or f"{skull.id} / {photo.id} / {method_label(result)}"
    values = {
        "__TITLE__": html.escape(title),
        "__SFO_MEAN__": "&ndash;" if mean is None else f"{mean:.2f}",
        "__AXES_SOURCE__": html.escape(axes_source),
        "__W__": str(size_wh[0]),
        "__H__": str(size_wh[1]),
        "__OPACITY__": str(DEFAULT_OPACITY_PCT),
        "__IMAGE__": "data:," if photo.image is None else _photo_data_url(photo.image),
        "__DATA__": script_json(data),
        "__POSITIONS__": base64_array(np.asarray(vertices, dtype=float) - pivot, "<f4"),
        "__INDICES__": base64_array(faces, "<u4"),
    }
    return web_page("workbench.html", "workbench.js", values)


def write_workbench(path, skull, photo, result, **kwargs):
    """Write :func:`workbench_page` to ``path`` (e.g. ``OUT/<photo>/<method>/workbench.html``).

    Keywords go to :func:`workbench_page`. Returns the path.
    """
    page = workbench_page(skull, photo, result, **kwargs)
    return write_page(path, page)
