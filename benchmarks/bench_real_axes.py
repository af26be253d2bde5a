"""What a real case's soft-tissue axes cost its identification: the bone normals (the default of
a skull given without axes) against axes beside the eye corners and the alae
(:func:`lilium.softtissue.normals.fitted_axes`, what ``lilium skull`` writes).

The real heads of ``bench_real_anatomy`` (the Cranium ``cr`` and headsq ``hq``; left out without
their CT), each photo pair (one frontal, one lateral, Exp. C) against its own skull and the other
head's, Lilium at the full budget, the same seed; three skull inputs per pair:

- ``normals``: the hand landmarks without an axes file (every axis the bone normal; the case
  warns ``normal_axes``);
- ``beside``: the same landmarks with the axes of ``fitted_axes`` in the head frame of
  :func:`lilium.fitness.regions.anatomical_frame` (the hand landmarks' own);
- ``automatic``: the bare mesh (``lilium case --skull MESH``: ``lilium skull``'s landmarks and
  axes; its conclusions are undetermined by the ``unreviewed_skull_landmarks`` cap, the LR is
  what to read).

Printed: the frontal + lateral log10 LR and conclusion of each. Run::

    PYTHONPATH=src python benchmarks/bench_real_axes.py --out real-axes [--photos 2]
"""

import argparse
import shutil
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent / "datasets"))

from bench_real_anatomy import photo_pairs, real_datasets  # noqa: E402

#: The heads and the skull each is read with: head -> subject id.
SUBJECTS = {"cranium": "cr", "headsq": "hq"}
VARIANTS = ("normals", "beside", "automatic")


def skull_inputs(subject_dir, work):
    """``{variant: SkullSource}`` of one skull (module notes)."""
    from lilium.casework.request import SkullSource
    from lilium.fitness.regions import anatomical_frame
    from lilium.io.case import parse_cranial_landmarks
    from lilium.io.jsonio import write_json
    from lilium.io.mesh import read_mesh
    from lilium.softtissue.landmarks import CRANIAL_TO_FACIAL
    from lilium.softtissue.normals import fitted_axes

    hand = Path(work) / "hand"
    hand.mkdir(parents=True, exist_ok=True)
    for name in ("skull.ply", "cranial_landmarks.json"):
        shutil.copy(subject_dir / name, hand / name)
    landmarks = parse_cranial_landmarks(hand / "cranial_landmarks.json")
    vertices, faces = read_mesh(hand / "skull.ply")
    frame = anatomical_frame(landmarks)
    with_axes = {n: p for n, p in landmarks.items() if n in CRANIAL_TO_FACIAL}
    axes = fitted_axes(vertices, faces, with_axes, frame.left, frame.anterior)
    beside = Path(work) / "beside_axes.json"
    write_json(beside, {"axes": {n: [float(x) for x in a] for n, a in axes.items()}})
    bare = Path(work) / "bare"
    bare.mkdir(exist_ok=True)
    shutil.copy(subject_dir / "skull.ply", bare / "skull.ply")
    return {
        "normals": SkullSource(hand),
        "beside": SkullSource(hand, axes=beside),
        "automatic": SkullSource(bare / "skull.ply"),
    }


def run(datasets, out, n_photos, log=print):
    """Every photo pair against every skull, each variant: list of dict rows."""
    from lilium.casework.case import run_case
    from lilium.casework.identify import decide
    from lilium.casework.request import CaseRequest, PhotoSource
    from lilium.io.calibration import Calibrations

    calibrations = Calibrations()
    skulls = {
        sid: skull_inputs(datasets[head] / "subjects" / sid, Path(out) / "skulls" / sid)
        for head, sid in SUBJECTS.items() if head in datasets
    }  # fmt: skip
    rows = []
    for head, sid in SUBJECTS.items():
        if head not in datasets:
            continue
        for k, (frontal, lateral) in enumerate(photo_pairs(datasets[head], sid, n_photos)):
            for skull_id, sources in skulls.items():
                for variant in VARIANTS:
                    request = CaseRequest(
                        sources[variant], Path(out) / "cases" / f"{variant}-{sid}{k}-{skull_id}",
                        photos=(PhotoSource(frontal), PhotoSource(lateral)), methods=("lilium",),
                    )  # fmt: skip
                    entries = run_case(request, log=lambda line: None)
                    pair = decide(entries[0].skull, [e.photo for e in entries],
                                  [e.result for e in entries], calibrations).to_dict()  # fmt: skip
                    row = {"photos": f"{sid}{k}", "skull": skull_id, "same": skull_id == sid,
                           "variant": variant, "log10_lr": pair.get("log10_lr"),
                           "conclusion": pair["conclusion"]}  # fmt: skip
                    rows.append(row)
                    lr = "-" if row["log10_lr"] is None else f"{row['log10_lr']:+.2f}"
                    log(f"photos {row['photos']} skull {skull_id} {variant:9s} {lr} "
                        f"{row['conclusion']}")  # fmt: skip
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="real-axes")
    parser.add_argument("--photos", type=int, default=2, help="photo pairs per head")
    args = parser.parse_args(argv)
    datasets = real_datasets(Path(args.out) / "datasets", args.photos)
    if not datasets:
        print("no real head's CT here: nothing to measure", file=sys.stderr)
        return 0
    run(datasets, args.out, args.photos)
    return 0


if __name__ == "__main__":
    sys.exit(main())
