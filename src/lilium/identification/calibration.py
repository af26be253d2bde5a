"""From identification terms to a calibrated log10 likelihood ratio (docs/method/identification.md).

**Model.** Logistic regression on the transformed terms (:func:`features`): with ``x`` the
standardised features of one SFO, ``logit P(same | x) = w . x + b``, fitted by L2-penalised
maximum likelihood on same- and different-person SFOs, each class weighing half (the prior
of Cllr; with the pairs' own 1:20 prior the fit served the different-person pairs and
calibrated the same-person ones worse: Cllr 0.675 -> 0.654 frontal, 0.620 -> 0.561 lateral
on 40 generated subjects). Its log LR is the posterior log odds minus the prior log odds:
``log10 LR = (w . x + b - ln(n_same / n_diff)) / ln 10``, ``b`` stored with the training
prior. The weights of the misfit terms (:data:`AGAINST`) are held at or below 0, and a missing
term reads as neither kind of pair (:func:`neutral_value`).
A model is fitted per method, variant and view (``frontal``, ``lateral``, ``joint``), and one
per method and variant for a frontal and a lateral photo's separate SFOs: the same logistic
regression on one feature, the sum of the two photos' log10 LRs (:data:`VIEWS_TERMS`), which
calibrates their combination instead of assuming them independent. A model may also carry a
bi-Gaussianized warp of its LRs (:func:`bigaussian_warp`, Morrison 2024); the benchmark compares
it with the plain logistic regression, and the shipped models are plain
(docs/decisions/0015-identification-calibration-model.md).

**Bounds.** An LR is never more extreme than the data it was fitted on can support: it is
clipped to ``[-log10(n_same), log10(n_diff)]`` (a different-person score rarer than
``1 / n_diff`` cannot be measured with ``n_diff`` pairs), after the empirical lower and upper
bound idea of forensic LR validation. Small calibration sets make LRs vary (Ali et al. 2015):
the shipped models are fitted on hundreds of pairs and cross-validated by subject.

**Range.** A model is valid only where it was fitted: each keeps the range of every feature
it saw (:attr:`Calibration.ranges`: per class, same- and different-person pairs apart, the
0.5 % and 99.5 % quantiles of the feature; the range is the lowest of the two lower quantiles
to the highest of the two upper ones, so the best-fitting true pairs, a few per cent of all
pairs, are inside it). :meth:`Calibration.outside` names the features of a decision that lie
beyond it: the logistic regression would extrapolate there, and the decision does not get
support (:mod:`lilium.identification.conclusion`, ``outside_calibration``); its LR is computed
with each such feature at the edge of its range, not extrapolated (a real skull that fitted its
photo's landmarks better than any generated true pair did was otherwise read at the largest
LR). Real photos once sat 3-8 SD outside the generated range on two photo-level terms, and
every real skull, the wrong one included, got the largest LR.

**Validation.** :func:`cross_validated` scores every pair with a model that never saw its
subject (k folds of subjects; training leaves out every pair whose photo or skull belongs to
the fold). :func:`performance` gives Cllr, Cllr_min (after the pool-adjacent-violators
transform, the best any monotone calibration of the same scores could do) and the rates of
misleading evidence (same-person pairs with LR < 1, different-person pairs with LR > 1).

Maths only: reading and writing a model is :mod:`lilium.io.calibration`'s job.
"""

from dataclasses import dataclass, field

import numpy as np

from .conclusion import UNDETERMINED, level
from .terms import CALIBRATED_TERMS, DERIVED_TERMS

#: The features that measure a misfit (the landmarks', the outline's, the camera's against its
#: priors): their weights are held at or below 0 in the fit (:func:`fit`).
AGAINST = frozenset({"landmark_chi2", "outside_fraction", "pll_face", "prior_excess",
                     "landmark_tension", "outside_refit", "landmark_worst", "landmark_cnorm"})

#: The feature of :data:`VIEWS_TERMS`.
VIEWS_LOG10_LR = "views_log10_lr"

