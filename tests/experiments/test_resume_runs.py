"""Long runs resume after a crash and never run on a wrong dataset: ``lilium experiment`` with
experiments added or dropped, a killed ``lilium synth`` over an older dataset, a full disk under
the results database, and writes refused inside the PNG and mesh writers."""

import errno
import json
import shutil
import sqlite3

import pytest
from test_experiments import db_keys, write_config

from lilium.cli.main import main
from lilium.experiments import runner
from lilium.experiments.config import load_config
from lilium.experiments.dataset import dataset_fingerprint
from lilium.experiments.store import ResultStore, database_error
from lilium.synthetic import dataset as ds
from lilium.synthetic.incomplete import curve_kept
from lilium.synthetic.toyhead import make_toy_subject, write_toy_subject
from standin_case import toy_dataset

#: POSEST-SFO only (deterministic, fast).
POSEST_ONLY = ('methods = ["posest-sfo", "lilium:base"]', 'methods = ["posest-sfo"]')

#: SFOs per experiment: 2 subjects x (1 frontal + 1 lateral photo) x 2 skulls.
PER_EXPERIMENT = 8


def _generate(out, seed=3, writer=write_toy_subject, **kwargs):
    return toy_dataset(out, seed, subject_writer=writer, **kwargs)


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("resume-ds")
    _generate(out, experiments=("A", "B"))
    return out


def _config(folder, dataset, experiments):
    """A POSEST-SFO config in ``folder/<experiments>/`` (one file per experiment list)."""
    path = write_config(folder / "".join(experiments), dataset, experiments=experiments)
    path.write_text(path.read_text().replace(*POSEST_ONLY))
    return path


def _experiment(capsys, config, db):
    """``lilium experiment`` -> (exit status, stderr); an error is one line."""
    status = main(["experiment", str(config), "--no-progress", "--db", str(db)])
    err = capsys.readouterr().err
    if status == 2:
        assert len(err.strip().splitlines()) == 1, err
    return status, err


def _edit_landmark(photo_dir):
    path = photo_dir / "photo.json"
    data = json.loads(path.read_text())
    name = sorted(data["landmarks"])[0]
    data["landmarks"][name][0] += 1.0
    path.write_text(json.dumps(data))


# -- D4: the dataset fingerprint covers the whole dataset ----------------------------------------
def test_experiments_added_and_dropped_resume_one_database(dataset, tmp_path, capsys):
    db = tmp_path / "r.sqlite"
    assert _experiment(capsys, _config(tmp_path, dataset, ("A",)), db)[0] == 0
    assert len(db_keys(db)) == PER_EXPERIMENT
    assert _experiment(capsys, _config(tmp_path, dataset, ("A", "B")), db)[0] == 0
    assert len(db_keys(db)) == 2 * PER_EXPERIMENT
    assert _experiment(capsys, _config(tmp_path, dataset, ("B",)), db)[0] == 0
    assert len(db_keys(db)) == 2 * PER_EXPERIMENT
    # A real change of the dataset is still refused, also in a folder the config does not read.
    data = tmp_path / "edited"
    shutil.copytree(dataset, data)
    _edit_landmark(data / "photos" / "B" / "s01_f00")
    status, err = _experiment(capsys, _config(tmp_path, data, ("A",)), db)
    assert status == 2 and str(db) in err and "holds results of another dataset" in err
    assert len(db_keys(db)) == 2 * PER_EXPERIMENT


def _as_made_before(db, root, experiments):
    """Make ``db`` look written before whole-dataset fingerprints: the fingerprint of the
    folders the tasks of ``experiments`` read, no scope."""
    cfg = load_config(str(_config(db.parent / "made-before", root, experiments)))
    _, index = runner.load_dataset(cfg)
    tasks = runner.enumerate_tasks(cfg, root, index)
    with ResultStore(db) as store:
        store.set_meta(runner.DATASET_FINGERPRINT_KEY, dataset_fingerprint(root, index, tasks))
        with store.conn:
            store.conn.execute("DELETE FROM meta WHERE key = ?", (runner.DATASET_SCOPE_KEY,))


def test_database_of_the_earlier_fingerprint_resumes(dataset, tmp_path, capsys):
    db = tmp_path / "r.sqlite"
    config_a = _config(tmp_path, dataset, ("A",))
    assert _experiment(capsys, config_a, db)[0] == 0
    _as_made_before(db, dataset, ("A",))
    # Other experiments than it was made with: refused, saying what to do.
    status, err = _experiment(capsys, _config(tmp_path, dataset, ("A", "B")), db)
    assert status == 2 and "resume it once with the experiments it was made with" in err
    # Its own experiments: accepted, and the whole-dataset fingerprint recorded ...
    assert _experiment(capsys, config_a, db)[0] == 0
    with ResultStore(db) as store:
        assert store.get_meta(runner.DATASET_SCOPE_KEY) == runner.WHOLE_DATASET
    # ... so that the next run may add an experiment.
    assert _experiment(capsys, _config(tmp_path, dataset, ("A", "B")), db)[0] == 0
    assert len(db_keys(db)) == 2 * PER_EXPERIMENT


# -- D5: a killed synth over an older dataset leaves no index ------------------------------------
class _Killed(Exception):
    """Stands for the SIGKILL of a ``lilium synth`` in the middle of its subjects."""


def _writer_killed_at(subject_id):
    def writer(folder, subject):
        if folder.name == subject_id:
            raise _Killed
        write_toy_subject(folder, subject)

    return writer


