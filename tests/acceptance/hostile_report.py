"""Report-consistency probes, tested: what the HTML report (``lilium case``'s
``report.html``, ``lilium lineup``'s), the console and ``lineup.json`` show must be what the
``result.json`` files hold. "Pictures they can judge and a conclusion they can sign": a report
that shows another conclusion, another LR, another camera, hides a cap, a warning or a term
switched off, or pictures another photo, is a silently wrong answer.

Each probe runs ``lilium case`` (one photo, several, ``--joint``), ``lilium lineup`` (several
candidates, one with several photos, candidates that tie, one whose SFO fails) or ``lilium sfo``
on inputs that reach different states (success, a failed SFO, warnings ``view_mismatch``,
``outside_prior``, ``landmark_outside_mask``, ``mesh_part_left_out``, a term switched off, the
caps of the conclusion, a skull outside the head) and checks, from the files alone, that the
report's SFO sections, overlays, pictures and conclusion rows and the console's lines say what
the ``result.json`` files say (those checks are in ``hostile_reportcheck.py``; how the
page and the console are read, in ``hostile_reportpage.py``). This module holds the
probes, their set-ups and command lines, and the checks of one command:

- a lineup's order follows its LRs (ties broken as documented: the views' log10 LRs added, then
  the unbounded score), and the report's ranking rows, the console's and ``lineup.json``'s agree;
- ``lilium sfo``'s console shows ``result.json``'s warnings, focal, terms switched off and
  identification.

Budgets: POSEST-SFO, or Lilium with 5 x 2. ::

    python -m pytest -m slow tests/acceptance/test_hostile_report.py [-k TEXT]
"""

import re
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from hostile_casework import TINY, _calibration, _only_models, _quiet_main  # noqa: E402
from hostile_fixtures import _edit_json, _in, _json, _syn  # noqa: E402
from hostile_machinery import Probe, _then  # noqa: E402
from hostile_reportcheck import (  # noqa: E402
    _conclusion_problems,
    _console_problems,
    _report_consistent,
)
from hostile_reportpage import _arm, _console  # noqa: E402
from hostile_semantic import _invert_mask, _view  # noqa: E402

# -- lineups ----------------------------------------------------------------------------------


def _rank_key(entry, first):
    rec = entry["identification"]
    lr, views, score = rec.get("log10_lr"), rec.get("views_log10_lr") or [], rec.get("score")
    return (
        entry["method"] != first,
        -(lr if lr is not None else float("-inf")),
        -(sum(views) if views and None not in views else float("-inf")),
        score if score is not None else float("inf"),
    )