#: The feature transforms: heavy-tailed terms on a log scale.
FEATURES = {
    "landmark_chi2": lambda v: np.log(np.maximum(v, 1e-6)),
    "soft_tissue_z2": lambda v: np.log1p(np.maximum(v, 0.0)),
    "outside_fraction": lambda v: np.log1p(100.0 * np.maximum(v, 0.0)),
    "pll_face": lambda v: np.log1p(10.0 * np.maximum(v, 0.0)),
    "prior_excess": lambda v: np.log1p(10.0 * np.maximum(v, 0.0)),
    "cohort_mean": lambda v: v,
    "cohort_sd": lambda v: np.log(np.maximum(v, 1e-6)),
    "skull_mean": lambda v: v,
    "skull_sd": lambda v: np.log(np.maximum(v, 1e-6)),
    "landmark_snorm": lambda v: v,
    "landmark_refit": lambda v: np.log(np.maximum(v, 1e-6)),
    # A per-view refit cannot beat a stacked soft tissue's fit on every photo set: a gap
    # below 0 reads as none.
    "landmark_tension": lambda v: np.log1p(np.maximum(v, 0.0)),
    "outside_refit": lambda v: np.log1p(100.0 * np.maximum(v, 0.0)),
    "landmark_worst": lambda v: np.log(np.maximum(v, 1e-6)),
    "centred_mean": lambda v: v,
    "centred_sd": lambda v: np.log(np.maximum(v, 1e-6)),
    "landmark_cnorm": lambda v: v,
    # Not a term: the frontal and the lateral photo's log10 LRs added, the one feature of the
    # model that turns them into one decision's LR (:data:`VIEWS_TERMS`).
    VIEWS_LOG10_LR: lambda v: v,
}

#: The features of the model of a frontal and a lateral photo's separate SFOs
#: (``<method>/<variant>/pair_sum``, :mod:`lilium.experiments.calibrate`).
VIEWS_TERMS = (VIEWS_LOG10_LR,)

#: The terms' models' L2 penalty on their standardised weights is this over their number of
#: same-person pairs (:func:`ridge_for`): the fitted loss is a mean over each class, so a
#: prior worth a fixed number of pairs is a penalty that shrinks as the same-person pairs (the
#: rarer class) grow. Chosen on 152 generated subjects and the joint SFO's 12
#: (docs/decisions/0015-identification-calibration-model.md,
#: "On 152 subjects"): a fixed 1e-3 lowered the single photos' Cllr on 140 subjects against the
#: 1e-2 first shipped but overfitted the 12-subject joint model (Cllr 0.50 -> 0.76); scaled by
#: the pairs it keeps both.
RIDGE_PAIRS = 0.1


def ridge_for(n_same):
    """The terms' models' L2 penalty for a fit on ``n_same`` same-person pairs."""
    return RIDGE_PAIRS / max(int(n_same), 1)


#: The views' model's (one feature): with the terms' ridge (then 1e-2) its slope shrank and its
#: cross-validated Cllr rose from 0.25 to 0.30 on the 52 subjects it was first fitted on; a
#: trace of a penalty keeps the slope finite where a small calibration set separates.
VIEWS_RIDGE = 1e-4

#: Default number of subject folds of the cross-validation.
FOLDS = 5

#: The quantiles of a feature, per class, that bound the range a model was fitted on
#: (:attr:`Calibration.ranges`).
RANGE_QUANTILES = (0.005, 0.995)


def _column(terms_list, name):
    """The raw values ``(P,)`` of one term (stored, or :data:`DERIVED_TERMS`), NaN where
    missing."""
    get = DERIVED_TERMS.get(name, lambda t: t.get(name))
    values = (get(t) for t in terms_list)
    return np.array([np.nan if v is None else float(v) for v in values], float)


def features(terms_list, names, fill):
    """Feature matrix ``(P, len(names))`` of several term dictionaries.

    A term that is None (its input missing) or not finite takes ``fill[name]``, the
    feature's neutral value (:func:`neutral_value`); a landmark term of ``inf`` (a landmark
    behind the camera) takes the largest finite value instead.
    """
    X = np.empty((len(terms_list), len(names)))
    for j, name in enumerate(names):
        col = _column(terms_list, name)
        with np.errstate(invalid="ignore", divide="ignore"):
            col = FEATURES[name](col)
        col[np.isposinf(col)] = np.nanmax(np.where(np.isfinite(col), col, np.nan), initial=0.0)
        col[~np.isfinite(col)] = fill[name]
        X[:, j] = col
    return X


