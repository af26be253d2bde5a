"""Joint SFO (docs/method/joint.md): one soft tissue shared by several photos, one camera each."""

import json
import sqlite3
from dataclasses import replace

import numpy as np
import pytest

from lilium.casework.build import read_photo, read_skull
from lilium.cli.main import main
from lilium.methods import SfoOptions, run_joint_sfo, run_sfo
from lilium.methods.joint import (
    ANGLE_PRIOR_WEIGHT,
    JointLiliumProblem,
    angle_prior,
    camera_on_priors,
    joint_lilium_sfo,
    photo_scale_px_per_mm,
)
from lilium.optimisation import DEOptions
from lilium.report.html import relative_href
from standin_case import toy_dataset

TINY_DE = DEOptions(population_size=8, max_generations=6, max_seconds=None)

#: docs/method/joint.md: the keys of a joint result.json and of each of its photos.
JOINT_KEYS = {"method", "variant", "seed", "subject", "joint", "photos", "fitness"}
JOINT_KEYS |= {"facial_landmarks_3d", "seconds", "history"}
PHOTO_KEYS = {"photo", "camera", "fitness", "terms", "terms_off"}


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    """Two toy subjects, each with one frontal and one lateral photo (Exps. A and C)."""
    out = tmp_path_factory.mktemp("joint-ds")
    toy_dataset(out, experiments=("A", "C"))
    return out


def _pair(root, subject="s01", exp="A"):
    index = json.loads((root / "dataset.json").read_text())
    mine = [p for p in index["photos"] if p["subject"] == subject]
    frontal = next(p for p in mine if p["view"] == "frontal")
    lateral = next(p for p in mine if p["view"] != "frontal")
    return root / "subjects" / subject, [root / p["paths"][exp] for p in (frontal, lateral)]


@pytest.fixture(scope="module")
def pair(dataset):
    subject_dir, photo_dirs = _pair(dataset)
    return read_skull(subject_dir), [read_photo(d) for d in photo_dirs], subject_dir, photo_dirs


def test_genes_span_the_union_of_the_photos_landmarks(pair):
    skull, photos, _, _ = pair
    problem = JointLiliumProblem(skull, photos, SfoOptions("skof+pll", TINY_DE))
    per_photo = [set(p.corr.cranial_names) for p in problem.problems]
    assert set(problem.union.cranial_names) == per_photo[0] | per_photo[1]
    assert per_photo[0] != per_photo[1]  # the lateral sees fewer: the union is needed
    assert problem.n_genes == 3 * len(problem.union.cranial_names)
    genes = np.random.default_rng(0).random((5, problem.n_genes))
    shared = problem.facial_landmarks(genes)
    for single, rows in zip(problem.problems, problem.rows, strict=True):
        names = [problem.union.cranial_names[i] for i in rows]
        assert names == list(single.corr.cranial_names)
        np.testing.assert_array_equal(problem.union.cranial_mm[rows], single.corr.cranial_mm)
        assert shared[:, rows].shape == (5, len(rows), 3)


@pytest.mark.parametrize("camera", ["least_squares", "priors"])
def test_fitness_is_the_sum_of_the_photos_fitnesses(pair, camera):
    skull, photos, _, _ = pair
    problem = JointLiliumProblem(
        skull, photos, SfoOptions("skof+pll", TINY_DE), weighting="sum", camera=camera
    )
    assert list(problem.weights) == [1.0, 1.0]
    rng = np.random.default_rng(1)
    members = problem.evaluate(rng.random((6, problem.n_genes)))
    genes = rng.random((6, problem.n_genes))
    terms = problem.evaluate(genes, members)
    assert terms["R"].shape == (6, 2, 3, 3) and terms["photo_fitness"].shape == (6, 2)
    prior = angle_prior(genes, ANGLE_PRIOR_WEIGHT)
    np.testing.assert_allclose(
        terms["fitness"], terms["photo_fitness"].sum(axis=1) + prior, rtol=1e-12
    )
    # Each photo's fitness is what its own problem gives for its rows of the shared soft tissue,
    # warm-started from the same members' cameras of that photo (its own chain).
    shared = problem.facial_landmarks(genes)
    for p, single in enumerate(problem.problems):
        mine = {k: members[k][:, p] for k in ("R", "t", "focal_px", "success")}
        alone = single.camera_terms(shared[:, problem.rows[p]], mine)
        if camera == "priors":
            least_squares = alone["fitness"].copy()
            camera_on_priors(single, shared[:, problem.rows[p]], alone, mine)
            assert np.all(alone["fitness"] <= least_squares)
        alone = single.add_image_terms(alone)
        np.testing.assert_allclose(terms["photo_fitness"][:, p], alone["fitness"], rtol=1e-9)


