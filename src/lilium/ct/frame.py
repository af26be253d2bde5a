"""The one patient frame of imported CT meshes, and how each file's frame maps to it.

``lilium import-ct`` writes every mesh and landmark in **LPS**, the right-handed patient frame
of DICOM, ITK and 3D Slicer's files: x towards the patient's left, y posterior, z superior, mm.
A volume's own frame (:attr:`lilium.ct.volume.Volume.space`) maps to it by a sign flip of some
axes, ``p_lps = SPACE_TO_LPS @ p_space``:

=====================================================  ==================  ===================
space                                                  map to LPS          anatomy
=====================================================  ==================  ===================
``LPS``, ``left-posterior-superior`` (DICOM, MetaImage)  identity            from the file
``RAS``, ``right-anterior-superior`` (NIfTI)              negate x and y      from the file
``LAS``, ``left-anterior-superior`` (left-handed)         negate y            from the file
``3D-right-handed``, ``scanner-xyz``, none (raw data)    identity            assumed
``3D-left-handed``                                       negate z            assumed
=====================================================  ==================  ===================

A left-handed space (``LAS``, ``3D-left-handed``) maps through a reflection, so the mesh comes
out right-handed: the same voxels declared right- and left-handed give mirror images, and an
imported skull is never mirrored. Where the file names no anatomy the axes are taken as LPS
(for ``3D-left-handed``, z negated: the usual cause of a left-handed CT is an axial stack whose
slice index runs head to feet with the rows and columns of DICOM, i.e. L, P, inferior, which is
exactly what z negation turns into LPS); ``ct_import.json`` then says ``"orientation":
"assumed"``, and the chirality still holds while the axis names are a guess.
"""

import numpy as np

#: The frame of imported meshes and landmarks.
PATIENT_FRAME = "LPS"
PATIENT_FRAME_TEXT = "LPS: right-handed patient frame, x to the left, y posterior, z superior, mm"

_LPS = np.eye(3)
_RAS = np.diag([-1.0, -1.0, 1.0])
_LAS = np.diag([1.0, -1.0, 1.0])
_FLIP_Z = np.diag([1.0, 1.0, -1.0])

#: Normalised space name -> (matrix to LPS, anatomy stated by the name).
SPACES = {
    "lps": (_LPS, True),
    "left-posterior-superior": (_LPS, True),
    "ras": (_RAS, True),
    "right-anterior-superior": (_RAS, True),
    "las": (_LAS, True),
    "left-anterior-superior": (_LAS, True),
    "3d-right-handed": (_LPS, False),
    "scanner-xyz": (_LPS, False),
    "3d-left-handed": (_FLIP_Z, False),
}

#: Unit vector of the LPS frame -> the side of the patient it points to.
_SIDES = {(0, 1): "left", (0, -1): "right", (1, 1): "posterior", (1, -1): "anterior"}
_SIDES.update({(2, 1): "superior", (2, -1): "inferior"})


def normalise_space(name, source="volume"):
    """The canonical lower-case name of a space, or None for none.

    Raises
    ------
    ValueError
        A 4D space (``...-time``) or a name NRRD does not define, with the accepted names.
    """
    if name is None:
        return None
    key = str(name).strip().lower()
    if key.endswith("-time"):
        raise ValueError(
            f"{source}: space {name!r} is 4D (space + time); export one 3D volume of the series"
        )
    if key not in SPACES:
        raise ValueError(
            f"{source}: unknown space {name!r}; use one of left-posterior-superior (LPS), "
            "right-anterior-superior (RAS), left-anterior-superior, 3D-right-handed, "
            "3D-left-handed or scanner-xyz"
        )
    return key


def space_to_lps(space, source="volume"):
    """The matrix taking points of ``space`` to LPS, and whether the space names the anatomy.

    Parameters
    ----------
    space : str or None
        A space name (any case); None: a frame of unknown anatomy, taken as LPS.

    Returns
    -------
    matrix : ndarray of shape (3, 3)
        Diagonal, entries +-1: ``p_lps = matrix @ p_space``.
    anatomy_known : bool
    """
    key = normalise_space(space, source)
    if key is None:
        return _LPS.copy(), False
    matrix, known = SPACES[key]
    return matrix.copy(), known