@dataclass(frozen=True)
class Calibration:
    """A fitted terms -> log10 LR model.

    Attributes
    ----------
    names : tuple of str
        The terms used (those that vary in the training data).
    centre, scale, fill : dict of str -> float
        Standardisation and the value of a missing term (:func:`neutral_value`).
    weights : dict of str -> float
        On the standardised features.
    intercept : float
    n_same, n_diff : int
        Training pairs.
    provenance : dict
        Where the model comes from (generator, pairs, budget, date...).
    warp : dict or None
        The bi-Gaussianized warp of the logistic regression's natural-log LR
        (:func:`bigaussian_warp`): ``knots`` and ``ln_lr``, increasing, interpolated linearly
        and held flat beyond the ends; None = the logistic regression's LR as it is.
    ranges : dict of str -> (float, float) or None
        Per feature, the range it was fitted on (:data:`RANGE_QUANTILES`, module docstring);
        None for a model stored without one (nothing is then said to lie outside it).
    """

    names: tuple
    centre: dict
    scale: dict
    fill: dict
    weights: dict
    intercept: float
    n_same: int
    n_diff: int
    provenance: dict = field(default_factory=dict)
    warp: dict | None = None
    ranges: dict | None = None

    @property
    def bounds(self):
        """``(lo, hi)``: the log10 LR range the training data supports."""
        return -float(np.log10(max(self.n_same, 1))), float(np.log10(max(self.n_diff, 1)))

    def log10_lr(self, terms_list):
        """log10 LR ``(P,)`` of term dictionaries; NaN for a None entry (a failed SFO). A
        feature beyond :attr:`ranges` counts as the range's edge."""
        keep = [i for i, t in enumerate(terms_list) if t is not None]
        out = np.full(len(terms_list), np.nan)
        if not keep:
            return out
        X = features([terms_list[i] for i in keep], self.names, self.fill)
        if self.ranges:  # no extrapolation: a feature beyond its range reads as its edge
            X = np.clip(X, *np.array([self.ranges[n] for n in self.names]).T)
        z = (X - [self.centre[n] for n in self.names]) / [self.scale[n] for n in self.names]
        logit = z @ [self.weights[n] for n in self.names] + self.intercept
        ln_lr = logit - np.log(self.n_same / self.n_diff)
        if self.warp is not None:
            ln_lr = np.interp(ln_lr, self.warp["knots"], self.warp["ln_lr"])
        out[keep] = np.clip(ln_lr / np.log(10.0), *self.bounds)
        return out

    def outside(self, terms):
        """The features of one decision's term dictionary that lie outside
        :attr:`ranges`: ``[(name, value, (lo, hi)), ...]`` in the model's order, empty when
        every feature is inside (or the model has no ranges). A missing term takes the
        neutral value and is never outside; one of ``inf`` (a landmark behind the camera)
        is."""
        if not self.ranges:
            return []
        out = []
        for name in self.names:
            value = _column([terms], name)
            with np.errstate(invalid="ignore", divide="ignore"):
                value = float(FEATURES[name](value)[0])
            lo, hi = self.ranges[name]
            if np.isnan(value) or np.isneginf(value):
                continue
            if not lo <= value <= hi:
                out.append((name, value, (lo, hi)))
        return out

    def to_dict(self):
        return {
            "names": list(self.names),
            "centre": self.centre,
            "scale": self.scale,
            "fill": self.fill,
            "weights": self.weights,
            "intercept": self.intercept,
            "n_same": self.n_same,
            "n_diff": self.n_diff,
            "provenance": self.provenance,
        } | ({} if self.warp is None else {"warp": self.warp}) | (
            {} if self.ranges is None else {"ranges": {n: list(v) for n, v in self.ranges.items()}}
        )

    @classmethod
    def from_dict(cls, data):
        """Inverse of :meth:`to_dict`; a ``ValueError`` (or ``KeyError``/``TypeError``) names
        what is wrong: every coefficient must be a finite JSON number (not text, not a
        boolean, not NaN), every ``scale`` above 0 and ``n_same``/``n_diff`` whole numbers of
        at least 1, or the model's LRs would be NaN or unbounded."""
        names = tuple(data["names"])
        unknown = [n for n in names if n not in FEATURES]
        if unknown:
            raise ValueError(f"unknown identification terms {unknown}; known: {list(FEATURES)}")
        coefficients = {
            key: {n: _finite(data[key][n], f"{key}.{n}") for n in names}
            for key in ("centre", "scale", "fill", "weights")
        }
        bad_scale = [n for n, v in coefficients["scale"].items() if v <= 0]
        if bad_scale:
            raise ValueError(f"scale.{bad_scale[0]} must be above 0")
        return cls(
            names,
            coefficients["centre"],
            coefficients["scale"],
            coefficients["fill"],
            coefficients["weights"],
            _finite(data["intercept"], "intercept"),
            _count(data["n_same"], "n_same"),
            _count(data["n_diff"], "n_diff"),
            dict(data.get("provenance", {})),
            _read_warp(data.get("warp")),
            _read_ranges(data.get("ranges"), names),
        )