def test_killed_synth_over_an_older_dataset_is_refused(tmp_path, capsys, monkeypatch):
    data = tmp_path / "data"
    _generate(data, seed=0, experiments=("A",))
    with pytest.raises(_Killed):
        _generate(data, seed=1, experiments=("A",), writer=_writer_killed_at("s02"))
    assert not (data / "dataset.json").exists()  # s01 of seed 1 beside s02 of seed 0
    status, err = _experiment(capsys, _config(tmp_path, data, ("A",)), tmp_path / "r.sqlite")
    assert status == 2 and "unfinished dataset" in err and str(data / "dataset.json") in err
    # With dataset.generate = true the runner generates it again, whole.
    config = _config(tmp_path, data, ("A",))
    generate = "generate = true\nsubjects = 2\nphotos = 1\nseed = 5"
    config.write_text(config.read_text().replace("generate = false", generate))
    monkeypatch.setattr(ds, "_default_subject_api", lambda: (make_toy_subject, write_toy_subject))
    assert _experiment(capsys, config, tmp_path / "r.sqlite")[0] == 0
    assert json.loads((data / "dataset.json").read_text())["seed"] == 5


def test_regenerating_removes_a_stale_face_curve(tmp_path):
    data = tmp_path / "data"
    _generate(data, experiments=("A",))
    index = _generate(data, experiments=("A",), drop_landmark_rate=0.9)
    kept = {
        p["id"]: curve_kept(p["view"], p.get("unmarked_landmarks", ())) for p in index["photos"]
    }
    assert not all(kept.values())  # the case this test is about
    for photo in index["photos"]:
        curve = data / photo["paths"]["A"] / "face_curve.json"
        assert curve.is_file() == kept[photo["id"]]


# -- D8: a full disk under the results database -------------------------------------------------
def test_full_disk_during_experiment_keeps_the_database(dataset, tmp_path, capsys, monkeypatch):
    db = tmp_path / "r.sqlite"
    config = _config(tmp_path, dataset, ("A",))
    opened = ResultStore._open

    def full_after_open(store):  # no page more than at the start: SQLITE_FULL on the 1st row
        opened(store)
        pages = store.conn.execute("PRAGMA page_count").fetchone()[0]
        store.conn.execute(f"PRAGMA max_page_count = {pages}")

    monkeypatch.setattr(ResultStore, "_open", full_after_open)
    status, err = _experiment(capsys, config, db)
    assert status == 2 and str(db) in err
    assert "could not write (disk full or a file-size limit" in err
    assert "run the same command again to resume" in err and "corrupt" not in err
    monkeypatch.setattr(ResultStore, "_open", opened)
    assert _experiment(capsys, config, db)[0] == 0
    assert len(db_keys(db)) == PER_EXPERIMENT


def test_database_error_tells_a_refused_write_from_a_damaged_file(tmp_path):
    db = tmp_path / "r.sqlite"
    db.write_bytes(b"not a database\n" * 100)
    with pytest.raises(sqlite3.DatabaseError) as damaged:
        sqlite3.connect(db).execute("SELECT 1 FROM sqlite_master").fetchall()
    assert "corrupt, truncated" in str(database_error(db, damaged.value))
    conn = sqlite3.connect(tmp_path / "full.sqlite")
    conn.execute("PRAGMA max_page_count = 1")
    with pytest.raises(sqlite3.OperationalError) as full:
        conn.execute("CREATE TABLE t (x TEXT)")
    message = str(database_error(tmp_path / "full.sqlite", full.value))
    assert message.startswith(f"{tmp_path / 'full.sqlite'}: could not write")
    assert "the stored SFOs are kept" in message


# -- D9b: writes refused inside OpenCV or the mesh writer name their file ------------------------
def _file_too_large(*args, **kwargs):
    raise OSError(errno.EFBIG, "File too large")


def test_png_write_refused_names_the_file(tmp_path, monkeypatch):
    from lilium.io import results

    monkeypatch.setattr(results, "_write_bytes", _file_too_large)
    with pytest.raises(OSError) as exc:
        ds.write_png(tmp_path / "image.png", [[0, 255]])
    assert exc.value.filename == str(tmp_path / "image.png") and exc.value.errno == errno.EFBIG
    assert list(tmp_path.iterdir()) == []  # no temporary file left


def test_synth_write_refused_is_one_line_naming_the_file(tmp_path, monkeypatch, capsys):
    def writer(folder, subject):  # trimesh's export says "File too large" with no file name
        _file_too_large()

    monkeypatch.setattr(ds, "_default_subject_api", lambda: (make_toy_subject, writer))
    monkeypatch.delenv("LILIUM_DEBUG", raising=False)
    out = tmp_path / "out"
    argv = ["synth", "--out", str(out), "--subjects", "1", "--photos", "1", "--workers", "1"]
    assert main([*argv, "--no-progress", "--experiments", "A"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(out / "subjects" / "s01") in err, err


def test_a_second_generation_in_one_folder_is_refused(tmp_path):
    from lilium.io.locks import RunLock
    from lilium.synthetic.dataset import generate_dataset

    out = tmp_path / "data"
    out.mkdir()
    with RunLock(out, "lilium run", "--out"):  # another synth holds the folder
        with pytest.raises(ValueError, match="in use by another lilium run"):
            generate_dataset(out, 1, 1, seed=0, experiments=("A",), workers=1)
    assert not (out / "dataset.json").exists()
