"""Identification over a results database (docs/method/identification.md): every stored SFO's terms,
the
decisions (one photo; a frontal + lateral pair), their calibration and its validation.

The terms of an SFO are stored by the runner in its ``result`` JSON
(``"identification_terms"``); for a database written before that, they are computed here
from the dataset the database was run on (``meta.config.dataset``), reading each skull and
photo once.

**Decisions** (the keys of a calibration, ``"<method>/<variant>/<decision>"``):

- ``frontal``, ``lateral``: one photo, one SFO;
- ``pair``: a person's frontal and lateral photo, two separate SFOs against one skull, taken
  together by one likelihood: the landmark term stacks both photos' residuals of each
  landmark with **one shared soft tissue** (:func:`lilium.identification.terms.landmark_chi2`),
  the other terms add up; calibrated as a model of its own;
- ``pair_sum``: the same two SFOs' cross-validated log10 LRs added and calibrated as one
  decision: a logistic regression on their sum
  (:data:`~lilium.identification.calibration.VIEWS_TERMS`), fitted on out-of-fold
  single-photo LRs, so on LRs like a new case's (stacking). Added alone they would count the
  photos as independent evidence, which they are not (they share the soft tissue); the fitted
  slope and offset calibrate the combination instead (for Lilium the slope came out above 1:
  each photo's model is conservative). Measured beside ``pair`` and beside the plain sum: for
  Lilium better than both, for POSEST-SFO level with the plain sum
  (docs/decisions/0014-identification-several-photos.md); it is
  what a case with one frontal and one lateral photo reports (:mod:`lilium.casework.identify`);
- ``joint``: a joint SFO (docs/method/joint.md) of the pair: its shared soft tissue and two cameras.
"""

import hashlib
import json
from collections import defaultdict
from pathlib import Path

import numpy as np

from ..casework.build import read_photo, read_skull
from ..geometry.camera import Camera
from ..identification.calibration import (
    CALIBRATED_TERMS,
    VIEWS_LOG10_LR,
    VIEWS_RIDGE,
    VIEWS_TERMS,
    cross_validated,
    fit,
    performance,
    ridge_for,
    subject_splits,
)
from ..identification.cohort import Cohort
from ..identification.score import LATE_TERMS, identification_terms, pll_face, with_late_terms
from ..identification.terms import TERM_NAMES, eye_corner_px
from ..io.calibration import shipped_cohort
from ..methods.pairs import correspondences
from ..synthetic.subjects import axes_on_skull, make_subjects
from .config import view_group
from .store import COLUMNS, ResultStore, task_key

#: Key of an SFO's identification terms in its stored ``result`` JSON (the runner writes
#: them; ``_joint``: a joint SFO's decision over both photos, on its frontal row).
TERMS_KEY = "identification_terms"


#: Cohort terms of the photos a worker process has scored (they describe the photo; an
#: experiment scores every skull against each photo), emptied when it reaches
#: :data:`COHORT_CACHE` entries.
_COHORT_TERMS = {}
COHORT_CACHE = 4096


def with_terms(row, skull, photos, singles, facial_landmarks_mm, rows, key=TERMS_KEY):
    """Add the identification terms of one decision to a row's ``result`` JSON (under
    ``key``; nothing for a failed SFO): ``lilium calibrate`` and ``lilium report`` read them
    instead of reading the skull and photos again
    (:func:`lilium.identification.score.identification_terms`). ``rows`` are the photos' own
    rows, whose skull raster and P_pll (:func:`row_image`) are not computed again.
    """
    if not all(singles) or not row.get("result"):
        return row
    cameras = [s.camera for s in singles]
    data = json.loads(row["result"])
    data[key] = identification_terms(
        skull,
        photos,
        cameras,
        facial_landmarks_mm,
        image=[row_image(r, skull, p, c) for r, p, c in zip(rows, photos, cameras, strict=True)],
        cohort=shipped_cohort(),
        cohort_cache=_COHORT_TERMS,
    )
    if len(_COHORT_TERMS) >= COHORT_CACHE:
        _COHORT_TERMS.clear()
    row["result"] = json.dumps(data)
    return row


