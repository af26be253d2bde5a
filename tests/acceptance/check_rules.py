"""Run the docs/checks.md checks over a whole generated dataset: no generated case may trip
a rule.

For every photo of every experiment of a ``lilium synth`` dataset, against its own skull (with
the subject's true axes, and for Exp. C every perturbed axis set too):

- the checks before any SFO (:func:`lilium.methods.checks.check_inputs`: left/right of the
  skull's labels and of a frontal photo's);
- the ground-truth camera against the skull-faces-camera rule and the declared view (the
  rules' thresholds must hold on the truth);
- POSEST-SFO (deterministic, fast) and its after-SFO checks: a camera refused for seeing the
  back of the skull, ``view_mismatch`` and the other warnings of ``result.json``.

::

    python tests/acceptance/check_rules.py /tmp/rules-ds

prints how many cases tripped each rule (errors must be 0; ``view_mismatch`` should be 0) and
the extreme angles measured. Exits 1 when an error rule was tripped. ``test_check_rules.py``
runs it on a small generated dataset.
"""

import argparse
import collections
import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from lilium.casework.build import read_photo, read_skull
from lilium.constants import FACING_MAX_DEG, VIEW_SPLIT_DEG
from lilium.io.truth import read_ground_truth
from lilium.methods import run_sfo
from lilium.methods.checks import (
    check_inputs,
    facing_angle_deg,
    label_handedness,
    skull_directions,
    view_warning,
)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("dataset", type=Path, help="a lilium synth output folder")
    args = parser.parse_args(argv)
    index = json.loads((args.dataset / "dataset.json").read_text())
    subjects = {s["id"]: s for s in index["subjects"]}
    counts = collections.Counter()
    angles = {"frontal": [], "lateral": []}
    estimated = {"frontal": [], "lateral": []}
    mismatches = []
    handedness = []
    examples = {}
    for entry in index["photos"]:
        subject = subjects[entry["subject"]]
        subject_dir = args.dataset / subject["path"]
        for experiment, rel in entry["paths"].items():
            photo_dir = args.dataset / rel
            photo = read_photo(photo_dir, load_image=False)
            photo = replace(photo, landmarks_file=str(photo_dir / "photo.json"))
            axes_files = [None]
            if experiment == "C":
                axes_files = [subject_dir / a for a in subject.get("axes_C", [])] or [None]
            for axes in axes_files:
                skull = read_skull(subject_dir, axes_path=axes)
                skull = replace(skull, landmarks_file=str(subject_dir / "cranial_landmarks.json"))
                counts["cases"] += 1
                try:
                    check_inputs(skull, photo)
                except ValueError as exc:
                    counts["error: left/right before the SFO"] += 1
                    examples.setdefault("left/right", str(exc))
                    continue
                if axes is axes_files[0]:  # truth and labels: once per photo
                    handedness.append(label_handedness(skull.landmarks_mm, skull.vertices_mm))
                    truth = read_ground_truth(photo_dir).camera
                    d = skull_directions(skull.landmarks_mm, skull.vertices_mm)
                    angle = float(facing_angle_deg(d, truth.R, truth.t)[0])
                    angles["frontal" if photo.view == "frontal" else "lateral"].append(angle)
                    true_angle = angle
                    if angle > FACING_MAX_DEG:
                        counts["error: true camera fails skull-faces-camera"] += 1
                    if view_warning(skull, photo, truth) is not None:
                        counts["true camera: view_mismatch"] += 1
                result = run_sfo("posest-sfo", skull, photo)
                counts["posest-sfo SFOs"] += 1
                if not result:
                    kind = "behind" if "behind the skull" in result.error else "other"
                    counts[f"posest-sfo failed ({kind})"] += 1
                    if kind == "behind":
                        counts["error: posest-sfo camera behind the skull"] += 1
                    examples.setdefault(f"failed {kind}", result.error)
                for w in result.warnings:
                    counts[f"posest-sfo warning {w.code}"] += 1
                    examples.setdefault(w.code, w.message)
                if result:
                    d = skull_directions(skull.landmarks_mm, skull.vertices_mm)
                    found = float(facing_angle_deg(d, result.camera.R, result.camera.t)[0])
                    estimated["frontal" if photo.view == "frontal" else "lateral"].append(found)
                    if any(w.code == "view_mismatch" for w in result.warnings):
                        mismatches.append(
                            (rel, axes.name if axes else "true axes", found, true_angle)
                        )
    print(
        f"dataset {args.dataset}: {len(index['photos'])} photos x {len(index['experiments'])} "
        f"experiments, {len(subjects)} subjects"
    )
    for key in sorted(counts):
        print(f"  {key}: {counts[key]}")
    h = np.array([x for x in handedness if x is not None])
    print(f"  label handedness (must be > 0): min {h.min():+.3f}, max {h.max():+.3f}")
    for view, a in angles.items():
        a = np.array(a)
        limit = f"<= {VIEW_SPLIT_DEG:g}" if view == "frontal" else f">= {VIEW_SPLIT_DEG:g}"
        print(f"  true camera angle, {view} ({limit}): min {a.min():.1f}, max {a.max():.1f} deg")
    for view, a in estimated.items():
        a = np.array(a)
        print(f"  POSEST-SFO camera angle, {view}: min {a.min():.1f}, max {a.max():.1f} deg")
    for rel, axes, found, true_angle in mismatches:
        print(
            f"  view_mismatch: {rel} ({axes}): POSEST-SFO camera at {found:.1f} deg, "
            f"true camera at {true_angle:.1f} deg"
        )
    for key, text in examples.items():
        print(f"  e.g. {key}: {text}")
    errors = sum(v for k, v in counts.items() if k.startswith("error"))
    print(f"{errors} error(s)")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
