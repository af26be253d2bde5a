"""SFOs from automatic cranial landmarks (``lilium skull``) against hand-placed ones.

For each skull, its subject folder as placed by hand and a copy whose landmarks
``lilium skull`` placed on the same mesh (:func:`lilium.skull.prepare.prepare_skull`;
``located`` points only, template points wait for a reviewer), each photo runs through Lilium
with the same photo, soft-tissue axes (the photo's Exp. C set, ``axes_C1.json``) and seed. Per
skull and overall: the mean BPE (mm, against the photo's ground truth camera) with hand and
automatic landmarks and their ratio, failures, and, for the real heads, every identification
(own skull and the other heads' skulls, single photos and frontal + lateral): the uncapped
conclusion and log10 LR with hand and automatic landmarks (the automatic ones also carry the
``unreviewed_landmarks`` cap).

Skulls: the demo's generated person (``lilium.demo.build_demo_case``) and the generated
subjects of a small Exp. C dataset (``--subjects``), and the real CT heads when their CT is here
(``benchmarks/datasets/headsq_case.py``, ``cranium_case.py``).

Run::

    PYTHONPATH=src python benchmarks/bench_skull_sfo.py --out skull-sfo [--subjects 4]
"""

import argparse
import shutil
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent / "datasets"))

from bench_real_anatomy import HEADS, photo_pairs, real_datasets  # noqa: E402
from lilium.casework.case import run_case  # noqa: E402
from lilium.casework.identify import decide  # noqa: E402
from lilium.casework.request import CaseRequest, PhotoSource, SkullSource  # noqa: E402
from lilium.demo import ground_truth_bpe  # noqa: E402
from lilium.io.calibration import Calibrations  # noqa: E402
from lilium.skull.prepare import prepare_skull  # noqa: E402


def automatic_folder(subject_dir, work):
    """A copy of ``subject_dir`` whose cranial landmarks ``lilium skull`` placed (its axes files
    kept)."""
    out = Path(work) / "automatic" / Path(subject_dir).parent.parent.name / Path(subject_dir).name
    if not (out / "cranial_landmarks.json").is_file():
        prepare_skull(Path(subject_dir) / "skull.ply", out)
        for axes in Path(subject_dir).glob("axes_*.json"):
            shutil.copy(axes, out / axes.name)
    return out


def sfos(skull_dir, photos, case_dir, calibrations, truth_dir):
    """Lilium on ``photos`` with ``skull_dir``: per photo (BPE against the ground truth of the
    subject folder ``truth_dir``, identification record), and the decision over them all."""
    request = CaseRequest(
        SkullSource(skull_dir, axes=Path(skull_dir) / "axes_C1.json"), case_dir,
        photos=tuple(PhotoSource(p) for p in photos), methods=("lilium",),
    )
    entries = run_case(request, log=lambda line: None)
    rows = []
    for entry, photo in zip(entries, photos, strict=True):
        folder = Path(case_dir) / entry.photo.id / "lilium-skof+pll"
        ok = entry.result.camera is not None
        bpe = ground_truth_bpe(folder / "result.json", truth_dir, photo) if ok else np.nan
        rows.append((bpe, entry.result.extra["identification"]))
    pair = None
    if len(entries) > 1:
        pair = decide(entries[0].skull, [e.photo for e in entries], [e.result for e in entries],
                      calibrations).to_dict()
    return rows, pair


def _fmt_id(record):
    lr = record.get("log10_lr")
    lr = "-" if lr is None else f"{lr:+.2f}"
    return f"{record.get('conclusion_uncapped', record.get('conclusion'))} ({lr})"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="skull-sfo")
    parser.add_argument("--subjects", type=int, default=4)
    args = parser.parse_args()
    work = Path(args.out)
    calibrations = Calibrations()
    from lilium.synthetic.dataset import generate_dataset

    generated = work / "generated"
    if not (generated / "dataset.json").is_file():
        generate_dataset(generated, args.subjects, 1, seed=11, experiments=("C",), workers=1)
    skulls = [(f"gen {p.name}", p, sorted((generated / "photos" / "C").glob(f"{p.name}_*")))
              for p in sorted((generated / "subjects").iterdir())]
    datasets = real_datasets(work / "real", n_photos=2)
    for head, root in datasets.items():
        for sid in HEADS[head][1]:
            subject = HEADS[head][1][0]
            photos = [p for pair in photo_pairs(root, subject, 2) for p in pair]
            skulls.append((f"{head} {sid}", root / "subjects" / sid, photos))
    print("| skull | photos | BPE hand mm | BPE automatic mm | ratio | failures hand / auto |")
    print("|---|---|---|---|---|---|")
    ratios, identifications = [], []
    for name, subject_dir, photos in skulls:
        auto_dir = automatic_folder(subject_dir, work)
        cases = work / "cases"
        hand, hand_pair = sfos(subject_dir, photos, cases / f"{name}-hand", calibrations,
                               subject_dir)
        # The mesh of the automatic folder is the hand folder's, in its frame: one truth.
        auto, auto_pair = sfos(auto_dir, photos, cases / f"{name}-auto", calibrations,
                               subject_dir)
        bh, ba = np.array([r[0] for r in hand]), np.array([r[0] for r in auto])
        ratio = np.nanmean(ba) / np.nanmean(bh)
        ratios.append(ratio)
        print(f"| {name} | {len(photos)} | {np.nanmean(bh):.2f} | {np.nanmean(ba):.2f} "
              f"| {ratio:.2f} | {int(np.isnan(bh).sum())} / {int(np.isnan(ba).sum())} |",
              flush=True)
        if not name.startswith("gen"):
            for photo, (_, rh), (_, ra) in zip(photos, hand, auto, strict=True):
                identifications.append((name, photo.name, _fmt_id(rh), _fmt_id(ra)))
            if hand_pair is not None:
                identifications.append((name, "all photos", _fmt_id(hand_pair),
                                        _fmt_id(auto_pair)))
    print(f"\nmean BPE ratio (automatic / hand) over skulls: {np.mean(ratios):.2f}\n")
    print("| skull | photos | hand: conclusion (log10 LR) | automatic |")
    print("|---|---|---|---|")
    for row in identifications:
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
