"""Hostile-input probes of the newer entry points, tested (issue 28):
``lilium lineup`` (one skull against several candidates), ``lilium calibrate DB...``, the
``--calibration FILE`` of ``lilium sfo``/``case``/``lineup`` and the joint SFO (``lilium sfo``
with several ``--photo``, ``lilium case --joint``).

Each probe runs on the stand-in case of the campaign (``in/subjects/standin``,
``in/photos/standin_frontal``), with POSEST-SFO or a tiny Lilium budget; the results databases
are generated here, with every SFO's identification terms stored, so ``lilium calibrate`` fits
a model in a second or two. A second photo of the stand-in is its image at half size with its
landmarks, mask and focal prior scaled (another photo of the same person, not a copy).
"""

import contextlib
import io
import json
import shutil
import sqlite3

from hostile_machinery import Probe, _write

#: The Lilium budget of the joint probes (DE/rand/1 needs 4 members).
TINY = ("--generations", "2", "--population", "5")


def _quiet_main(argv):
    """Run a ``lilium`` command in a probe's set-up without printing."""
    from lilium.cli.main import main

    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        return main([str(a) for a in argv])


def _in(ws, *parts):
    return ws.root.joinpath("in", *parts)


# -- photos -----------------------------------------------------------------------------------


def _second_photo(name="p2", view=None, landmarks=True):
    """Set-up: ``in/photos/<name>``, the stand-in photo at half size (its own bytes), declared
    ``view`` (default frontal), without landmarks unless ``landmarks``."""

    def setup(ws):
        from standin_case import scaled_photo

        folder = scaled_photo(ws.photo, _in(ws, "photos", name), 0.5)
        data = json.loads((folder / "photo.json").read_text())
        data["landmarks"] = data["landmarks"] if landmarks else {}
        data["view"] = view or data["view"]
        (folder / "photo.json").write_text(json.dumps(data))

    return setup


def _copied_photo(name="copy"):
    return lambda ws: shutil.copytree(ws.photo, _in(ws, "photos", name))


def _p(ws, name):
    return _in(ws, "photos", name)


# -- calibration files ------------------------------------------------------------------------


def _calibration(change, name="cal.json"):
    """Set-up: ``in/<name>``, the shipped calibration after ``change(data)`` (NaN and inf are
    written as JSON's ``NaN``/``Infinity``, which Python reads)."""

    def setup(ws):
        from lilium.io.calibration import shipped_path

        data = json.loads(shipped_path().read_text())
        change(data)
        _in(ws, name).write_text(json.dumps(data))

    return setup


def _model(key, value, model="posest-sfo//frontal", inner=None):
    def change(data):
        entry = data["models"][model]
        (entry[inner] if inner else entry)[key] = value

    return change


def _only_models(*keys):
    return lambda data: data.update(models={k: v for k, v in data["models"].items() if k in keys})


# -- results databases ------------------------------------------------------------------------


def _terms_db(n_subjects=12, change=None, name="r.sqlite"):
    """Set-up: ``in/<name>``, a results database of POSEST-SFO frontal SFOs of ``n_subjects``
    generated people, every photo against every skull, each with its camera and its stored
    identification terms (same-person pairs fit better); ``change`` an SQL statement after."""

    def setup(ws):
        from standin_case import terms_database

        path = terms_database(_in(ws, name), n_subjects)
        if change:
            conn = sqlite3.connect(path)
            with conn:
                conn.execute(change)
            conn.close()

    return setup


def _models_written(*expected):
    def check(ws):
        models = json.loads((ws.out / "calibration.json").read_text())["models"]
        return None if sorted(models) == sorted(expected) else f"models {sorted(models)}"

    return check


# -- checks of a success's outputs ------------------------------------------------------------


def _no_lr(ws):
    lr = json.loads((ws.out / "result.json").read_text())["identification"]["log10_lr"]
    return None if lr is None else f"log10 LR {lr} without a model for the decision"


def _ranking(ws):
    return json.loads((ws.out / "lineup.json").read_text())["ranking"]


def _inputs_kept(ws):
    base = ws.base / "photos" / "standin_frontal"
    changed = [f.name for f in base.iterdir() if (ws.photo / f.name).read_bytes() != f.read_bytes()]  # noqa: E501
    return f"input files rewritten: {changed}" if changed else None


def _joint_cameras(ws):
    data = json.loads((ws.out / "result.json").read_text())
    ok = data.get("joint") is True and [bool(p["camera"]) for p in data["photos"]] == [True, True]
    return None if ok else "not a joint result with a camera per photo"


