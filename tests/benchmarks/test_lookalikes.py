"""benchmarks/studies/lookalikes.py: the equal error rate that bounds any calibration's misleading
evidence, and the skulls' likeness."""

import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks" / "studies"))
import lookalikes  # noqa: E402


def test_equal_error_rate_bounds_every_threshold():
    rng = np.random.default_rng(3)
    same = np.r_[np.ones(200, bool), np.zeros(3000, bool)]
    lr = np.where(same, rng.normal(1.0, 1.0, same.size), rng.normal(-1.0, 1.0, same.size))
    eer = lookalikes.equal_error_rate(lr, same)
    # Two unit Gaussians two apart cross at 0: 15.9 % each side, to within sampling.
    assert abs(eer - 0.159) < 0.03, eer
    for t in np.linspace(-3, 3, 61):  # no threshold has both rates below it
        assert max(np.mean(lr[same] < t), np.mean(lr[~same] >= t)) >= eer - 1e-12
    separated = np.where(same, 2.0, -2.0)
    assert lookalikes.equal_error_rate(np.r_[separated, np.nan], np.r_[same, True]) == 0.0


def test_disparity_is_shape_only(tmp_path):
    """The same skull moved, turned and scaled is as alike as itself; another is not."""
    rng = np.random.default_rng(4)
    points = rng.normal(0.0, 50.0, (12, 3))
    turn = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    other = points + rng.normal(0.0, 5.0, points.shape)
    root = tmp_path / "ds"
    subjects = []
    for sid, pts in (("a", points), ("b", 1.3 * points @ turn.T + 7.0), ("c", other)):
        folder = root / "subjects" / sid
        folder.mkdir(parents=True)
        names = {f"l{i}": p.tolist() for i, p in enumerate(pts)}
        (folder / "cranial_landmarks.json").write_text(json.dumps({"landmarks": names}))
        subjects.append({"id": sid, "path": f"subjects/{sid}"})
    (root / "dataset.json").write_text(json.dumps({"subjects": subjects, "photos": []}))
    shapes = lookalikes.SkullShapes([])
    shapes.inputs["0"] = lookalikes.DatasetInputs(root)
    assert shapes.disparity("0:a", "0:b") < 1e-12
    assert shapes.disparity("0:a", "0:c") > 1e-3
    assert np.isnan(shapes.disparity("0:a", "1:a"))  # no dataset for database 1
