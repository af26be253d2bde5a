"""Identification as a likelihood ratio (docs/method/identification.md) in casework: the conclusion
and its
caps, the ``"identification"`` record of ``lilium sfo`` and ``lilium case`` (a frontal and a
lateral photo's LRs added, each photo's own decision reused), and the line-up's ranking. The
terms are ``test_lr_terms.py``'s; the calibration ``test_lr_calibration.py``'s."""

import json

import numpy as np
import pytest

from lilium.casework.identify import conclusion_line, decide
from lilium.cli.main import main
from lilium.geometry.camera import Camera
from lilium.identification.conclusion import conclude, level, material_caps
from lilium.io.calibration import Calibrations
from standin_case import scaled_photo


def identify(skull, photos, results, calibrations):
    """The decision's record, as ``result.json``'s ``"identification"`` holds it."""
    return decide(skull, photos, results, calibrations).to_dict()


def test_conclusion_scale_caps_and_consistency():
    assert [level(x) for x in (-3, -1.5, -0.7, 0.0, 0.7, 1.5, 3)] == list(range(7))
    assert conclude(2.5).label == "strong support"
    caps = material_caps(has_mandible=False, photos=1, unreviewed_automatic=False, pairs=12)
    assert set(caps) == {"no_mandible", "single_photo"}
    capped = conclude(2.5, caps)
    assert capped.label == "limited support" and capped.uncapped == "strong support"
    assert "no mandible" in conclusion_line(
        {"conclusion": capped.label, "conclusion_uncapped": capped.uncapped, "caps": caps,
         "log10_lr": 2.5, "inconsistent": {}})
    four = material_caps(False, 1, True, 6)
    assert conclude(3.0, four).label == "undetermined"
    assert conclude(-2.5, four).label == "strong support for exclusion"  # exclusion uncapped
    inconsistent = conclude(2.5, {}, {"view_mismatch": "the camera looks at the side"})
    assert inconsistent.label == "undetermined"
    # A camera that contradicts the view reads no LR either way; a skull outside the head
    # stops support only.
    assert conclude(-2.5, {}, {"view_mismatch": "sideways"}).label == "undetermined"
    outside = {"skull_outside_head": "40 % of the skull's pixels lie outside the head mask"}
    assert conclude(-2.5, {}, outside).label == "strong support for exclusion"
    assert conclude(None).label == conclude(float("nan")).label == "undetermined"


