"""A command never writes over its own inputs, and user text in a page is never read as part of
its template: the review page's placeholders are filled in one pass (a photo named
``a__W__.png``), ``lilium photo`` refuses a photo that is one of the files it writes in --out,
``lilium report`` a database that one of its files would overwrite."""

import html
import json
import os
import re

import numpy as np
import pytest
from PIL import Image

from lilium.cli.main import main
from lilium.experiments.report import REPORT_FILES, write_report
from lilium.experiments.store import ResultStore
from lilium.photo.folder import check_photo_not_output
from lilium.photo.review import fill_template, review_page, script_json

#: Text a user controls (a file name, a folder) that looks like the review page's template.
HOSTILE = 'a__W____DATA____TITLE__</script><!--&".png'


def _page(title=HOSTILE, message=f"written to out/{HOSTILE}", priors=None):
    image = np.full((40, 60, 3), 128, np.uint8)
    sources = {"pronasale": {"source": "automatic", "quality": "tracked"}}
    priors = {"note": "</script><script>alert(1)</script>"} if priors is None else priors
    outline = np.array([[1.0, 1.0], [50.0, 1.0], [50.0, 30.0]])
    return review_page(image, {"pronasale": (30, 20)}, sources, outline, priors, title, message)


def _page_data(page):
    """The JSON the page's script reads, parsed back."""
    found = re.search(r"const DATA = (.*);\n", page)
    assert found, "no DATA in the page"
    return json.loads(found.group(1))


# -- the review page ---------------------------------------------------------------------------


def test_a_placeholder_in_the_title_or_message_stays_as_written():
    page = _page()
    shown = html.escape(HOSTILE)
    assert f"<title>Review: {shown}</title>" in page
    assert f"<h3>{shown}</h3>" in page
    assert f"<p>written to out/{shown}</p>" in page
    assert 'viewBox="-0.5 -0.5 60 40"' in page  # the page's own placeholders are filled


def test_json_in_the_script_cannot_close_it():
    priors = {"note": "</script><script>alert(1)</script>", "amp": "a & b <!-- c -->"}
    page = _page(priors=priors)
    assert page.count("</script>") == 1 and "<!--" not in page
    assert _page_data(page)["priors"] == priors


def test_fill_template_never_rescans_a_value():
    values = {"__A__": "__B__", "__B__": "__A__", "__AB__": "x"}
    assert fill_template("__A__ __B__ __AB__ __C__", values) == "__B__ __A__ x __C__"


def test_script_json_reads_back_the_same_value():
    value = {"</script>": ["<!--", "&amp;", "\u2028", "é"]}
    text = script_json(value)
    assert not set("<>&\u2028") & set(text)
    assert json.loads(text) == value


# -- lilium photo: the photo is one of its outputs ---------------------------------------------


def test_the_photo_may_be_the_folder_s_own_image_but_no_other_output(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "image.png").write_bytes(b"png")
    check_photo_not_output(out, out / "image.png", "image.png")  # copied unchanged: kept
    with pytest.raises(ValueError, match=r"image.png, a file lilium photo writes in --out"):
        check_photo_not_output(out, out / "image.png", None)  # the turned copy would replace it
    elsewhere = tmp_path / "photo.jpg"
    os.link(out / "image.png", elsewhere)  # the same file under a JPEG name
    with pytest.raises(ValueError, match="give another --out or rename the photo"):
        check_photo_not_output(out, elsewhere, "image.jpg")


def test_lilium_photo_refuses_its_own_face_mask_as_the_photo(tmp_path, capsys):
    pytest.importorskip("ai_edge_litert")
    from skimage import data

    out = tmp_path / "out"
    out.mkdir()
    photo = out / "face_mask.png"
    Image.fromarray(data.astronaut()).save(photo)
    before = photo.read_bytes()
    assert main(["photo", str(photo), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"{photo}: the photo is {photo}" in err[0], err
    assert "give another --out or rename the photo" in err[0]
    assert photo.read_bytes() == before
    assert sorted(p.name for p in out.iterdir()) == ["face_mask.png"]


# -- lilium report: the database is one of its outputs -----------------------------------------


@pytest.fixture
def rows():
    from report_rows import make_rows

    return make_rows()


def _database(path, rows):
    with ResultStore(path) as store:
        for row in rows:
            assert store.insert(row)
    return path


@pytest.mark.parametrize("name", ["summary.csv", "report.md", ".lilium-write-test"])
def test_lilium_report_refuses_a_database_it_would_overwrite(tmp_path, capsys, rows, name):
    db = _database(tmp_path / name, rows)
    before = db.read_bytes()
    assert main(["report", str(db), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert f"--out {tmp_path}: lilium report writes {name} there, over the database {db}" in err[0]
    assert "give another --out" in err[0]
    assert db.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]


def test_a_link_to_the_database_in_out_is_refused(tmp_path, rows):
    db = _database(tmp_path / "r.sqlite", rows)
    out = tmp_path / "out"
    out.mkdir()
    (out / "ranks.csv").symlink_to(db)
    with pytest.raises(ValueError, match="writes ranks.csv there, over the database"):
        write_report(db, out)


def test_report_files_lists_every_file_the_report_writes(tmp_path, rows):
    db = _database(tmp_path / "r.sqlite", rows)
    write_report(db, tmp_path / "out")
    written = {p.name for p in (tmp_path / "out").iterdir()}
    assert written <= set(REPORT_FILES), written - set(REPORT_FILES)
