"""JSON reading and writing with numpy values and clear errors."""

import json
import os
import re
from pathlib import Path

import numpy as np

from .paths import naming_errors


def _to_builtin(value):
    if isinstance(value, dict):
        return {str(k): _to_builtin(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_to_builtin(v) for v in value]
    if isinstance(value, np.ndarray):
        return _to_builtin(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, float) and not np.isfinite(value):
        return None
    if isinstance(value, Path):
        return str(value)
    return value


def write_json(path, data, indent=2):
    """Write ``data`` (numpy arrays allowed; NaN/inf become null) atomically to ``path``.

    Raises
    ------
    OSError
        Naming ``path`` (a full disk, a file-size limit, ...); no temporary file is left.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(path.suffix + ".tmp")
    text = json.dumps(_to_builtin(data), indent=indent) + "\n"
    try:
        with naming_errors(path):
            tmp.write_text(text)
            os.replace(tmp, path)
    except OSError:
        tmp.unlink(missing_ok=True)
        raise


class _DuplicateKey(ValueError):
    """A key that occurs twice in one JSON object (raised inside the decoder)."""


def _unique_keys(pairs):
    out = {}
    for key, value in pairs:
        if key in out:
            raise _DuplicateKey(key)
        out[key] = value
    return out


#: Deepest nesting of arrays and objects a JSON input may have: contract files need 4 levels; a
#: deeper file is hostile or broken, and would exhaust Python's recursion further on.
MAX_JSON_DEPTH = 64


_STRING = re.compile(r'"(?:[^"\\]|\\.)*"')


def _depth(text):
    """Deepest nesting of arrays and objects in JSON text (brackets in strings not counted),
    found before parsing, in linear time."""
    codes = np.frombuffer(_STRING.sub("", text).encode("utf-8", "replace"), dtype=np.uint8)
    folded = codes | 32  # "[" (91) becomes "{" (123), "]" (93) becomes "}" (125)
    brackets = folded[(folded == 123) | (folded == 125)]
    return int(np.cumsum(np.where(brackets == 123, 1, -1)).max()) if len(brackets) else 0


def parse_json(text, source):
    """Parse JSON text; malformed JSON or a key given twice in one object is a ``ValueError``
    naming ``source`` (a file path, for messages).

    Python's ``json`` lets the last of two equal keys win silently; here it is an error, as a
    landmark or prior written twice is a mistake the user must resolve.
    """
    deep = ValueError(
        f"{source}: JSON nested deeper than {MAX_JSON_DEPTH} levels of arrays or objects; "
        "this is not a Lilium file: check that you gave the right file"
    )
    if _depth(text) > MAX_JSON_DEPTH:
        raise deep
    try:
        data = json.loads(text, object_pairs_hook=_unique_keys)
    except RecursionError:
        raise deep from None
    except _DuplicateKey as exc:
        raise ValueError(
            f"{source}: the key {exc.args[0]!r} appears twice in one JSON object; keep one of them"
        ) from None
    except json.JSONDecodeError as exc:
        raise ValueError(f"{source}: not valid JSON ({exc}); fix the file's syntax") from exc
    return data


def read_json(path):
    """Read a JSON file (UTF-8, a byte-order mark allowed).

    A missing, undecodable or malformed file, or a key repeated in one object, is a
    ``ValueError`` naming the file.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: file not found")
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path}: cannot read the file ({exc}); save it as UTF-8 text") from exc
    return parse_json(text, path)