def row_image(row, skull, photo, camera):
    """``(outside_fraction, pll_face)`` of a stored row from its own skull raster
    (``outside_px``, ``skull_px``) and P_pll (computed only when the row has none); None when
    the row has no raster (no face mask)."""
    if row.get("skull_px") is None:
        return None
    eye_px = eye_corner_px(camera, correspondences(skull, photo).cranial_mm)
    pll = row["p_pll"] / eye_px if row.get("p_pll") is not None else None
    if pll is None:
        pll = pll_face(skull, photo, camera, eye_px)
    outside = row["outside_px"] / row["skull_px"] if row["skull_px"] else 1.0
    return outside, pll


class DatasetInputs:
    """Skulls (with a task's axes set) and photos of a generated dataset, read once each, by
    the paths ``dataset.json`` gives (as the experiment runner reads them)."""

    def __init__(self, root):
        self.root = Path(root)
        index = json.loads((self.root / "dataset.json").read_text())
        self.subjects = {s["id"]: s for s in index["subjects"]}
        self.photo_paths = {p["id"]: p["paths"] for p in index["photos"]}
        self._skulls, self._photos = {}, {}

    def skull(self, subject, experiment, axes_set):
        key = (subject, experiment, axes_set)
        if key not in self._skulls:
            entry, axes = self.subjects[subject], None
            if experiment == "C":
                names = entry.get("axes_C", [])
                if not 1 <= axes_set <= len(names):
                    raise ValueError(f"subject {subject}: no perturbed axes set {axes_set}")
                axes = str(self.root / entry["path"] / names[axes_set - 1])
            self._skulls[key] = read_skull(self.root / entry["path"], axes_path=axes)
        return self._skulls[key]

    def photo(self, photo, experiment):
        key = (photo, experiment)
        if key not in self._photos:
            folder = self.root / self.photo_paths[photo][experiment]
            self._photos[key] = read_photo(folder, load_image=False)
        return self._photos[key]


def stored_rows(db):
    """Every row of a results database with its parsed ``result`` (``row["data"]``).

    Raises
    ------
    ValueError
        A row whose ``result`` is not a JSON object, or whose camera or stored terms cannot be
        read, naming the database and the row.
    """
    with ResultStore(db, read_only=True) as store:
        rows = [dict(r) for r in store.rows(list(COLUMNS), with_id=True)]
        config = store.get_meta("config")
    for r in rows:
        r["data"] = _stored_result(db, r.pop("id"), r.get("result"))
    return rows, (config or {}).get("dataset")


def _stored_result(db, row_id, text):
    """The ``result`` JSON of the row of id ``row_id``, parsed and checked (None when empty)."""

    def damaged(what):
        return ValueError(
            f"{db}: row {row_id} holds {what}; the database was edited or damaged: restore it, "
            "or delete that row (lilium experiment then runs its SFO again)"
        )

    if text is None or text == "":
        return None
    try:
        data = json.loads(text)
    except (TypeError, ValueError, RecursionError):
        raise damaged("a result that is not valid JSON") from None
    if not isinstance(data, dict):
        raise damaged("a result that is not a JSON object")
    if data.get("camera") is not None:
        try:
            Camera.from_dict(data["camera"])
        except ValueError as exc:
            raise damaged(f"an unreadable camera ({exc})") from None
    for key in (TERMS_KEY, TERMS_KEY + "_joint"):
        terms = data.get(key)
        if terms is not None and not (
            isinstance(terms, dict)
            and all(
                v is None or (isinstance(v, (int, float)) and not isinstance(v, bool))
                for v in terms.values()
            )
        ):
            raise damaged(f"{key} that are not numbers by name")
    return data


#: What ``lilium calibrate`` writes in its output folder.
OUTPUT_FILES = ("calibration.json", "calibration.csv", "tippett.png")