def test_angle_prior_charges_the_polar_angle_only():
    """The joint DE's prior: 0 on the cone axes, growing with the square of each polar angle
    in units of the direction spread; depth and azimuth genes cost nothing."""
    genes = np.zeros((3, 6))
    genes[1, [0, 2, 3, 5]] = 0.9  # depths and azimuths only
    genes[2, 1] = 0.375  # one polar angle of 15 degrees: (15 / 15)^2 over two landmarks
    np.testing.assert_allclose(angle_prior(genes, 30.0), [0.0, 0.0, 15.0])
    np.testing.assert_array_equal(angle_prior(genes, 0.0), 0.0)


def test_camera_on_priors_lowers_only_what_p_cam_charges(pair):
    """A camera outside its photo's priors moves to a lower MSE_pix + P_cam; one inside stays."""
    skull, photos, _, _ = pair
    problem = JointLiliumProblem(skull, photos, SfoOptions("base", TINY_DE), camera="priors")
    single = problem.problems[0]
    genes = np.random.default_rng(4).random((12, problem.n_genes))
    facial = problem.facial_landmarks(genes)[:, problem.rows[0]]
    before = single.camera_terms(facial)
    after = camera_on_priors(single, facial, {k: v.copy() for k, v in before.items()})
    inside = before["success"] & (before["p_cam"] == 0)
    np.testing.assert_array_equal(after["focal_px"][inside], before["focal_px"][inside])
    assert np.all(after["fitness"] <= before["fitness"])
    moved = after["fitness"] < before["fitness"]
    assert moved.any() and np.all(after["p_cam"][moved] < before["p_cam"][moved])


def test_early_exit_skips_only_trials_that_lose(pair):
    skull, photos, _, _ = pair
    problem = JointLiliumProblem(skull, photos, SfoOptions("skof+pll", TINY_DE))
    genes = np.random.default_rng(2).random((8, problem.n_genes))
    members = problem.evaluate(genes)
    trial = np.random.default_rng(3).random((8, problem.n_genes))
    full = problem.evaluate(trial, members)
    threshold = np.full(8, np.median(full["fitness"]))
    cut = problem.evaluate(trial, members, threshold)
    win_full, win_cut = full["fitness"] <= threshold, cut["fitness"] <= threshold
    np.testing.assert_array_equal(win_full, win_cut)
    np.testing.assert_allclose(cut["fitness"][win_cut], full["fitness"][win_full], rtol=1e-12)
    assert np.all(cut["fitness"][~win_cut] > threshold[~win_cut])


