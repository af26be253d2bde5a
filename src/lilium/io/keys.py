"""Keys of ``photo.json`` and its ``priors`` that Lilium reads: any other key is reported.

docs/contract.md allows extra fields, so an unknown key is a warning (``unknown_key``), not an
error; but a typo'd prior (``focal_pxx``) would otherwise vanish without a word while the user
believes the SFO used it. The warning names the key and the closest known one.
"""

import difflib

from ..inputs import CaseWarning

#: Top-level keys of ``photo.json`` (docs/contract.md and docs/method/photo.md, the generator's
#: extras).
PHOTO_KEYS = (
    "view",
    "landmarks",
    "priors",
    "ground_truth",
    "landmark_sources",
    "soft_tissue_axes_sets",
    # written by ``lilium photo`` (docs/method/photo.md)
    "prepared_by",
    "face_mask_is_head",
    "warnings",
)

#: Keys of ``photo.json``'s ``priors`` (docs/contract.md; ``lilium photo``'s automatic ones).
PRIOR_KEYS = (
    "focal_px",
    "scd_mm",
    "head_rotation_skull2cam",
    "head_tolerance_deg",
    "source",
    "sources",
    "head_rotation_face2cam",
    "head_tolerance_face_deg",
    "head_angles_deg",
    "iris_diameter_px",
)


def json_type(value):
    """The JSON name of a parsed value's type (``object``, ``array``, ``string``, ...)."""
    names = {dict: "object", list: "array", str: "string", bool: "boolean", type(None): "null"}
    return names.get(type(value), "number")


def _unknown(path, where, keys, known):
    out = []
    for key in keys:
        if key in known:
            continue
        close = difflib.get_close_matches(str(key), known, n=1, cutoff=0.6)
        hint = f"did you mean {where}{close[0]}?" if close else f"known: {', '.join(known)}"
        out.append(
            CaseWarning(
                "unknown_key", f"{path}: key {where}{key} is not read by Lilium (ignored); {hint}"
            )
        )
    return out


def unknown_key_warnings(path, meta):
    """Warnings ``unknown_key`` for the keys of ``photo.json`` (a dict) and of its ``priors``.

    Examples
    --------
    >>> [w.message for w in unknown_key_warnings("photo.json", {"priors": {"focal_pxx": 1}})]
    ... # doctest: +ELLIPSIS
    ['photo.json: key priors.focal_pxx is not read by Lilium (ignored); did you mean priors...']
    """
    out = _unknown(path, "", meta, PHOTO_KEYS)
    priors = meta.get("priors")
    if isinstance(priors, dict):
        out += _unknown(path, "priors.", priors, PRIOR_KEYS)
    return tuple(out)
