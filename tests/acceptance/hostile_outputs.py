"""Hostile-output probes, tested (issue 28): what the commands write and
where, for ``lilium case``, ``lineup``, ``sfo``, ``report`` and ``photo`` (its review page).

- Hostile text reaching the HTML pages: a ``--title``, candidate names, photo folder and file
  names, EXIF text, with ``<script>``, ``<img onerror>``, quotes, ``&``, ``</td>``, RTL marks,
  newlines, names that are not UTF-8 and names longer than a file name may be. Each page is
  parsed (one ``<script>`` of its own, no ``on*`` attribute, the text shown as written) and,
  where Chromium is installed, loaded headless: a payload that runs marks ``<body>``.
- The output folder: ``--out`` a file, a path too long for the file system, with spaces and
  unicode, the photo's or the skull's folder; two photos whose output folders would collide;
  a photo folder named like the report; a lineup resumed after its photo, skull or budget
  changed under the same names (a stored SFO of other inputs must not be reused).
- Links inside ``--out`` where a command writes (``report.html``, ``overlay.png``, the temporary
  ``result.json.tmp``, a candidate's folder, ``lilium report``'s write test, ``lilium photo``'s
  ``review.html``): the file outside that they point to is in the probe's folder, so writing
  through the link shows as a write outside ``--out``.

Budgets: POSEST-SFO, or Lilium with 5 x 2 (the joint and budget probes).
"""

import json
import os
import re
import shutil
from html.parser import HTMLParser

from hostile_casework import TINY, _inputs_kept, _quiet_main, _second_photo
from hostile_machinery import Probe, _then

#: Runs in a browser it is loaded in: marks ``<body>`` (checked with Chromium's ``--dump-dom``).
PWN = "<img src=x onerror=document.body.setAttribute('data-pwned',1)>"
#: The same without ``/``, so it can name a folder; and one with a script element.
SCRIPT = "<script>document.body.setAttribute('data-pwned',2)</script>"
NASTY = f"{SCRIPT} \"q\" 'a' & </td></tr></table> \u202eRTL\u202c end"


def _in(ws, *parts):
    return ws.root.joinpath("in", *parts)


# -- checks of the pages ----------------------------------------------------------------------