def _finite(value, name):
    """A stored coefficient: a finite number (a JSON text or boolean is not one)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {str(value)[:40]!r}")
    return float(value)


def _count(value, name):
    """A stored number of training pairs: a whole number of at least 1."""
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ValueError(f"{name} must be a whole number of at least 1, got {str(value)[:40]!r}")
    return value


def _read_ranges(ranges, names):
    """Stored :attr:`Calibration.ranges` checked: a ``[lo, hi]`` of finite numbers, ``lo <=
    hi``, for every feature of the model (None stays None)."""
    if ranges is None:
        return None
    out = {}
    for name in names:
        if name not in ranges:
            raise ValueError(f"ranges.{name} is missing (every feature of the model needs one)")
        value = ranges[name]
        if not isinstance(value, (list, tuple)) or len(value) != 2:
            raise ValueError(f"ranges.{name} must be [lo, hi], got {str(value)[:40]!r}")
        lo, hi = (_finite(v, f"ranges.{name}") for v in value)
        if lo > hi:
            raise ValueError(f"ranges.{name} must have lo <= hi, got [{lo}, {hi}]")
        out[name] = (lo, hi)
    return out


def feature_ranges(X, same):
    """The range of each column of a feature matrix ``X`` ``(P, F)`` (module docstring):
    ``(F, 2)``, per class the :data:`RANGE_QUANTILES` of the finite values, the lower of the
    two lows to the higher of the two highs."""
    same = np.asarray(same, bool)
    out = np.empty((X.shape[1], 2))
    for j in range(X.shape[1]):
        quantiles = []
        for group in (same, ~same):
            col = X[group, j]
            col = col[np.isfinite(col)]
            if len(col):
                quantiles.append(np.quantile(col, RANGE_QUANTILES))
        quantiles = np.array(quantiles)
        out[j] = quantiles[:, 0].min(), quantiles[:, 1].max()
    return out


def _read_warp(warp):
    """A stored :attr:`Calibration.warp` checked (None stays None)."""
    if warp is None:
        return None
    knots = np.asarray(warp["knots"], float)
    ln_lr = np.asarray(warp["ln_lr"], float)
    if knots.ndim != 1 or knots.shape != ln_lr.shape or len(knots) < 2:
        raise ValueError("a calibration warp needs equal lists 'knots' and 'ln_lr' (2+ values)")
    if not (np.all(np.isfinite(knots)) and np.all(np.isfinite(ln_lr))):
        raise ValueError("a calibration warp's 'knots' and 'ln_lr' must be finite numbers")
    if np.any(np.diff(knots) <= 0) or np.any(np.diff(ln_lr) < 0):
        raise ValueError("a calibration warp must be increasing")
    return {"knots": knots.tolist(), "ln_lr": ln_lr.tolist()}


def neutral_value(column, same):
    """The value a missing feature takes: halfway between its same-person and its
    different-person median over the pairs where it is finite (the pooled median when a class
    has none). A missing term says nothing about the pair, so it reads as neither class; the
    pooled median, a different-person value, pushed such decisions towards exclusion.

    Parameters
    ----------
    column : ndarray of shape (P,)
        The feature (transformed), NaN or infinite where missing.
    same : ndarray of bool, shape (P,)
    """
    finite = np.isfinite(column)
    medians = [np.median(column[finite & m]) for m in (same, ~same) if (finite & m).any()]
    if len(medians) < 2:
        return float(np.median(column[finite]))
    return float(0.5 * (medians[0] + medians[1]))


def fit(terms_list, same, names=CALIBRATED_TERMS, provenance=None, ridge=None, warp=False,
        keep_ranges=True):
    """Fit a :class:`Calibration` on term dictionaries and their labels.

    Parameters
    ----------
    terms_list : list of dict
        One per SFO with a camera (no None).
    same : array_like of bool, shape (P,)
        True for a same-person pair.
    names : sequence of str
        Candidate terms; those missing in every pair or constant are left out.
    provenance : dict, optional
    ridge : float, optional
        L2 penalty on the standardised weights (default :func:`ridge_for` the same-person
        pairs).
    warp : bool
        Warp the logistic regression's LRs by :func:`bigaussian_warp` (fitted on the same
        pairs).
    keep_ranges : bool
        Record the features' ranges (:attr:`Calibration.ranges`). The views' model
        (:data:`VIEWS_TERMS`) keeps none: its one feature is a sum of LRs whose terms their own
        models range-check, and two photos at their models' bounds add up beyond any sum its
        out-of-fold training LRs reached.
    """
    same = np.asarray(same, bool)
    if same.all() or not same.any():
        raise ValueError("a calibration needs both same- and different-person pairs")
    ridge = ridge_for(same.sum()) if ridge is None else ridge
    raw = {}
    for name in names:
        col = _column(terms_list, name)
        with np.errstate(invalid="ignore", divide="ignore"):
            col = FEATURES[name](col)
        if np.isfinite(col).sum() >= 2 and np.nanstd(np.where(np.isfinite(col), col, np.nan)) > 0:
            raw[name] = col
    used = tuple(raw)
    fill = {n: neutral_value(raw[n], same) for n in used}
    X = features(terms_list, used, fill)
    # Measured on the terms as given (a missing term is not at its median for the range).
    ranges = feature_ranges(np.column_stack([raw[n] for n in used]), same)
    centre = X.mean(axis=0)
    scale = X.std(axis=0)
    scale[scale == 0] = 1.0
    Z = (X - centre) / scale
    y = same.astype(float)
    # Each class weighs half, as in Cllr: the fitted logit is then the log LR itself.
    weight = np.where(same, 0.5 / same.sum(), 0.5 / (~same).sum())

    def loss(p):
        logit = Z @ p[:-1] + p[-1]
        nll = np.sum(weight * (np.logaddexp(0.0, logit) - y * logit))
        residual = weight * (0.5 * (1.0 + np.tanh(0.5 * logit)) - y)
        grad = np.concatenate([Z.T @ residual, [np.sum(residual)]])
        return nll + ridge * p[:-1] @ p[:-1], grad + np.concatenate([2 * ridge * p[:-1], [0.0]])

    from scipy.optimize import minimize  # 0.12 s to import: fitting only, not scoring

    bounds = [(None, 0.0) if n in AGAINST else (None, None) for n in used] + [(None, None)]
    p = minimize(loss, np.zeros(len(used) + 1), jac=True, method="L-BFGS-B", bounds=bounds).x
    # Fitted with the classes weighing half each, the logit is the natural-log LR itself.
    warped = bigaussian_warp(Z @ p[:-1] + p[-1], same) if warp else None
    # Stored with the training prior's log odds, as :meth:`Calibration.log10_lr` reads it.
    p[-1] += np.log(same.sum() / (~same).sum())
    return Calibration(
        used,
        dict(zip(used, map(float, centre), strict=True)),
        dict(zip(used, map(float, scale), strict=True)),
        fill,
        dict(zip(used, map(float, p[:-1]), strict=True)),
        float(p[-1]),
        int(same.sum()),
        int((~same).sum()),
        dict(provenance or {}),
        warped,
        {n: (float(lo), float(hi)) for n, (lo, hi) in zip(used, ranges, strict=True)}
        if keep_ranges else None,
    )


def _bigaussian_cllr(sigma):
    """Cllr (bits) of a perfectly calibrated bi-Gaussian system: same-person natural-log LRs
    ``N(sigma^2 / 2, sigma^2)``, different-person ``N(-sigma^2 / 2, sigma^2)``."""
    x = np.linspace(-12.0, 12.0, 4001)
    density = np.exp(-0.5 * x * x) / np.sqrt(2.0 * np.pi)
    ln_lr = 0.5 * sigma * sigma + sigma * x
    return float(np.trapezoid(np.logaddexp(0.0, -ln_lr) * density, x) / np.log(2.0))


def bigaussian_warp(ln_lr, same):
    """The bi-Gaussianized calibration (Morrison, Law, Probability and Risk 2024) of natural-log
    LRs ``ln_lr`` (P,) that are already roughly calibrated (a logistic regression's).

    The perfectly calibrated bi-Gaussian system with the same Cllr as ``ln_lr`` has
    same-person log LRs ``N(sigma^2 / 2, sigma^2)`` and different-person ``N(-sigma^2 / 2,
    sigma^2)``; each value is sent to the quantile of that system's two-class mixture at which
    the pairs' own mixture has the same cumulative share, each class weighing half (``1 / (2 (n
    + 1))`` per pair, so no share reaches 0 or 1). The warp keeps the order of the pairs and
    moves LR 1 to where the two classes' error rates meet (the equal-error point), so a
    same-person pair is misled as often as a different-person one; a logistic regression's LR
    1 sits where the fitted line crosses, which need not be there.

    Returns
    -------
    dict
        ``knots`` (the distinct input values, increasing) and ``ln_lr`` (their warped
        natural-log LRs), as :attr:`Calibration.warp` reads them.
    """
    from scipy.optimize import brentq
    from scipy.special import ndtr

    ln_lr = np.asarray(ln_lr, float)
    same = np.asarray(same, bool)
    n1, n0 = int(same.sum()), int((~same).sum())
    c = cllr(ln_lr / np.log(10.0), same)
    c = min(max(c, 1e-4), 0.999)
    sigma = brentq(lambda s: _bigaussian_cllr(s) - c, 1e-3, 30.0)
    knots, inverse = np.unique(ln_lr, return_inverse=True)
    weight = np.where(same, 0.5 / (n1 + 1), 0.5 / (n0 + 1))
    share = np.cumsum(np.bincount(inverse, weights=weight))
    half = 0.5 * sigma * sigma
    grid = np.linspace(-half - 8.0 * sigma, half + 8.0 * sigma, 20001)
    mixture = 0.5 * ndtr((grid + half) / sigma) + 0.5 * ndtr((grid - half) / sigma)
    return {"knots": knots.tolist(), "ln_lr": np.interp(share, mixture, grid).tolist()}


def subject_folds(subjects, folds=FOLDS):
    """``{subject: fold}``: subjects in sorted order dealt to ``folds`` folds in turn."""
    return {s: i % folds for i, s in enumerate(sorted(set(subjects)))}


def subject_splits(pairs, folds=FOLDS):
    """The cross-validation's splits of ``pairs`` by subject: for each fold ``k``, ``(training,
    test)`` with ``training(items)`` the items (pairs of any decision on the same subjects)
    whose photo's subject and skull's subject are both outside fold ``k``, and ``test`` the
    indices of the ``pairs`` whose photo's subject is in it."""
    fold_of = subject_folds([p["person"] for p in pairs] + [p["skull"] for p in pairs], folds)
    for k in sorted(set(fold_of.values())):

        def training(items, k=k):
            return [p for p in items if fold_of[p["person"]] != k and fold_of[p["skull"]] != k]

        yield training, [i for i, p in enumerate(pairs) if fold_of[p["person"]] == k]