def side_name(direction_lps):
    """The patient side a direction (LPS) points to most: ``"superior"``, ``"left"``, ...

    Parameters
    ----------
    direction_lps : array_like of shape (3,)
    """
    d = np.asarray(direction_lps, dtype=float)
    axis = int(np.argmax(np.abs(d)))
    return _SIDES[(axis, 1 if d[axis] > 0 else -1)]


#: ITK's orientation letters: the side each index axis comes *from* ("RAI": i runs right to left,
#: j anterior to posterior, k inferior to superior = the identity in LPS).
_FROM_LETTER = {
    "R": (0, 1.0),
    "L": (0, -1.0),
    "A": (1, 1.0),
    "P": (1, -1.0),
    "I": (2, 1.0),
    "S": (2, -1.0),
}


def orientation_code_to_direction(code, source="volume"):
    """Direction matrix (columns: index axes in LPS) of an ITK orientation code such as ``RAI``.

    MetaImage's ``AnatomicalOrientation`` uses ITK's convention: each letter names the side an
    index axis runs *from*, so ``RAI`` (what ITK writes for the identity) is i = right to left,
    j = anterior to posterior, k = inferior to superior.

    Raises
    ------
    ValueError
        Not three letters from R/L, A/P, I/S covering the three axes once each.
    """
    letters = str(code).strip().upper()
    if len(letters) != 3 or any(c not in _FROM_LETTER for c in letters):
        raise ValueError(
            f"{source}: AnatomicalOrientation {code!r} must be three letters from R/L, A/P, "
            "I/S (e.g. RAI)"
        )
    direction = np.zeros((3, 3))
    for column, letter in enumerate(letters):
        axis, sign = _FROM_LETTER[letter]
        direction[axis, column] = sign
    if sorted(_FROM_LETTER[c][0] for c in letters) != [0, 1, 2]:
        raise ValueError(
            f"{source}: AnatomicalOrientation {code!r} names an axis twice; use one letter of "
            "each pair R/L, A/P, I/S"
        )
    return direction


#: ``--orientation`` letters: the side each index axis runs *towards* as its index grows
#: (nibabel's axis codes; the opposite of ITK's letters above) -> (LPS axis, sign).
_TO_LETTER = {
    "L": (0, 1.0),
    "R": (0, -1.0),
    "P": (1, 1.0),
    "A": (1, -1.0),
    "S": (2, 1.0),
    "I": (2, -1.0),
}


def index_orientation_to_lps(code, source="--orientation"):
    """The columns of the index axes (i, j, k) in LPS from a code such as ``LPI``.

    Each letter names the side of the patient its index axis points to as the index grows:
    i = column (fastest in the file), j = row, k = slice. ``LPS`` is the identity; a raw axial
    stack whose first slice is the vertex, rows and columns as in DICOM, is ``LPI``.

    Parameters
    ----------
    code : str
        Three letters, one of each pair R/L, A/P, I/S.

    Returns
    -------
    ndarray of shape (3, 3)
        ``p_lps = matrix @ (ijk * spacing) + origin``; a signed permutation (det +-1).

    Raises
    ------
    ValueError
        Naming ``source`` and the form expected.
    """
    letters = str(code).strip().upper()
    valid = len(letters) == 3 and all(c in _TO_LETTER for c in letters)
    if not valid or sorted(_TO_LETTER[c][0] for c in letters) != [0, 1, 2]:
        raise ValueError(
            f"{source} {code!r}: give three letters, one of each pair R/L, A/P, S/I, naming "
            "the side each index axis (column, row, slice) points to as it grows, e.g. LPS or "
            "LPI (first slice at the top of the head)"
        )
    matrix = np.zeros((3, 3))
    for column, letter in enumerate(letters):
        axis, sign = _TO_LETTER[letter]
        matrix[axis, column] = sign
    return matrix