def check_databases(dbs, out_dir, dataset=None):
    """Refuse, before anything is read or written, a database given twice (its SFOs would
    count twice, as other people's), one with no SFO, one ``out_dir`` would write over, and a
    ``dataset`` folder without its ``dataset.json``.

    Raises
    ------
    ValueError
        Naming the database or the option, and the fix.
    """
    seen = {}
    outputs = {(Path(out_dir) / name).resolve(): name for name in OUTPUT_FILES}
    for db in dbs:
        key = Path(db).resolve()
        if key in seen:
            raise ValueError(
                f"{db}: the same database as {seen[key]}; give each database once (its SFOs "
                "would count twice, as other people's)"
            )
        seen[key] = db
        if key in outputs:
            raise ValueError(
                f"--out {out_dir}: lilium calibrate writes {outputs[key]} there, over the "
                f"database {db}; give another --out"
            )
        with ResultStore(db, read_only=True) as store:
            if store.count() == 0:
                raise ValueError(
                    f"{db}: no SFO in this results database (its experiment stored none); "
                    "give a database lilium experiment has filled"
                )
    if dataset is not None and not (Path(dataset) / "dataset.json").is_file():
        raise ValueError(
            f"--dataset {dataset}: no dataset.json there; give the dataset folder the "
            "experiment ran on (the one holding dataset.json)"
        )


def _camera(row):
    data = row["data"]
    return Camera.from_dict(data["camera"]) if data and data.get("camera") else None


def _inputs(row, inputs):
    skull = inputs.skull(row["subject"], row["experiment"], row["axes_set"])
    return skull, inputs.photo(row["photo"], row["experiment"])


def _complete(terms):
    """Whether stored terms have every term of this version (older runs lack the cohort's)."""
    return terms is not None and all(name in terms for name in TERM_NAMES)


def _completed(terms, skull, photos, cameras):
    """Stored terms lacking only some of :data:`~lilium.identification.score.LATE_TERMS`,
    completed; else None."""
    if terms is None or not all(n in terms for n in TERM_NAMES if n not in LATE_TERMS):
        return None
    return with_late_terms(terms, skull, photos, cameras, cohort=shipped_cohort())


def single_terms(rows, inputs=None, cohort_cache=None):
    """The terms of every row (None for a failed SFO): stored, or computed with ``inputs``
    (also when the stored ones lack a term of this version)."""
    out = []
    cohort_cache = {} if cohort_cache is None else cohort_cache
    for r in rows:
        camera = _camera(r) if r["success"] else None
        if camera is None:
            out.append(None)
        elif _complete(r["data"].get(TERMS_KEY)):
            out.append(r["data"][TERMS_KEY])
        elif inputs is None:
            raise ValueError(
                "the database has no identification terms stored (or, from an older version, "
                "not the cohort terms) and its dataset is missing; give --dataset DIR"
            )
        else:
            skull, photo = _inputs(r, inputs)
            terms = _completed(r["data"].get(TERMS_KEY), skull, [photo], [camera])
            if terms is None:
                image = [row_image(r, skull, photo, camera)]
                terms = identification_terms(
                    skull, [photo], [camera], _facial(r), image=image, cohort=shipped_cohort(),
                    cohort_cache=cohort_cache,
                )
            out.append(terms)
    return out


def make_cohort(n_skulls, seed):
    """A :class:`~lilium.identification.cohort.Cohort` of ``n_skulls`` generated people
    (:func:`lilium.synthetic.subjects.make_subjects` at ``seed``): each skull's cranial
    landmarks and true soft-tissue axes."""
    subjects = make_subjects(n_skulls, seed=seed, prefix="cohort")
    return Cohort(
        tuple(dict(s.cranial_landmarks) for s in subjects),
        tuple(axes_on_skull(s) for s in subjects),
        {"generator": "lilium.synthetic.subjects.make_subjects", "skulls": int(n_skulls),
         "seed": int(seed)},
    )


def _facial(row):
    data = row["data"] or {}
    return {k: np.asarray(v, float) for k, v in (data.get("facial_landmarks_3d") or {}).items()}


def _run_key(r):
    return (r["experiment"], r["method"], r["variant"], r["axes_set"], r["repetition"])