def _lineup_extra(expect_tie=False, expect_failed=None, order=None):
    """The lineup's own checks: ``lineup.json``'s order follows its LRs (README: ranked by LR;
    docs/method/identification.md: ties at the bound by the views' sum, then the score), its entries
    are the
    candidates' ``result.json`` identifications, the report's ranking rows and the console's
    say the same. ``expect_tie``: two candidates must tie on the LR (a probe of tie-breaking);
    ``expect_failed``: that candidate's decision is undetermined without an LR; ``order``: the
    expected candidate order."""

    def extra(ws, rep, problems):
        path = ws.out / "lineup.json"
        if not path.is_file():
            problems.append("no lineup.json")
            return
        ranking = _json(path)["ranking"]
        first = ranking[0]["method"] if ranking else ""
        keys = [_rank_key(e, first) for e in ranking]
        for k in range(len(keys) - 1):
            if keys[k] > keys[k + 1]:
                a, b = ranking[k], ranking[k + 1]
                problems.append(
                    f"lineup.json rank {a['rank']} {a['candidate']} (log10 LR {a['identification'].get('log10_lr')}, score {a['identification'].get('score')}) above rank {b['rank']} {b['candidate']} (log10 LR {b['identification'].get('log10_lr')}, score {b['identification'].get('score')})"  # noqa: E501
                )
        if [e["rank"] for e in ranking] != list(range(1, len(ranking) + 1)):
            problems.append(f"ranks {[e['rank'] for e in ranking]}")
        if order is not None:
            got = [e["candidate"] for e in ranking if e["method"] == first]
            if got != list(order):
                problems.append(f"candidates ranked {got}, expected {list(order)}")
        lrs = [e["identification"].get("log10_lr") for e in ranking if e["method"] == first]
        if expect_tie and len({lr for lr in lrs if lr is not None}) == len([x for x in lrs if x is not None]):  # noqa: E501
            problems.append(f"no tie to break (log10 LRs {lrs}): the probe's premise failed")
        # each single-photo candidate's decision is its result.json's identification
        for e in ranking:
            if len(e["photos"]) == 1:
                found = [
                    _json(r) for r in (ws.out).rglob("result.json")
                    if _json(r).get("photo") == e["photos"][0]
                    and (_json(r)["method"] + ("-" + _json(r)["variant"] if _json(r).get("variant") else "")) == e["method"]  # noqa: E501
                ]
                if len(found) != 1:
                    problems.append(f"{e['candidate']}: {len(found)} result.json for {e['photos'][0]} {e['method']}")  # noqa: E501
                    continue
                rec, own = e["identification"], found[0]["identification"]
                for key in ("conclusion", "log10_lr", "caps", "inconsistent"):
                    if rec.get(key) != own.get(key):
                        problems.append(f"{e['candidate']}: lineup.json {key} {rec.get(key)!r}, result.json {own.get(key)!r}")  # noqa: E501
            if expect_failed == e["candidate"]:
                rec = e["identification"]
                if rec.get("log10_lr") is not None or rec.get("conclusion") != "undetermined":
                    problems.append(f"{e['candidate']} (a failed SFO): {rec.get('conclusion')!r}, log10 LR {rec.get('log10_lr')}")  # noqa: E501
        # the report's ranking rows: the first len(ranking) rows, in order
        rows = rep.conclusion_rows()
        for k, e in enumerate(ranking):
            want = f"{e['rank']}. candidate {e['candidate']} ({len(e['photos'])} photo(s)), {e['method']}"  # noqa: E501
            if k >= len(rows) or rows[k][0] != want:
                problems.append(f"report ranking row {k + 1}: {rows[k][0] if k < len(rows) else None!r}, lineup.json {want!r}")  # noqa: E501
                continue
            problems.extend(_conclusion_problems(f"report ranking row {k + 1}", rows[k], e["identification"]))  # noqa: E501
        # the console: "k. name (method): identification: ..."
        out_text, _ = _console(ws)
        lines = [ln for ln in out_text.splitlines() if re.match(r"\d+\. ", ln)]
        if len(lines) != len(ranking):
            problems.append(f"console ranks {len(lines)} entries, lineup.json {len(ranking)}")
        for ln, e in zip(lines, ranking, strict=False):
            if not ln.startswith(f"{e['rank']}. {e['candidate']} ({e['method']}): "):
                problems.append(f"console {ln[:60]!r}, lineup.json rank {e['rank']} {e['candidate']}")  # noqa: E501
            problems.extend(_console_problems(f"console rank {e['rank']}", ln, e["identification"]))  # noqa: E501

    return extra


# -- lilium sfo: the console against result.json ---------------------------------------------


def _sfo_console(joint=False, failed=False):
    def check(ws):
        path = ws.out / "result.json"
        if not path.is_file():
            return "no result.json"
        data = _json(path)
        out_text, err_text = _console(ws)
        idn = data.get("identification") or {}
        p = []
        parts = data["photos"] if joint else [data]
        for part in parts:
            for w in part.get("warnings", []):
                want = f"warning {w['code']}" + (f" ({part['photo']})" if joint else "") + f": {w['message']}"  # noqa: E501
                if want not in err_text:
                    p.append(f"stderr lacks {want[:80]!r}")
            if part.get("camera"):
                focal = f"focal {part['camera']['focal_px']:.0f} px"
                if focal not in out_text:
                    p.append(f"stdout lacks {focal!r} of {part.get('photo')}")
            for term in part.get("terms_off") or {}:
                if f"{term} switched off" not in out_text:
                    p.append(f"stdout does not say {term} switched off")
        line = next((ln for ln in out_text.splitlines() if ln.startswith("identification:")), "")
        if failed:
            if "SFO failed" not in err_text:
                p.append("stderr does not say the SFO failed")
            if idn.get("conclusion") != "undetermined" or idn.get("log10_lr") is not None:
                p.append(f"a failed SFO's result.json: {idn.get('conclusion')!r}, {idn.get('log10_lr')}")  # noqa: E501
            if line:
                p.extend(_console_problems("console", line, idn))
        else:
            p.extend(_console_problems("console", line, idn))
        return "; ".join(p[:4]) if p else None

    return check


