"""Hostile-input probes of ``lilium sfo``, ``case``, ``experiment``, ``report``, ``synth``,
``demo``, ``photo`` and ``import-ct``, tested (issue 28): broken
``photo.json`` files, subject folders and meshes; broken images, masks and face curves; bad
options of ``lilium sfo`` and ``lilium case`` (depth tables, priors on the command line);
experiment configs and result databases; bad options of ``synth`` and ``demo``; and the
probes of ``lilium photo`` and ``lilium import-ct`` (owners ``"photo"`` and ``"ct"``: their
fixes belong to the photo/CT work of issue 28, and the campaign counts them apart).

Each probe runs on the stand-in case of the campaign (``in/subjects/standin``,
``in/photos/standin_frontal``), with the verdicts of :func:`hostile_machinery.run_probe`.
"""

import json
import sqlite3
import struct
import zlib

from hostile_machinery import Probe, _write


def _png_header(width, height):
    def chunk(kind, data):
        crc = struct.pack(">I", zlib.crc32(kind + data))
        return struct.pack(">I", len(data)) + kind + data + crc

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IEND", b"")


# -- the probes -------------------------------------------------------------------------------
# One probe a line: the tables read better than the formatter's 1000 lines.
# fmt: off


def _photo_json(change):
    return lambda ws: ws.edit(ws.photo / "photo.json", change)


def _cranial(change):
    return lambda ws: ws.edit(ws.skull / "cranial_landmarks.json", change)


def _set(path_key, value):
    def change(data):
        node = data
        *keys, last = path_key
        for k in keys:
            node = node.setdefault(k, {})
        node[last] = value

    return change


def _sfo(*extra, method="posest-sfo"):
    return lambda ws: [*ws.sfo(), "--method", method, *extra]


def _case(*extra):
    return lambda ws: ["case", "--skull", ws.skull, "--photo", ws.photo, "--out", ws.out, *extra]


def _swap_sides(landmarks):
    flip = {"_l": "_r", "_r": "_l"}
    return {(k[:-2] + flip[k[-2:]] if k[-2:] in flip else k): v for k, v in landmarks.items()}