def cross_validated(pairs, folds=FOLDS, names=CALIBRATED_TERMS, ridge=None, warp=False):
    """Cross-validated log10 LR of every pair: each scored by a model that never saw its
    photo's subject (nor any pair with that subject's skull).

    Parameters
    ----------
    pairs : list of dict
        ``terms`` (dict or None for a failed SFO), ``same`` (bool), ``person`` (the photo's
        subject), ``skull`` (the skull's subject).

    Returns
    -------
    ndarray of shape (P,)
        NaN for a failed SFO, and for the pairs of a fold whose training pairs lack one of
        the two classes (too few pairs to calibrate).
    """
    out = np.full(len(pairs), np.nan)
    for training, test in subject_splits(pairs, folds):
        train = [p for p in training(pairs) if p["terms"] is not None]
        if not test or {p["same"] for p in train} != {True, False}:
            continue  # nothing to score, or too few pairs to fit: left NaN
        model = fit(
            [p["terms"] for p in train], [p["same"] for p in train], names, ridge=ridge, warp=warp
        )
        out[test] = model.log10_lr([pairs[i]["terms"] for i in test])
    return out


def cllr(log10_lr, same):
    """The log-likelihood-ratio cost (bits): 0 perfect, 1 = an uninformative system."""
    lr = np.asarray(log10_lr, float) * np.log(10.0)
    same = np.asarray(same, bool)
    c_same = np.mean(np.logaddexp(0.0, -lr[same])) / np.log(2.0)
    c_diff = np.mean(np.logaddexp(0.0, lr[~same])) / np.log(2.0)
    return 0.5 * (c_same + c_diff)


