"""Identification on real anatomy: real photos against real skulls, the same person and another.

The real heads are CT scans (``benchmarks/datasets/headsq_case.py``: headsq, with its mandible
``hq`` and without ``hq_nm``; ``benchmarks/datasets/cranium_case.py``: InVesalius' Cranium
``cr``, no mandible), each photographed by the generator's cameras from its own skin (Exp. C:
landmarks with noise, perturbed soft-tissue axes). Every photo pair (one frontal, one lateral) of
a head runs through :func:`lilium.casework.case.run_case` against its own skull and against the
other heads' skulls, with POSEST-SFO and Lilium at the full budget and the skull's first set of
Exp. C soft-tissue axes (``axes_C1.json``: the true directions turned by up to 30 degrees, as
the calibration's SFOs had them; with the true axes a real skull fits its photo better than
any calibration pair and is read as outside the calibration); each decision (single photo,
frontal + lateral) is one row: same person or not, log10 LR, conclusion, caps and consistency
failures. :func:`summary` gives the figures of the validation (:mod:`bench_validation`): own
skull log10 LR > 0, at a bound, different person with support, ``outside_calibration``.

It also measures the tolerance of "skull outside the head" on the true pairs: for each SFO of a
photo with its own skull, the skull's pixels outside the head mask and how far outside
(:func:`lilium.identification.score.outside_depths`), in pixels and in eye-corner units.

Run::

    PYTHONPATH=src python benchmarks/bench_real_anatomy.py --out real-anatomy [--photos 3]

Resumable (the cases are; a second run reads them back). Without either CT the head is left
out and the script says so.
"""

import argparse
import sys
from pathlib import Path

import numpy as np

#: The data tools (benchmarks/datasets) this script imports, e.g. ``headsq_case``.
sys.path.insert(0, str(Path(__file__).resolve().parent / "datasets"))

#: The real heads: id -> (case module, subject ids of its skulls). Each head is one person.
HEADS = {"headsq": ("headsq_case", ("hq", "hq_nm")), "cranium": ("cranium_case", ("cr",))}

#: Methods compared, with their labels.
METHODS = ("lilium", "posest-sfo")


def real_datasets(work, n_photos):
    """``{head: dataset folder}`` of the real heads whose CT is here (built under ``work``)."""
    import importlib

    out = {}
    for head, (module, _) in HEADS.items():
        try:
            ensure = importlib.import_module(module).ensure_dataset
        except ImportError:
            continue
        root = ensure(Path(work) / head, n_photos=n_photos)
        if root is not None:
            out[head] = Path(root)
    return out


def photo_pairs(root, subject, n_photos):
    """The (frontal, lateral) Exp. C photo folders of ``subject``, up to ``n_photos``."""
    folder = Path(root) / "photos" / "C"
    return [
        (folder / f"{subject}_f{k:02d}", folder / f"{subject}_l{k:02d}")
        for k in range(n_photos)
        if (folder / f"{subject}_f{k:02d}").is_dir() and (folder / f"{subject}_l{k:02d}").is_dir()
    ]


def run_pairs(datasets, out, n_photos, log=print, calibration=None):
    """Every real photo pair against every real skull (module docstring), identified with
    ``calibration`` (a calibration file; None: the shipped one).

    Returns
    -------
    list of dict
        One per decision: ``head`` (the photos' person), ``skull``, ``same`` (bool),
        ``method``, ``decision`` (``frontal``, ``lateral``, ``frontal + lateral``), ``photo``,
        ``log10_lr``, ``conclusion``, ``caps`` (codes), ``inconsistent`` (codes), ``bound``
        (the LR sits at its model's bound), ``terms``, and for single photos of the true
        skull ``outside`` (:func:`lilium.identification.score.outside_depths`).
    """
    from lilium.casework.case import run_case
    from lilium.casework.identify import decide
    from lilium.casework.request import CaseRequest, PhotoSource, SkullSource
    from lilium.identification.score import outside_depths
    from lilium.io.calibration import Calibrations

    calibrations = Calibrations(calibration)
    skulls = {sid: (head, datasets[head] / "subjects" / sid)
              for head, (_, ids) in HEADS.items() if head in datasets for sid in ids}
    rows = []
    for head, root in datasets.items():
        main_subject = HEADS[head][1][0]
        for k, (frontal, lateral) in enumerate(photo_pairs(root, main_subject, n_photos)):
            for sid, (skull_head, skull_dir) in skulls.items():
                case_dir = Path(out) / "cases" / f"{main_subject}{k:02d}-{sid}"
                request = CaseRequest(
                    SkullSource(skull_dir, axes=skull_dir / "axes_C1.json"), case_dir,
                    photos=(PhotoSource(frontal), PhotoSource(lateral)), methods=tuple(METHODS),
                    calibration=calibration,
                )
                entries = run_case(request, log=lambda line: None)
                for method in METHODS:
                    items = [e for e in entries if e.result.method == method]
                    pair = decide(items[0].skull, [e.photo for e in items],
                                  [e.result for e in items], calibrations).to_dict()
                    decisions = [(e.photo.view, e.photo.id, e.result.extra["identification"], e)
                                 for e in items]
                    for view, photo_id, record, entry in decisions + [
                        ("frontal + lateral", f"{main_subject}{k:02d}", pair, None)
                    ]:
                        row = _row(head, sid, skull_head == head, method, view, photo_id,
                                   record, calibrations)
                        if entry is not None and row["same"] and entry.result.camera is not None:
                            row["outside"] = outside_depths(
                                entry.skull, entry.photo, entry.result.camera
                            )
                        rows.append(row)
                log(f"{main_subject}{k:02d} against {sid}: done")
    return rows


