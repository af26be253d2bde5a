"""Landmark files users already have, converted to the canonical names of docs/method/skull.md.

Readers
-------
- 3D Slicer markups: ``.mrk.json`` (schema v1) and ``.fcsv`` (Markups fiducial CSV);
- MeshLab picked points: ``.pp`` (XML);
- CSV: ``name,x,y,z`` (cranial, mm) or ``name,u,v`` (facial, pixels), with or without a header
  (a header may name the columns ``name``/``label``/``landmark`` and ``x,y,z`` or ``u,v``);
  ``,``, ``;`` or tab separated;
- JSON: the contract's format ``{"landmarks": {name: coords}}``, a flat ``{name: coords}``, or a
  Slicer markups document.

Names
-----
Names are matched case-, space- and hyphen-insensitively against the aliases common in the
craniometric and anthropometric literature (``n``, ``Nasion``, ``N`` -> ``nasion``; ``gn`` ->
``gnathion``; ``A point`` -> ``subspinale`` ...). The cranial (bone) and facial (skin) sets have
separate alias tables: ``sn`` is the facial subnasale, ``ss`` the cranial subspinale; a facial
prime (``pg'``) or a ``soft tissue`` prefix is accepted only in the facial set.

Sides are the *subject's* left and right, written as a suffix or prefix in any of these forms:
``ex_l``, ``exL``, ``ex l``, ``ex(L)``, ``ex left``, ``l_ex``, ``Left ex``, ``R. Zygion``.
A bilateral landmark without a side is an error (the side cannot be guessed).

Slicer coordinate systems: markups stored in RAS are converted to LPS (Slicer's file default,
also the frame Slicer writes meshes in) unless told otherwise; see :func:`read_landmarks`. The
rule is ``lilium import-ct``'s: a file that states no system is LPS (Slicer's default since
4.11, and the ``.mrk.json`` schema's); a stated system Slicer does not write (neither ``LPS``,
``RAS`` nor the old ``1``/``0``) is refused with a one-line error naming the file, the value and
the fix, since its points would be read in a frame nobody stated.
"""

import difflib
import re
from pathlib import Path

import numpy as np

from ..softtissue.landmarks import CRANIAL_NAMES, FACIAL_NAMES, base_name, side
from ..validation import is_numeric
from .jsonio import parse_json
from .landmark_parsers import (
    _csv_entries,
    _fcsv_entries,
    _json_entries,
    _pp_entries,
    _slicer_json_entries,
)

KINDS = ("cranial", "facial")

#: Suffixes :func:`read_landmarks` understands, longest first.
LANDMARK_SUFFIXES = (".mrk.json", ".fcsv", ".pp", ".csv", ".tsv", ".txt", ".json")

#: Aliases per base name (no side). Keys are normalised (lower case, ``_`` separators).
CRANIAL_ALIASES = {
    "glabella": ("g", "gl", "gla", "glab"),
    "nasion": ("n", "na", "nas"),
    "metopion": ("m", "met", "metop"),
    "bregma": ("b", "br", "breg"),
    "prosthion": ("pr", "pros", "sd", "supradentale", "upper_alveolare", "alveolare"),
    "subspinale": ("ss", "a", "a_point", "point_a", "a_pt", "pt_a"),
    "pogonion": ("pg", "pog", "pgn"),
    "gnathion": ("gn", "gnath"),
    "infradentale": ("id", "lower_alveolare"),
    "ectoconchion": ("ec", "ek", "ecto", "ektoconchion"),
    "dacryon": ("d", "da", "dac", "dacrion"),
    "zygion": ("zy", "zyg"),
    "gonion": ("go", "gon"),
    "alare": ("al", "ala", "alare_point"),
    "frontotemporale": ("ft", "fmt", "frontotemporal"),
    "porion": ("po",),
    "orbitale": ("or", "orb"),
    "mental_foramen": ("mf", "mentale", "foramen_mentale", "mental", "mnf"),
}