# -- set-ups ----------------------------------------------------------------------------------


def _P(ws):
    return ws.photo


def _S(ws):
    return ws.skull


def _p(name):
    return lambda ws: _in(ws, "photos", name)


def _syn_photo(name):
    return lambda ws: _in(ws, "syn", "photos", "A", name)


def _syn_subject(name):
    return lambda ws: _in(ws, "syn", "subjects", name)


S1 = _syn_subject("s01")
F1, L1, F2, L2 = (_syn_photo(n) for n in ("s01_f00", "s01_l00", "s02_f00", "s02_l00"))


def _keep_landmarks(where, names):
    return _edit_json(
        where, "photo.json",
        lambda d: d.update(landmarks={k: v for k, v in d["landmarks"].items() if k in names}),
    )  # fmt: skip


def _jitter(where, px, seed):
    """Every facial landmark of ``where``'s ``photo.json`` moved by up to ``px`` pixels (placed
    again by hand: another photo, not a copy of one, for the copy check of the case)."""

    def change(d):
        rng = np.random.default_rng(seed)
        d["landmarks"] = {
            k: [u + rng.uniform(-px, px), v + rng.uniform(-px, px)]
            for k, (u, v) in d["landmarks"].items()
        }

    return _edit_json(where, "photo.json", change)


def _other_photo(name="p2", px=4.0, seed=7, scale=0.5):
    """``in/photos/<name>``: another photo of the stand-in: its image at ``scale``, its
    landmarks placed again (``px`` of jitter: 2-3 % of their extent)."""

    def setup(ws):
        from standin_case import scaled_photo

        scaled_photo(ws.photo, _in(ws, "photos", name), scale)
        _jitter(_p(name), px, seed)(ws)

    return setup


#: The stand-in's facial landmarks on the midline (on one plane in 3D, as their skull's).
MIDLINE_FACE = ("glabella", "nasion", "metopion", "bregma", "subnasale", "labiale_superius",
                "pogonion", "gnathion")  # fmt: skip


def _failing_photo(name="fail"):
    """``in/photos/<name>``: another photo of the stand-in (:func:`_other_photo`) with its
    midline landmarks only and no head-rotation prior (POSEST: no 4-point sample of points on
    one plane gives a real camera: the SFO fails, as hostile_geometry.py's)."""

    def no_rotation(d):
        for k in ("head_rotation_skull2cam", "head_tolerance_deg"):
            d.get("priors", {}).pop(k, None)

    return _then(
        _other_photo(name, scale=0.6),
        _keep_landmarks(_p(name), MIDLINE_FACE),
        _edit_json(_p(name), "photo.json", no_rotation),
    )


def _drop_cranial(where, names):
    return _edit_json(
        where, "cranial_landmarks.json",
        lambda d: d.update(landmarks={k: v for k, v in d["landmarks"].items() if k not in names}),
    )  # fmt: skip


def _automatic(where):
    """Every facial landmark of ``photo.json`` tagged automatic, tracked, unreviewed."""

    def change(d):
        d["landmark_sources"] = {
            k: {"source": "automatic", "quality": "tracked"} for k in d["landmarks"]
        }

    return _edit_json(where, "photo.json", change)


