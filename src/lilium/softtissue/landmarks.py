"""The landmark catalogue of docs/method/skull.md.

Canonical names are snake_case; ``_l``/``_r`` are the *subject's* left/right. A cranial landmark
(on bone) is paired with a facial landmark (on skin); the soft-tissue vector of the pair goes from
the cranial to the facial landmark.
"""

#: (cranial, facial) correspondences used for pose estimation, bilateral ones expanded.
CORRESPONDENCES = (
    ("ectoconchion_l", "exocanthion_l"),
    ("ectoconchion_r", "exocanthion_r"),
    ("dacryon_l", "endocanthion_l"),
    ("dacryon_r", "endocanthion_r"),
    ("zygion_l", "zygion_l"),
    ("zygion_r", "zygion_r"),
    ("gonion_l", "gonion_l"),
    ("gonion_r", "gonion_r"),
    ("alare_l", "alare_l"),
    ("alare_r", "alare_r"),
    ("frontotemporale_l", "frontotemporale_l"),
    ("frontotemporale_r", "frontotemporale_r"),
    ("glabella", "glabella"),
    ("nasion", "nasion"),
    ("metopion", "metopion"),
    ("bregma", "bregma"),
    ("prosthion", "labiale_superius"),
    ("subspinale", "subnasale"),
    ("pogonion", "pogonion"),
    ("gnathion", "gnathion"),
)

#: Cranial landmarks used only to cut regions and frames.
EXTRA_CRANIAL = (
    "infradentale",
    "mental_foramen_l",
    "mental_foramen_r",
    "porion_l",
    "porion_r",
    "orbitale_l",
    "orbitale_r",
)

#: Facial landmarks used only to cut regions.
EXTRA_FACIAL = ("cheilion_l", "cheilion_r")

CRANIAL_TO_FACIAL = dict(CORRESPONDENCES)
FACIAL_TO_CRANIAL = {facial: cranial for cranial, facial in CORRESPONDENCES}

#: Every cranial / facial name the package understands.
CRANIAL_NAMES = tuple(c for c, _ in CORRESPONDENCES) + EXTRA_CRANIAL
FACIAL_NAMES = tuple(f for _, f in CORRESPONDENCES) + EXTRA_FACIAL

#: Cranial landmarks on the mandible: absent from a skull without it (a skull with none of them
#: has no mandible).
MANDIBLE_LANDMARKS = (
    "infradentale",
    "mental_foramen_l",
    "mental_foramen_r",
    "pogonion",
    "gnathion",
    "gonion_l",
    "gonion_r",
)

#: Midline cranial landmarks (lie on the midsagittal plane).
MIDLINE_CRANIAL = (
    "glabella",
    "nasion",
    "metopion",
    "bregma",
    "prosthion",
    "subspinale",
    "pogonion",
    "gnathion",
    "infradentale",
)


def twin(name):
    """The bilateral twin of a landmark name (``zygion_l`` <-> ``zygion_r``), or None."""
    if name.endswith("_l"):
        return name[:-2] + "_r"
    if name.endswith("_r"):
        return name[:-2] + "_l"
    return None


def side(name):
    """``"l"``, ``"r"`` or ``None`` (midline)."""
    return name[-1] if name.endswith(("_l", "_r")) else None


def base_name(name):
    """Name without its side suffix: ``zygion_l`` -> ``zygion``."""
    return name[:-2] if side(name) else name


def bilateral_pairs(cranial_names):
    """Index pairs ``(i_left, i_right)`` of twins that are both in ``cranial_names``."""
    index = {n: i for i, n in enumerate(cranial_names)}
    return [
        (i, index[twin(n)])
        for i, n in enumerate(cranial_names)
        if side(n) == "l" and twin(n) in index
    ]