#: Facial (skin) aliases; a prime or ``soft tissue`` prefix is stripped before the look-up.
FACIAL_ALIASES = {
    "glabella": ("g", "gl", "gla", "glab"),
    "nasion": ("n", "na", "nas"),
    "metopion": ("m", "met", "metop"),
    "bregma": ("b", "br"),
    "labiale_superius": (
        "ls",
        "lab_sup",
        "labrale_superius",
        "labiale_sup",
        "upper_lip",
        "ul",
    ),
    "subnasale": ("sn", "subn"),
    "pogonion": ("pg", "pog"),
    "gnathion": ("gn", "gnath", "menton_gnathion"),
    "exocanthion": (
        "ex",
        "exo",
        "ectocanthion",
        "exocanthus",
        "lateral_canthus",
        "outer_canthus",
        "outer_eye_corner",
    ),
    "endocanthion": (
        "en",
        "endo",
        "entocanthion",
        "endocanthus",
        "medial_canthus",
        "inner_canthus",
        "inner_eye_corner",
    ),
    "zygion": ("zy", "zyg"),
    "gonion": ("go", "gon"),
    "alare": ("al", "ala"),
    "frontotemporale": ("ft", "frontotemporal"),
    "cheilion": ("ch", "mouth_corner", "stomion_laterale"),
}

_SIDE_WORDS = {"l": "l", "left": "l", "lt": "l", "r": "r", "right": "r", "rt": "r"}
_PRIME = re.compile(r"['\u2019\u2032`]+")


def _known(kind):
    if kind == "cranial":
        return CRANIAL_NAMES, CRANIAL_ALIASES
    if kind == "facial":
        return FACIAL_NAMES, FACIAL_ALIASES
    raise ValueError(f"kind must be one of {', '.join(KINDS)}, got {kind!r}")


def _alias_table(kind):
    """Normalised alias -> canonical base name, for one landmark set."""
    names, aliases = _known(kind)
    table = {}
    for name in names:
        table[base_name(name)] = base_name(name)
    for base, words in aliases.items():
        for word in words:
            table[word] = base
    return table


_TABLES = {kind: _alias_table(kind) for kind in KINDS}
_SIDED = {kind: {base_name(n) for n in _known(kind)[0] if side(n)} for kind in KINDS}


def normalise_name(name):
    """Lower-case ``name`` with ``_`` between its words: ``"Zygion-L"`` -> ``"zygion_l"``.

    CamelCase and a trailing capital side letter are split: ``"exR"`` -> ``"ex_r"``.
    """
    text = str(name).strip()
    text = re.sub(r"([a-z])([A-Z])", r"\1_\2", text)
    text = re.sub(r"[^0-9A-Za-z'\u2019\u2032`]+", "_", text).strip("_")
    return text.lower()


def _strip_facial_decorations(key):
    key = _PRIME.sub("", key).strip("_")
    for prefix in ("soft_tissue_", "softtissue_", "st_", "skin_"):
        if key.startswith(prefix):
            key = key[len(prefix) :]
    return key


def _side_splits(key):
    """Candidate ``(base, side)`` readings of a normalised name, most explicit first."""
    parts = key.split("_")
    out = []
    if len(parts) > 1 and parts[-1] in _SIDE_WORDS:
        out.append(("_".join(parts[:-1]), _SIDE_WORDS[parts[-1]]))
    if len(parts) > 1 and parts[0] in _SIDE_WORDS:
        out.append(("_".join(parts[1:]), _SIDE_WORDS[parts[0]]))
    # Glued single letter: "exl", "gor" (only when the rest is a known alias).
    if len(key) > 1 and key[-1] in "lr":
        out.append((key[:-1].rstrip("_"), key[-1]))
    if len(key) > 1 and key[0] in "lr":
        out.append((key[1:].lstrip("_"), key[0]))
    return out


def canonical_name(name, kind):
    """The canonical name of a landmark written in any of the accepted ways, or None.

    Parameters
    ----------
    name : str
        As written in the user's file.
    kind : {"cranial", "facial"}

    Returns
    -------
    str or None
        ``None`` when the name is not recognised; :func:`name_error` explains why.

    Examples
    --------
    >>> canonical_name("ExR", "facial")
    'exocanthion_r'
    >>> canonical_name("A point", "cranial")
    'subspinale'
    """
    table, sided = _TABLES[kind], _SIDED[kind]
    key = normalise_name(name)
    if kind == "facial":
        key = _strip_facial_decorations(key)
    if key in table and table[key] not in sided:
        return table[key]
    if key in table:  # a bilateral name written without its side
        return None
    for base, s in _side_splits(key):
        if kind == "facial":
            base = _strip_facial_decorations(base)
        if base in table and table[base] in sided:
            return f"{table[base]}_{s}"
    return None


def _at(path, where):
    """``"path: where"`` (or just the path when ``where`` is empty), to start a message."""
    return f"{path}: {where}" if where else f"{path}"