class _Page(HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.scripts, self.handlers, self.text = 0, [], []

    def handle_starttag(self, tag, attrs):
        self.scripts += tag == "script"
        self.handlers += [f"<{tag} {k}=...>" for k, _ in attrs if k.lower().startswith("on")]

    def handle_data(self, data):
        self.text.append(data)


def _browser_problem(ws, page):
    """What Chromium saw run in ``page`` (None when nothing, or no Chromium here)."""
    try:
        from browser import CHROMIUM, run_chromium
    except ImportError:  # pytest missing: the parser's check stands alone
        return None
    if CHROMIUM is None:
        return None
    profile = ws.root / "chromium"
    profile.mkdir(exist_ok=True)
    try:
        dom = run_chromium("--dump-dom", page.resolve().as_uri(), tmp_path=profile).stdout
    except Exception as exc:  # noqa: BLE001 - a browser that fails says nothing of the page
        return f"chromium failed on {page.name}: {exc!r}"[:200]
    ran = re.search(r"<body[^>]*\sdata-pwned=", dom)  # the payloads' text, escaped, is no mark
    return f"{page.name}: a payload ran in Chromium" if ran else None


def _page_safe(relpath, *shown, scripts=1):
    """Check: ``out/<relpath>`` has ``scripts`` script elements, no ``on*`` attribute, shows each
    text of ``shown`` as written, and runs no payload in Chromium."""

    def check(ws):
        page = ws.out / relpath
        if not page.is_file():
            return f"no {relpath}"
        parser = _Page()
        parser.feed(page.read_text(encoding="utf-8"))
        if parser.scripts != scripts or parser.handlers:
            return f"{relpath}: {parser.scripts} <script>, handlers {parser.handlers[:3]}"
        text = "".join(parser.text)
        missing = [s for s in shown if s not in text]
        if missing:
            return f"{relpath}: does not show {missing[0]!r}"
        return _browser_problem(ws, page)

    return check


def _all(*checks):
    def check(ws):
        return next((p for p in (c(ws) for c in checks) if p), None)

    return check


def _lineup_names(*names):
    def check(ws):
        try:
            data = json.loads((ws.out / "lineup.json").read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            return f"lineup.json unreadable: {exc}"
        got = sorted(e["candidate"] for e in data["ranking"])
        return None if got == sorted(names) else f"lineup.json candidates {got}"

    return check


def _results(n, under=""):
    """Check: ``n`` distinct ``result.json`` under ``out/<under>``, each of its own photo."""

    def check(ws):
        found = sorted((ws.out / under).rglob("result.json"))
        photos = {json.loads(p.read_text())["photo"] for p in found}
        if len(found) != n or len(photos) != n:
            return f"{len(found)} result.json for {n} photos ({sorted(photos)})"
        return None

    return check


def _report_written(ws):
    page = ws.out / "report.html"
    return None if page.is_file() and not page.is_symlink() else "no report.html of its own"


# -- set-ups ----------------------------------------------------------------------------------


def _rename_photo(name):
    """Set-up: the stand-in photo folder renamed ``name`` (``ws.photo`` follows)."""

    def setup(ws):
        target = ws.photo.parent / name
        os.rename(ws.photo, target)
        ws.photo = target

    return setup


def _link(where, target, directory=False):
    """Set-up: ``out/<where>`` a link to ``<probe folder>/<target>`` (made when it is a file
    that must exist; left dangling when ``target`` ends with ``?``)."""

    def setup(ws):
        dangling = target.endswith("?")
        aim = ws.root / target.rstrip("?")
        if directory:
            aim.mkdir(parents=True, exist_ok=True)
        elif not dangling:
            aim.write_text("a file outside --out\n")
        link = ws.out / where
        link.parent.mkdir(parents=True, exist_ok=True)
        link.symlink_to(aim, target_is_directory=directory)

    return setup


def _lineup(*candidates, extra=(), method="posest-sfo"):
    """``lilium lineup``; each candidate ``(name, photo, ...)``, a photo a callable of ``ws``."""

    def argv(ws):
        out = ["lineup", "--no-progress", "--skull", ws.skull, "--out", ws.out, "--method", method]
        for name, *photos in candidates:
            out += ["--candidate", name, *(p(ws) for p in photos)]
        return out + list(extra)

    return argv


def _P(ws):
    return ws.photo


def _case(*extra, photos=None, out=None):
    """``lilium case`` (POSEST-SFO) of ``photos`` (callables of ``ws``; default the stand-in's)
    into ``out(ws)`` (default ``ws.out``)."""

    def argv(ws):
        found = [ws.photo] if photos is None else [p(ws) for p in photos]
        where = ws.out if out is None else out(ws)
        return [
            "case",
            "--skull",
            ws.skull,
            *(a for p in found for a in ("--photo", p)),
            "--out",
            where,
            "--method",
            "posest-sfo",
            *extra,
        ]  # noqa: E501

    return argv


def _colliding_photos(ws):
    """Set-up: ``in/a/front`` (the stand-in), ``in/b/front`` (at half size) and ``in/c/front_2``
    (at 3/4): three different photos; the case names the second ``front_2``."""
    from standin_case import scaled_photo

    shutil.copytree(ws.photo, _in(ws, "a", "front"))
    scaled_photo(ws.photo, _in(ws, "b", "front"), 0.5)
    scaled_photo(ws.photo, _in(ws, "c", "front_2"), 0.75)


_COLLIDING = [
    lambda ws: _in(ws, "a", "front"),
    lambda ws: _in(ws, "b", "front"),
    lambda ws: _in(ws, "c", "front_2"),
]  # noqa: E501


def _exif_photo(ws):
    """Set-up: the stand-in photo as ``image.jpg`` with hostile EXIF text (an editing program
    in ``Software``, so its text reaches the warnings) and no focal prior in ``photo.json``."""
    from PIL import Image

    image = Image.open(ws.photo / "image.png").convert("RGB")
    exif = Image.Exif()
    exif[0x0131] = f"Adobe Photoshop {NASTY}"
    exif[0x010F] = f"Canon{PWN}"
    exif[0x0110] = "EOS <b>5D</b>"
    exif[0x8769] = {0x920A: (50, 1), 0xA405: 50}
    image.save(ws.photo / "image.jpg", exif=exif, quality=95)
    (ws.photo / "image.png").unlink()
    ws.edit(ws.photo / "photo.json", lambda d: d["priors"].pop("focal_px", None))


def _astronaut(name, folder=("in",)):
    def setup(ws):
        from hostile_inputs import _astronaut as face
        from hostile_inputs import _pil

        path = ws.root.joinpath(*folder, name)
        path.parent.mkdir(parents=True, exist_ok=True)
        _pil(face()).save(path)

    return setup


# -- lineup resumed over changed inputs -------------------------------------------------------


def _stored_lineup_result(ws, out=None):
    found = sorted((out or ws.out).joinpath("A").rglob("result.json"))
    return json.loads(found[0].read_text())


def _fresh_lineup(*extra, method="posest-sfo"):
    """Check: the resumed lineup's stored SFO is the one a fresh lineup of the same command
    computes (fitness and focal), not the SFO of the inputs that were there before."""

    def check(ws):
        fresh = ws.root / "fresh"
        argv = _lineup(("A", _P), extra=extra, method=method)(ws)
        argv[argv.index("--out") + 1] = fresh
        if _quiet_main(argv) != 0:
            return "the fresh lineup failed"
        old, new = _stored_lineup_result(ws), _stored_lineup_result(ws, fresh)
        same = abs(old["fitness"] - new["fitness"]) <= 1e-9 * max(1.0, abs(new["fitness"]))
        if not same:
            return (
                f"reused a stored SFO of other inputs: fitness {old['fitness']:.6g}, focal "
                f"{old['camera']['focal_px']:.0f} px; a fresh run: {new['fitness']:.6g}, "
                f"{new['camera']['focal_px']:.0f} px"
            )
        return None

    return check


def _prior_lineup(*extra, method="posest-sfo"):
    return lambda ws: _quiet_main(_lineup(("A", _P), extra=extra, method=method)(ws))


def _swap_photo(ws):
    """The photo folder now holds another photo (the stand-in at half size), same name."""
    from standin_case import scaled_photo

    other = scaled_photo(ws.photo, _in(ws, "half"), 0.5)
    shutil.rmtree(ws.photo)
    shutil.copytree(other, ws.photo)


# -- the report database (lilium report) ------------------------------------------------------


def _report_db(ws):
    from hostile_runs import _report_db as make

    make()(ws)


# One probe a line: the tables read better than the formatter's 1000 lines.
# fmt: off


def html_probes():
    """Hostile text reaching the HTML pages (and the JSON written beside them)."""
    names = (f"{SCRIPT}x", f"B \"'&</td>\u202e\nnew line{PWN}")
    emoji = "\U0001f600" * 70
    return [
        Probe("outputs case hostile --title", _case("--title", f"{NASTY}\n{PWN}"), "ok", (), check=_page_safe("report.html", NASTY)),  # noqa: E501
        Probe("outputs case hostile photo folder name", _case(), "ok", (), _rename_photo(f"p{PWN} \"'&\u202e"), check=_page_safe("report.html")),  # noqa: E501
        Probe("outputs case hostile EXIF text", _case(), "ok", (), _exif_photo, check=_page_safe("report.html", "Adobe Photoshop <script>")),  # noqa: E501
        Probe("outputs lineup hostile candidate names", _lineup((names[0], _P), (names[1], lambda ws: _in(ws, "photos", "p2"))), "ok", (), _second_photo(), check=_all(_lineup_names(*names), _page_safe("report.html", names[0]))),  # noqa: E501
        Probe("outputs lineup candidate name of 70 emoji (280 bytes)", _lineup((emoji, _P)), "ok", (), check=_lineup_names(emoji)),  # noqa: E501
        Probe("outputs lineup candidate name not UTF-8", _lineup(("B\udcff", _P)), "ok", (), check=_report_written),  # noqa: E501
        Probe("outputs case photo folder name not UTF-8", _case(), "ok", (), _rename_photo("caf\udce9"), check=_report_written),  # noqa: E501
        Probe("outputs sfo joint photo folder of 62 emoji (248 bytes)", lambda ws: ["sfo", "--skull", ws.skull, "--photo", ws.photo, "--photo", _in(ws, "photos", "\U0001f600" * 62), "--out", ws.out, "--method", "lilium", *TINY], "ok", (), _second_photo("\U0001f600" * 62), check=lambda ws: None if len(list(ws.out.glob("overlay_*.png"))) == 2 else "not 2 overlays"),  # noqa: E501
        Probe("outputs photo file named a__W__.png", lambda ws: ["photo", _in(ws, "a__W__.png"), "--out", ws.out], "ok", (), _astronaut("a__W__.png"), "photo", check=_page_safe("review.html", "a__W__.png")),  # noqa: E501
        Probe("outputs photo file named a__DATA__.png", lambda ws: ["photo", _in(ws, "a__DATA__.png"), "--out", ws.out], "ok", (), _astronaut("a__DATA__.png"), "photo", check=_page_safe("review.html", "a__DATA__.png")),  # noqa: E501
        Probe("outputs photo hostile file name", lambda ws: ["photo", _in(ws, f"{PWN}'\"&.png"), "--out", ws.out], "ok", (), _astronaut(f"{PWN}'\"&.png"), "photo", check=_page_safe("review.html", f"{PWN}'\"&.png")),  # noqa: E501
    ]


def folder_probes():
    """``--out``: a file, too long, unusual names, an input's folder, colliding outputs."""
    long_name = "x" * 300  # in an existing folder: the long name itself is checked
    made_out = lambda ws: ws.out.mkdir()  # noqa: E731

    def db_named(name):  # the database in the folder --out names, under a name report writes
        def setup(ws):
            _report_db(ws)
            _in(ws, "r.sqlite").rename(_in(ws, name))
            ws.out = _in(ws)
        return setup
    deep = "/".join(["d" * 200] * 22)  # 4.4 kB: over PATH_MAX
    report_html = lambda ws: _in(ws, "photos", "report.html")  # noqa: E731

    def out_is(path):
        def setup(ws):
            ws.out = path(ws)
        return setup

    def skull_kept(ws):
        changed = [f.name for f in (ws.base / "subjects" / "standin").iterdir() if (ws.skull / f.name).read_bytes() != f.read_bytes()]  # noqa: E501
        return f"skull files rewritten: {changed}" if changed else None
    return [
        Probe("outputs case --out a file", lambda ws: ["case", "--skull", ws.skull, "--photo", ws.photo, "--out", ws.photo / "photo.json", "--method", "posest-sfo"], "error", ("--out",)),  # noqa: E501
        Probe("outputs lineup --out a file", lambda ws: ["lineup", "--no-progress", "--skull", ws.skull, "--candidate", "A", ws.photo, "--out", ws.photo / "photo.json", "--method", "posest-sfo"], "error", ("--out",)),  # noqa: E501
        Probe("outputs photo --out a file", lambda ws: ["photo", ws.photo / "image.png", "--out", ws.photo / "photo.json"], "error", ("--out",), None, "photo"),  # noqa: E501
        Probe("outputs report --out a file", lambda ws: ["report", _in(ws, "r.sqlite"), "--out", ws.photo / "photo.json"], "error", ("--out",), _report_db),  # noqa: E501
        Probe("outputs case --out a 300-character name", _case(out=lambda ws: ws.out / long_name), "error", ("--out",), made_out),  # noqa: E501
        Probe("outputs sfo --out a 300-character name", lambda ws: ["sfo", "--skull", ws.skull, "--photo", ws.photo, "--out", ws.out / long_name, "--method", "posest-sfo"], "error", ("--out",), made_out),  # noqa: E501
        Probe("outputs lineup --out a 300-character name", lambda ws: ["lineup", "--no-progress", "--skull", ws.skull, "--candidate", "A", ws.photo, "--out", ws.out / long_name, "--method", "posest-sfo"], "error", ("--out",), made_out),  # noqa: E501
        Probe("outputs case --out over PATH_MAX", _case(out=lambda ws: ws.out / deep), "error", ("--out",)),  # noqa: E501
        Probe("outputs case --calibration a 300-character name", _case("--calibration", long_name), "error", ("--calibration",)),  # noqa: E501
        Probe("outputs case --out with spaces and unicode", _case(out=lambda ws: ws.out / "my case é 😀 $HOME"), "ok", (), check=lambda ws: None if (ws.out / "my case é 😀 $HOME" / "report.html").is_file() else "no report.html"),  # noqa: E501
        Probe("outputs case --out the photo folder", _case(), "ok", (), out_is(lambda ws: ws.photo), check=_inputs_kept),  # noqa: E501
        Probe("outputs case --out the skull folder", _case(), "ok", (), out_is(lambda ws: ws.skull), check=skull_kept),  # noqa: E501
        Probe("outputs case photo ids collide (front, front, front_2)", _case(photos=_COLLIDING), "ok", (), _colliding_photos, check=_results(3)),  # noqa: E501
        Probe("outputs lineup photo ids collide (front, front, front_2)", _lineup(("A", *_COLLIDING)), "ok", (), _colliding_photos, check=_results(3, "A")),  # noqa: E501
        Probe("outputs case photo folder named report.html", _case(photos=[report_html]), "ok", (), lambda ws: shutil.copytree(ws.photo, report_html(ws)), check=is_file("report.html_2/posest-sfo/result.json")),  # noqa: E501
        Probe("outputs case --out holding another method's result", _case(), "ok", (), lambda ws: _quiet_main(["case", "--skull", ws.skull, "--photo", ws.photo, "--out", ws.out, "--method", "lilium", *TINY]), check=lambda ws: "report links the old lilium result" if "lilium-skof+pll" in (ws.out / "report.html").read_text() else None),  # noqa: E501
        Probe("outputs lineup resumed with another photo of the same name", _lineup(("A", _P)), "ok", (), _then(_prior_lineup(), _swap_photo), check=_fresh_lineup()),  # noqa: E501
        Probe("outputs report --out would overwrite the database", lambda ws: ["report", _in(ws, "summary.csv"), "--out", _in(ws)], "error", ("--out", "summary.csv"), db_named("summary.csv")),  # noqa: E501
        Probe("outputs photo input is face_mask.png in --out", lambda ws: ["photo", ws.out / "face_mask.png", "--out", ws.out], "error", ("face_mask.png",), _astronaut("face_mask.png", ("out",)), "photo"),  # noqa: E501
    ]


def is_file(name):
    """A check: ``--out/name`` is a file of its own (not a link)."""
    return lambda ws: None if (ws.out / name).is_file() and not (ws.out / name).is_symlink() else f"{name} not a file of its own"  # noqa: E501


def link_probes():
    """Links inside ``--out`` where a command writes, pointing outside it."""
    sfo = lambda *extra: lambda ws: ["sfo", "--skull", ws.skull, "--photo", ws.photo, "--out", ws.out, "--method", "posest-sfo", *extra]  # noqa: E501, E731
    report = lambda ws: ["report", _in(ws, "r.sqlite"), "--out", ws.out]  # noqa: E731
    photo = lambda ws: ["photo", _in(ws, "face.png"), "--out", ws.out]  # noqa: E731
    return [
        Probe("outputs case report.html a link outside", _case(), "error", ("symbolic link",), _link("report.html", "victim.txt")),  # noqa: E501
        Probe("outputs case overlay.png a dangling link outside", _case(), "error", ("symbolic link",), _link("standin_frontal/posest-sfo/overlay.png", "created.png?")),  # noqa: E501
        Probe("outputs sfo overlay.png a link outside", sfo(), "error", ("symbolic link",), _link("overlay.png", "victim.png")),  # noqa: E501
        Probe("outputs sfo result.json.tmp a link outside", sfo(), "error", ("symbolic link",), _link("result.json.tmp", "victim.txt")),  # noqa: E501
        Probe("outputs lineup report.html a link outside", _lineup(("A", _P)), "error", ("symbolic link",), _link("report.html", "victim.txt")),  # noqa: E501
        Probe("outputs lineup candidate folder a link outside", _lineup(("A", _P)), "error", ("A",), _link("A", "elsewhere", directory=True)),  # noqa: E501
        Probe("outputs report summary.csv a link outside", report, "error", ("symbolic link",), _then(_report_db, _link("summary.csv", "victim.txt"))),  # noqa: E501
        Probe("outputs report write test a link outside", report, "error", ("symbolic link",), _then(_report_db, _link(".lilium-write-test", "victim.txt"))),  # noqa: E501
        Probe("outputs photo review.html a dangling link outside", photo, "error", ("symbolic link",), _then(_astronaut("face.png"), _link("review.html", "created.html?")), "photo"),  # noqa: E501
    ]


# fmt: on


def output_probes():
    return html_probes() + folder_probes() + link_probes()
