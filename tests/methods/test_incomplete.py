"""Incomplete skulls and photos: terms that cannot apply are switched off, not fatal
(docs/method/lilium.md), and the generator makes such cases (skulls without the mandible, unmarked
landmarks)."""

import json
import sqlite3
from dataclasses import replace

import numpy as np
import pytest

from lilium.casework.build import read_photo, read_skull
from lilium.cli.main import main
from lilium.experiments.report import write_report
from lilium.experiments.terms_off import terms_off_rows, terms_off_table
from lilium.fitness.camera_penalty import CameraPriors
from lilium.fitness.curves import face_curve_bounds, face_curve_from_mask, missing_curve_bounds
from lilium.geometry.camera import principal_point_of
from lilium.io.jsonio import read_json
from lilium.methods import SfoOptions, run_sfo
from lilium.methods.lilium import LiliumProblem
from lilium.methods.lilium_terms import (
    PllTerm,
    TermOff,
    image_terms,
    planned_terms_off,
    pll_off_reason,
    prior_terms_off,
)
from lilium.methods.registry import check_runnable
from lilium.optimisation.de import DEOptions
from lilium.synthetic import dataset as ds
from lilium.synthetic import incomplete
from lilium.synthetic.photos import CameraRanges
from lilium.synthetic.subjects import MANDIBLE_LANDMARKS
from lilium.synthetic.toyhead import make_toy_subject, write_toy_subject
from standin_case import toy_dataset

SMALL = CameraRanges(image_sizes=((640, 480), (800, 600)))
TINY_DE = DEOptions(population_size=8, max_generations=4)


def _generate(out, seed=5, **kw):
    return toy_dataset(out, seed, image_sizes=SMALL.image_sizes, experiments=("A", "C"), **kw)


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    """The same seed twice: complete skulls, and every skull without its mandible."""
    root = tmp_path_factory.mktemp("incomplete")
    full = _generate(root / "complete")
    jawless = _generate(root / "no_mandible", no_mandible_share=1.0)
    return root, full, jawless


def _case(root, name, view="frontal", exp="C"):
    index = read_json(root / name / "dataset.json")
    entry = next(p for p in index["photos"] if p["view"].startswith(view))
    subject_dir = root / name / "subjects" / entry["subject"]
    return subject_dir, root / name / entry["paths"][exp]


# -- the generator ------------------------------------------------------------------------------


def test_no_mandible_keeps_the_person_and_drops_the_jaw(pair):
    root, full, jawless = pair
    assert "incomplete" not in full and all("mandible" not in s for s in full["subjects"])
    assert jawless["incomplete"]["subjects_without_mandible"] == ["s01", "s02"]
    assert all(s["mandible"] is False for s in jawless["subjects"])
    for sid in ("s01", "s02"):
        a, b = root / "complete" / "subjects" / sid, root / "no_mandible" / "subjects" / sid
        lm_a = read_json(a / "cranial_landmarks.json")["landmarks"]
        lm_b = read_json(b / "cranial_landmarks.json")["landmarks"]
        assert set(lm_a) - set(lm_b) == set(MANDIBLE_LANDMARKS)
        assert all(lm_a[n] == lm_b[n] for n in lm_b)
        # The face and its true landmarks are the person's: unchanged.
        assert (a / "face.ply").read_bytes() == (b / "face.ply").read_bytes()
        assert read_json(a / "facial_landmarks.json") == read_json(b / "facial_landmarks.json")
        # The axes given to the methods: the skull's landmarks only, the same draws.
        for name in ("soft_tissue_axes.json", "axes_C1.json", "axes_C5.json"):
            ax_a, ax_b = read_json(a / name)["axes"], read_json(b / name)["axes"]
            assert set(ax_b) == set(ax_a) - set(MANDIBLE_LANDMARKS)
            assert all(ax_a[n] == ax_b[n] for n in ax_b)
        skull_a, skull_b = read_skull(a), read_skull(b)
        assert len(skull_b.faces) < len(skull_a.faces)
        used = skull_b.vertices_mm[np.unique(skull_b.faces)]
        front = used[used[:, 2] > 20]
        assert front[:, 1].min() > lm_a["pogonion"][1] + 5  # the chin's bone is gone
    # The photos are the same photos.
    for p_a, p_b in zip(full["photos"], jawless["photos"], strict=True):
        for exp in ("A", "C"):
            fa, fb = root / "complete" / p_a["paths"][exp], root / "no_mandible" / p_b["paths"][exp]
            assert read_json(fa / "photo.json") == read_json(fb / "photo.json")
            assert (fa / "image.png").read_bytes() == (fb / "image.png").read_bytes()
            assert (fa / "face_mask.png").read_bytes() == (fb / "face_mask.png").read_bytes()