def photo_json_probes():
    """Broken ``photo.json`` files (``lilium sfo``)."""
    p, J = [], "photo.json"
    coords = {"bool": [True, False], "text": ["599", "449"], "null": [None, None], "one": [599.5],
              "three": [599.5, 449.5, 1.0], "nested": [[599.5, 449.5]], "object": {"u": 1, "v": 2},
              "huge": [1e300, 1e300], "negative": [-1e6, 10], "string": "599,449"}
    for key, value in coords.items():
        p.append(Probe(f"photo.json nasion {key}", _sfo(), "error", (J,), _photo_json(_set(["landmarks", "nasion"], value))))  # noqa: E501
    roots = {"list": "[1, 2, 3]", "number": "42", "string": '"photo"', "null": "null", "empty": "",
             "bom only": "\ufeff", "truncated": '{"view": "frontal", "landm',
             "deep": "[" * 100000 + "]" * 100000, "deep 200": '{"view": ' + "[" * 200 + "]" * 200 + "}",  # noqa: E501
             "binary": "\x00\x01\x02"}
    for key, text in roots.items():
        p.append(Probe(f"photo.json is {key}", _sfo(), "error", (J,), _write("photo", J, text)))
    p.append(Probe("photo.json duplicate key", _sfo(), "error", (J, "twice"), _write("photo", J, '{"view": "frontal", "view": "lateral_left", "landmarks": {}}')))  # noqa: E501
    for view in ("Frontal", "front", "", None, 1, ["frontal"], True):
        p.append(Probe(f"view {view!r}", _sfo(), "error", (J, "view"), _photo_json(_set(["view"], view))))  # noqa: E501
    p.append(Probe("view missing", _sfo(), "error", (J, "view"), _photo_json(lambda d: d.pop("view"))))  # noqa: E501
    p.append(Probe("landmarks missing", _sfo(), "error", (J,), _photo_json(lambda d: d.pop("landmarks"))))  # noqa: E501
    p.append(Probe("landmarks a list", _sfo(), "error", (J, "landmarks"), _photo_json(_set(["landmarks"], [[1, 2]]))))  # noqa: E501
    p.append(Probe("landmarks empty", _sfo(), "error", (J,), _photo_json(_set(["landmarks"], {}))))
    p.append(Probe("landmark unknown name", _sfo(), "error", (J, "nasoin"), _photo_json(lambda d: d["landmarks"].update(nasoin=d["landmarks"].pop("nasion")))))  # noqa: E501
    p.append(Probe("landmark twice via alias", _sfo(), "error", (J, "nasion"), _photo_json(lambda d: d["landmarks"].update(n=d["landmarks"]["nasion"]))))  # noqa: E501
    p.append(Probe("landmarks all at one pixel", _sfo(), "error", (J, "one place"), _photo_json(lambda d: d.update(landmarks={k: [600, 450] for k in d["landmarks"]}))))  # noqa: E501
    p.append(Probe("landmarks on a line", _sfo(), "error", (J, "line"), _photo_json(lambda d: d.update(landmarks={k: [100 + 10 * i, 450] for i, k in enumerate(d["landmarks"])}))))  # noqa: E501
    p.append(Probe("landmarks mirrored", _sfo(), "error", (J, "mirrored"), _photo_json(lambda d: d.update(landmarks=_swap_sides(d["landmarks"])))))  # noqa: E501
    priors = {
        "focal 1e300": ("focal_px", [1e300, 1e301], "physical range"),
        "focal 1e-9": ("focal_px", [1e-9, 2e-9], "physical range"),
        "focal zero": ("focal_px", [0, 1000], "focal_px"),
        "focal inverted": ("focal_px", [3000, 1000], "focal_px"),
        "focal bool": ("focal_px", [True, True], "focal_px"),
        "focal text": ("focal_px", ["1000", "2000"], "focal_px"),
        "focal scalar": ("focal_px", 2000, "focal_px"),
        "focal nan": ("focal_px", [None, 2000], "focal_px"),
        "scd 1e9": ("scd_mm", [1e9, 2e9], "physical range"),
        "scd 1 mm": ("scd_mm", [1, 2], "physical range"),
        "scd negative": ("scd_mm", [-900, 900], "scd_mm"),
        "tolerance 0": ("head_tolerance_deg", 0, "head_tolerance_deg"),
        "tolerance 720": ("head_tolerance_deg", 720, "head_tolerance_deg"),
        "tolerance bool": ("head_tolerance_deg", True, "head_tolerance_deg"),
        "rotation bool": ("head_rotation_skull2cam", [[True, False, False], [False, True, False], [False, False, True]], "head_rotation"),  # noqa: E501
        "rotation scaled": ("head_rotation_skull2cam", [[2, 0, 0], [0, 2, 0], [0, 0, 2]], "rotation"),  # noqa: E501
        "rotation mirrored": ("head_rotation_skull2cam", [[-1, 0, 0], [0, 1, 0], [0, 0, 1]], "rotation"),  # noqa: E501
        "rotation 2x2": ("head_rotation_skull2cam", [[1, 0], [0, 1]], "3x3"),
    }
    for name, (key, value, needle) in priors.items():
        p.append(Probe(f"prior {name}", _sfo(), "error", (J, needle), _photo_json(_set(["priors", key], value))))  # noqa: E501
    p.append(Probe("priors a list", _sfo(), "error", (J, "priors"), _photo_json(_set(["priors"], [1, 2]))))  # noqa: E501
    p.append(Probe("rotation without tolerance", _sfo(), "error", (J, "together"), _photo_json(lambda d: d["priors"].pop("head_tolerance_deg"))))  # noqa: E501
    p.append(Probe("typo'd prior key", _sfo(), "warn", ("priors.focal_pxx", "did you mean priors.focal_px"), _photo_json(lambda d: d["priors"].update(focal_pxx=d["priors"].pop("focal_px")))))  # noqa: E501
    p.append(Probe("typo'd top key", _sfo(), "warn", ("key landmark ", "did you mean landmarks"), _photo_json(lambda d: d.update(landmark={}))))  # noqa: E501
    p.append(Probe("landmark_sources garbage", _sfo(), "ok", (), _photo_json(_set(["landmark_sources"], [1, "x"]))))  # noqa: E501
    return p