def name_error(path, where, name, kind):
    """The ``ValueError`` for a name :func:`canonical_name` does not recognise."""
    names, _ = _known(kind)
    other = "facial" if kind == "cranial" else "cranial"
    table, key = _TABLES[kind], normalise_name(name)
    if kind == "facial":
        key = _strip_facial_decorations(key)
    if key in table:
        base = table[key]
        return ValueError(
            f"{_at(path, where)}: landmark {name!r} ({base}) needs a side; write {base}_l or "
            f"{base}_r (the subject's left or right)"
        )
    elsewhere = canonical_name(name, other)
    if elsewhere is not None:
        return ValueError(
            f"{_at(path, where)}: {name!r} is a {other} landmark ({elsewhere}) but this file "
            f"holds {kind} landmarks; use the {kind} name (docs/conventions.md) or the other file"
        )
    guess = suggest_name(key, kind)
    if guess:
        hint = f"did you mean {guess}?"
    else:
        hint = f"use a {kind} name of docs/method/skull.md (e.g. {names[0]!r})"
    return ValueError(f"{_at(path, where)}: unknown {kind} landmark {name!r}; {hint}")


def suggest_name(key, kind):
    """The closest known landmark to a normalised unknown name, quoted, keeping its side.

    A misspelt bilateral name keeps the side it was written with (``exocanthoin_L`` ->
    ``'exocanthion_l'``, ``l_exocantion`` -> ``'exocanthion_l'``); when its side cannot be read
    both are offered (``'exocanthion_l' or 'exocanthion_r'``), never the other side alone.

    Returns
    -------
    str or None
        ``None`` when nothing is close.
    """
    names, _ = _known(kind)
    table, sided = _TABLES[kind], _SIDED[kind]
    for base, s in _side_splits(key):
        if kind == "facial":
            base = _strip_facial_decorations(base)
        close = difflib.get_close_matches(base, list(table), n=1, cutoff=0.6)
        if close and table[close[0]] in sided:
            return repr(f"{table[close[0]]}_{s}")
    close = difflib.get_close_matches(key, list(names) + list(table), n=1, cutoff=0.6)
    if not close:
        return None
    guess = close[0] if close[0] in names else table[close[0]]
    if side(guess) or guess in sided:
        base = base_name(guess)
        return f"{base + '_l'!r} or {base + '_r'!r} (the subject's left or right)"
    return repr(guess)


def canonical_points(path, entries, kind, dim=None, allow_empty=False, finite=True):
    """Validate and rename ``(name, coords, where)`` entries read from a landmark file.

    The one check every landmark reader goes through (the contract's JSON files, 3D Slicer, MeshLab,
    CSV): names through the alias tables, ``dim`` numbers each, finite, each canonical landmark
    once.

    Parameters
    ----------
    path : str or Path
        The file, for messages.
    entries : iterable of (str, sequence, str)
        Name as written, coordinates, and where in the file it was (e.g. ``"line 3"``,
        ``"landmarks"``; ``""`` for nowhere in particular).
    kind : {"cranial", "facial"}
    dim : int, optional
        Numbers per point; default 3 (mm) for cranial and 2 (pixels) for facial landmarks.
    allow_empty : bool
        Accept a file without any entry (e.g. ``soft_tissue_axes.json`` with none given).
    finite : bool
        Reject NaN and infinite coordinates (``null`` in JSON reads as NaN). False only for
        ground truth, where a landmark behind the camera has no image point.

    Returns
    -------
    dict of str -> ndarray of shape (dim,)
        Keyed by canonical name, in the file's order.

    Raises
    ------
    ValueError
        Naming the file and place: unknown or side-less name (with the closest known one),
        wrong number of coordinates, NaN or infinite ones, two entries for one landmark
        (e.g. ``n`` and ``nasion``), no entry at all.
    """
    _known(kind)
    if dim is None:
        dim = 3 if kind == "cranial" else 2
    out, origin = {}, {}
    for name, coords, where in entries:
        canonical = canonical_name(name, kind)
        if canonical is None:
            raise name_error(path, where, name, kind)
        try:
            point = np.asarray(coords, dtype=float) if is_numeric(coords) else np.empty(0)
        except (TypeError, ValueError):
            point = np.empty(0)
        if point.shape != (dim,):
            raise ValueError(
                f"{_at(path, where)}: {name!r} must have {dim} numeric coordinates (numbers, not "
                f"true/false or quoted text), got {_short_repr(coords)}"
            )
        if finite and not np.all(np.isfinite(point)):
            raise ValueError(
                f"{_at(path, where)}: {name!r} has NaN or infinite coordinates; give its "
                "coordinates or remove it"
            )
        if canonical in out:
            raise ValueError(
                f"{_at(path, where)}: {name!r} and {origin[canonical]!r} are both {canonical}; "
                "keep one of them"
            )
        out[canonical], origin[canonical] = point, name
    if not out and not allow_empty:
        raise ValueError(f"{path}: no landmarks found; place landmarks and save the file again")
    return out