def test_share_picks_a_seeded_whole_number_of_subjects():
    ids = [f"s{k:02d}" for k in range(10)]
    half = incomplete.mandible_less(ids, 0.5, 3)
    assert len(half) == 5 and half == incomplete.mandible_less(ids, 0.5, 3)
    assert half != incomplete.mandible_less(ids, 0.5, 4)
    assert len(incomplete.mandible_less(ids, 0.01, 3)) == 1
    assert incomplete.mandible_less(ids, 0.0, 3) == frozenset()
    assert incomplete.mandible_less(ids, 1.0, 3) == frozenset(ids)
    with pytest.raises(ValueError, match=r"no_mandible_share must be a number in \[0, 1\]"):
        incomplete.mandible_less(ids, 1.5, 3)


def test_unmarked_landmarks_keep_enough_pairs():
    visible = [f"p{k}" for k in range(8)] + ["cheilion_l", "cheilion_r"]
    pairable = set(visible[:8])
    assert incomplete.unmarked_landmarks(visible, pairable, 0.0, 1) == ()
    dropped = incomplete.unmarked_landmarks(visible, pairable, 0.99, 1)
    assert {"cheilion_l", "cheilion_r"} <= set(dropped)  # no pair: always droppable
    assert sum(1 for n in visible if n in pairable and n not in dropped) == 6
    some = incomplete.unmarked_landmarks(visible, pairable, 0.3, 7)
    assert some == incomplete.unmarked_landmarks(visible, pairable, 0.3, 7)
    assert list(some) == [n for n in visible if n in some]  # in the photo's order
    with pytest.raises(ValueError, match=r"drop_landmark_rate must be a number in \[0, 1\)"):
        incomplete.unmarked_landmarks(visible, pairable, 1.0, 1)


def test_dropped_landmarks_are_unmarked_in_every_experiment(tmp_path, pair):
    root, full, _ = pair
    index = _generate(tmp_path / "drop", drop_landmark_rate=0.5)
    again = _generate(tmp_path / "again", drop_landmark_rate=0.5)
    assert [p.get("unmarked_landmarks") for p in index["photos"]] == [
        p.get("unmarked_landmarks") for p in again["photos"]
    ]
    assert index["incomplete"]["drop_landmark_rate"] == 0.5
    assert sum(len(p.get("unmarked_landmarks", ())) for p in index["photos"]) > 0
    for entry, whole in zip(index["photos"], full["photos"], strict=True):
        unmarked = entry.get("unmarked_landmarks", [])
        for exp in ("A", "C"):
            rec = read_json(tmp_path / "drop" / entry["paths"][exp] / "photo.json")
            ref = read_json(root / "complete" / whole["paths"][exp] / "photo.json")
            assert set(rec["landmarks"]) == set(ref["landmarks"]) - set(unmarked)
            # The marked ones are the same noisy positions; the truth keeps them all.
            assert all(rec["landmarks"][n] == ref["landmarks"][n] for n in rec["landmarks"])
            assert (
                rec["ground_truth"]["landmarks_noise_free"]
                == (ref["ground_truth"]["landmarks_noise_free"])
            )
            assert rec["ground_truth"].get("unmarked_landmarks", []) == unmarked
            curve = tmp_path / "drop" / entry["paths"][exp] / "face_curve.json"
            bounds = set(face_curve_bounds(entry["view"]))
            assert curve.is_file() == (not bounds & set(unmarked))