PLY = "ply\nformat ascii 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\nelement face {f}\nproperty list uchar int vertex_indices\nend_header\n"  # noqa: E501


def skull_probes():
    """Broken subject folders and meshes (``lilium sfo``)."""
    p, C = [], "cranial_landmarks.json"
    for key, value in {"bool": [True, False, True], "text": ["1", "2", "3"], "2d": [1.0, 2.0], "null": [None, 0, 0], "far": [1e4, 0, 0], "huge": [1e300, 0, 0]}.items():  # noqa: E501
        p.append(Probe(f"cranial nasion {key}", _sfo(), "error", (C,), _cranial(_set(["landmarks", "nasion"], value))))  # noqa: E501
    for key, text in {"list": "[]", "empty": "", "deep": "[" * 5000 + "]" * 5000, "no landmarks": "{}"}.items():  # noqa: E501
        p.append(Probe(f"cranial file {key}", _sfo(), "error", (C,), _write("skull", C, text)))
    p.append(Probe("cranial left/right swapped", _sfo(), "error", (C, "mirrored"), _cranial(lambda d: d.update(landmarks=_swap_sides(d["landmarks"])))))  # noqa: E501
    p.append(Probe("cranial file missing", _sfo(), "error", (C,), lambda ws: (ws.skull / C).unlink()))  # noqa: E501
    meshes = {
        "garbage ply": "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\nx y z\n",  # noqa: E501
        "empty ply": b"",
        "binary junk": bytes(range(256)) * 16,
        "text": "hello world\n",
        "header only": "ply\nformat ascii 1.0\nend_header\n",
        "points only": PLY.format(n=3, f=0) + "0 0 0\n1 0 0\n0 1 0\n",
        "metres": PLY.format(n=4, f=2) + "0 0 0\n0.1 0 0\n0 0.1 0\n0 0 0.1\n3 0 1 2\n3 0 1 3\n",
        "nan vertex": PLY.format(n=3, f=1) + "nan 0 0\n100 0 0\n0 100 0\n3 0 1 2\n",
        "face index out of range": PLY.format(n=3, f=1) + "0 0 0\n100 0 0\n0 100 0\n3 0 1 99\n",
        "flat": PLY.format(n=4, f=2) + "0 0 0\n100 0 0\n0 100 0\n100 100 0\n3 0 1 2\n3 1 2 3\n",
    }
    for key, content in meshes.items():
        p.append(Probe(f"mesh {key}", _sfo(), "error", ("skull.ply",), _write("skull", "skull.ply", content)))  # noqa: E501
    p.append(Probe("mesh missing", _sfo(), "error", ("skull",), lambda ws: (ws.skull / "skull.ply").unlink()))  # noqa: E501
    p.append(Probe("mesh is a folder", _sfo(), "error", ("skull",), lambda ws: ((ws.skull / "skull.ply").unlink(), (ws.skull / "skull.ply").mkdir())))  # noqa: E501
    p.append(Probe("axes zero vector", _sfo(), "error", ("soft_tissue_axes.json", "zero"), lambda ws: ws.edit(ws.skull / "soft_tissue_axes.json", _set(["axes", "nasion"], [0, 0, 0]))))  # noqa: E501
    p.append(Probe("axes booleans", _sfo(), "error", ("soft_tissue_axes.json",), lambda ws: ws.edit(ws.skull / "soft_tissue_axes.json", _set(["axes", "nasion"], [True, False, False]))))  # noqa: E501
    return p