def decisions(rows, terms, inputs=None, cohort_cache=None):
    """Every decision of the database with its terms (see the module docstring).

    Returns
    -------
    dict
        ``{(method, variant, decision): [pair, ...]}``, each pair a dict ``terms`` (None for a
        failed SFO), ``same``, ``person`` (the photo's subject), ``skull``, ``photo`` (the
        frontal photo of a pair), ``run`` (the run key).
    """
    out = defaultdict(list)
    by_person = defaultdict(dict)
    for r, t in zip(rows, terms, strict=True):
        group = view_group(r["view"])
        method = r["method"]
        entry = dict(
            terms=t,
            same=bool(r["positive"]),
            person=r["true_subject"],
            skull=r["subject"],
            photo=r["photo"],
            run=_run_key(r),
        )
        if method != "lilium-joint":
            out[(method, r["variant"], group)].append(entry)
        by_person[(_run_key(r), r["true_subject"], r["subject"])].setdefault(group, []).append(
            (r, t)
        )
    for (run, person, skull_id), groups in sorted(by_person.items()):
        # The k-th frontal with the k-th lateral photo, in photo-id order (the rows' key order)
        for (fr, ft), (lr, lt) in zip(groups.get("frontal", []), groups.get("lateral", []),
                                      strict=False):
            joint = run[1] == "lilium-joint"
            base = dict(same=person == skull_id, person=person, skull=skull_id,
                        photo=fr["photo"], run=run)
            if ft is None or lt is None:
                out[(run[1], run[2], "joint" if joint else "pair")].append(base | {"terms": None})
                if not joint:  # a failed SFO: ranked last, counted as failed
                    out[(run[1], run[2], "pair_sum")].append(base | {"parts": (ft, lt)})
                continue
            stored = (fr["data"] or {}).get(TERMS_KEY + "_joint") if joint else None
            if not _complete(stored):
                if inputs is None:
                    raise ValueError("pair terms need the dataset; give --dataset DIR")
                skull, pf = _inputs(fr, inputs)
                _, pl = _inputs(lr, inputs)
                cameras = [_camera(fr), _camera(lr)]
                stored = _completed(stored, skull, [pf, pl], cameras)
                if stored is None:
                    image = [(t["outside_fraction"], t["pll_face"]) for t in (ft, lt)]
                    stored = identification_terms(
                        skull, [pf, pl], cameras, _facial(fr), image=image,
                        cohort=shipped_cohort(), cohort_cache=cohort_cache,
                    )
            out[(run[1], run[2], "joint" if joint else "pair")].append(base | {"terms": stored})
            if not joint:
                out[(run[1], run[2], "pair_sum")].append(base | {"parts": (ft, lt)})
    return dict(out)


def validate(decision_pairs, folds=5, warped=None, names=CALIBRATED_TERMS):
    """Cross-validated log10 LR of every decision and its performance.

    ``pair_sum`` decisions add their two photos' cross-validated single-photo log10 LRs
    (``added``, with its ``performance_added`` on the pairs the calibrated sum scores) and
    calibrate the sum, nested (:func:`_nested_views_lr`).

    ``warped``: the decisions whose models are bi-Gaussianized (default :data:`WARPED`);
    ``names``: the terms' models' candidate features.

    Returns
    -------
    dict
        ``{key: {"log10_lr": ndarray, "performance": dict, ...}}``.
    """
    warped = WARPED if warped is None else warped
    out = {}
    for key, pairs in sorted(decision_pairs.items()):
        if key[2] == "pair_sum":
            continue
        lr = cross_validated(pairs, folds, names, warp=key[2] in warped)
        out[key] = {"log10_lr": lr, "performance": performance(lr, [p["same"] for p in pairs])}
    for key, pairs in decision_pairs.items():
        if key[2] != "pair_sum":
            continue
        same = [p["same"] for p in pairs]
        added = _pair_sum(pairs, decision_pairs, out, key)
        lr = _nested_views_lr(pairs, added, decision_pairs, key, folds, warped, names)
        scored = np.where(np.isfinite(lr), added, np.nan)
        out[key] = {"log10_lr": lr, "performance": performance(lr, same),
                    "added": added, "performance_added": performance(scored, same)}
    return out