def test_synth_cli_options(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(ds, "_default_subject_api", lambda: (make_toy_subject, write_toy_subject))
    argv = ["synth", "--out", str(tmp_path / "d"), "--subjects", "2", "--photos", "1"]
    argv += ["--workers", "1", "--experiments", "A", "--no-progress"]
    assert main(argv + ["--no-mandible-share", "0.5", "--drop-landmark-rate", "0.2"]) == 0
    out = capsys.readouterr().out
    assert "incomplete: 1 skull(s) without the mandible" in out
    index = read_json(tmp_path / "d" / "dataset.json")
    assert sum(1 for s in index["subjects"] if s.get("mandible") is False) == 1
    assert main(argv + ["--no-mandible-share", "2"]) == 2
    err = capsys.readouterr().err
    assert "--no-mandible-share" in err and "must be a number in [0, 1]" in err


# -- terms switched off ---------------------------------------------------------------------


def test_pll_off_without_the_mandible_on_frontal_photos_only(pair):
    root = pair[0]
    subject_dir, photo_dir = _case(root, "no_mandible", "frontal")
    skull, photo = read_skull(subject_dir), read_photo(photo_dir)
    centre = principal_point_of(photo.image_size_wh)
    with pytest.raises(TermOff, match="has no infradentale, mental_foramen_l, mental_foramen_r"):
        PllTerm(skull, photo, centre)
    skof, pll, off = image_terms(skull, photo, centre, True, True)
    assert skof is not None and pll is None and list(off) == ["p_pll"]
    assert "(no mandible?)" in off["p_pll"] and "chin-jaw" in off["p_pll"]
    # The forehead of a lateral photo needs no mandible.
    subject_dir, photo_dir = _case(root, "no_mandible", "lateral")
    lateral = read_photo(photo_dir)
    assert pll_off_reason(skull, lateral) == ""
    # A skull with its jaw whose infradentale and foramina lilium skull left as template points
    # (not used until confirmed): the message says so, not "no mandible".
    from dataclasses import replace

    subject_dir, photo_dir = _case(root, "complete", "frontal")
    whole = read_skull(subject_dir)
    gone = ("infradentale", "mental_foramen_l", "mental_foramen_r")
    automatic = replace(
        whole,
        landmarks_mm={n: p for n, p in whole.landmarks_mm.items() if n not in gone},
        landmark_sources=dict.fromkeys(whole.landmarks_mm, "located"),
    )
    why = pll_off_reason(automatic, read_photo(photo_dir))
    assert "lilium skull's template points" in why and "no mandible" not in why
    plain = replace(automatic, landmark_sources={})
    assert "no mandible" not in pll_off_reason(plain, read_photo(photo_dir))
    assert image_terms(skull, lateral, centre, True, True)[2] == {}
    # Without glabella on the skull, the forehead cannot be cut either.
    no_glabella = replace(
        skull, landmarks_mm={k: v for k, v in skull.landmarks_mm.items() if k != "glabella"}
    )
    assert "no glabella" in pll_off_reason(no_glabella, lateral)


def test_pll_off_without_a_mouth_corner_unless_the_curve_is_given(pair):
    subject_dir, photo_dir = _case(pair[0], "complete", "frontal")
    skull, photo = read_skull(subject_dir), read_photo(photo_dir)
    hidden = {k: v for k, v in photo.landmarks_uv.items() if k != "cheilion_l"}
    corner = replace(photo, landmarks_uv=hidden)
    assert pll_off_reason(skull, corner) == ""  # face_curve.json bounds the curve already
    no_curve = replace(corner, face_curve_uv=None)
    reason = pll_off_reason(skull, no_curve)
    assert "no cheilion_l to bound the chin-jaw curve on the face mask" in reason
    assert "face_curve.json" in reason
    assert "neither face_curve.json nor a face mask" in pll_off_reason(
        skull, replace(no_curve, face_mask=None)
    )
    assert missing_curve_bounds("frontal", hidden) == ["cheilion_l"]
    with pytest.raises(ValueError, match="cheilion_l is not marked; mark it"):
        face_curve_from_mask(photo.face_mask, "frontal", hidden)


def test_lilium_runs_with_the_terms_that_apply(pair):
    subject_dir, photo_dir = _case(pair[0], "no_mandible", "frontal")
    skull, photo = read_skull(subject_dir), read_photo(photo_dir)
    photo = replace(photo, face_mask=None)  # and P_skof has no mask
    result = run_sfo("lilium", skull, photo, SfoOptions("skof+pll", TINY_DE), seed=1)
    assert result and set(result.terms_off) == {"p_skof", "p_pll"}
    assert result.terms["p_skof"] is None and result.terms["p_pll"] is None
    assert result.fitness == pytest.approx(result.terms["mse_pix"] + result.terms["p_cam"])
    data = result.to_dict()
    assert data["terms_off"] == result.terms_off and "no face mask" in data["terms_off"]["p_skof"]
    # The same with the terms switched off by hand: the same numbers.
    base = run_sfo("lilium", skull, photo, SfoOptions("base", TINY_DE), seed=1)
    assert base.fitness == result.fitness and base.terms_off == {}
    assert "terms_off" not in base.to_dict()  # every term asked for ran


def test_prior_parts_off_without_their_prior(pair):
    subject_dir, photo_dir = _case(pair[0], "complete", "frontal")
    skull, photo = read_skull(subject_dir), read_photo(photo_dir)
    assert prior_terms_off(photo.priors) == {}
    bare = replace(photo, priors=CameraPriors(focal_px=(500.0, 900.0)))
    assert set(prior_terms_off(bare.priors)) == {"p_cam_scd", "p_cam_head"}
    problem = LiliumProblem(skull, bare, SfoOptions("skof+pll", TINY_DE))
    assert set(problem.terms_off) == {"p_cam_scd", "p_cam_head"}
    assert planned_terms_off(skull, bare, (True, True)) == problem.terms_off


def test_check_runnable_says_what_is_switched_off(pair):
    subject_dir, photo_dir = _case(pair[0], "no_mandible", "frontal")
    skull, photo = read_skull(subject_dir), read_photo(photo_dir)
    photo_file = photo_dir / "photo.json"
    off = check_runnable(skull, photo, ["lilium"], "skof+pll", photo_file)
    assert list(off) == ["p_pll"]
    assert check_runnable(skull, photo, ["posest-sfo"], "skof+pll", photo_file) == {}
    # Fewer than four pairs: the one case no term set can run.
    three = replace(photo, landmarks_uv=dict(list(photo.landmarks_uv.items())[:3]))
    with pytest.raises(ValueError, match="photo.json: only 3 usable landmark pairs"):
        check_runnable(skull, three, ["lilium"], "skof+pll", photo_file)


# -- the user's case and the experiment report ------------------------------------------------


def test_case_without_mandible_reports_the_terms(pair, tmp_path, capsys):
    root = pair[0]
    subject_dir, frontal = _case(root, "no_mandible", "frontal")
    _, lateral = _case(root, "no_mandible", "lateral")
    out = tmp_path / "case"
    argv = ["case", "--skull", subject_dir, "--photo", frontal, "--photo", lateral]
    argv += ["--generations", "4", "--population", "8", "--out", out]
    assert main([str(a) for a in argv]) == 0
    stdout = capsys.readouterr().out
    lines = stdout.splitlines()
    planned = [i for i, line in enumerate(lines) if "P_pll switched off" in line]
    ran = [i for i, line in enumerate(lines) if "lilium skof+pll: focal" in line]
    assert len(planned) == 1 and len(ran) == 2 and planned[0] < ran[0]  # said before the run
    assert frontal.name in lines[planned[0]] and "infradentale" in lines[planned[0]]
    assert "off: p_pll" in lines[ran[0]] and "off:" not in lines[ran[1]]
    front = json.loads((out / frontal.name / "lilium-skof+pll" / "result.json").read_text())
    side = json.loads((out / lateral.name / "lilium-skof+pll" / "result.json").read_text())
    assert set(front["terms_off"]) == {"p_pll"} and front["terms"]["p_pll"] is None
    assert "terms_off" not in side and side["terms"]["p_pll"] is not None
    html = (out / "report.html").read_text()
    assert html.count("switched off: skull") == 1 and "(no mandible?)" in html


def test_experiment_report_counts_sfos_with_a_term_off(tmp_path):
    from lilium.experiments.store import ResultStore

    db = tmp_path / "r.sqlite"
    with ResultStore(db) as store:
        for k, (view, off) in enumerate(
            [("frontal", {"p_pll": "no mandible"}), ("frontal", {}), ("lateral_left", {})]
            + [("frontal", {"p_pll": "x", "p_skof": "y"})]
        ):
            store.insert(
                dict(
                    experiment="C",
                    method="lilium",
                    variant="skof+pll",
                    axes_set=1,
                    repetition=0,
                    seed=0,
                    photo=f"p{k}",
                    subject="s1",
                    view=view,
                    true_subject="s1",
                    positive=1,
                    success=1,
                    score=1.0,
                    bpe_mm=1.0,
                    outside_px=0,
                    skull_px=10,
                    percent_outside=0.0,
                    seconds=1.0,
                    result=json.dumps({"terms_off": off} if off else {}),
                )
            )
    table = terms_off_table(terms_off_rows(db))
    assert [(t["view"], t["sfos"], t["with_term_off"], t["off_p_pll"]) for t in table] == [
        ("frontal", 3, 2, 2),
        ("lateral", 1, 0, 0),
    ]
    assert table[0]["off_p_skof"] == 1
    paths = write_report(db, tmp_path / "report")
    text = paths["markdown"].read_text()
    assert "| C | Lilium+P_skof+P_pll | frontal | 3 | 2 | 2 | 1 |" in text
    assert paths["terms_off"].read_text().startswith("experiment,method,view,sfos")
    with sqlite3.connect(db) as conn:  # none off: the report says so
        conn.execute("UPDATE sfo SET result = '{}'")
    assert "None: every SFO ran" in write_report(db, tmp_path / "r2")["markdown"].read_text()


@pytest.mark.slow
def test_procedural_subject_without_mandible():
    from lilium.synthetic.head import prepare_head
    from lilium.synthetic.subjects import make_subject

    whole, jawless = make_subject("s", 5), make_subject("s", 5, mandible=False)
    assert np.array_equal(whole.skin_vertices_mm, jawless.skin_vertices_mm)
    assert all(
        np.array_equal(whole.facial_landmarks[n], jawless.facial_landmarks[n])
        for n in whole.facial_landmarks
    )
    assert set(whole.cranial_landmarks) - set(jawless.cranial_landmarks) == set(MANDIBLE_LANDMARKS)
    assert set(jawless.removed_landmarks) == set(MANDIBLE_LANDMARKS)
    # The cranium ends above the mandible's landmarks (its lowest bone: the upper teeth).
    assert jawless.skull_vertices_mm[:, 1].min() > whole.cranial_landmarks["infradentale"][1]
    assert np.array_equal(jawless.head_skull_vertices_mm, whole.skull_vertices_mm)
    # The photos' mask clears the complete skull: the same head model.
    assert np.array_equal(prepare_head(whole).head_faces, prepare_head(jawless).head_faces)
