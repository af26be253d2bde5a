"""A real-anatomy benchmark case from the headsq CT (issue 27): subject folders and photos.

A script and a module: other benchmarks import :func:`build_headsq_dataset` (a stand-alone
dataset of the headsq subjects) or :func:`add_headsq_subjects` (the headsq subjects appended
to an existing generated dataset); both return None when the CT is absent. Run::

    PYTHONPATH=src .venv/bin/python benchmarks/datasets/headsq_case.py --out headsq-case --photos 3

The subjects come from ``benchmarks/datasets/headsq_ct.py`` (the CT and its data folder, the
volume edits, ``lilium.ct.import_ct`` and the turn into the generator's skull frame), their
landmarks from the rules of ``benchmarks/datasets/headsq_landmarks.py``. Built here, with the
generator's own code (``lilium.synthetic.dataset``: cameras drawn from ``CameraRanges``, the
render, visibility, face mask, chin-jaw curve, Exp. B/C noise and the five perturbed axes sets):
the photos, the same for the complete and the mandible-less variant (the same person and seed:
identical photos), so each headsq photo is solved against both skulls; the subject folders and
``dataset.json``.

Subjects: ``hq`` (complete skull) and ``hq_nm`` (the same head, skull without its mandible;
``"mandible": false`` in ``dataset.json`` and ``subject.json``, the mandible's landmarks under
``removed_landmarks``). Both are one person: in an identification run keep one of them
(``variants``), or the photos of one count as negative pairs of the other.
"""

import argparse
import sys
from pathlib import Path

import numpy as np

from headsq_ct import DEFAULT_DATA, LPS_TO_SKULL, data_dir, headsq_subjects

#: Subject ids and whether the skull keeps its mandible.
VARIANTS = {"hq": True, "hq_nm": False}


# -- dataset ----------------------------------------------------------------------------------
#: ``SeedSequence(seed, spawn_key=(HEADSQ_SPAWN_KEY,))`` draws the headsq photos: apart from the
#: generated subjects' streams, and the same for both variants (identical photos).
HEADSQ_SPAWN_KEY = 2700


def _factory(subjects):
    def factory(subject_id, rng=None, mandible=True):
        del rng
        subject = subjects[subject_id]
        assert subject.mandible == mandible
        return subject

    return factory


def _write_subjects(root, n_photos, seed, experiments, variants, path):
    """Subject folders and photos of the headsq variants under ``root``; index entries."""
    from lilium.io.jsonio import write_json
    from lilium.synthetic import dataset as _dataset
    from lilium.synthetic.photos import CameraRanges
    from lilium.synthetic.subjects import write_subject

    subjects = headsq_subjects(path)
    factory = _factory(subjects)
    entries, photos = [], []
    for sid in variants:
        seq = np.random.SeedSequence(seed, spawn_key=(HEADSQ_SPAWN_KEY,))
        task = (str(root), sid, seq, n_photos, tuple(experiments), CameraRanges(), factory)
        task += (write_subject, VARIANTS[sid], 0.0)
        entry, photo_entries = _dataset._generate_subject(task)
        entry["source"] = "headsq CT (benchmarks/datasets/headsq_case.py)"
        write_json(
            Path(root) / entry["path"] / "headsq.json",
            {
                "source": "headsq CT, benchmarks/datasets/headsq_case.py "
                "(rules: headsq_landmarks.py)",
                "frame": "mm; x = subject's left, y = up, z = anterior",
                "skull_frame_from_lps": {
                    "rotation": LPS_TO_SKULL,
                    "origin_lps_mm": subjects["_origin_lps"],
                },
                "ct_import": subjects["_record"],
            },
        )
        entries.append(entry)
        photos.extend(photo_entries)
    return entries, photos