def test_joint_result_is_the_member_de_ranked_and_reproducible(pair):
    skull, photos, _, _ = pair
    options = SfoOptions("skof+pll", TINY_DE)
    a = joint_lilium_sfo(skull, photos, options, seed=4)
    b = joint_lilium_sfo(skull, photos, options, seed=4)
    assert a.fitness == b.fitness and a.extra["genes"] == b.extra["genes"]
    assert a.extra["weighting"] == "scale" and a.extra["camera_fit"] == "priors"
    weighted = sum(w * r.fitness for w, r in zip(a.weights, a.photos, strict=True))
    assert a.fitness == pytest.approx(weighted, rel=1e-12)
    full = joint_lilium_sfo(skull, photos, replace(options, working_face_px=None), seed=4)
    # At full level the DE's own fitness: the photos' weighted sum and the angular prior.
    prior = angle_prior(np.array(full.extra["genes"]), ANGLE_PRIOR_WEIGHT)[0]
    assert full.fitness + prior == pytest.approx(full.extra["history"][-1], rel=1e-12)
    assert full.extra["angle_prior_weight"] == ANGLE_PRIOR_WEIGHT
    plain = joint_lilium_sfo(
        skull, photos, replace(options, working_face_px=None), seed=4, prior_weight=0.0
    )
    assert plain.fitness == plain.extra["history"][-1]
    assert a.weights[0] != a.weights[1]  # the toy photos differ in scale
    for r in a.photos:
        assert r.fitness == pytest.approx(sum(v for v in r.terms.values() if v is not None))
        # The photo's landmarks are the shared ones it sees; its camera fits them as reported.
        for name, xyz in r.facial_landmarks_mm.items():
            np.testing.assert_array_equal(xyz, a.facial_landmarks_mm[name])
    photo = photos[1]
    r = a.photos[1]
    names = list(r.facial_landmarks_mm)
    uv = r.camera.project(np.array([r.facial_landmarks_mm[n] for n in names]))
    mse = np.mean(np.sum((uv - np.array([photo.landmarks_uv[n] for n in names])) ** 2, axis=1))
    assert mse == pytest.approx(r.terms["mse_pix"], rel=1e-9)
    assert len(a.facial_landmarks_mm) > max(len(r.facial_landmarks_mm) for r in a.photos) - 1


def test_scale_weighting_equalises_pixels_per_mm(pair):
    skull, photos, _, _ = pair
    problem = JointLiliumProblem(skull, photos, SfoOptions("base", TINY_DE), weighting="scale")
    k = np.array([photo_scale_px_per_mm(p.corr) for p in problem.problems])
    np.testing.assert_allclose(problem.weights * k**2, (problem.weights * k**2)[0])
    assert np.prod(problem.weights) == pytest.approx(1.0)
    result = joint_lilium_sfo(skull, photos, SfoOptions("base", TINY_DE), weighting="scale")
    fitness = sum(w * r.fitness for w, r in zip(result.weights, result.photos, strict=True))
    assert result.fitness == pytest.approx(fitness, rel=1e-12)


def test_joint_refuses_what_it_cannot_run(pair):
    skull, photos, _, _ = pair
    with pytest.raises(ValueError, match="two or more photos"):
        run_joint_sfo("lilium", skull, photos[:1])
    with pytest.raises(ValueError, match="photo ids repeat"):
        run_joint_sfo("lilium", skull, [photos[0], photos[0]])
    with pytest.raises(ValueError, match="no joint SFO"):
        run_joint_sfo("posest-sfo", skull, photos)
    with pytest.raises(ValueError, match="unknown weighting"):
        JointLiliumProblem(skull, photos, weighting="mean")


