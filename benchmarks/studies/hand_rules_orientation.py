"""How far the real heads' written hand placements move when the head is turned a little.

The benchmark of ``lilium skull`` (``benchmarks/bench_skull_landmarks.py``) measures the
automatic landmarks of the real heads against the written hand placements of
``benchmarks/datasets/headsq_landmarks.py`` and ``cranium_landmarks.py``. Many of their rules
take an extreme point ("most anterior", "most posterior", "lowest", "most lateral") in the
CT's own frame, so the reference itself depends on how the head lay in the scanner. This study
places them again on each head turned by +-2.5 and +-5 degrees about each axis of the skull
frame (x to the subject's left: pitch; y up: yaw; z to the front: roll; about the frame's
origin), turns the points back and prints, per turn, how far each landmark moved from the
placement on the head as scanned (median, 90th percentile and largest over the landmarks; the
landmarks that moved more than 3 mm) and the turns whose rules found nothing (a window or a ray
that no longer meets the mesh). An examiner orients a skull to a few degrees; a reference that
moves by more than the benchmark's target under such a turn cannot tell that target.

Run (the CTs as ``headsq_case.py`` and ``cranium_case.py`` find them; ``LILIUM_CRANIUM``)::

    PYTHONPATH=src python benchmarks/studies/hand_rules_orientation.py
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "datasets"))

#: Turns (degrees) about each axis of the skull frame.
TURNS_DEG = (-5.0, -2.5, 2.5, 5.0)
AXES = {"x (pitch)": "x", "y (yaw)": "y", "z (roll)": "z"}
#: Landmarks that moved more than this (mm) are named.
NAMED_MM = 3.0


def headsq_placer():
    """``place(R) -> cranial landmarks`` of headsq (with its mandible) on the head turned by
    ``R`` (3, 3), turned back; None without the CT."""
    import headsq_ct
    from headsq_landmarks import place_landmarks

    if headsq_ct.data_dir() is None:
        return None
    subjects = headsq_ct.headsq_subjects()
    hq, nm = subjects["hq"], subjects["hq_nm"]
    skull, skin = hq.skull_vertices_mm, hq.skin_vertices_mm
    mandible = headsq_ct.mandible_vertices(skull, nm.skull_vertices_mm)

    def place(R):
        cranial = place_landmarks(skull @ R.T, hq.skull_faces, skin @ R.T, hq.skin_faces,
                                  mandible)[0]  # fmt: skip
        return {n: p @ R for n, p in cranial.items()}

    return place


def cranium_placer():
    """The same for the Cranium; None without its file."""
    import cranium_ct
    from cranium_landmarks import place_landmarks

    try:
        out = cranium_ct.cranium_subject()
    except (OSError, ValueError):
        return None
    cr = out["cr"]
    origin = out["_origin_lps"] @ cranium_ct.LPS_TO_SKULL.T  # the skull frame's, skull axes
    hu_at = cranium_ct.hu_sampler(cranium_ct.edited_volume()[0], origin)
    skull, skin = cr.skull_vertices_mm, cr.skin_vertices_mm

    def place(R):
        cranial = place_landmarks(skull @ R.T, cr.skull_faces, skin @ R.T, cr.skin_faces,
                                  lambda p: hu_at(np.asarray(p) @ R))[0]  # fmt: skip
        return {n: p @ R for n, p in cranial.items()}

    return place


def main():
    from scipy.spatial.transform import Rotation

    for head, make in (("headsq", headsq_placer), ("Cranium", cranium_placer)):
        place = make()
        if place is None:
            print(f"{head}: left out (no CT)")
            continue
        base = place(np.eye(3))
        moved, failed = [], []
        print(f"\n{head}: {len(base)} landmarks; movement (mm) from the placement as scanned")
        for label, axis in AXES.items():
            for deg in TURNS_DEG:
                R = Rotation.from_euler(axis, deg, degrees=True).as_matrix()
                try:
                    turned = place(R)
                except (ValueError, IndexError, TypeError) as exc:  # a rule found nothing
                    failed.append(f"{axis}{deg:+.1f}")
                    print(f"  {label:9s} {deg:+4.1f}: no placement ({type(exc).__name__}: {exc})")
                    continue
                d = {n: float(np.linalg.norm(turned[n] - base[n])) for n in base if n in turned}
                v = np.array(list(d.values()))
                moved += list(v)
                far = " ".join(f"{n} {x:.1f}" for n, x in d.items() if x > NAMED_MM)
                print(f"  {label:9s} {deg:+4.1f}: median {np.median(v):5.2f} p90 "
                      f"{np.percentile(v, 90):5.2f} max {v.max():6.1f}  {far}")  # fmt: skip
        moved = np.array(moved)
        print(
            f"  {head}, turns placed ({len(TURNS_DEG) * len(AXES) - len(failed)} of "
            f"{len(TURNS_DEG) * len(AXES)}), every landmark: median {np.median(moved):.2f}, "
            f"p90 {np.percentile(moved, 90):.2f}, share > 4 mm {np.mean(moved > 4):.0%}"
        )


if __name__ == "__main__":
    main()