def build_headsq_dataset(
    out_dir, n_photos=3, seed=0, experiments=("A", "B", "C"), variants=tuple(VARIANTS), data=None
):
    """A dataset of the headsq subjects only (``dataset.json`` in the generator's format).

    Parameters
    ----------
    out_dir : path
    n_photos : int
        Frontal photos per subject, as many lateral ones (left/right alternating).
    seed : int
    experiments : sequence of {"A", "B", "C"}
    variants : sequence of {"hq", "hq_nm"}
        ``hq`` complete skull, ``hq_nm`` without the mandible (same photos).
    data : path, optional
        The headsq folder (default ``LILIUM_HEADSQ`` or ``../shared/data/headsq``).

    Returns
    -------
    Path or None
        ``out_dir``; None when the CT is absent (nothing written).
    """
    from lilium.io.jsonio import write_json

    if data_dir(data) is None:
        return None
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    subjects, photo_entries = _write_subjects(out, n_photos, seed, experiments, variants, data)
    index = dataset_index(seed, n_photos, experiments, subjects, photo_entries)
    index["headsq"] = _index_note(variants)
    if "hq_nm" in variants:
        index["incomplete"] = {
            "no_mandible_share": sum(not VARIANTS[v] for v in variants) / len(variants),
            "subjects_without_mandible": [v for v in variants if not VARIANTS[v]],
            "drop_landmark_rate": 0.0,
        }
    write_json(out / "dataset.json", index)
    return out


def dataset_index(seed, n_photos, experiments, subjects, photo_entries):
    """The fields of a generated ``dataset.json`` for these subject and photo entries (the
    generator's format; a real-anatomy case adds its own note)."""
    from lilium.synthetic import noise, photos
    from lilium.synthetic.photos import CameraRanges

    return {
        "format": "lilium-synthetic-dataset",
        "version": 1,
        "seed": seed,
        "n_subjects": len(subjects),
        "n_photos_per_view": n_photos,
        "experiments": list(experiments),
        "camera_ranges": CameraRanges().as_dict(),
        "min_visible_landmarks": photos.MIN_VISIBLE_LANDMARKS,
        "priors": {
            "focal_fraction": photos.PRIOR_FOCAL_FRACTION,
            "scd_fraction": photos.PRIOR_SCD_FRACTION,
            "head_rotation": "true rotation",
            "head_tolerance_deg": photos.PRIOR_HEAD_TOLERANCE_DEG,
        },
        "noise": {
            "landmark_px": noise.LANDMARK_NOISE_PX,
            "axis_deg": noise.AXIS_NOISE_DEG,
            "n_axes_sets": noise.N_AXES_SETS,
        },
        "subjects": subjects,
        "photos": photo_entries,
    }


def _index_note(variants):
    return {
        "subjects": list(variants),
        "note": "real-anatomy case from the headsq CT (benchmarks/datasets/headsq_case.py); "
        "hq and hq_nm "
        "are one person (same photos), so one is a negative pair of the other's photos",
    }


def add_headsq_subjects(dataset_dir, n_photos=None, seed=None, variants=("hq",), data=None):
    """Append headsq subjects and their photos to an existing generated dataset.

    ``n_photos``, ``seed`` and the experiments default to the dataset's own. The index gains
    the subjects, their photos and a ``"headsq"`` note; subjects already there are replaced.

    Returns
    -------
    Path or None
        ``dataset_dir``; None when the CT is absent (nothing changed).
    """
    from lilium.io.jsonio import read_json, write_json

    if data_dir(data) is None:
        return None
    root = Path(dataset_dir)
    index = read_json(root / "dataset.json")
    n_photos = index.get("n_photos_per_view", 3) if n_photos is None else n_photos
    seed = index.get("seed", 0) if seed is None else seed
    experiments = index.get("experiments", ["A", "B", "C"])
    subjects, photo_entries = _write_subjects(root, n_photos, seed, experiments, variants, data)
    index["subjects"] = [s for s in index["subjects"] if s["id"] not in variants] + subjects
    index["photos"] = [p for p in index["photos"] if p["subject"] not in variants]
    index["photos"] += photo_entries
    index["n_subjects"] = len(index["subjects"])
    index["headsq"] = _index_note(variants)
    if any(not VARIANTS[v] for v in variants):
        inc = index.setdefault(
            "incomplete", {"no_mandible_share": 0.0, "subjects_without_mandible": []}
        )
        inc.setdefault("drop_landmark_rate", 0.0)
        lost = set(inc["subjects_without_mandible"]) | {v for v in variants if not VARIANTS[v]}
        inc["subjects_without_mandible"] = sorted(lost)
        inc["no_mandible_share"] = len(lost) / len(index["subjects"])
    write_json(root / "dataset.json", index)
    return root