def image_probes():
    """Broken images, masks and face curves (``lilium sfo``)."""
    from PIL import Image

    def image(size, mode="RGB"):
        return lambda ws: Image.new(mode, size).save(ws.photo / "image.png")

    def mask(size=(1200, 900), value=255):
        return lambda ws: Image.new("L", size, value).save(ws.photo / "face_mask.png")

    def truncate(ws):
        (ws.photo / "image.png").write_bytes((ws.photo / "image.png").read_bytes()[:200])

    p = [
        Probe("image missing", _sfo(), "error", ("image",), lambda ws: (ws.photo / "image.png").unlink()),  # noqa: E501
        Probe("image is text", _sfo(), "error", ("image.png",), _write("photo", "image.png", "not a png")),  # noqa: E501
        Probe("image truncated", _sfo(), "error", ("image.png",), truncate),
        Probe("image header 400 MP", _sfo(), "error", ("image.png", "too large"), _write("photo", "image.png", _png_header(20000, 20000))),  # noqa: E501
        Probe("image 1x1", _sfo(), "error", ("image.png", "32 px"), image((1, 1))),
        Probe("image 31x900", _sfo(), "error", ("image.png",), image((31, 900))),
        Probe("image smaller than landmarks", _sfo(), "error", ("photo.json", "outside"), image((300, 200))),  # noqa: E501
        Probe("image 16-bit grey", _sfo(), "ok", (), image((1200, 900), mode="I;16")),
        Probe("mask wrong size", _sfo(), "error", ("face_mask.png",), mask((100, 100))),
        Probe("mask empty", _sfo(), "error", ("face_mask.png",), mask(value=0)),
        Probe("mask full", _sfo(), "error", ("face_mask.png",), mask(value=255)),
        Probe("mask is text", _sfo(), "error", ("face_mask.png",), _write("photo", "face_mask.png", "x")),  # noqa: E501
    ]
    n = 20000
    zig = [[100 + 1000 * k / n, 100 if k % 2 else 800] for k in range(n)]
    curves = {
        "zig-zag 20000": ({"chin_jaw": zig}, "perimeter"),
        "outside": ({"chin_jaw": [[100, 700], [5e6, 5e6]]}, "outside"),
        "booleans": ({"chin_jaw": [[True, 1], [500, 600]]}, "chin_jaw"),
        "one point": ({"chin_jaw": [[600, 800]]}, "two"),
        "wrong view": ({"forehead": [[1, 2], [3, 4]]}, "chin_jaw"),
        "a list": ([[1, 2], [3, 4]], "object"),
        "text points": ({"chin_jaw": "[[1,2],[3,4]]"}, "chin_jaw"),
        "nan": ({"chin_jaw": [[600, 800], [700, None]]}, "finite"),
    }
    for key, (data, needle) in curves.items():
        p.append(Probe(f"face curve {key}", _sfo(), "error", ("face_curve.json", needle), _write("photo", "face_curve.json", json.dumps(data))))  # noqa: E501
    dense = [[600 + 400 * x, 500 + 300 * (1 - x * x) ** 0.5] for x in (i / 100000 - 1 for i in range(200001))]  # noqa: E501
    p.append(Probe("face curve 200k smooth points", _sfo(), "ok", (), _write("photo", "face_curve.json", json.dumps({"chin_jaw": dense}))))  # noqa: E501
    return p


