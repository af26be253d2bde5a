"""The landmarked template skull: the generator's mean subject, built at run time.

The template is the skull of :mod:`lilium.synthetic` with every shape parameter at its
population mean (:data:`~lilium.synthetic.anatomy.shape.SHAPE_PRIORS`) and a fixed seed for the
vault's bumps: its mesh, every cranial landmark (placed by the generator's own rules,
:func:`~lilium.synthetic.anatomy.landmarks.locate_cranial_landmarks`), which vertices are the
mandible's and the design points the landmark searches start from. Building it takes about 1.5 s
and is done once per process (:func:`mean_template`). Skull frame, mm (x = the subject's left,
y = up, z = anterior; :mod:`lilium.synthetic.subjects`).
"""

from dataclasses import dataclass, field, fields
from functools import lru_cache

import numpy as np

#: Seed of the template's vault bumps (any fixed value: the template must not change).
TEMPLATE_SEED = 0
#: Faces of the template mesh.
TEMPLATE_FACES = 40_000
#: A template vertex farther than this (mm) from the skull built without the mandible is the
#: mandible's.
MANDIBLE_GAP_MM = 2.5


@dataclass(frozen=True)
class Template:
    """A landmarked skull in the skull frame (mm).

    Attributes
    ----------
    vertices : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int
    landmarks : dict of str -> ndarray of shape (3,)
        Every name of :data:`~lilium.softtissue.landmarks.CRANIAL_NAMES`.
    mandible : ndarray of shape (V,), bool
        The mandible's vertices (and the lower teeth's).
    anchors : dict of str -> ndarray of shape (3,)
        Design points of the generator the searches start from: ``orbit_l``, ``orbit_r``
        (orbit centres), ``aperture`` (nasal aperture centre), ``ans`` (anterior nasal spine),
        ``canal_l``, ``canal_r`` (ear canal centres), ``menton``.
    """

    vertices: np.ndarray
    faces: np.ndarray
    landmarks: dict = field(default_factory=dict)
    mandible: np.ndarray | None = None
    anchors: dict = field(default_factory=dict)


def _anchors(design):
    orbit = np.asarray(design["orbit"], float)
    canal = np.asarray(design["canal"], float)
    return {
        "orbit_l": orbit,
        "orbit_r": orbit * (-1, 1, 1),
        "aperture": np.asarray(design["nasal_aperture"], float),
        "ans": np.asarray(design["ans"], float),
        "canal_l": canal,
        "canal_r": canal * (-1, 1, 1),
        "menton": np.array([0.0, design["menton_y"], design["chin_z"]]),
    }


@lru_cache(maxsize=1)
def mean_template():
    """The generator's mean skull with its landmarks (built once per process).

    Returns
    -------
    Template
    """
    from scipy.spatial import cKDTree

    from ..synthetic.anatomy.bone import build_bone
    from ..synthetic.anatomy.landmarks import locate_cranial_landmarks
    from ..synthetic.anatomy.shape import SHAPE_PRIORS, SubjectShape
    from ..synthetic.subjects import _mesh

    shape = SubjectShape(**{f.name: SHAPE_PRIORS[f.name].mean for f in fields(SubjectShape)})
    bone, design = build_bone(shape, np.random.default_rng(TEMPLATE_SEED))
    vertices, faces = _mesh(bone, TEMPLATE_FACES)
    landmarks = locate_cranial_landmarks(bone, design)
    cranium, _ = build_bone(shape, np.random.default_rng(TEMPLATE_SEED), mandible=False)
    cranium_v, _ = _mesh(cranium, TEMPLATE_FACES)
    gap, _ = cKDTree(cranium_v).query(vertices)
    return Template(vertices, faces, landmarks, gap > MANDIBLE_GAP_MM, _anchors(design))