# fmt: off


def _lineup(*candidates, extra=()):
    """``lilium lineup`` (POSEST-SFO); each candidate ``(name, photo, ...)``, a photo a callable
    of the workspace."""
    def argv(ws):
        out = ["lineup", "--no-progress", "--skull", ws.skull, "--out", ws.out, "--method", "posest-sfo"]  # noqa: E501
        for name, *photos in candidates:
            out += ["--candidate", name, *(p(ws) for p in photos)]
        return out + list(extra)
    return argv


def _resumed(change):
    """Set-up: a finished lineup of candidate A in ``out/``, then ``change(ws)``."""
    def setup(ws):
        _quiet_main(_lineup(("A", _P))(ws))
        change(ws)
    return setup


def _tamper(value):
    def change(ws):
        path = ws.out / "A" / "standin_frontal" / "posest-sfo" / "result.json"
        data = json.loads(path.read_text())
        data["identification"]["log10_lr"] = value
        path.write_text(json.dumps(data))
    return change


def _stored_as_folder(ws):
    path = ws.out / "A" / "standin_frontal" / "posest-sfo" / "result.json"
    path.unlink()
    path.mkdir()


def _P(ws):
    return ws.photo


def lineup_probes():
    """``lilium lineup``."""
    p2 = lambda ws: _p(ws, "p2")  # noqa: E731
    copy = lambda ws: _p(ws, "copy")  # noqa: E731
    empty = lambda ws: _in(ws, "empty")  # noqa: E731
    mkdir = lambda name: lambda ws: _in(ws, name).mkdir()  # noqa: E731

    def photo_out(ws):
        ws.out = ws.photo  # --out is the photo folder: its own files must stay as they are
    return [
        Probe("lineup two candidates", _lineup(("A", _P), ("B", p2)), "ok", (), _second_photo(), check=lambda ws: None if [e["rank"] for e in _ranking(ws)] == [1, 2] else "not 2 ranks"),  # noqa: E501
        Probe("lineup candidate folder empty", _lineup(("A", empty)), "error", ("empty",), mkdir("empty")),  # noqa: E501
        Probe("lineup candidate is a text file", _lineup(("A", lambda ws: _in(ws, "x.txt"))), "error", ("x.txt",), _write("in", "x.txt", "x")),  # noqa: E501
        Probe("lineup candidate is the skull folder", _lineup(("A", lambda ws: ws.skull)), "error", ("standin",)),  # noqa: E501
        Probe("lineup candidate name empty", _lineup(("", _P)), "error", ("--candidate", "name")),
        Probe("lineup candidate named lineup.json", _lineup(("lineup.json", _P)), "error", ("--candidate", "lineup.json")),  # noqa: E501
        Probe("lineup duplicate candidate names", _lineup(("A", _P), ("A", p2)), "error", ("--candidate A", "twice"), _second_photo()),  # noqa: E501
        Probe("lineup one photo twice for a candidate", _lineup(("A", _P, _P)), "error", ("--candidate A", "same photo")),  # noqa: E501
        Probe("lineup one photo for two candidates", _lineup(("A", _P), ("B", _P)), "error", ("--candidate B", "same photo")),  # noqa: E501
        Probe("lineup copied photo for two candidates", _lineup(("A", _P), ("B", copy)), "error", ("--candidate B", "copy", "byte for byte"), _copied_photo()),  # noqa: E501
        Probe("lineup --out is the photo folder", _lineup(("A", _P)), "ok", (), photo_out, check=_inputs_kept),  # noqa: E501
        Probe("lineup resumed with another --calibration", _lineup(("A", _P), extra=["--calibration", "in/cal.json"]), "ok", (), lambda ws: (_resumed(lambda ws: None)(ws), _calibration(_only_models("lilium/skof+pll/frontal"))(ws)), check=lambda ws: None if _ranking(ws)[0]["identification"]["log10_lr"] is None else "the stored LR of the other calibration"),  # noqa: E501
        Probe("lineup resumed over an edited LR", _lineup(("A", _P)), "ok", (), _resumed(_tamper("abc")), check=lambda ws: None if isinstance(_ranking(ws)[0]["identification"]["log10_lr"], float) else "the edited LR"),  # noqa: E501
        Probe("lineup stored result.json a folder", _lineup(("A", _P)), "error", ("result.json",), _resumed(_stored_as_folder)),  # noqa: E501
    ]