def option_probes():
    """Bad options of ``lilium sfo`` and ``lilium case``."""
    p = []
    bad = {"--seed -1": ("--seed", "-1"), "--seed 2^64": ("--seed", str(2**64)),
           "--seed text": ("--seed", "abc"), "--population 3": ("--population", "3"),
           "--population 1e8": ("--population", "100000000"),
           "--generations 0": ("--generations", "0"), "--max-seconds nan": ("--max-seconds", "nan"),
           "--max-seconds -1": ("--max-seconds", "-1"), "--variant bogus": ("--variant", "bogus")}
    for name, args in bad.items():
        p.append(Probe(f"sfo {name}", _sfo(*args, method="lilium"), "error", (args[0],)))
    ply = lambda ws: ws.skull / "skull.ply"  # noqa: E731
    p.append(Probe("sfo --method bogus", lambda ws: [*ws.sfo(), "--method", "bogus"], "error", ("--method",)))  # noqa: E501
    p.append(Probe("sfo --out is a file", lambda ws: ["sfo", "--skull", ws.skull, "--photo", ws.photo, "--out", ply(ws), "--method", "posest-sfo"], "error", ("--out",)))  # noqa: E501
    p.append(Probe("sfo --out under a file", lambda ws: ["sfo", "--skull", ws.skull, "--photo", ws.photo, "--out", ply(ws) / "x", "--method", "posest-sfo"], "error", ("--out",)))  # noqa: E501
    p.append(Probe("sfo --axes missing", _sfo("--axes", "nope.json"), "error", ("--axes",)))
    p.append(Probe("sfo --skull missing", lambda ws: ["sfo", "--skull", "nope", "--photo", ws.photo, "--out", ws.out, "--method", "posest-sfo"], "error", ("nope",)))  # noqa: E501
    p.append(Probe("sfo --photo missing", lambda ws: ["sfo", "--skull", ws.skull, "--photo", "nope", "--out", ws.out, "--method", "posest-sfo"], "error", ("nope",)))  # noqa: E501
    tables = {
        "nasion max 1e9": "landmark,mean,sd,min,max\nnasion,6,1,0,1e9\n",
        "negative": "landmark,mean,sd,min,max\nnasion,-6,1,-9,0\n",
        "negative sd": "landmark,mean,sd,min,max\nnasion,6,-1,0,9\n",
        "text": "landmark,mean,sd,min,max\nnasion,six,1,0,9\n",
        "short row": "landmark,mean,sd,min,max\nnasion,6\n",
        "no header": "nasion,6,1,0,9\n",
        "unknown landmark": "landmark,mean,sd,min,max\nbogus,6,1,0,9\n",
        "min above max": "landmark,mean,sd,min,max\nnasion,6,1,9,3\n",
        "inf": "landmark,mean,sd,min,max\nnasion,6,1,0,inf\n",
    }
    for name, text in tables.items():
        p.append(Probe(f"depth table {name}", lambda ws: [*ws.sfo(), "--method", "posest-sfo", "--depth-table", ws.root / "in" / "d.csv"], "error", ("d.csv",), _write("in", "d.csv", text)))  # noqa: E501
    cli = {
        "--focal-px 1e-9": (["--focal-px", "1e-9", "2e-9"], "--focal-px"),
        "--focal-px 1e300": (["--focal-px", "1e300", "1e301"], "--focal-px"),
        "--focal-px inverted": (["--focal-px", "3000", "1000"], "--focal-px"),
        "--focal-px nan": (["--focal-px", "nan", "1000"], "--focal-px"),
        "--scd-mm 0": (["--scd-mm", "0", "900"], "--scd-mm"),
        "--scd-mm 1e9": (["--scd-mm", "1e9", "2e9"], "--scd-mm"),
        "--view with a folder": (["--view", "lateral_left"], "--view"),
        "--view bogus": (["--view", "sideways"], "--view"),
        "--mask without image": (["--mask", "m.png"], "--mask"),
        "--photo-landmarks twice": (["--photo-landmarks", "a.csv", "--photo-landmarks", "b.csv"], "--photo-landmarks"),  # noqa: E501
        "--population 1e8": (["--population", "100000000"], "--population"),
        "--seed -5": (["--seed", "-5"], "--seed"),
    }
    for name, (args, needle) in cli.items():
        p.append(Probe(f"case {name}", _case(*args), "error", (needle,)))
    p.append(Probe("case --landmarks deep JSON", lambda ws: ["case", "--skull", ws.skull, "--landmarks", ws.root / "in" / "deep.json", "--photo", ws.photo, "--out", ws.out], "error", ("deep.json", "nested"), _write("in", "deep.json", '{"landmarks": ' + "[" * 3000 + "]" * 3000 + "}")))  # noqa: E501
    p.append(Probe("case --photo a text file", lambda ws: ["case", "--skull", ws.skull, "--photo", ws.root / "in" / "x.txt", "--out", ws.out], "error", ("x.txt",), _write("in", "x.txt", "x")))  # noqa: E501
    p.append(Probe("case --skull a text file", lambda ws: ["case", "--skull", ws.root / "in" / "x.txt", "--photo", ws.photo, "--out", ws.out], "error", ("x.txt",), _write("in", "x.txt", "x")))  # noqa: E501
    return p


TINY = """name = "tiny"
methods = ["posest-sfo"]
experiments = ["A"]
repetitions = 1
db = "results.sqlite"
[dataset]
path = "data"
generate = false
[de]
population = 5
generations = 2
"""