def test_sfo_cli_writes_the_joint_contract(pair, tmp_path, capsys):
    _, _, subject_dir, photo_dirs = pair
    out = tmp_path / "joint"
    argv = ["sfo", "--method", "lilium", "--variant", "skof+pll", "--seed", "2"]
    argv += ["--skull", str(subject_dir), "--out", str(out)]
    argv += ["--generations", "4", "--population", "6"]
    for d in photo_dirs:
        argv += ["--photo", str(d)]
    assert main(argv) == 0
    data = json.loads((out / "result.json").read_text())
    assert JOINT_KEYS <= set(data) and data["joint"] is True
    assert "camera" not in data and "photo" not in data
    assert [p["photo"] for p in data["photos"]] == [d.name for d in photo_dirs]
    for p in data["photos"]:
        assert PHOTO_KEYS <= set(p) and set(p["camera"]) == {
            "focal_px",
            "principal_point_px",
            "skull2cam",
        }
        assert (out / f"overlay_{p['photo']}.png").is_file()
    # docs/method/joint.md: the total is the sum of the photos' fitnesses (each photo's weighted
    # share).
    assert data["fitness"] == pytest.approx(sum(p["fitness"] for p in data["photos"]))
    weighted = sum(p["weight"] * p["fitness_unweighted"] for p in data["photos"])
    assert data["fitness"] == pytest.approx(weighted) and data["weighting"] == "scale"
    # Each photo's terms at full level, as a single SFO's (the DE's history is at the working
    # level): their sum is the photo's fitness.
    for p in data["photos"]:
        own = sum(v for v in p["terms"].values() if v is not None)
        assert p["fitness_unweighted"] == pytest.approx(own, rel=1e-12)
    assert not (out / "overlay.png").exists()
    printed = capsys.readouterr().out
    assert "joint (2 photos)" in printed and photo_dirs[1].name in printed
    # One --photo keeps docs/contract.md.
    single = tmp_path / "single"
    argv = ["sfo", "--method", "lilium", "--skull", str(subject_dir), "--out", str(single)]
    argv += ["--photo", str(photo_dirs[0]), "--generations", "3", "--population", "6"]
    assert main(argv) == 0
    one = json.loads((single / "result.json").read_text())
    assert "joint" not in one and one["photo"] == photo_dirs[0].name and one["camera"]
    assert (single / "overlay.png").is_file()


def test_sfo_cli_refuses_a_joint_it_cannot_run(pair, tmp_path, capsys):
    _, _, subject_dir, photo_dirs = pair
    base = ["sfo", "--skull", str(subject_dir), "--out", str(tmp_path / "o")]
    two = ["--photo", str(photo_dirs[0]), "--photo", str(photo_dirs[1])]
    assert main(base + ["--method", "posest-sfo"] + two) == 2
    assert "runs with --method lilium only" in capsys.readouterr().err
    same = ["--photo", str(photo_dirs[0]), "--photo", str(photo_dirs[0]) + "/"]
    assert main(base + ["--method", "lilium"] + same) == 2
    assert "the same photo as --photo" in capsys.readouterr().err
    assert not (tmp_path / "o" / "result.json").exists()


def test_case_joint_reports_every_photo_and_the_shared_landmarks(pair, tmp_path, capsys):
    _, _, subject_dir, photo_dirs = pair
    out = tmp_path / "case"
    argv = ["case", "--skull", str(subject_dir), "--out", str(out), "--joint"]
    argv += ["--generations", "10", "--population", "10", "--method", "lilium"]
    for d in photo_dirs:
        argv += ["--photo", str(d)]
    assert main(argv) == 0
    folder = out / "joint" / "lilium-skof+pll"
    data = json.loads((folder / "result.json").read_text())
    assert data["joint"] is True and len(data["photos"]) == 2
    for d in photo_dirs:
        assert (folder / f"overlay_{d.name}.png").is_file()
        assert not (out / d.name / "lilium-skof+pll").exists()
    html = (out / "report.html").read_text()
    assert "Joint SFO: lilium skof+pll joint" in html
    assert html.count("lilium skof+pll joint") >= 3  # the joint section and each photo's
    for name in data["facial_landmarks_3d"]:
        assert f"<td>{name}</td>" in html
    assert relative_href(f"joint/lilium-skof+pll/overlay_{photo_dirs[1].name}.png") in html
    assert "--joint" in html  # the provenance's command line
    # each photo's section shows its own fitness, named as result.json names it
    assert html.count("of this photo alone (result.json: <code>fitness_unweighted</code>)") == 2
    log = capsys.readouterr().out
    assert "joint (" in log
    # --joint needs two photos.
    assert main(argv[: argv.index("--photo")] + ["--photo", str(photo_dirs[0])]) == 2
    assert "--joint needs two or more --photo" in capsys.readouterr().err