def _face_only_mask(where, margin=0.02):
    """The mask cut to the face from the brow to the chin (a mask drawn from the hairline to
    the chin, which README warns of): the vault off the mask, so the skull leaves it."""

    def setup(ws):
        from PIL import Image

        lm = _json(where(ws) / "photo.json")["landmarks"]
        face = np.array([p for k, p in lm.items() if k not in ("metopion", "bregma")], float)
        path = where(ws) / "face_mask.png"
        with Image.open(path) as im:
            a = np.asarray(im.convert("L")) > 0
        h, w = a.shape
        m = margin * max(w, h)
        u0, v0 = np.floor(face.min(axis=0) - m).astype(int)
        u1, v1 = np.ceil(face.max(axis=0) + m).astype(int)
        keep = np.zeros_like(a)
        keep[max(v0, 0) : v1, max(u0, 0) : u1] = True
        Image.fromarray(((a & keep) * 255).astype(np.uint8)).save(path)

    return setup


def _no_mask(where):
    return lambda ws: (where(ws) / "face_mask.png").unlink()


def _fragment_beside(where, dx=-150.0):
    """A fragment (icosphere, 10 mm) ``dx`` mm beside the skull (mesh_part_left_out)."""

    def setup(ws):
        import trimesh

        from lilium.io.mesh import read_mesh, write_mesh

        path = where(ws) / "skull.ply"
        v, f = read_mesh(path)
        s = trimesh.creation.icosphere(subdivisions=3)
        v2 = np.asarray(s.vertices) * 10.0 + [dx, 0.0, 0.0]
        v = np.vstack([np.asarray(v, float), v2])
        f = np.vstack([np.asarray(f), np.asarray(s.faces) + len(v) - len(v2)])
        write_mesh(path, v, f)

    return setup


CAL = lambda ws: _in(ws, "cal.json")  # noqa: E731


def _then_run(argv):
    """Set-up: run ``argv(ws)`` once, quietly (a run to resume)."""
    return lambda ws: _quiet_main(argv(ws))


# -- command lines ----------------------------------------------------------------------------


def _cmd(command, skull, photos, *extra, method=("posest-sfo",)):
    def argv(ws):
        out = [command, "--skull", skull(ws)]
        for ph in photos:
            out += ["--photo", ph(ws)]
        for m in method:
            out += ["--method", m]
        return [*out, "--out", ws.out, *(e(ws) if callable(e) else e for e in extra)]

    return argv


def _case(skull, photos, *extra, method=("posest-sfo",)):
    return _cmd("case", skull, photos, *extra, method=method)


def _sfo(skull, photos, *extra, method="posest-sfo"):
    return _cmd("sfo", skull, photos, *extra, method=(method,))


def _lineup(skull, candidates, *extra, method=("posest-sfo",)):
    def argv(ws):
        out = ["lineup", "--no-progress", "--skull", skull(ws), "--out", ws.out]
        for m in method:
            out += ["--method", m]
        for name, *photos in candidates:
            out += ["--candidate", name, *(ph(ws) for ph in photos)]
        return out + [e(ws) if callable(e) else e for e in extra]

    return argv


def _armed(*setups):
    return _then(*setups, _arm)


# fmt: off