def test_sfo_writes_the_identification_and_prints_the_conclusion(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    out = tmp_path / "out"
    code = main(["sfo", "--method", "posest-sfo", "--skull", str(subject_dir),
                 "--photo", str(photo_dir), "--out", str(out)])
    stdout = capsys.readouterr().out
    assert code == 0
    ident = json.loads((out / "result.json").read_text())["identification"]
    assert set(ident) >= {"score", "terms", "log10_lr", "conclusion", "caps", "calibration"}
    assert ident["calibration"]["model"] == "posest-sfo//frontal"
    assert "single_photo" in ident["caps"]
    assert ident["terms"]["landmark_chi2"] > 0
    assert f"identification: {ident['conclusion']}" in stdout


def test_the_record_names_a_misplaced_landmark(case, tmp_path):
    """One photo landmark moved far off (a misclick): the identification names it as the
    worst-fitting landmark, with a larger misfit, and the report shows the name."""
    from dataclasses import replace
    from types import SimpleNamespace

    from lilium.casework.build import read_photo, read_skull
    from lilium.methods.pairs import correspondences
    from lilium.report.conclusion_html import conclusion_section

    subject_dir, photo_dir = case
    assert main(["sfo", "--method", "posest-sfo", "--skull", str(subject_dir),
                 "--photo", str(photo_dir), "--out", str(tmp_path / "out")]) == 0
    data = json.loads((tmp_path / "out" / "result.json").read_text())
    assert data["identification"]["worst_landmark"]["misfit"] > 0
    result = SimpleNamespace(method="posest-sfo", variant="", warnings=[], camera_source="search",
                             camera=Camera.from_dict(data["camera"]), facial_landmarks_mm=None)
    skull, photo = read_skull(subject_dir), read_photo(photo_dir)
    moved_name = correspondences(skull, photo).facial_names[2]
    landmarks = dict(photo.landmarks_uv)
    landmarks[moved_name] = np.asarray(landmarks[moved_name], float) + [60.0, -60.0]
    calibrations = Calibrations()
    before = identify(skull, [photo], [result], calibrations)["worst_landmark"]
    after = identify(skull, [replace(photo, landmarks_uv=landmarks)], [result], calibrations)
    assert after["worst_landmark"]["name"] == moved_name
    assert after["worst_landmark"]["misfit"] > 3 * before["misfit"]
    assert after["terms"]["landmark_worst"] == pytest.approx(after["worst_landmark"]["misfit"])
    html = conclusion_section([("photo", "", after)])
    assert f"worst-fitting landmark: {moved_name}" in html


def test_case_without_a_calibrated_model_says_so(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    calibration = tmp_path / "empty.json"
    calibration.write_text(json.dumps({"format": "lilium-calibration", "models": {}}))
    out = tmp_path / "out"
    other = scaled_photo(photo_dir, tmp_path / "other", 0.75)
    code = main(["case", "--skull", str(subject_dir), "--photo", str(photo_dir),
                 "--photo", str(other), "--method", "posest-sfo",
                 "--calibration", str(calibration), "--out", str(out)])
    stdout = capsys.readouterr().out
    assert code == 0
    assert "no calibration for posest-sfo//frontal" in stdout
    assert "together, posest-sfo: identification: undetermined" in stdout
    text = (out / "report.html").read_text()
    assert text.index("Identification") < text.index("Summary")
    assert "the paper&#x27;s alignment score" in text or "the paper's alignment score" in text


def test_a_file_that_is_not_a_calibration_is_refused(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    code = main(["sfo", "--skull", str(subject_dir), "--photo", str(photo_dir),
                 "--calibration", str(bad), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and "not a Lilium calibration file" in err and str(bad) in err


def test_lineup_orders_ties_at_the_bound_by_what_was_clipped():
    from lilium.casework.lineup import rank_key

    def entry(name, lr, views=None, score=None, method="lilium-skof+pll"):
        record = {"log10_lr": lr, "views_log10_lr": views, "score": score}
        return {"candidate": name, "method": method, "identification": record}

    entries = [
        entry("none", None),
        entry("bound, smaller sum", 2.95, [1.5, 0.8], 3.0),
        entry("other method", 3.5, method="posest-sfo"),
        entry("bound, larger sum", 2.95, [2.5, 1.9], 9.0),
        entry("below", 1.2, [0.5, 0.6], 1.0),
        entry("one photo, bound, lower score", 2.95, None, 2.0),
    ]
    ranked = sorted(entries, key=lambda e: rank_key(e, "lilium-skof+pll"))
    assert [e["candidate"] for e in ranked] == [
        "bound, larger sum", "bound, smaller sum", "one photo, bound, lower score", "below",
        "none", "other method",
    ]


def test_rankings_break_ties_at_the_bound_by_the_plain_sum():
    from lilium.experiments.identification import photo_matches
    from lilium.experiments.lr_report import ranking_rows

    pairs = [dict(run=(0, "e", "m", "", "C1", 0), photo="p1", person="a", skull=s)
             for s in ("a", "b", "c")]
    lr = np.array([2.95, 2.95, 1.0])  # the true skull and a wrong one at the upper bound
    for added, better, tied in (([5.0, 3.0, 0.5], 0, 0), ([3.0, 5.0, 0.5], 1, 0),
                                (None, 0, 1)):
        rows = ranking_rows(pairs, lr, "frontal", None if added is None else np.array(added))
        match = photo_matches(rows)[0]
        assert (match["better"], match["tied"]) == (better, tied)


def test_lineup_ranks_candidates_and_resumes(case, tmp_path, capsys, monkeypatch):
    subject_dir, photo_dir = case
    out = tmp_path / "lineup"
    # Each photo once (a photo given twice is refused): bea's are the stand-in at other sizes.
    bea = [scaled_photo(photo_dir, tmp_path / f"bea{k}", f) for k, f in enumerate((0.5, 0.75))]
    argv = ["lineup", "--skull", str(subject_dir), "--candidate", "anna", str(photo_dir),
            "--candidate", "bea", *map(str, bea), "--method", "posest-sfo",
            "--no-progress", "--out", str(out)]
    assert main(argv) == 0
    stdout = capsys.readouterr().out
    ranking = json.loads((out / "lineup.json").read_text())["ranking"]
    assert [e["rank"] for e in ranking] == [1, 2]
    assert {e["candidate"] for e in ranking} == {"anna", "bea"}
    lrs = [e["identification"]["log10_lr"] for e in ranking]
    assert lrs[0] >= lrs[1]
    assert (out / "anna" / "standin_frontal" / "posest-sfo" / "overlay.png").is_file()
    assert "1. " in stdout and (out / "report.html").is_file()

    import lilium.casework.lineup as lineup

    def no_rerun(*args, **kwargs):
        raise AssertionError("a stored SFO ran again")

    monkeypatch.setattr(lineup, "run_sfo", no_rerun)
    assert main(argv) == 0  # every SFO read back
    again = json.loads((out / "lineup.json").read_text())["ranking"]
    assert [e["identification"]["log10_lr"] for e in again] == lrs


def test_lineup_refuses_a_name_given_twice(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    code = main(["lineup", "--skull", str(subject_dir), "--candidate", "a", str(photo_dir),
                 "--candidate", "a", str(photo_dir), "--out", str(tmp_path / "o")])
    assert code == 2 and "given twice" in capsys.readouterr().err


def _posest_sfo(case, tmp_path):
    """``lilium sfo --method posest-sfo`` on the stand-in case: a result with its camera, the
    skull, the photo and the ``result.json`` written."""
    from types import SimpleNamespace

    from lilium.casework.build import read_photo, read_skull

    subject_dir, photo_dir = case
    assert main(["sfo", "--method", "posest-sfo", "--skull", str(subject_dir),
                 "--photo", str(photo_dir), "--out", str(tmp_path / "out")]) == 0
    data = json.loads((tmp_path / "out" / "result.json").read_text())
    result = SimpleNamespace(method="posest-sfo", variant="", warnings=[], camera_source="search",
                             camera=Camera.from_dict(data["camera"]), facial_landmarks_mm=None)
    return result, read_skull(subject_dir), read_photo(photo_dir), data


def test_a_frontal_and_a_lateral_photo_add_their_log_lrs(case, tmp_path, monkeypatch):
    """Separate SFOs of one frontal and one lateral photo: the decision's log10 LR is the sum
    of the two photos' own (each from its view's model) calibrated by the method's
    ``pair_sum`` model, or the plain sum without one; other sets use the pair model."""
    from dataclasses import replace
    from types import SimpleNamespace


    result, skull, frontal, data = _posest_sfo(case, tmp_path)
    lateral = replace(frontal, view="lateral_left")  # the same landmarks, scored as lateral
    calibrations = Calibrations()
    one = [identify(skull, [p], [result], calibrations) for p in (frontal, lateral)]
    both = identify(skull, [frontal, lateral], [result, result], calibrations)
    assert both["calibration"]["model"] == (
        "posest-sfo//frontal + posest-sfo//lateral -> posest-sfo//pair_sum"
    )
    added = one[0]["log10_lr"] + one[1]["log10_lr"]
    assert both["views_log10_lr"] == [one[0]["log10_lr"], one[1]["log10_lr"]]
    views = calibrations.get("posest-sfo//pair_sum")
    assert both["calibration"]["views_model"] == "posest-sfo//pair_sum"
    assert both["log10_lr"] == pytest.approx(views.log10_lr([{"views_log10_lr": added}])[0])
    assert "calibrated as one decision" in both["note"]
    without = Calibrations()
    del without.models["posest-sfo//pair_sum"]
    plain = identify(skull, [frontal, lateral], [result, result], without)
    assert plain["log10_lr"] == pytest.approx(added)
    assert "as if independent" in plain["note"] and plain["calibration"]["views_model"] is None
    assert plain["calibration"]["model"] == "posest-sfo//frontal + posest-sfo//lateral"
    assert "single_photo" not in both["caps"]
    # Each photo's LR comes from its own SFO's soft tissue, not the first photo's.
    import lilium.identification.decision as identify_module

    own = {k: np.asarray(v, float) for k, v in data["facial_landmarks_3d"].items()}
    moved = {k: v + np.array([4.0, -3.0, 8.0]) for k, v in own.items()}
    first = SimpleNamespace(**{**vars(result), "facial_landmarks_mm": own})
    second = SimpleNamespace(**{**vars(result), "facial_landmarks_mm": moved})
    seen = []

    def recording(skull, photos, cameras, facial, **kwargs):
        seen.append(([p.view for p in photos], facial))
        return terms_of(skull, photos, cameras, facial, **kwargs)

    terms_of = identify_module.terms_and_overlaps
    monkeypatch.setattr(identify_module, "terms_and_overlaps", recording)
    identify(skull, [frontal, lateral], [first, second], calibrations)
    singles = {tuple(views): facial for views, facial in seen if len(views) == 1}
    assert singles[("frontal",)] is own and singles[("lateral_left",)] is moved
    # The photos' terms together take the frontal photo's soft tissue, as the calibration's
    # pairs do, whichever photo comes first.
    seen.clear()
    identify(skull, [lateral, frontal], [second, first], calibrations)
    assert [facial for views, facial in seen if len(views) == 2] == [own]
    two_frontal = identify(skull, [frontal, frontal], [result, result], calibrations)
    assert two_frontal["calibration"]["model"] == "posest-sfo//pair"
    assert "these photos differ" in two_frontal["note"]


def test_two_photos_reuse_each_photos_own_decision(case, tmp_path, monkeypatch):
    """A frontal and a lateral photo's decision reads each photo's LR from the record its
    result already carries (same calibration file and model), not from a second
    computation; the decision is the one computed from scratch."""
    from dataclasses import replace
    from pathlib import Path
    from types import SimpleNamespace

    import lilium.identification.decision as identify_module
    from lilium.casework.build import read_photo, read_skull

    subject_dir, photo_dir = case
    assert main(["sfo", "--method", "posest-sfo", "--skull", str(subject_dir),
                 "--photo", str(photo_dir), "--out", str(tmp_path / "out")]) == 0
    data = json.loads((tmp_path / "out" / "result.json").read_text())
    result = SimpleNamespace(method="posest-sfo", variant="", warnings=[], camera_source="search",
                             extra={}, camera=Camera.from_dict(data["camera"]),
                             facial_landmarks_mm=None)
    skull, frontal = read_skull(subject_dir), read_photo(photo_dir)
    lateral = replace(frontal, view="lateral_left")
    calibrations = Calibrations()
    scratch = identify(skull, [frontal, lateral], [result, result], calibrations)
    # What with_identification stores in a result's extra.
    own = [SimpleNamespace(**{**vars(result), "extra": {
        "identification": identify(skull, [p], [result], calibrations)}})
        for p in (frontal, lateral)]
    calls = []
    real = identify_module.terms_and_overlaps
    monkeypatch.setattr(identify_module, "terms_and_overlaps",
                        lambda *a, **k: calls.append(len(a[1])) or real(*a, **k))
    reused = identify(skull, [frontal, lateral], own, calibrations)
    assert calls == [2]  # the pair's own terms only
    assert reused["log10_lr"] == pytest.approx(scratch["log10_lr"], abs=1e-12)
    assert reused["views_log10_lr"] == pytest.approx(scratch["views_log10_lr"], abs=1e-12)
    (tmp_path / "other.json").write_bytes(Path(calibrations.path).read_bytes())
    other = Calibrations(tmp_path / "other.json")  # another file: computed again
    calls.clear()
    identify(skull, [frontal, lateral], own, other)
    assert calls == [2, 1, 1]


def _one_term_model(ranges):
    """A calibration of POSEST-SFO's frontal photos that reads any case as strong support
    (log10 LR 3, its upper bound), with ``ranges`` for its one feature."""
    from lilium.identification.calibration import Calibration

    n_same, n_diff = 1, 1000
    return Calibration(
        ("landmark_chi2",), {"landmark_chi2": 0.0}, {"landmark_chi2": 1.0},
        {"landmark_chi2": 0.0}, {"landmark_chi2": 0.0},
        3.0 * np.log(10.0) + np.log(n_same / n_diff), n_same, n_diff,
        ranges=ranges,
    )


def test_a_case_outside_the_calibrations_range_gets_no_support(case, tmp_path, capsys):
    """The same case and model, once with the feature's training range around the case's
    value (moderate support: strong, capped one step for the single photo) and once with a
    range that leaves it out: then ``outside_calibration`` names the feature, its value and
    the range, the conclusion is undetermined, and the console and the report say so first."""
    from lilium.io.calibration import write_calibration

    subject_dir, photo_dir = case
    conclusions = {}
    for name, ranges in (("inside", {"landmark_chi2": (-50.0, 50.0)}),
                         ("outside", {"landmark_chi2": (-50.0, -40.0)})):
        calibration = tmp_path / f"{name}.json"
        write_calibration(calibration, {"posest-sfo//frontal": _one_term_model(ranges)}, {})
        out = tmp_path / name
        code = main(["case", "--skull", str(subject_dir), "--photo", str(photo_dir),
                     "--method", "posest-sfo", "--calibration", str(calibration),
                     "--out", str(out)])
        stdout = capsys.readouterr().out
        assert code == 0
        ident = json.loads((out / photo_dir.name / "posest-sfo" / "result.json").read_text())[
            "identification"]
        assert ident["log10_lr"] == pytest.approx(3.0)
        conclusions[name] = ident["conclusion"]
        if name == "outside":
            assert list(ident["caps"])[0] == "outside_calibration"
            text = ident["caps"]["outside_calibration"]
            assert "landmark_chi2" in text and "[-50, -40]" in text
            value = float(np.log(ident["terms"]["landmark_chi2"]))
            assert f"{value:.3g}" in text
            line = next(x for x in stdout.splitlines() if "identification:" in x)
            assert line.index("capped: feature landmark_chi2") > 0
            report = (out / "report.html").read_text()
            why = report[report.index("<table class='conclusions'>"):]
            assert why.index("outside_calibration") < why.index("single_photo")
        else:
            assert "outside_calibration" not in ident["caps"]
    assert conclusions == {"inside": "moderate support", "outside": "undetermined"}


def test_a_camera_far_outside_its_priors_is_no_support():
    """The head orientation 173 deg from its prior (a wrong skull's SFO on a real head) reads
    no LR either way; a focal length beyond 1.5 x its prior's interval is no support;
    2.5 tolerances or 1.45 x off is neither."""
    from types import SimpleNamespace

    from lilium.geometry.rotations import rotvec_to_matrix
    from lilium.inputs import Priors
    from lilium.methods.prior_checks import prior_conflicts

    priors = Priors(focal_px=(900.0, 1100.0), scd_mm=None, head_rotation_skull2cam=np.eye(3),
                    head_tolerance_deg=10.0)
    photo = SimpleNamespace(id="p", priors=priors, prior_sources={})
    expected = {(25.0, 1000.0): set(), (173.0, 1000.0): {"head_outside_prior"},
                (0.0, 1595.0): set(), (0.0, 1700.0): {"camera_outside_priors"},
                (0.0, 590.0): {"camera_outside_priors"},
                (40.0, 1700.0): {"camera_outside_priors", "head_outside_prior"}}
    found = {}
    for (angle_deg, focal), codes in expected.items():
        R = rotvec_to_matrix(np.radians([0.0, angle_deg, 0.0]))
        camera = Camera.from_rt(R, np.array([0.0, 0.0, 1000.0]), focal, np.array([500.0, 500.0]))
        found[(angle_deg, focal)] = prior_conflicts(photo, camera, None)
        assert set(found[(angle_deg, focal)]) == codes, (angle_deg, focal)
    assert "173.0 deg" in found[(173.0, 1000.0)]["head_outside_prior"]
    assert "1700 px" in found[(0.0, 1700.0)]["camera_outside_priors"]
    head = {"head_outside_prior": "173 deg"}
    assert conclude(-2.5, {}, head).label == conclude(2.5, {}, head).label == "undetermined"
    focal = {"camera_outside_priors": "1700 px"}
    assert conclude(2.5, {}, focal).label == "undetermined"
    assert conclude(-2.5, {}, focal).label == "strong support for exclusion"


def test_skull_outside_the_head_is_decided_beyond_the_edge_noise(case):
    """The head mask is the skull's own raster grown, shrunk by one pixel (a pixel-wide ring
    of the skull outside it: raster and mask-edge noise) or cut at the brow (the vault really
    leaves the head): only the last is ``skull_outside_head``, though the ring already counts
    in ``outside_fraction``."""
    from dataclasses import replace

    from scipy import ndimage as ndi

    from lilium.casework.build import read_photo, read_skull
    from lilium.identification.decision import skull_outside_head
    from lilium.identification.score import head_overlap, outside_fraction, skull_beyond_head
    from lilium.imaging.raster import mesh_mask
    from lilium.io.truth import read_ground_truth

    subject_dir, photo_dir = case
    skull, photo = read_skull(subject_dir), read_photo(photo_dir)
    camera = read_ground_truth(photo_dir).camera
    height, width = np.asarray(photo.face_mask).shape
    raster = mesh_mask(skull.vertices_mm, skull.faces, camera, (width, height)) != 0
    rows = np.nonzero(raster.any(axis=1))[0]
    cut = raster.copy()
    cut[: rows[0] + (rows[-1] - rows[0]) // 4] = False
    masks = {"grown": ndi.binary_dilation(raster, iterations=8),
             "one pixel in": ndi.binary_erosion(raster), "cut at the brow": cut}
    found = {}
    for name, mask in masks.items():
        masked = replace(photo, face_mask=mask.astype(np.uint8) * 255)
        beyond, skull_px, band = skull_beyond_head(skull, masked, camera)
        assert skull_px == raster.sum() and band >= 2.0
        found[name] = beyond
        sentence = skull_outside_head([masked], [head_overlap(skull, masked, camera)])
        assert (sentence is not None) == (name == "cut at the brow"), (name, sentence)
    assert found["grown"] == found["one pixel in"] == 0 < found["cut at the brow"]
    ring = outside_fraction(skull, replace(photo, face_mask=masks["one pixel in"]), camera)
    assert ring > 0


def test_a_frontal_and_lateral_decision_is_outside_when_a_photo_is(case, tmp_path):
    """The frontal + lateral decision inherits a photo's ``outside_calibration`` (naming the
    photo); inside every photo's range it is not capped so, whatever the views model (which
    keeps no range: two photos at their bounds add up beyond its training sums)."""
    from dataclasses import replace

    from lilium.identification.calibration import VIEWS_LOG10_LR, Calibration

    result, skull, frontal, _ = _posest_sfo(case, tmp_path)
    lateral = replace(frontal, id="side", view="lateral_left")
    wide = {"landmark_chi2": (-50.0, 50.0)}

    one = {VIEWS_LOG10_LR: 0.0}
    views = Calibration((VIEWS_LOG10_LR,), one, {VIEWS_LOG10_LR: 1.0}, one,
                        {VIEWS_LOG10_LR: 1.0}, 0.0, 1, 1000)
    calibrations = Calibrations()
    for ranges_lateral, expected in ((wide, None), ({"landmark_chi2": (-50.0, -40.0)},
                                                    "side: feature landmark_chi2")):
        calibrations.models = {
            "posest-sfo//frontal": _one_term_model(wide),
            "posest-sfo//lateral": _one_term_model(ranges_lateral),
            "posest-sfo//pair_sum": views,
        }
        record = identify(skull, [frontal, lateral], [result, result], calibrations)
        if expected is None:
            assert "outside_calibration" not in record["caps"]
        else:
            assert list(record["caps"])[0] == "outside_calibration"
            assert record["caps"]["outside_calibration"].startswith(expected)
            assert record["conclusion"] == "undetermined"