def _row(head, skull, same, method, view, photo, record, calibrations):
    """One decision's row of :func:`run_pairs`."""
    lr = record.get("log10_lr")
    model_key = (record.get("calibration") or {}).get("model", "")
    model = calibrations.get(model_key.split(" -> ")[-1])
    bound = (lr is not None and model is not None
             and min(abs(lr - b) for b in model.bounds) < 1e-6)
    return {
        "head": head, "skull": skull, "same": same, "method": method,
        "decision": "frontal + lateral" if view == "frontal + lateral" else
        ("frontal" if view == "frontal" else "lateral"),
        "photo": photo, "log10_lr": lr, "conclusion": record["conclusion"],
        "caps": list(record.get("caps") or {}), "inconsistent": list(record.get("inconsistent")
                                                                      or {}),
        "bound": bool(bound), "terms": record.get("terms"),
    }


def summary(rows):
    """Per method and decision kind (single photo, frontal + lateral): the figures of the
    validation on real pairs.

    Returns
    -------
    dict
        ``{(method, kind): {"own_positive", "own_bound", "own_undetermined_by_outside",
        "diff_support", "diff_negative", "outside_calibration", "n_same", "n_diff"}}``, shares
        in [0, 1] (``diff_support`` a count).
    """
    out = {}
    for method in METHODS:
        for kind in ("single", "frontal + lateral"):
            sel = [r for r in rows if r["method"] == method and r["log10_lr"] is not None
                   and (r["decision"] == kind if kind != "single"
                        else r["decision"] != "frontal + lateral")]
            same = [r for r in sel if r["same"]]
            diff = [r for r in sel if not r["same"]]
            support = ("support" in r["conclusion"] and "exclusion" not in r["conclusion"]
                       for r in diff)
            out[(method, kind)] = {
                "own_positive": _share(r["log10_lr"] > 0 for r in same),
                "own_bound": _share(r["bound"] for r in same),
                "own_outside_head": _share("skull_outside_head" in r["inconsistent"]
                                           for r in same),
                "diff_support": int(sum(support)),
                "diff_negative": _share(r["log10_lr"] < 0 for r in diff),
                "bound": _share(r["bound"] for r in sel),
                "outside_calibration": _share("outside_calibration" in r["caps"] for r in sel),
                "n_same": len(same), "n_diff": len(diff),
            }
    return out


def _share(flags):
    flags = list(flags)
    return float(np.mean(flags)) if flags else float("nan")


def print_rows(rows, file=sys.stdout):
    print("| photos | skull | same | method | decision | log10 LR | conclusion | caps, "
          "consistency |", file=file)
    print("|---|---|---|---|---|---|---|---|", file=file)
    for r in rows:
        lr = "-" if r["log10_lr"] is None else f"{r['log10_lr']:+.2f}{' (bound)' * r['bound']}"
        why = ", ".join(r["inconsistent"] + r["caps"]) or "-"
        print(f"| {r['photo']} | {r['skull']} | {'yes' if r['same'] else 'no'} | {r['method']} "
              f"| {r['decision']} | {lr} | {r['conclusion']} | {why} |", file=file)


def print_outside(rows, file=sys.stdout):
    """The true pairs' skull pixels outside the head mask (the tolerance's measurement)."""
    print("| photo | skull | method | skull px | outside px | deepest px | deepest / eye "
          "corners | beyond 2 px | beyond 1 % eye |", file=file)
    print("|---|---|---|---|---|---|---|---|---|", file=file)
    for r in rows:
        if "outside" not in r:
            continue
        depth, skull_px, eye_px = r["outside"]
        deepest = float(depth.max()) if len(depth) else 0.0
        print(f"| {r['photo']} | {r['skull']} | {r['method']} | {skull_px} | {len(depth)} | "
              f"{deepest:.1f} | {deepest / eye_px:.4f} | {int((depth > 2).sum())} | "
              f"{int((depth > 0.01 * eye_px).sum())} |", file=file)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="real-anatomy")
    parser.add_argument("--photos", type=int, default=3, help="photo pairs per head")
    parser.add_argument("--calibration", help="calibration file (default: the shipped one)")
    args = parser.parse_args(argv)
    datasets = real_datasets(Path(args.out) / "datasets", args.photos)
    missing = [h for h in HEADS if h not in datasets]
    if missing:
        print(f"left out (CT not found): {', '.join(missing)}")
    if not datasets:
        return 0
    rows = run_pairs(datasets, args.out, args.photos, calibration=args.calibration)
    print_rows(rows)
    print()
    print_outside(rows)
    print()
    for (method, kind), s in summary(rows).items():
        print(f"{method} {kind}: " + ", ".join(
            f"{k} {v:.2f}" if isinstance(v, float) else f"{k} {v}" for k, v in s.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