def report_probes():
    """Report, console and result.json against each other (module docstring)."""
    L = ("lilium",)
    PL = ("posest-sfo", "lilium")
    syn = lambda *s: _armed(_syn, *s)  # noqa: E731
    ok = lambda *a, **k: _report_consistent(*a, **k)  # noqa: E731
    half = _p("p2")
    return [
        # lilium case
        Probe("report case one photo (posest: outside_prior, single_photo cap)", _case(_S, [_P]), "ok", (), _armed(), check=ok(_S, n_sfos=1, reach=("outside_prior", "single_photo"))),  # noqa: E501
        Probe("report case one photo lilium (P_pll switched off)", _case(_S, [_P], *TINY, method=L), "ok", (), _armed(), check=ok(_S, n_sfos=1, reach=("p_pll",))),  # noqa: E501
        Probe("report case two photos, posest and lilium (decisions together)", _case(_S, [_P, half], *TINY, method=PL), "ok", (), _armed(_other_photo()), check=ok(_S, n_sfos=4)),  # noqa: E501
        Probe("report case --joint two photos, lilium and posest", _case(_S, [_P, half], "--joint", *TINY, method=PL), "ok", (), _armed(_other_photo()), check=ok(_S, n_sfos=4)),  # noqa: E501
        Probe("report case a failed SFO beside a good one", _case(_S, [_P, _p("fail")]), "ok", (), _armed(_failing_photo()), check=ok(_S, n_sfos=2, reach=("failed",)), code=1),  # noqa: E501
        Probe("report case lilium: a photo POSEST fails on beside a good one", _case(_S, [_P, _p("fail")], *TINY, method=L), "ok", (), _armed(_failing_photo()), check=ok(_S, n_sfos=2)),  # noqa: E501
        Probe("report case view_mismatch (lateral_left declared lateral_right)", _case(S1, [L1]), "ok", (), syn(_view(L1, "lateral_right")), check=ok(S1, n_sfos=1, reach=("view_mismatch",))),  # noqa: E501
        Probe("report case view_mismatch beside a good frontal (decision together)", _case(S1, [F1, L1]), "ok", (), syn(_view(L1, "lateral_right")), check=ok(S1, n_sfos=2, reach=("view_mismatch",))),  # noqa: E501
        Probe("report case frontal and lateral (views' LRs added)", _case(S1, [F1, L1], *TINY, method=PL), "ok", (), syn(), check=ok(S1, n_sfos=4)),  # noqa: E501
        Probe("report case inverted mask (landmark_outside_mask, skull outside the head)", _case(_S, [_P]), "ok", (), _armed(_invert_mask(_P)), check=ok(_S, n_sfos=1, reach=("landmark_outside_mask", "skull_outside_head"))),  # noqa: E501
        Probe("report case lilium inverted mask", _case(_S, [_P], *TINY, method=L), "ok", (), _armed(_invert_mask(_P)), check=ok(_S, n_sfos=1, reach=("landmark_outside_mask", "skull_outside_head"))),  # noqa: E501
        Probe("report case mask cut to the face (skull outside the head)", _case(_S, [_P], *TINY, method=PL), "ok", (), _armed(_face_only_mask(_P)), check=ok(_S, n_sfos=2, reach=("skull_outside_head",))),  # noqa: E501
        Probe("report case fragment 150 mm beside the skull (mesh_part_left_out)", _case(_S, [_P], *TINY, method=PL), "ok", (), _armed(_fragment_beside(_S)), check=ok(_S, n_sfos=2, reach=("mesh_part_left_out",))),  # noqa: E501
        Probe("report case lilium skof without a mask (P_skof off)", _case(_S, [_P], "--variant", "skof", *TINY, method=L), "ok", (), _armed(_no_mask(_P)), check=ok(_S, n_sfos=1, reach=("p_skof",))),  # noqa: E501
        Probe("report case posest without a mask", _case(_S, [_P]), "ok", (), _armed(_no_mask(_P)), check=ok(_S, n_sfos=1)),  # noqa: E501
        Probe("report case no mandible (no_mandible cap)", _case(S1, [F1], *TINY, method=PL), "ok", (), syn(_drop_cranial(S1, ("pogonion", "gnathion", "gonion_l", "gonion_r", "infradentale", "mental_foramen_l", "mental_foramen_r"))), check=ok(S1, n_sfos=2, reach=("no_mandible",))),  # noqa: E501
        Probe("report case 7 landmark pairs (few_pairs cap)", _case(_S, [_P]), "ok", (), _armed(_keep_landmarks(_P, ("nasion", "gnathion", "exocanthion_l", "exocanthion_r", "subnasale", "zygion_l", "zygion_r"))), check=ok(_S, n_sfos=1, reach=("few_pairs",))),  # noqa: E501
        Probe("report case unreviewed automatic landmarks (cap)", _case(_S, [_P]), "ok", (), _armed(_automatic(_P)), check=ok(_S, n_sfos=1, reach=("unreviewed_landmarks",))),  # noqa: E501
        Probe("report case two photos, one with unreviewed automatic landmarks", _case(_S, [_P, half]), "ok", (), _armed(_other_photo(), _automatic(half)), check=ok(_S, n_sfos=2, reach=("unreviewed_landmarks",))),  # noqa: E501
        # lilium lineup
        Probe("report lineup true candidate with two photos, another with one", _lineup(S1, [("True", F1, L1), ("Other", F2)]), "ok", (), syn(), check=ok(S1, n_sfos=3, extra=_lineup_extra())),  # noqa: E501
        Probe("report lineup three candidates two methods", _lineup(S1, [("A", F1), ("B", F2), ("C", L2)], *TINY, method=PL), "ok", (), syn(), check=ok(S1, n_sfos=6, extra=_lineup_extra())),  # noqa: E501
        Probe("report lineup candidates tied at the calibration bound", _lineup(_S, [("A", _P), ("B", half)]), "ok", (), _armed(_other_photo()), check=ok(_S, n_sfos=2, extra=_lineup_extra(expect_tie=True))),  # noqa: E501
        Probe("report lineup tie, candidates given in the other order", _lineup(_S, [("B", half), ("A", _P)]), "ok", (), _armed(_other_photo()), check=ok(_S, n_sfos=2, extra=_lineup_extra(expect_tie=True))),  # noqa: E501
        Probe("report lineup a candidate whose SFO fails", _lineup(_S, [("Fails", _p("fail")), ("A", _P)]), "ok", (), _armed(_failing_photo()), check=ok(_S, n_sfos=2, reach=("failed",), extra=_lineup_extra(expect_failed="Fails", order=("A", "Fails")))),  # noqa: E501
        Probe("report lineup a candidate with a failed and a good photo", _lineup(_S, [("Both", _P, _p("fail")), ("Solo", half)]), "ok", (), _armed(_other_photo(), _failing_photo()), check=ok(_S, n_sfos=3, reach=("failed",), extra=_lineup_extra(expect_failed="Both", order=("Solo", "Both")))),  # noqa: E501
        Probe("report lineup view_mismatch candidate", _lineup(S1, [("True", L1), ("Other", F2)]), "ok", (), syn(_view(L1, "lateral_right")), check=ok(S1, n_sfos=2, reach=("view_mismatch",), extra=_lineup_extra())),  # noqa: E501
        # another calibration: no model for the decision (no LR; ranked by the score), and a
        # case resumed with it (the stored SFOs identified again, result.json rewritten)
        Probe("report lineup calibration without models (no LR for anyone)", _lineup(S1, [("A", F1), ("B", F2)], "--calibration", CAL), "ok", (), syn(_calibration(lambda d: d.update(models={}))), check=ok(S1, n_sfos=2, extra=_lineup_extra())),  # noqa: E501
        Probe("report case resumed with a calibration without the method's model", _case(_S, [_P, half], *TINY, "--calibration", CAL, method=PL), "ok", (), _armed(_other_photo(), _then_run(_case(_S, [_P, half], *TINY, method=PL)), _calibration(_only_models("posest-sfo//frontal"))), check=ok(_S, n_sfos=4)),  # noqa: E501
        Probe("report case --joint resumed with a calibration without the joint model", _case(_S, [_P, half], "--joint", *TINY, "--calibration", CAL, method=L), "ok", (), _armed(_other_photo(), _then_run(_case(_S, [_P, half], "--joint", *TINY, method=L)), _calibration(_only_models("lilium/skof+pll/frontal"))), check=ok(_S, n_sfos=2)),  # noqa: E501
        # lilium sfo: console against result.json
        Probe("report sfo console (posest)", _sfo(_S, [_P]), "ok", (), _armed(), check=_sfo_console()),  # noqa: E501
        Probe("report sfo console lilium (a term off, warnings)", _sfo(_S, [_P], *TINY, method="lilium"), "ok", (), _armed(), check=_sfo_console()),  # noqa: E501
        Probe("report sfo console view_mismatch", _sfo(S1, [L1]), "ok", (), syn(_view(L1, "lateral_right")), check=_sfo_console()),  # noqa: E501
        Probe("report sfo console failed SFO", _sfo(_S, [_p("fail")]), "ok", (), _armed(_failing_photo()), check=_sfo_console(failed=True), code=1),  # noqa: E501
        Probe("report sfo console joint", _sfo(_S, [_P, half], *TINY, method="lilium"), "ok", (), _armed(_other_photo()), check=_sfo_console(joint=True)),  # noqa: E501
    ]


# fmt: on