def _short_repr(value, limit=60):
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def points_from_object(path, field, raw, kind, dim=None, allow_empty=False, finite=True):
    """Validate a JSON object ``{name: coords}`` (the ``field`` of a docs/contract.md file).

    The ``"landmarks"`` of ``cranial_landmarks.json``, ``facial_landmarks.json`` and
    ``photo.json``, the ``"axes"`` of ``soft_tissue_axes.json``: the same checks and aliases as
    every other landmark file (:func:`canonical_points`).

    Returns
    -------
    dict of str -> ndarray of shape (dim,)
    """
    if not isinstance(raw, dict):
        n = dim or (3 if kind == "cranial" else 2)
        raise ValueError(f"{_at(path, field)} must be an object {{name: [{n} numbers]}}")
    entries = [(name, value, field) for name, value in raw.items()]
    return canonical_points(path, entries, kind, dim, allow_empty=allow_empty, finite=finite)


def landmark_format(path):
    """The format of a landmark file from its name: ``mrk.json``, ``fcsv``, ``pp``, ``csv``,
    ``json``; ``ValueError`` for anything else."""
    name = Path(path).name.lower()
    for suffix in LANDMARK_SUFFIXES:
        if name.endswith(suffix):
            return {".tsv": "csv", ".txt": "csv"}.get(suffix, suffix[1:])
    raise ValueError(
        f"{path}: unknown landmark file type; use .mrk.json or .fcsv (3D Slicer), .pp (MeshLab), "
        ".csv (name,x,y,z or name,u,v) or .json"
    )


def read_landmarks(path, kind, coordinate_system="LPS"):
    """Read a landmark file of any supported format.

    Parameters
    ----------
    path : str or Path
    kind : {"cranial", "facial"}
        Cranial files hold 3D points in the mesh's frame (mm), facial files 2D pixel points
        ``(u = column, v = row)``.
    coordinate_system : {"LPS", "RAS", None}
        For 3D Slicer files only: the frame to return (Slicer writes meshes in LPS by default).
        Points stored in the other one get x and y negated. ``None`` keeps them as stored.

    Returns
    -------
    dict of str -> ndarray of shape (3,) or (2,)
        Keyed by canonical name.

    Raises
    ------
    ValueError
        Missing or unreadable file, unknown or side-less landmark name (with the closest
        known), non-numeric or NaN coordinates, duplicates, no landmarks at all.
    """
    _known(kind)
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{path}: is a folder, not a landmark file; give the file's path")
    if not path.is_file():
        raise ValueError(f"{path}: file not found; check the landmark file's path")
    fmt = landmark_format(path)
    dim = 3 if kind == "cranial" else 2
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path}: cannot read the file ({exc}); save it as UTF-8 text") from exc
    if fmt == "json":
        data = parse_json(text, path)
        if isinstance(data, dict) and "markups" in data:
            entries, system = _slicer_json_entries(path, data)
        else:
            entries, system = _json_entries(path, data), None
    elif fmt == "mrk.json":
        entries, system = _slicer_json_entries(path, parse_json(text, path))
    elif fmt == "fcsv":
        entries, system = _fcsv_entries(path, text)
    elif fmt == "pp":
        entries, system = _pp_entries(path, text), None
    else:
        entries, system = _csv_entries(path, text, dim), None
    points = canonical_points(path, entries, kind, dim)
    if system and coordinate_system and system != coordinate_system and dim == 3:
        points = {k: v * np.array([-1.0, -1.0, 1.0]) for k, v in points.items()}
    return points


def find_landmark_file(folder, stems):
    """A landmark file in ``folder`` under one of ``stems`` (any supported suffix), or the only
    Slicer/MeshLab file there; ``None`` when there is none.

    Raises
    ------
    ValueError
        Several candidate files and no way to tell which one is meant.
    """
    folder = Path(folder)
    for stem in stems:
        for suffix in LANDMARK_SUFFIXES:
            if (folder / f"{stem}{suffix}").is_file():
                return folder / f"{stem}{suffix}"
    found = sorted(
        p
        for p in folder.iterdir()
        if p.is_file() and p.name.lower().endswith((".mrk.json", ".fcsv", ".pp"))
    )
    if len(found) > 1:
        raise ValueError(
            f"{folder}: several landmark files ({', '.join(p.name for p in found)}); keep one or "
            f"name it {stems[0]}.<suffix>"
        )
    return found[0] if found else None