def calibrate_probes():
    """``lilium calibrate DB...``."""
    cal = lambda *dbs, extra=(): lambda ws: ["calibrate", *(_in(ws, d) for d in dbs), "--out", ws.out, *extra]  # noqa: E501, E731

    def truncated(ws):
        _terms_db()(ws)
        path = _in(ws, "r.sqlite")
        path.write_bytes(path.read_bytes()[:3000])

    def foreign(ws):
        conn = sqlite3.connect(_in(ws, "r.sqlite"))
        with conn:
            conn.execute("CREATE TABLE people (name TEXT, born INTEGER)")
        conn.close()

    def db_in_out(ws):
        _terms_db(name="calibration.csv")(ws)
        ws.out = _in(ws)
    T = "UPDATE sfo SET result = json_set(result, '$.identification_terms.landmark_chi2', {}) WHERE id = 5"  # noqa: E501
    return [
        Probe("calibrate 12 subjects", cal("r.sqlite"), "ok", (), _terms_db(), check=_models_written("posest-sfo//frontal")),  # noqa: E501
        Probe("calibrate one subject only", cal("r.sqlite"), "ok", (), _terms_db(1), check=_models_written()),  # noqa: E501
        Probe("calibrate zero rows", cal("r.sqlite"), "error", ("r.sqlite", "no SFO"), _terms_db(change="DELETE FROM sfo")),  # noqa: E501
        Probe("calibrate truncated database", cal("r.sqlite"), "error", ("r.sqlite",), truncated),
        Probe("calibrate empty file", cal("r.sqlite"), "error", ("r.sqlite",), _write("in", "r.sqlite", b"")),  # noqa: E501
        Probe("calibrate another program's SQLite", cal("r.sqlite"), "error", ("r.sqlite", "not a Lilium"), foreign),  # noqa: E501
        Probe("calibrate the same database twice", lambda ws: ["calibrate", _in(ws, "r.sqlite"), ws.root / "in" / "." / "r.sqlite", "--out", ws.out], "error", ("r.sqlite", "twice"), _terms_db()),  # noqa: E501
        Probe("calibrate result not JSON", cal("r.sqlite"), "error", ("r.sqlite", "row 1"), _terms_db(change="UPDATE sfo SET result = '{bad' WHERE id = 1")),  # noqa: E501
        Probe("calibrate result a JSON list", cal("r.sqlite"), "error", ("r.sqlite", "row 2"), _terms_db(change="UPDATE sfo SET result = '[1, 2]' WHERE id = 2")),  # noqa: E501
        Probe("calibrate terms as text", cal("r.sqlite"), "error", ("r.sqlite", "row 5"), _terms_db(change=T.format("'0.3'"))),  # noqa: E501
        Probe("calibrate camera garbage", cal("r.sqlite"), "error", ("r.sqlite", "camera"), _terms_db(change="UPDATE sfo SET result = json_set(result, '$.camera.focal_px', -1) WHERE id = 3")),  # noqa: E501
        Probe("calibrate --dataset missing", cal("r.sqlite", extra=["--dataset", "nowhere"]), "error", ("--dataset", "nowhere"), _terms_db()),  # noqa: E501
        Probe("calibrate --out would overwrite the database", lambda ws: ["calibrate", _in(ws, "calibration.csv"), "--out", _in(ws)], "error", ("--out", "calibration.csv"), db_in_out),  # noqa: E501
    ]