def pav_log10_lr(scores, same):
    """The pool-adjacent-violators log10 LR of ``scores`` (higher = more likely the same):
    the best monotone calibration of these very scores (for Cllr_min). Pairs of equal score
    are pooled first (one LR for all of them, from their share of same-person pairs), so the
    result does not depend on the order the pairs come in."""
    scores = np.asarray(scores, float)
    same = np.asarray(same, bool)
    from scipy.optimize import isotonic_regression

    _, inverse, counts = np.unique(scores, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    share = np.bincount(inverse, weights=same.astype(float)) / counts
    post = isotonic_regression(share, weights=counts.astype(float)).x[inverse]
    n1, n0 = same.sum(), (~same).sum()
    eps = 1e-12
    with np.errstate(divide="ignore"):
        return np.log10(np.clip(post, eps, 1 - eps) / np.clip(1 - post, eps, 1)) - np.log10(
            n1 / n0
        )


def performance(log10_lr, same):
    """Cllr, Cllr_min and the rates of misleading evidence of calibrated LRs.

    Pairs whose SFO failed (NaN) are left out and counted.

    Returns
    -------
    dict
        ``cllr``, ``cllr_min``, ``misleading_same`` (share of same-person pairs with
        log10 LR < 0), ``misleading_diff`` (different-person pairs with log10 LR > 0),
        ``wrong_conclusion_same`` / ``wrong_conclusion_diff`` (the shares whose LR falls in a
        band of the verbal scale that supports the other proposition: same-person pairs at
        "support for exclusion", log10 LR <= -0.5, and different-person pairs at "support",
        >= 0.5; :mod:`lilium.identification.conclusion`, before any cap), ``n_same``,
        ``n_diff``, ``failed``.
    """
    log10_lr = np.asarray(log10_lr, float)
    same = np.asarray(same, bool)
    ok = np.isfinite(log10_lr)
    v, s = log10_lr[ok], same[ok]
    if not s.any() or s.all():
        nan = float("nan")
        return dict(cllr=nan, cllr_min=nan, misleading_same=nan, misleading_diff=nan,
                    wrong_conclusion_same=nan, wrong_conclusion_diff=nan,
                    n_same=int(s.sum()), n_diff=int((~s).sum()), failed=int((~ok).sum()))
    band = np.array([level(x) for x in v])
    return {
        "cllr": float(cllr(v, s)),
        "cllr_min": float(cllr(pav_log10_lr(v, s), s)),
        "misleading_same": float(np.mean(v[s] < 0)) if s.any() else float("nan"),
        "misleading_diff": float(np.mean(v[~s] > 0)) if (~s).any() else float("nan"),
        "wrong_conclusion_same": float(np.mean(band[s] < UNDETERMINED)),
        "wrong_conclusion_diff": float(np.mean(band[~s] > UNDETERMINED)),
        "n_same": int(s.sum()),
        "n_diff": int((~s).sum()),
        "failed": int((~ok).sum()),
    }
