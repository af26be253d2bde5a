"""One request: the command line read once into a :class:`CaseRequest` (``lilium.cli.options``)
that ``lilium sfo``, ``case`` and ``lineup`` run; the report records it, and ``lilium sfo``
reads the files a practitioner has as ``lilium case`` does."""

import json
import shutil
from pathlib import Path

import pytest

from cli_helpers import _one_line_error
from lilium.casework.request import CaseRequest, PhotoSource, SkullSource
from lilium.cli.main import build_parser, main
from lilium.cli.options import case_request


@pytest.fixture
def files(case, tmp_path):
    """The stand-in case as plain files: a mesh with its landmarks and an image with its
    landmarks and mask, each beside it under the sidecar names."""
    subject_dir, photo_dir = case
    folder = tmp_path / "files"
    folder.mkdir()
    shutil.copy(subject_dir / "skull.ply", folder / "skull.ply")
    shutil.copy(subject_dir / "cranial_landmarks.json", folder / "skull.json")
    meta = json.loads((photo_dir / "photo.json").read_text())
    rows = [f"{n},{u},{v}" for n, (u, v) in meta["landmarks"].items()]
    (folder / "front.csv").write_text("name,u,v\n" + "\n".join(rows) + "\n")
    shutil.copy(photo_dir / "image.png", folder / "front.png")
    shutil.copy(photo_dir / "face_mask.png", folder / "front_mask.png")
    return folder


def _request(argv):
    args = build_parser().parse_args(argv)
    args.argv = argv
    return case_request(args)


def test_the_command_line_becomes_one_request(case, tmp_path):
    subject_dir, photo_dir = case
    image = tmp_path / "b.png"
    image.write_bytes(b"")
    request = _request([
        "case", "--skull", str(subject_dir), "--photo", str(photo_dir), "--photo", str(image),
        "--photo-landmarks", "b.csv", "--view", "lateral_left", "--focal-px", "900", "1100",
        "--no-exif", "--generations", "7", "--method", "posest-sfo", "--method", "lilium",
        "--method", "posest-sfo", "--out", str(tmp_path / "out"),
    ])
    assert request.methods == ("posest-sfo", "lilium")  # repeated methods once, in order
    folder, plain = request.photos
    # The per-image options go to the images; a single --view to every photo (a folder's is
    # checked against its photo.json).
    assert folder == PhotoSource(photo_dir, view="lateral_left")
    assert plain == PhotoSource(image, landmarks=Path("b.csv"), view="lateral_left")
    assert request.priors.focal_px == (900.0, 1100.0) and not request.priors.use_exif
    assert request.options.de.max_generations == 7
    assert request.command.startswith("lilium case --skull ")
    record = request.to_dict()
    assert record["photos"][1]["landmarks"] == "b.csv"
    assert record["options"]["generations"] == 7 and record["skull"]["path"] == str(subject_dir)
    assert "command" not in record  # the report's command row holds it
    json.dumps(record)  # plain JSON values only
    with pytest.raises(ValueError, match="--mask given 2 times for 1 photo image"):
        _request(["case", "--skull", str(subject_dir), "--photo", str(image), "--mask", "a.png",
                  "--mask", "b.png", "--out", str(tmp_path / "out")])
    # Each command's default method, applied when --method is not given.
    base = ["--skull", str(subject_dir), "--photo", str(photo_dir), "--out", str(tmp_path / "o")]
    assert _request(["sfo", *base]).methods == ("posest-sfo",)
    assert _request(["case", *base]).methods == ("lilium",)


def test_sfo_reads_a_mesh_and_an_image_with_their_sidecar_files(files, tmp_path, capsys):
    out = tmp_path / "sfo"
    argv = ["sfo", "--skull", str(files / "skull.ply"), "--photo", str(files / "front.png"),
            "--out", str(out)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "skull: using cranial landmarks skull.json (found beside the mesh)" in printed
    assert "front: using facial landmarks front.csv (found beside the photo)" in printed
    result = json.loads((out / "result.json").read_text())
    assert result["method"] == "posest-sfo" and result["camera"] is not None
    _one_line_error(capsys, [*argv, "--method", "lilium", "--method", "posest-sfo"],
                    "--method given 2 times: lilium sfo runs one method")


def test_the_report_records_the_command_and_the_request(case, tmp_path):
    subject_dir, photo_dir = case
    out = tmp_path / "case"
    argv = ["case", "--skull", str(subject_dir), "--photo", str(photo_dir), "--method",
            "posest-sfo", "--out", str(out)]
    assert main(argv) == 0
    page = (out / "report.html").read_text()
    assert "lilium case --skull" in page  # the command line as typed
    assert "&quot;methods&quot;: [&quot;posest-sfo&quot;]" in page  # the request, as JSON


def test_a_script_runs_a_case_from_a_request(files, tmp_path):
    from lilium.casework.case import run_case

    request = CaseRequest(
        SkullSource(files / "skull.ply"), tmp_path / "script",
        photos=(PhotoSource(files / "front.png"),), methods=("posest-sfo",),
    )
    lines = []
    (entry,) = run_case(request, log=lines.append)
    assert entry.result and (tmp_path / "script" / "front" / "posest-sfo" / "result.json").is_file()
    assert any("found beside the photo" in line for line in lines)


def test_a_request_refuses_what_it_can_check_before_reading_a_file(tmp_path):
    # Nothing named here exists: the request's own faults come first, before any file is read.
    skull, out = SkullSource(tmp_path / "none.ply"), tmp_path / "out"
    one = (PhotoSource(tmp_path / "a.png"),)
    with pytest.raises(ValueError, match="unknown method 'bogus'"):
        CaseRequest(skull, out, photos=one, methods=("bogus",))
    with pytest.raises(ValueError, match="--joint needs two or more --photo"):
        CaseRequest(skull, out, photos=one, joint=True)
    two = (*one, PhotoSource(tmp_path / "b.png"))
    with pytest.raises(ValueError, match="--joint: none of the methods"):
        CaseRequest(skull, out, photos=two, methods=("posest-sfo",), joint=True)
    assert CaseRequest(skull, out, photos=two, joint=True).joint  # files are read later