def calibration_file_probes():
    """``--calibration FILE`` of ``lilium sfo``, ``case`` and ``lineup``."""
    sfo = lambda ws: [*ws.sfo(), "--method", "posest-sfo", "--calibration", _in(ws, "cal.json")]  # noqa: E501, E731
    case = lambda ws: ["case", "--skull", ws.skull, "--photo", ws.photo, "--out", ws.out, "--method", "posest-sfo", "--calibration", _in(ws, "cal.json")]  # noqa: E501, E731
    C = "cal.json"
    return [
        Probe("calibration empty file", sfo, "error", (C,), _write("in", C, "")),
        Probe("calibration truncated JSON", sfo, "error", (C, "JSON"), _write("in", C, '{"format": "lilium-calibration", "models": {')),  # noqa: E501
        Probe("calibration a folder", lambda ws: [*ws.sfo(), "--calibration", _in(ws, "photos")], "error", ("--calibration",)),  # noqa: E501
        Probe("calibration models a list", sfo, "error", (C, "models"), _calibration(lambda d: d.update(models=[1, 2]))),  # noqa: E501
        Probe("calibration weight NaN", sfo, "error", (C, "weights.landmark_chi2"), _calibration(_model("landmark_chi2", float("nan"), inner="weights"))),  # noqa: E501
        Probe("calibration intercept inf", sfo, "error", (C, "intercept"), _calibration(_model("intercept", float("inf")))),  # noqa: E501
        Probe("calibration weight as text", sfo, "error", (C, "weights.landmark_chi2"), _calibration(_model("landmark_chi2", "-1.3", inner="weights"))),  # noqa: E501
        Probe("calibration n_same 0", sfo, "error", (C, "n_same"), _calibration(_model("n_same", 0))),  # noqa: E501
        Probe("calibration scale 0", sfo, "error", (C, "scale"), _calibration(_model("landmark_chi2", 0, inner="scale"))),  # noqa: E501
        Probe("calibration warp NaN", sfo, "error", (C, "warp"), _calibration(_model("warp", {"knots": [0, float("nan")], "ln_lr": [0, 1]}))),  # noqa: E501
        Probe("calibration no models", sfo, "ok", (), _calibration(lambda d: d.update(models={})), check=_no_lr),  # noqa: E501
        Probe("calibration only another method's model", sfo, "ok", (), _calibration(_only_models("lilium/skof+pll/frontal")), check=_no_lr),  # noqa: E501
        Probe("case calibration weight NaN", case, "error", (C,), _calibration(_model("landmark_chi2", float("nan"), inner="weights"))),  # noqa: E501
        Probe("lineup calibration n_diff text", _lineup(("A", _P), extra=["--calibration", "in/cal.json"]), "error", (C, "n_diff"), _calibration(_model("n_diff", "500"))),  # noqa: E501
    ]


def joint_probes():
    """The joint SFO: ``lilium sfo`` with several ``--photo`` and ``lilium case --joint``."""
    def sfo(*names, method="lilium"):
        return lambda ws: ["sfo", "--skull", ws.skull, "--out", ws.out, "--method", method, *TINY, *(a for n in names for a in ("--photo", ws.photo if n == "P" else _p(ws, n)))]  # noqa: E501

    def case(*names, method="lilium"):
        return lambda ws: ["case", "--joint", "--skull", ws.skull, "--out", ws.out, "--method", method, *TINY, *(a for n in names for a in ("--photo", ws.photo if n == "P" else _p(ws, n)))]  # noqa: E501
    same = lambda ws: [*sfo("P")(ws), "--photo", f"{ws.photo}/"]  # noqa: E731
    plain = lambda ws: ["case", "--skull", ws.skull, "--photo", ws.photo, "--out", ws.out, "--method", "posest-sfo"]  # noqa: E501, E731
    return [
        Probe("joint photos of two sizes", sfo("P", "p2"), "ok", (), _second_photo(), check=_joint_cameras),  # noqa: E501
        Probe("joint the same photo twice", same, "error", ("--photo", "same photo")),
        Probe("joint a copied photo folder", sfo("P", "copy"), "error", ("--photo", "copy", "byte for byte"), _copied_photo()),  # noqa: E501
        Probe("joint frontal declared lateral", sfo("P", "p2"), "warn", ("view_mismatch", "p2"), _second_photo(view="lateral_left")),  # noqa: E501
        Probe("joint a photo without landmarks", sfo("P", "p2"), "error", ("p2", "photo.json"), _second_photo(landmarks=False)),  # noqa: E501
        Probe("joint --method posest-sfo", sfo("P", "p2", method="posest-sfo"), "error", ("--method",), _second_photo()),  # noqa: E501
        Probe("case --joint a copied photo", case("P", "copy"), "error", ("--photo", "copy"), _copied_photo()),  # noqa: E501
        Probe("case --joint photos of two sizes", case("P", "p2"), "ok", (), _second_photo(), check=lambda ws: None if (ws.out / "joint" / "lilium-skof+pll" / "result.json").is_file() else "no joint result"),  # noqa: E501
        # Without --joint a repeated photo would count as a second view (the single-photo cap).
        Probe("case the same photo twice", lambda ws: [*plain(ws), "--photo", f"{ws.photo}/"], "error", ("--photo", "same photo")),  # noqa: E501
        Probe("case a copied photo folder", lambda ws: [*plain(ws), "--photo", _p(ws, "copy")], "error", ("--photo", "copy", "byte for byte"), _copied_photo()),  # noqa: E501
    ]


# fmt: on


def casework_probes():
    return lineup_probes() + calibrate_probes() + calibration_file_probes() + joint_probes()