def _rows_db(change=None):
    def setup(ws):
        from lilium.experiments.store import ResultStore
        from report_rows import make_rows

        path = ws.root / "in" / "r.sqlite"
        with ResultStore(path) as store:
            for row in make_rows():
                store.insert(row)
        if change:
            conn = sqlite3.connect(path)
            with conn:
                conn.execute(change)
            conn.close()  # a connection left open leaves its WAL for the command to merge

    return setup


def _foreign_db(ws):
    conn = sqlite3.connect(ws.root / "in" / "r.sqlite")
    with conn:
        conn.execute("CREATE TABLE t (x)")
    conn.close()


def experiment_probes():
    """``lilium experiment``, ``lilium report``, ``lilium synth`` and ``lilium demo``."""
    config = lambda text: _write("in", "c.toml", text)  # noqa: E731
    exp = lambda *extra: lambda ws: ["experiment", ws.root / "in" / "c.toml", "--no-progress", "--db", ws.out / "r.sqlite", *extra]  # noqa: E501, E731
    report = lambda ws: ["report", ws.root / "in" / "r.sqlite", "--out", ws.out]  # noqa: E731
    p = [
        Probe("experiment config missing", lambda ws: ["experiment", ws.root / "in" / "none.toml"], "error", ("none.toml",)),  # noqa: E501
        Probe("experiment unknown preset", lambda ws: ["experiment", "bogus"], "error", ("bogus",)),
        Probe("experiment TOML garbage", exp(), "error", ("c.toml",), config("name = [\n")),
        Probe("experiment TOML binary", exp(), "error", ("c.toml",), config(b"\xff\xfe\x00")),
        Probe("experiment population 1e8", exp(), "error", ("c.toml", "population"), config(TINY.replace("population = 5", "population = 100000000"))),  # noqa: E501
        Probe("experiment repetitions 0", exp(), "error", ("c.toml", "repetitions"), config(TINY.replace("repetitions = 1", "repetitions = 0"))),  # noqa: E501
        Probe("experiment bool repetitions", exp(), "error", ("c.toml", "repetitions"), config(TINY.replace("repetitions = 1", "repetitions = true"))),  # noqa: E501
        Probe("experiment unknown method", exp(), "error", ("c.toml", "bogus"), config(TINY.replace('"posest-sfo"', '"bogus"'))),  # noqa: E501
        Probe("experiment dataset missing", exp(), "error", ("data",), config(TINY)),
        Probe("experiment --workers -1", exp("--workers", "-1"), "error", ("--workers",), config(TINY)),  # noqa: E501
        Probe("experiment --db a folder", lambda ws: ["experiment", ws.root / "in" / "c.toml", "--db", ws.root / "in"], "error", ("--db",), config(TINY)),  # noqa: E501
        Probe("experiment --scheduler refused", exp("--scheduler", "tcp://127.0.0.1:1"), "error", ("--scheduler",), config(TINY)),  # noqa: E501
        Probe("experiment --scheduler garbage", exp("--scheduler", "tcp://[::nope"), "error", ("--scheduler",), config(TINY)),  # noqa: E501
        Probe("report db missing", report, "error", ("r.sqlite",)),
        Probe("report db garbage", report, "error", ("r.sqlite",), _write("in", "r.sqlite", bytes(range(256)) * 16)),  # noqa: E501
        Probe("report db empty file", report, "error", ("r.sqlite",), _write("in", "r.sqlite", b"")),  # noqa: E501
        Probe("report db a folder", report, "error", ("r.sqlite",), lambda ws: (ws.root / "in" / "r.sqlite").mkdir()),  # noqa: E501
        Probe("report db foreign sqlite", report, "error", ("r.sqlite",), _foreign_db),
        Probe("report text score", report, "error", ("r.sqlite", "score"), _rows_db("UPDATE sfo SET score = 'abc' WHERE id = 3")),  # noqa: E501
        Probe("report text seconds", report, "error", ("r.sqlite", "seconds"), _rows_db("UPDATE sfo SET seconds = 'slow' WHERE id = 1")),  # noqa: E501
        Probe("report huge score", report, "ok", (), _rows_db("UPDATE sfo SET score = 1e308 WHERE id = 2")),  # noqa: E501
        Probe("report valid", report, "ok", (), _rows_db()),
    ]
    # synth --subjects 0, --workers 0, --seed -1, --experiments X and --out a file: in
    # hostile_inputs.py's synth_probes.
    synth = {"--subjects 1e8": (["--subjects", "100000000"], "--subjects"),
             "--photos -1": (["--photos", "-1"], "--photos"),
             "--drop-landmark-rate 2": (["--drop-landmark-rate", "2"], "--drop-landmark-rate"),
             "--no-mandible-share -1": (["--no-mandible-share", "-1"], "--no-mandible-share")}
    for name, (args, needle) in synth.items():
        p.append(Probe(f"synth {name}", lambda ws, a=args: ["synth", "--out", ws.out, "--no-progress", *a], "error", (needle,)))  # noqa: E501
    p.append(Probe("demo --out a file", lambda ws: ["demo", "--out", ws.skull / "skull.ply"], "error", ("--out",)))  # noqa: E501
    p.append(Probe("demo --seed -1", lambda ws: ["demo", "--out", ws.out, "--seed", "-1"], "error", ("--seed",)))  # noqa: E501
    p.append(Probe("demo --variant bogus", lambda ws: ["demo", "--out", ws.out, "--variant", "x"], "error", ("--variant",)))  # noqa: E501
    return p