def _nested_views_lr(pairs, added, decision_pairs, key, folds, warped, names):
    """Cross-validated calibrated sums of the ``pair_sum`` ``pairs``: for each subject fold
    ``k``, the views' model is fitted on sums of single-photo LRs that never saw fold ``k``
    (the two views' models cross-validated again within the other folds' pairs) and scores
    fold ``k``'s own sums ``added`` (P,) of its cross-validated LRs. NaN where an SFO failed,
    or a fold's training pairs lack a class."""
    out = np.full(len(pairs), np.nan)
    for training, test in subject_splits(pairs, folds):
        inner_pairs, inner_lr = {}, {}
        for view in ("frontal", "lateral"):
            view_key = (key[0], key[1], view)
            inner_pairs[view_key] = training(decision_pairs.get(view_key, []))
            inner_lr[view_key] = {
                "log10_lr": cross_validated(inner_pairs[view_key], folds, names,
                                            warp=view in warped)
            }
        train = training(pairs)
        inner = views_pairs(train, _pair_sum(train, inner_pairs, inner_lr, key))
        inner = [p for p in inner if p["terms"] is not None]
        if not test or {p["same"] for p in inner} != {True, False}:
            continue
        model = fit([p["terms"] for p in inner], [p["same"] for p in inner], VIEWS_TERMS,
                    ridge=VIEWS_RIDGE, warp=key[2] in warped)
        out[test] = model.log10_lr(
            [{VIEWS_LOG10_LR: added[i]} if np.isfinite(added[i]) else None for i in test]
        )
    return out


def views_pairs(pairs, added):
    """``pair_sum`` pairs with their one feature, the sum ``added`` (P,) of their views'
    log10 LRs, as ``terms`` (None where an SFO failed)."""
    return [
        p | {"terms": None if not np.isfinite(v) else {VIEWS_LOG10_LR: float(v)}}
        for p, v in zip(pairs, added, strict=True)
    ]


def _pair_sum(pairs, decision_pairs, validated, key):
    """Per pair: the frontal and the lateral SFO's cross-validated log10 LR, added (the
    person's first lateral photo against the same skull in the same run)."""
    frontal, lateral = {}, {}
    for view, table in (("frontal", frontal), ("lateral", lateral)):
        single = decision_pairs.get((key[0], key[1], view), [])
        lrs = validated.get((key[0], key[1], view), {}).get("log10_lr", [])
        for p, v in zip(single, lrs, strict=True):
            person = (p["run"], p["person"], p["skull"])
            if view == "frontal":
                table[person + (p["photo"],)] = v
            else:
                table.setdefault(person, v)
    out = []
    for p in pairs:
        person = (p["run"], p["person"], p["skull"])
        f = frontal.get(person + (p["photo"],), np.nan)
        out.append(f + lateral[person] if person in lateral else np.nan)
    return np.array(out, float)


#: The decisions whose logistic regression is bi-Gaussianized
#: (:func:`lilium.identification.calibration.bigaussian_warp`): the frontal + lateral sum
#: (since 2026-12-05). The warp moves LR 1 to where the two kinds of pair are misled equally
#: often; on 232 generated subjects (cross-validated, docs/decisions/0016-identification-features.md
#: "The worst landmark") it
#: takes Lilium's sum from 3.0 / 5.6 % misleading same / different-person pairs to 4.7 / 4.5 %
#: and its different-person wrong conclusions from 3.4 to 2.9 % (same-person ones 1.3 % both
#: ways), for a Cllr of 0.187 against 0.179: fewer wrong persons supported, no more wrong
#: exclusions. The single photos' models stay logistic (warped, their Cllr rose);
#: ``bench_identification`` prints both calibrations for every decision.
WARPED = frozenset({"pair_sum"})

#: Fewest same-person and different-person pairs a decision needs for a model of its own.
MIN_PAIRS = 10

#: The ``model`` of a ``pair_sum`` model's provenance (the terms' models keep the caller's).
VIEWS_MODEL = (
    "logistic regression on the sum of the frontal and the lateral photo's out-of-fold log10 "
    "LRs, bi-Gaussianized (lilium.experiments.calibrate)"
)


