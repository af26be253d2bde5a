"""The plain records behind the HTML report, and the provenance they carry."""

import dataclasses
import hashlib

import numpy as np
import pytest

from lilium.casework.build import read_photo, read_skull
from lilium.experiments.task_io import score_result
from lilium.io.provenance import input_files, sha256_of, software_versions
from lilium.methods.posest_sfo import posest_sfo
from lilium.report import ReportEntry, report_record, sfo_record
from lilium.report.html import template_text


@pytest.fixture
def sfo(case):
    subject_dir, photo_dir = case
    skull, photo = read_skull(subject_dir), read_photo(photo_dir)
    result = posest_sfo(skull, photo)
    assert result
    inputs = {"skull mesh": subject_dir / "skull.ply", "photo": photo_dir / "image.png"}
    return skull, photo, result, inputs


def _shifted(result, dx_mm):
    """The result with its camera moved sideways (so part of the skull leaves the face)."""
    camera = result.camera
    T = camera.skull2cam.copy()
    T[0, 3] += dx_mm
    moved = type(camera)(T, camera.focal_px, camera.principal_point_px)
    return dataclasses.replace(result, camera=moved)


@pytest.mark.parametrize("dx_mm", [0.0, 15.0])
def test_outside_pixels_are_the_experiment_stores_number(sfo, dx_mm):
    skull, photo, result, _ = sfo
    result = _shifted(result, dx_mm)
    record = sfo_record(ReportEntry(skull, photo, result))
    expected = score_result(result, skull, photo)
    assert record.outside.outside_px == expected["outside_px"]
    assert record.outside.skull_px == expected["skull_px"]
    assert record.summary.outside_pct == pytest.approx(expected["percent_outside"])
    if dx_mm:
        assert record.outside.outside_px > 0 and record.pictures.outside_png is not None


def test_record_is_plain_data(sfo):
    skull, photo, result, inputs = sfo
    record = sfo_record(ReportEntry(skull, photo, result, inputs, {"focal prior": "photo.json"}))
    assert record.ok and record.summary.status == "ok"
    assert record.pictures.photo_jpeg[:2] == b"\xff\xd8"
    assert record.pictures.skull_png[:4] == b"\x89PNG"
    assert record.pictures.outside_png is None  # the true camera keeps the skull in the face
    assert all(isinstance(r.error_px, float) for r in record.landmarks)
    np.testing.assert_allclose(np.array(record.camera.skull2cam), result.camera.skull2cam)
    assert record.camera.focal_px == pytest.approx(result.camera.focal_px)
    assert record.mean_error_px == pytest.approx(np.mean([r.error_px for r in record.landmarks]))
    assert record.notes == (("focal prior", "photo.json"),)
    assert [f.label for f in record.inputs] == ["skull mesh", "photo"]
    # A failed SFO has rows without estimates and no camera or skull layer.
    failed = sfo_record(ReportEntry(skull, photo, dataclasses.replace(result, camera=None)))
    assert not failed.ok and failed.camera is None and failed.pictures.skull_png is None
    assert failed.outside is None and failed.mean_error_px is None
    assert all(np.isnan(r.error_px) for r in failed.landmarks)


def test_report_record_and_errors(sfo):
    skull, photo, result, inputs = sfo
    page = report_record([ReportEntry(skull, photo, result, inputs)] * 2, date="2024-01-01")
    assert [s.index for s in page.sfos] == [1, 2] and page.skull_ids == (skull.id,)
    assert page.lilium_version == dict(page.versions)["lilium"]
    with pytest.raises(ValueError, match="at least one SFO"):
        report_record([])
    no_image = dataclasses.replace(photo, image=None)
    with pytest.raises(ValueError, match="without its image"):
        sfo_record(ReportEntry(skull, no_image, result))


def test_provenance_hashes_files(tmp_path):
    path = tmp_path / "a.bin"
    path.write_bytes(b"lilium" * 1000)
    assert sha256_of(path, chunk=7) == hashlib.sha256(b"lilium" * 1000).hexdigest()
    cache = {}
    files = input_files({"a": path, "b": tmp_path / "missing.ply"}, cache)
    assert files[0].sha256 == sha256_of(path) and files[0].size_bytes == 6000
    assert files[1].sha256 is None and files[1].size_bytes is None
    assert list(cache.values()) == [sha256_of(path)]
    versions = software_versions(("numpy", "no-such-package-xyz"))
    assert (
        versions["numpy"] == np.__version__ and versions["no-such-package-xyz"] == "not installed"
    )


def test_templates_ship_with_the_package():
    for name in ("report.html", "sfo.html", "controls.html", "report.css", "report.js"):
        assert template_text(name).strip()
    assert "$sections" in template_text("report.html")


@pytest.mark.parametrize("method", ["posest-sfo", "lilium"])
def test_skull_outside_the_mask_is_implausible_whatever_the_method(sfo, method):
    from lilium.methods import SfoOptions, run_sfo
    from lilium.report.html import format_report

    skull, photo, _, _ = sfo
    options = SfoOptions(variant="base").with_de(max_generations=2, population_size=6)
    result = run_sfo(method, skull, photo, options)
    ok = sfo_record(ReportEntry(skull, photo, result))
    assert ok.summary.status == "ok" and ok.summary.implausible is False
    assert ok.summary.mean_error_px == pytest.approx(result.landmark_error["mean_px"])
    assert ok.summary.mean_error_mm == pytest.approx(result.landmark_error["mean_mm"])
    expected_label = "mean landmark error, px" if method == "posest-sfo" else "fitness"
    assert ok.summary.score_label == expected_label
    moved = sfo_record(ReportEntry(skull, photo, _shifted(result, 15.0)))
    assert moved.summary.status == "implausible" and moved.summary.implausible
    page = format_report(report_record([ReportEntry(skull, photo, _shifted(result, 15.0))]))
    assert ">implausible</span>" in page and "lie outside the face mask" in page
    assert f"({expected_label})" in page
