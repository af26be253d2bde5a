"""The demo: a realistic case built from the package's own generator, solved both ways.

One procedural subject (skull, face, landmarks, true soft tissue) and one frontal and one lateral
photo of it, with the realistic noise of the paper's Exp. C: landmarks moved by up to 5 px and the
soft-tissue directions given to the methods perturbed by up to 30 degrees. Both photos go through
``lilium case`` with POSEST-SFO and Lilium; as the truth is known, the demo also reports each
method's back-projection error (BPE, mm).
"""

from pathlib import Path

from .evaluation import score
from .io.results import read_result_camera
from .io.truth import read_ground_truth

#: Subjects and photos per view of the demo dataset.
DEMO_SUBJECTS, DEMO_PHOTOS = 1, 1


def build_demo_case(folder, seed=0):
    """Generate the demo's subject and photos.

    Returns
    -------
    subject_dir : Path
    photo_dirs : list of Path
        Frontal then lateral (Exp. C).
    axes_path : Path
        The perturbed soft-tissue axes the methods are given.
    """
    from .synthetic.dataset import generate_dataset

    folder = Path(folder)
    index = generate_dataset(
        folder, DEMO_SUBJECTS, DEMO_PHOTOS, seed=seed, experiments=("C",), workers=1
    )
    subject_dir = folder / index["subjects"][0]["path"]
    photo_dirs = [folder / p["paths"]["C"] for p in index["photos"]]
    return subject_dir, photo_dirs, subject_dir / "axes_C1.json"


def ground_truth_bpe(result_path, subject_dir, photo_dir):
    """BPE (mm) of a written ``result.json`` against the synthetic ground truth (NaN if failed)."""
    truth = read_ground_truth(photo_dir, subject_dir)
    return score(read_result_camera(result_path), truth).bpe_mm