def sfo_problems_from_dataset(root, experiment="C", axes_set=1, subjects=None):
    """POSEST-SFO problems of the positive pairs of a dataset on disk (``bench_posest --sfo``).

    What POSEST-SFO hands POSEST for each photo of ``subjects`` (default all) against its own
    skull: the photo's marked landmarks of ``experiment`` and the cranial landmarks pushed by the
    mean depths along the axes set ``axes_set`` (Exp. C; the folder's true axes for A/B), as
    ``sfo_problems.SfoProblem`` (scored by BPE over every true facial landmark).

    Returns
    -------
    list of sfo_problems.SfoProblem
    """
    from lilium.casework.build import read_photo, read_skull
    from lilium.geometry.camera import Camera
    from lilium.io.jsonio import read_json
    from lilium.methods.pairs import correspondences
    from lilium.methods.posest_sfo import mean_depth_landmarks
    from sfo_problems import SfoProblem

    root = Path(root)
    index = read_json(root / "dataset.json")
    entries = {s["id"]: s for s in index["subjects"]}
    problems = []
    for photo_entry in index["photos"]:
        sid = photo_entry["subject"]
        if subjects is not None and sid not in subjects:
            continue
        folder = root / entries[sid]["path"]
        axes = None
        if experiment == "C":
            axes = folder / entries[sid]["axes_C"][axes_set - 1]
        skull = read_skull(folder, axes_path=axes)
        photo_dir = root / photo_entry["paths"][experiment]
        photo = read_photo(photo_dir, load_image=False)
        truth = read_json(photo_dir / "photo.json")["ground_truth"]
        facial = read_json(folder / "facial_landmarks.json")["landmarks"]
        names = sorted(set(facial) & set(truth["landmarks_noise_free"]))
        corr = correspondences(skull, photo)
        camera = Camera.from_rt(
            np.asarray(truth["skull2cam"])[:3, :3],
            np.asarray(truth["skull2cam"])[:3, 3],
            truth["focal_px"],
            truth["principal_point_px"],
        )
        problems.append(
            SfoProblem(
                photo_id=photo_entry["id"],
                view="frontal" if photo_entry["view"] == "frontal" else "lateral",
                image_size_wh=tuple(photo.image_size_wh),
                uv_px=corr.uv_px,
                points_mm=mean_depth_landmarks(corr),
                facial_true_mm=np.array([facial[n] for n in names]),
                uv_true_px=np.array([truth["landmarks_noise_free"][n] for n in names]),
                camera=camera,
            )
        )
    return problems


def ensure_dataset(folder, n_photos=6, seed=0, data=None):
    """The headsq dataset at ``folder``, built there first if it has no ``dataset.json``
    (:func:`build_headsq_dataset`); None when the CT is absent."""
    folder = Path(folder)
    if (folder / "dataset.json").is_file():
        return folder
    return build_headsq_dataset(folder, n_photos=n_photos, seed=seed, data=data)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="headsq-case", help="dataset folder to write")
    parser.add_argument("--add-to", help="append to this generated dataset instead")
    parser.add_argument("--photos", type=int, default=3, help="frontal (and lateral) per subject")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS))
    parser.add_argument("--data", help="headsq folder (default ../shared/data/headsq)")
    args = parser.parse_args(argv)
    if args.add_to:
        out = add_headsq_subjects(args.add_to, args.photos, args.seed, args.variants, args.data)
    else:
        out = build_headsq_dataset(
            args.out, args.photos, args.seed, variants=args.variants, data=args.data
        )
    if out is None:
        print(f"no headsq CT at {args.data or DEFAULT_DATA}: nothing built", file=sys.stderr)
        return 0
    print(f"headsq dataset -> {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