def photo_and_ct_probes():
    """``lilium photo`` and ``lilium import-ct`` (fixed by the photo/CT work of issue 28)."""
    from PIL import Image

    img = lambda size: lambda ws: Image.new("RGB", size).save(ws.root / "in" / "p.png")  # noqa: E731
    photo = lambda *extra, name="p.png": lambda ws: ["photo", ws.root / "in" / name, "--out", ws.out, *extra]  # noqa: E501, E731
    ct = lambda name, content: _write("in", name, content)  # noqa: E731
    imp = lambda name, *extra: lambda ws: ["import-ct", ws.root / "in" / name, "--out", ws.out, *extra]  # noqa: E501, E731
    nhdr = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 10 10 10\nencoding: raw\ndata file: /etc/passwd\n\n"  # noqa: E501
    return [
        Probe("photo 1x1 image", photo(), "error", ("32 px",), img((1, 1)), "photo"),
        Probe("photo folder as image", photo(name=""), "error", ("folder",), None, "photo"),
        Probe("photo text as image", photo(), "error", ("p.png",), _write("in", "p.png", "x"), "photo"),  # noqa: E501
        Probe("photo missing image", photo(name="none.png"), "error", ("none.png",), None, "photo"),  # noqa: E501
        Probe("photo --sensor-width-mm -3", photo("--sensor-width-mm", "-3"), "error", ("--sensor-width-mm",), img((64, 64)), "photo"),  # noqa: E501
        Probe("photo same file as output", lambda ws: ["photo", ws.photo / "image.png", "--out", ws.photo], "error", ("--out", "lilium photo replaces only its own files"), None, "photo"),  # noqa: E501
        Probe("photo header 400 MP", photo(), "error", ("too large",), _write("in", "p.png", _png_header(20000, 20000)), "photo"),  # noqa: E501
        Probe("import-ct missing", imp("none.nrrd"), "error", ("none.nrrd",), None, "ct"),
        Probe("import-ct garbage nrrd", imp("v.nrrd"), "error", ("v.nrrd",), ct("v.nrrd", bytes(range(256)) * 2), "ct"),  # noqa: E501
        Probe("import-ct text nii", imp("v.nii"), "error", ("v.nii",), ct("v.nii", "hello"), "ct"),
        Probe("import-ct detached header /etc/passwd", imp("v.nhdr"), "error", ("v.nhdr",), ct("v.nhdr", nhdr), "ct"),  # noqa: E501
        Probe("import-ct --spacing 1e-9", imp("v.raw", "--raw-shape", "8,8,8", "--spacing", "1e-9,3,3"), "error", ("--spacing",), ct("v.raw", bytes(512)), "ct"),  # noqa: E501
        Probe("import-ct raw too short", imp("v.raw", "--raw-shape", "80,80,80", "--spacing", "1,1,1"), "error", ("v.raw",), ct("v.raw", bytes(512)), "ct"),  # noqa: E501
    ]


# fmt: on
