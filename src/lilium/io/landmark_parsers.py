"""The per-format readers of landmark files: ``(name, coords, where)`` entries as written.

3D Slicer markups (``.mrk.json``, ``.fcsv``, with their coordinate system), MeshLab picked
points (``.pp``), CSV and plain JSON. Names and coordinates are checked afterwards, by
:func:`lilium.io.formats.canonical_points` (:func:`lilium.io.formats.read_landmarks` does both).
"""

import csv
import xml.etree.ElementTree as ET


def _json_entries(path, data):
    if isinstance(data, dict) and "landmarks" in data:
        data, where = data["landmarks"], "landmarks"
    else:
        where = ""
    if not isinstance(data, dict):
        raise ValueError(
            f'{path}: expected {{"landmarks": {{name: [coords]}}}} or {{name: [coords]}}'
        )
    return [(name, value, where) for name, value in data.items()]


#: What 3D Slicer writes as a markup's coordinate system (``0`` = RAS, ``1`` = LPS in old files).
SLICER_SYSTEMS = {"LPS": "LPS", "RAS": "RAS", "1": "LPS", "0": "RAS"}

#: The system of a Slicer markup that states none (Slicer's default since 4.11).
SLICER_DEFAULT_SYSTEM = "LPS"


def _slicer_system(path, value):
    """``LPS`` or ``RAS`` from a stated Slicer coordinate system; an empty value is the default.

    Raises
    ------
    ValueError
        A value Slicer does not write (``XYZ``, ``2``, ...), naming the file and the fix.
    """
    text = str(value).strip()
    if not text:
        return SLICER_DEFAULT_SYSTEM
    system = SLICER_SYSTEMS.get(text.upper())
    if system is None:
        example = (
            '"coordinateSystem": "LPS"'
            if str(path).lower().endswith(".json")
            else "'# CoordinateSystem = LPS'"
        )
        raise ValueError(
            f"{path}: coordinate system {text!r} is not one 3D Slicer writes; state LPS or "
            f"RAS (the frame the points were placed in), e.g. {example}"
        )
    return system


def _slicer_json_entries(path, data):
    markups = data.get("markups") if isinstance(data, dict) else None
    if not isinstance(markups, list) or not markups:
        raise ValueError(f"{path}: no 'markups' list; export the markups from 3D Slicer again")
    entries, systems = [], {}
    for m, markup in enumerate(markups):
        if not isinstance(markup, dict):
            raise ValueError(f"{path}: markups[{m}] is not an object; export the markups again")
        system = _slicer_system(path, markup.get("coordinateSystem", SLICER_DEFAULT_SYSTEM))
        systems.setdefault(system, m)
        units = markup.get("coordinateUnits", "mm")
        if units not in ("mm", ["mm"]):
            raise ValueError(
                f"{path}: markups[{m}].coordinateUnits is {units!r}; save the points in mm"
            )
        points = markup.get("controlPoints") or []
        if not isinstance(points, list) or not all(isinstance(p, dict) for p in points):
            raise ValueError(
                f"{path}: markups[{m}].controlPoints is not a list of points; export the "
                "markups from 3D Slicer again"
            )
        for k, point in enumerate(points):
            status = point.get("positionStatus", "defined")
            if status != "defined" or "position" not in point:
                continue  # an unplaced or skipped point
            label = point.get("label") or point.get("id") or f"point {k + 1}"
            entries.append((label, point["position"], f"markups[{m}].controlPoints[{k}]"))
    if len(systems) > 1:
        (a, i), (b, j) = sorted(systems.items(), key=lambda item: item[1])
        raise ValueError(
            f"{path}: markups[{i}] is in {a} and markups[{j}] in {b}; save the points as one "
            "point list (one coordinate system) from 3D Slicer"
        )
    return entries, next(iter(systems), SLICER_DEFAULT_SYSTEM)


def _fcsv_entries(path, text):
    system, columns, entries = SLICER_DEFAULT_SYSTEM, None, []
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            key, _, value = stripped.lstrip("#").partition("=")
            if key.strip().lower() == "coordinatesystem":
                system = _slicer_system(path, value)
            elif key.strip().lower() == "columns":
                columns = [c.strip().lower() for c in value.split(",")]
            continue
        row = next(csv.reader([line]))
        cols = columns or ["id", "x", "y", "z"] + [""] * 7 + ["label"]
        record = dict(zip(cols, row, strict=False))
        if not {"x", "y", "z"} <= record.keys():
            raise ValueError(f"{path}: line {number}: expected id,x,y,z,...,label columns")
        label = record.get("label") or record.get("id") or f"point {number}"
        entries.append((label, _numbers(record["x"], record["y"], record["z"]), f"line {number}"))
    return entries, system


def _pp_entries(path, text):
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise ValueError(
            f"{path}: not a valid MeshLab .pp file ({exc}); save the picked points again"
        ) from exc
    entries = []
    for k, point in enumerate(root.iter("point")):
        if point.get("active", "1").strip() == "0":
            continue  # unticked in MeshLab's picking dialogue
        name = point.get("name") or f"point {k + 1}"
        coords = _numbers(*(point.get(a, "") for a in "xyz"))
        entries.append((name, coords, f"point {name!r}"))
    return entries


def _numbers(*values):
    out = []
    for value in values:
        try:
            out.append(float(str(value).strip()))
        except ValueError:
            return list(values)
    return out


def _is_number(text):
    try:
        float(text)
    except ValueError:
        return False
    return True


_NAME_COLUMNS = ("name", "label", "landmark", "id", "point")
_COORD_COLUMNS = {3: (("x", "y", "z"),), 2: (("u", "v"), ("x", "y"), ("column", "row"))}


def _csv_entries(path, text, dim):
    lines = [line for line in text.splitlines() if line.strip() and not line.startswith("#")]
    if not lines:
        raise ValueError(f"{path}: no landmarks found; write one landmark per line")
    delimiter = max(",;\t", key=lines[0].count)
    rows = list(csv.reader(lines, delimiter=delimiter))
    header = [c.strip().lower() for c in rows[0]]
    name_col, coord_cols, start = 0, list(range(1, dim + 1)), 0
    if len(header) > dim and not any(_is_number(c) for c in header):
        start = 1
        name_col = next((header.index(c) for c in _NAME_COLUMNS if c in header), 0)
        for names in _COORD_COLUMNS[dim]:
            if all(c in header for c in names):
                coord_cols = [header.index(c) for c in names]
                break
        else:
            want = " or ".join(",".join(n) for n in _COORD_COLUMNS[dim])
            raise ValueError(f"{path}: header {rows[0]!r} has no {want} columns; name them so")
    entries = []
    for number, row in enumerate(rows[start:], start=start + 1):
        if len(row) <= max(name_col, *coord_cols):
            raise ValueError(
                f"{path}: line {number}: expected a name and {dim} coordinates, got {row!r}"
            )
        coords = _numbers(*(row[c] for c in coord_cols))
        entries.append((row[name_col].strip(), coords, f"line {number}"))
    return entries
