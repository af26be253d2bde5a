"""A second real-anatomy benchmark case, from InVesalius' "Cranium" CT: subject folder and photos.

A script and a module: other benchmarks import :func:`build_cranium_dataset` (a stand-alone
dataset of the Cranium subject) or :func:`ensure_dataset`; both return None when the CT is
absent. Run::

    # once: apt-get download
    python benchmarks/datasets/cranium_case.py --fetch ../shared/data/cranium
    python benchmarks/datasets/cranium_case.py --out cranium-case --photos 3

The subject comes from ``benchmarks/datasets/cranium_ct.py`` (the CT and where it is found, the
volume edits, ``lilium.ct.import_ct`` and the turn into the generator's skull frame), its
landmarks from the rules of ``benchmarks/datasets/cranium_landmarks.py``. Built here exactly as
``benchmarks/datasets/headsq_case.py`` builds the headsq case, with the generator's own code
(``lilium.synthetic.dataset``: cameras drawn from ``CameraRanges``, the render, visibility, face
mask, face curves, Exp. B/C noise and the five perturbed axes sets): the photos (frontal and
lateral), the subject folder and ``dataset.json``.

Subject: ``cr``, a skull without its mandible (``"mandible": false`` in ``dataset.json`` and
``subject.json``): the CT ends at the upper teeth, so the mandible was never scanned and its
true landmarks are unknown (``removed_landmarks`` is empty); the skin ends at the upper lip, so
the frontal photos have no chin-jaw curve (no cheilia); the lateral ones have the forehead curve.
The photo stream is ``SeedSequence(seed, spawn_key=(CRANIUM_SPAWN_KEY,))``, apart from the
headsq case's and the generated subjects'.
"""

import argparse
import sys
from pathlib import Path

import numpy as np

from cranium_ct import DEFAULT_DATA, FILE_NAME, LPS_TO_SKULL, cranium_subject, data_path, fetch
from headsq_case import _factory, dataset_index

SUBJECT_ID = "cr"
CRANIUM_SPAWN_KEY = 2800


def _write_subject(root, n_photos, seed, experiments, path):
    """The subject folder and photos of ``cr`` under ``root``; its index entries."""
    from lilium.io.jsonio import write_json
    from lilium.synthetic import dataset as _dataset
    from lilium.synthetic.photos import CameraRanges
    from lilium.synthetic.subjects import write_subject

    subjects = cranium_subject(path)
    factory = _factory(subjects)
    seq = np.random.SeedSequence(seed, spawn_key=(CRANIUM_SPAWN_KEY,))
    task = (str(root), SUBJECT_ID, seq, n_photos, tuple(experiments), CameraRanges(), factory)
    task += (write_subject, False, 0.0)
    entry, photo_entries = _dataset._generate_subject(task)
    entry["source"] = "Cranium CT (benchmarks/datasets/cranium_case.py)"
    write_json(
        Path(root) / entry["path"] / "cranium.json",
        {
            "source": "InVesalius example Cranium.inv3 (Debian invesalius-examples), "
            "benchmarks/datasets/cranium_case.py (rules: cranium_landmarks.py)",
            "frame": "mm; x = subject's left, y = up, z = anterior",
            "skull_frame_from_lps": {
                "rotation": LPS_TO_SKULL,
                "origin_lps_mm": subjects["_origin_lps"],
            },
            "removed_voxels": subjects["_removed_voxels"],
            "sanity_mm": {
                name: {"value": value, "adult_range": [lo, hi]}
                for name, (value, lo, hi) in subjects["_sanity"].items()
            },
            "ct_import": subjects["_record"],
        },
    )
    return entry, photo_entries


def build_cranium_dataset(out_dir, n_photos=3, seed=0, experiments=("A", "B", "C"), data=None):
    """A dataset of the Cranium subject only (``dataset.json`` in the generator's format).

    Parameters
    ----------
    out_dir : path
    n_photos : int
        Frontal photos, as many lateral ones (left/right alternating).
    seed : int
    experiments : sequence of {"A", "B", "C"}
    data : path, optional
        ``Cranium.inv3`` or its folder (default ``LILIUM_CRANIUM``,
        ``../shared/data/cranium`` or the installed Debian path).

    Returns
    -------
    Path or None
        ``out_dir``; None when the CT is absent (nothing written).
    """
    from lilium.io.jsonio import write_json

    if data_path(data) is None:
        return None
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    entry, photo_entries = _write_subject(out, n_photos, seed, experiments, data)
    index = dataset_index(seed, n_photos, experiments, [entry], photo_entries)
    index["cranium"] = {
        "subjects": [SUBJECT_ID],
        "note": "real-anatomy case from InVesalius' Cranium CT "
        "(benchmarks/datasets/cranium_case.py); "
        "the skull has no mandible (never scanned) and a defect of the right frontal bone",
    }
    index["incomplete"] = {
        "no_mandible_share": 1.0,
        "subjects_without_mandible": [SUBJECT_ID],
        "drop_landmark_rate": 0.0,
    }
    write_json(out / "dataset.json", index)
    return out


def ensure_dataset(folder, n_photos=6, seed=0, data=None):
    """The Cranium dataset at ``folder``, built there first if it has no ``dataset.json``
    (:func:`build_cranium_dataset`); None when the CT is absent."""
    folder = Path(folder)
    if (folder / "dataset.json").is_file():
        return folder
    return build_cranium_dataset(folder, n_photos=n_photos, seed=seed, data=data)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="cranium-case", help="dataset folder to write")
    parser.add_argument("--photos", type=int, default=3, help="frontal (and lateral) photos")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--data", help=f"{FILE_NAME} or its folder (default {DEFAULT_DATA})")
    parser.add_argument(
        "--fetch",
        metavar="CACHE_DIR",
        help=f"apt-get download invesalius-examples into CACHE_DIR, extract {FILE_NAME} there "
        "and build from it",
    )
    args = parser.parse_args(argv)
    data = args.data
    if args.fetch:
        data = fetch(args.fetch)
        print(f"{FILE_NAME} -> {data}")
    out = build_cranium_dataset(args.out, args.photos, args.seed, data=data)
    if out is None:
        print(f"no {FILE_NAME} at {data or DEFAULT_DATA}: nothing built", file=sys.stderr)
        return 0
    print(f"cranium dataset -> {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