def test_each_photo_is_finished_like_a_single_sfo(pair):
    """Each photo of a joint SFO gets the terms, priors and landmark error of a single one."""
    skull, photos, _, _ = pair
    options = SfoOptions("base", TINY_DE)
    joint = run_joint_sfo("lilium", skull, photos, options, seed=1)
    for photo, r in zip(photos, joint.photos, strict=True):
        single = run_sfo("lilium", skull, photo, options, seed=1)
        assert set(r.to_dict()["terms"]) == set(single.to_dict()["terms"])
        assert r.landmark_error is not None and r.priors is not None  # finish_result ran


# -- experiments ----------------------------------------------------------------------------
TOML = """
name = "joint-tiny"
methods = ["lilium:base", "lilium-joint:base"]
experiments = ["C"]
axes_sets = 1
runs_per_axes_set = 1
workers = 1
db = "results.sqlite"

[dataset]
path = "{dataset}"
generate = false

[de]
population = 10
generations = 10
max_seconds = 20
"""


def test_experiment_runs_joint_pairs_and_reports_them(dataset, tmp_path):
    from lilium.experiments.config import load_config, method_label, parse_methods
    from lilium.experiments.runner import enumerate_tasks, load_dataset

    assert parse_methods(["lilium-joint:skof"]) == (("lilium-joint", "skof"),)
    assert len(parse_methods(["lilium-joint"])) == 4
    assert method_label("lilium-joint", "skof+pll") == "Lilium joint+P_skof+P_pll"
    with pytest.raises(ValueError, match="lilium-joint:<variant>"):
        parse_methods(["lilium-joint:fancy"])
    path = tmp_path / "cfg.toml"
    path.write_text(TOML.format(dataset=dataset))
    cfg = load_config(path)
    root, index = load_dataset(cfg)
    tasks = enumerate_tasks(cfg, root, index)
    joint = [t for t in tasks if t.method == "lilium-joint"]
    single = [t for t in tasks if t.method == "lilium"]
    assert len(single) == 4 * 2 and len(joint) == 2 * 2  # 2 pairs x 2 skulls
    for t in joint:
        assert t.view == "frontal" and len(t.joint_with) == 1
        assert t.joint_with[0][0].split("_")[0] == t.photo.split("_")[0] == t.true_subject
    assert main(["experiment", str(path), "--no-progress"]) == 0
    with sqlite3.connect(tmp_path / "results.sqlite") as conn:
        rows = conn.execute(
            "SELECT photo, subject, view, score, bpe_mm, positive * success FROM sfo "
            "WHERE method = ?",
            ("lilium-joint",),
        ).fetchall()
    assert len(rows) == 2 * len(joint)  # one row per photo
    by_pair = {}
    for photo, subject, view, score, bpe, positive in rows:
        by_pair.setdefault((photo.split("_")[0], subject), []).append((view, score, bpe, positive))
    for got in by_pair.values():
        (v1, s1, _, p1), (v2, s2, _, _) = sorted(got, key=lambda g: g[0])
        assert v1 == "frontal" and v2.startswith("lateral")
        assert s1 == s2  # the pair's joint fitness ranks both photos
        # A positive photo that solved has its BPE (at this tiny budget one may fail).
        assert all(b is not None for _, _, b, ok in got if ok)
    assert any(all(ok for *_, ok in got) for got in by_pair.values())
    # A rerun finds every task done.
    assert main(["experiment", str(path), "--no-progress"]) == 0
    assert main(["report", str(tmp_path / "results.sqlite"), "--out", str(tmp_path / "rep")]) == 0
    table = (tmp_path / "rep" / "identification.csv").read_text()
    assert "Lilium joint,C,frontal" in table and "Lilium joint,C,lateral" in table