def fit_models(decision_pairs, provenance, log=print, validated=None):
    """One :class:`Calibration` per decision, fitted on every pair; a decision with fewer
    than :data:`MIN_PAIRS` pairs of either kind gets none (and says so). ``pair_sum`` models
    are fitted on the cross-validated single-photo LRs of :func:`validate` (``validated``;
    without it, none)."""
    models = {}
    for key, pairs in sorted(decision_pairs.items()):
        names, ridge, origin = CALIBRATED_TERMS, None, dict(provenance, decision=key[2])
        if key[2] == "pair_sum":
            if validated is None or key not in validated:
                continue
            pairs = views_pairs(pairs, validated[key]["added"])
            names, ridge, origin["model"] = VIEWS_TERMS, VIEWS_RIDGE, VIEWS_MODEL
        train = [p for p in pairs if p["terms"] is not None]
        same = [p["same"] for p in train]
        if min(sum(same), len(same) - sum(same)) < MIN_PAIRS:
            log(f"{'/'.join(key)}: {sum(same)} same- and {len(same) - sum(same)} "
                f"different-person pairs, fewer than {MIN_PAIRS}: no model")
            continue
        origin["ridge"] = ridge_for(sum(same)) if ridge is None else ridge
        models["/".join(key)] = fit(
            [p["terms"] for p in train], same, names, origin, origin["ridge"],
            warp=key[2] in WARPED, keep_ranges=key[2] != "pair_sum",
        )
    return models


def _content_key(rows):
    """A SHA-256 of a database's rows (their keys and results, in key order)."""
    digest = hashlib.sha256()
    for r in rows:
        digest.update(repr(task_key(r)).encode())
        digest.update(str(r.get("result") or "").encode())
    return digest.hexdigest()


def read_databases(dbs):
    """``[(db, rows, dataset root), ...]`` (:func:`stored_rows`) of every database, in the
    order of their contents (:func:`_content_key`), not of the command line: the pooled
    subject ids carry the index in this order (:func:`database_decisions`), and the subject
    folds are dealt from those ids, so the cross-validated figures must not depend on it."""
    read = [(db, *stored_rows(db)) for db in dbs]
    read.sort(key=lambda item: _content_key(item[1]))
    return read


def database_decisions(dbs, dataset=None, log=print):
    """The decisions of one or several results databases, pooled.

    Subjects of different databases are different people even when their ids agree (two
    dataset seeds both have an ``s01``), so each id is prefixed with its database's index, the
    databases taken in the order of their contents (:func:`_content_key`), whatever the order
    they are given in.

    Parameters
    ----------
    dbs : sequence of path
    dataset : path, optional
        The dataset of a database written without stored terms (default: the one its
        ``meta`` names).

    Returns
    -------
    decisions : dict
        As :func:`decisions`.
    rows : list of dict
        Every row, with its ``terms`` and the database index ``db``.
    """
    pooled, all_rows = defaultdict(list), []
    for k, (db, rows, root) in enumerate(read_databases(dbs)):
        root = dataset or root
        inputs = DatasetInputs(root) if root and Path(root, "dataset.json").is_file() else None
        cache = {}
        terms = single_terms(rows, inputs, cache)
        for key, pairs in decisions(rows, terms, inputs, cache).items():
            for p in pairs:
                p.update(person=f"{k}:{p['person']}", skull=f"{k}:{p['skull']}",
                         run=(k,) + tuple(p["run"]))
            pooled[key] += pairs
        for r, t in zip(rows, terms, strict=True):
            r.update(terms=t, db=k)
        all_rows += rows
        log(f"{db}: {len(rows)} SFOs")
    return dict(pooled), all_rows


def performance_table(validated):
    """Rows of ``calibration.csv``: one per decision, its cross-validated performance."""
    out = []
    for (method, variant, decision), v in sorted(validated.items()):
        out.append(dict(method=method, variant=variant, decision=decision, **v["performance"]))
    return out
