"""Where the commands write (tests/acceptance/hostile_outputs.py): never through a link left in
the output folder, one folder per photo whatever the photos are called, names the file system
refuses and file names that are not UTF-8 as one-line errors or reports, not tracebacks."""

import errno
import os

import pytest

from cli_helpers import _one_line_error, _run, _sfo
from lilium.casework.inputs import unique_id
from lilium.cli.argtypes import describe_os_error
from lilium.io.paths import MAX_ID_BYTES, check_no_links, safe_id
from standin_case import scaled_photo


@pytest.mark.parametrize("where", ["report.html", "a/b/overlay.png", "result.json.tmp"])
def test_a_link_inside_the_output_folder_is_refused_before_anything_runs(
    case, tmp_path, capsys, where
):
    out = tmp_path / "out"
    link = out / where
    link.parent.mkdir(parents=True)
    os.symlink(tmp_path / "victim.txt", link)  # dangling: a write would create it outside
    _one_line_error(capsys, _sfo(case, out, "--method", "posest-sfo"), link, "symbolic link")
    assert not (tmp_path / "victim.txt").exists() and not (out / "result.json").exists()


def test_a_linked_folder_inside_the_output_folder_is_refused(tmp_path):
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "out").mkdir()
    os.symlink(tmp_path / "elsewhere", tmp_path / "out" / "A", target_is_directory=True)
    with pytest.raises(ValueError, match="out/A is a symbolic link"):
        check_no_links(tmp_path / "out")
    check_no_links(tmp_path / "elsewhere")  # no link below it
    check_no_links(tmp_path / "not yet")  # nothing to check


def test_the_output_folder_itself_may_be_a_link(case, tmp_path, capsys):
    (tmp_path / "real").mkdir()
    os.symlink(tmp_path / "real", tmp_path / "out", target_is_directory=True)
    code, _, err = _run(_sfo(case, tmp_path / "out", "--method", "posest-sfo"), capsys)
    assert code == 0, err
    assert (tmp_path / "real" / "result.json").is_file()


@pytest.mark.parametrize("command", ["sfo", "case"])
def test_a_name_too_long_for_the_file_system_is_one_line(case, tmp_path, capsys, command):
    subject_dir, photo_dir = case
    out = tmp_path / ("x" * 300)
    argv = [command, "--skull", subject_dir, "--photo", photo_dir, "--out", out]
    _one_line_error(capsys, argv + ["--method", "posest-sfo"], "name is too long", "shorter path")


def test_os_errors_say_what_to_do():
    too_long = OSError(errno.ENAMETOOLONG, "File name too long", "a/b")
    assert describe_os_error(too_long) == "a/b: the name is too long; give a shorter path"
    other = OSError(errno.EIO, "Input/output error", "a/b")
    assert describe_os_error(other).startswith("a/b: Input/output error; check the path")
    assert "(OSError)" in describe_os_error(OSError(errno.EIO, "Input/output error"))


def test_ids_fit_the_file_system_and_utf8():
    emoji = safe_id("\N{GRINNING FACE}" * 70)  # 280 bytes in UTF-8
    assert len(emoji.encode()) <= MAX_ID_BYTES and emoji == "\N{GRINNING FACE}" * 50
    assert len(f"overlay_{emoji}.png.tmp".encode()) <= 255
    not_utf8 = os.fsdecode(b"caf\xe9")  # a Latin-1 folder name, as Python holds it
    assert safe_id(not_utf8) == "caf_"
    safe_id(not_utf8).encode("utf-8")  # can be written


def test_every_photo_gets_its_own_output_id():
    taken = set()
    for name, expected in [
        ("front", "front"),
        ("front", "front_2"),
        ("front_2", "front_2_2"),
        ("front", "front_3"),
    ]:
        assert unique_id(name, taken) == expected
        taken.add(expected)


def test_photos_named_front_front_and_front_2_write_three_folders(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    photos = [
        scaled_photo(photo_dir, tmp_path / "a" / "front", 0.9),
        scaled_photo(photo_dir, tmp_path / "b" / "front", 0.8),
        scaled_photo(photo_dir, tmp_path / "c" / "front_2", 0.7),
        scaled_photo(photo_dir, tmp_path / "d" / "report.html", 0.6),  # the case's own name
    ]
    out = tmp_path / "out"
    argv = ["case", "--skull", subject_dir, "--method", "posest-sfo", "--out", out]
    code, _, err = _run(argv + [x for p in photos for x in ("--photo", p)], capsys)
    assert code == 0, err
    for photo_id in ("front", "front_2", "front_2_2", "report.html_2"):
        assert (out / photo_id / "posest-sfo" / "result.json").is_file(), photo_id
    assert (out / "report.html").is_file()


def test_a_photo_folder_name_that_is_not_utf8_gets_a_report(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    other = scaled_photo(photo_dir, tmp_path / os.fsdecode(b"caf\xe9"), 0.8)
    out = tmp_path / "out"
    argv = ["case", "--skull", subject_dir, "--photo", other, "--method", "posest-sfo"]
    code, _, err = _run(argv + ["--out", out], capsys)
    assert code == 0, err
    assert (out / "caf_" / "posest-sfo" / "result.json").is_file()
    assert "caf\N{REPLACEMENT CHARACTER}" in (out / "report.html").read_text(encoding="utf-8")


def test_a_write_error_without_a_file_name_gets_the_written_path(tmp_path, monkeypatch):
    from pathlib import Path

    from lilium.io.jsonio import write_json

    def too_large(self, text, *args, **kwargs):
        raise OSError(errno.EFBIG, "File too large")  # what write() says: no file name

    monkeypatch.setattr(Path, "write_text", too_large)
    with pytest.raises(OSError) as caught:
        write_json(tmp_path / "result.json", {"a": 1})
    assert caught.value.filename == str(tmp_path / "result.json")
    assert list(tmp_path.iterdir()) == []  # no temporary file left


def test_an_sfo_leaves_no_overlay_of_an_earlier_one(case, tmp_path, capsys):
    subject_dir, photo_dir = case
    other = scaled_photo(photo_dir, tmp_path / "b" / "other", 0.8)
    out = tmp_path / "out"
    joint = ["sfo", "--skull", subject_dir, "--photo", photo_dir, "--photo", other]
    tiny = ["--method", "lilium", "--generations", "2", "--population", "5", "--out", out]
    code, _, err = _run(joint + tiny, capsys)
    assert code == 0, err
    assert len(list(out.glob("overlay_*.png"))) == 2
    code, _, err = _run(_sfo(case, out, "--method", "posest-sfo"), capsys)  # one photo, after
    assert code == 0, err
    assert not list(out.glob("overlay_*.png")) and (out / "overlay.png").is_file()
    code, _, err = _run(joint + tiny, capsys)  # the joint SFO again, after the single one
    assert code == 0, err
    assert not (out / "overlay.png").exists() and len(list(out.glob("overlay_*.png"))) == 2


def test_a_candidate_name_cannot_rewrite_the_terminal_line(case, tmp_path, capsys):
    _, photo_dir = case
    name = "A\u202eB\nC"  # a right-to-left override and a newline
    argv = ["lineup", "--no-progress", "--skull", case[0], "--candidate", name, photo_dir]
    code, stdout, err = _run(argv + ["--method", "posest-sfo", "--out", tmp_path / "out"], capsys)
    assert code == 0, err
    (line,) = [ln for ln in stdout.splitlines() if ln.startswith("1. ")]
    assert line.startswith("1. A\\u202eB\\u000aC (posest-sfo): ")
