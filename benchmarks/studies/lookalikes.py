"""Where the misleading evidence falls: the separation's limit and look-alike skulls.

Two diagnostics of the cross-validated log10 LRs of every decision (``bench_identification``
prints them after the LR tables), neither a method:

- **the best any calibration could do**: the equal error rate of the LRs, the threshold at
  which as many same-person pairs fall below as different-person pairs above it (in-sample,
  on every pair). Any calibration that keeps the LRs' order puts "log10 LR = 0" at some
  threshold, so it cannot make both rates of misleading evidence lower than the equal error
  rate: where that misses a target, the separation of same- and different-person pairs is
  the limit, not the calibration;
- **look-alike skulls**: how alike the skull of a different-person pair is to the person's
  own, as the Procrustes disparity of their cranial landmarks (shape only: position, rotation
  and size removed; :func:`scipy.spatial.procrustes`, over the landmarks both skulls have),
  and how the misleading LRs (log10 LR > 0) share out between the nearest tenth of the pairs
  and the rest, with the rank correlation of the log10 LR with likeness. Needs the datasets
  the databases were run on (their ``meta``); a database without one is left out.
"""

import json
import sys
from pathlib import Path

import numpy as np
from scipy.spatial import procrustes
from scipy.stats import spearmanr

from lilium.experiments.calibrate import DatasetInputs, read_databases
from lilium.experiments.config import method_label

#: The share of different-person pairs counted as look-alikes (the most alike skulls).
NEAREST = 0.1


def equal_error_rate(log10_lr, same):
    """The smallest, over thresholds ``t``, of the larger of the share of same-person pairs
    with ``log10_lr < t`` and of different-person pairs with ``log10_lr >= t`` (NaN left
    out): both rates of misleading evidence of any order-keeping calibration of these LRs
    cannot be below it."""
    log10_lr, same = np.asarray(log10_lr, float), np.asarray(same, bool)
    ok = np.isfinite(log10_lr)
    v, s = log10_lr[ok], same[ok]
    t = np.unique(v)
    below = np.searchsorted(np.sort(v[s]), t, side="left") / s.sum()
    above = 1.0 - np.searchsorted(np.sort(v[~s]), t, side="left") / (~s).sum()
    return float(np.min(np.maximum(below, above)))


class SkullShapes:
    """Cranial landmarks of the pooled databases' subjects, read once each; a pooled id is
    ``"<database index>:<subject>"`` (:func:`lilium.experiments.calibrate.database_decisions`)."""

    def __init__(self, dbs):
        self.inputs = {}
        for k, (_db, _rows, root) in enumerate(read_databases(dbs)):
            if root and Path(root, "dataset.json").is_file():
                self.inputs[str(k)] = DatasetInputs(root)
        self._landmarks = {}

    def landmarks(self, pooled_id):
        """``{name: (3,) mm}`` of a pooled subject id, or None without its dataset."""
        if pooled_id not in self._landmarks:
            k, subject = pooled_id.split(":", 1)
            inputs = self.inputs.get(k)
            out = None
            if inputs is not None and subject in inputs.subjects:
                path = inputs.root / inputs.subjects[subject]["path"] / "cranial_landmarks.json"
                raw = json.loads(path.read_text())["landmarks"]
                out = {name: np.asarray(xyz, float) for name, xyz in raw.items()}
            self._landmarks[pooled_id] = out
        return self._landmarks[pooled_id]

    def disparity(self, a, b):
        """Procrustes disparity of two pooled subjects' skulls (0 = the same shape), NaN
        without both datasets."""
        la, lb = self.landmarks(a), self.landmarks(b)
        if la is None or lb is None:
            return float("nan")
        names = sorted(set(la) & set(lb))
        return float(procrustes(np.array([la[n] for n in names]),
                                np.array([lb[n] for n in names]))[2])


def print_lookalikes(dbs, decision_pairs, validated, file=sys.stdout):
    """One row per decision: the equal error rate of its LRs, and the
    different-person pairs' misleading LRs among the nearest tenth of skull pairs and the
    rest (``decision_pairs`` and ``validated`` as
    :func:`lilium.experiments.calibrate.validate` takes and gives them)."""
    shapes = SkullShapes(dbs)
    print("| decision | method | equal error rate | "
          "different pairs | misleading, nearest tenth / the rest | misleading on the nearest "
          "tenth | Spearman (log10 LR, likeness) |", file=file)
    print("|---|---|---|---|---|---|---|", file=file)
    for key in sorted(validated):
        pairs, lr = decision_pairs[key], np.asarray(validated[key]["log10_lr"], float)
        same = np.array([p["same"] for p in pairs])
        eer = equal_error_rate(lr, same)
        diff = np.flatnonzero(~same & np.isfinite(lr))
        d = np.array([shapes.disparity(pairs[i]["person"], pairs[i]["skull"]) for i in diff])
        keep = np.isfinite(d)
        cells = ["-"] * 4
        if keep.sum() >= 10:
            d, v = d[keep], lr[diff[keep]]
            near = d <= np.quantile(d, NEAREST)
            misleading = v > 0
            share = misleading[near].sum() / max(misleading.sum(), 1)
            rho = spearmanr(v, -d).statistic
            cells = [
                f"{len(d)}",
                f"{100 * misleading[near].mean():.1f} / {100 * misleading[~near].mean():.1f} %",
                f"{100 * share:.0f} %",
                f"{rho:.2f}",
            ]
        print(f"| {key[2]} | {method_label(key[0], key[1])} | {100 * eer:.1f} % | "
              f"{' | '.join(cells)} |", file=file)
