"""Experiment configuration (a small TOML file) and the presets ``quick`` and ``paper``.

A config names the dataset (an existing folder with ``dataset.json``, or one to generate), the
experiments (A, B, C of docs/method/evaluation.md), the methods, the repetitions, the DE settings of
Lilium,
the number of local workers and the results database. Relative paths are relative to the config
file's folder (to the current folder for a preset). Example::

    preset = "quick"                 # optional: start from a preset, override below
    name = "my-run"
    experiments = ["A", "B", "C"]
    methods = ["posest-sfo", "lilium:base", "lilium:pll", "lilium:skof", "lilium:skof+pll"]
    repetitions = 5                  # Lilium runs per SFO in A and B
    axes_sets = 5                    # Exp. C: perturbed soft-tissue axis sets
    runs_per_axes_set = 5            # Exp. C: Lilium runs per axis set
    seed = 0                         # Lilium run r uses the seed ``seed + r``
    workers = 0                      # local processes; 0 = all cores
    db = "results.sqlite"

    [dataset]
    path = "dataset"
    generate = true                  # generate it when dataset.json is missing
    subjects = 5
    photos = 2                       # frontal photos per subject (as many lateral)
    seed = 0
    no_mandible_share = 0.0          # share of skulls without the mandible (default 0)
    drop_landmark_rate = 0.0         # chance a visible photo landmark is unmarked (default 0)

    [de]
    population = 10
    generations = 10
    max_seconds = 10.0

``methods`` entries are ``"posest-sfo"``, ``"lilium:<variant>"`` (variant among ``base``,
``pll``, ``skof``, ``skof+pll``) or ``"lilium"`` for all four variants; ``"lilium-joint:<variant>"``
(or ``"lilium-joint"``, all variants) runs one joint SFO per subject's frontal + lateral photo
pair and skull (docs/method/joint.md, :mod:`lilium.experiments.joint_tasks`).

Every key is checked, with a message naming it: integers in the ranges of
:data:`LIMITS` (seeds such that ``seed + run`` fits :data:`MAX_SEED`), ``max_seconds`` a finite
number >= 0, paths non-empty strings, ``name`` a one-line string, unknown keys refused.
"""

import hashlib
import json
import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..constants import EXPERIMENTS, MAX_DE_POPULATION
from ..methods.registry import METHODS
from ..optimisation.de import DEOptions

#: Lilium fitness variants (from the method registry).
LILIUM_VARIANTS = METHODS["lilium"].variants

#: Every method of the paper's protocol, as (method, variant) pairs.
ALL_METHODS = (("posest-sfo", ""),) + tuple(("lilium", v) for v in LILIUM_VARIANTS)

#: Largest seed (``seed + run`` included): 2^32 - 1, the range every seeded library takes and
#: far inside SQLite's 64-bit INTEGER column.
MAX_SEED = 2**32 - 1

#: Ranges ``(lo, hi)`` of the integer keys. The upper bounds keep a typing slip from asking for
#: runaway resources (a task list of billions, thousands of processes, a DE population that
#: does not fit in memory); the paper's protocol lies far inside them.
LIMITS = {
    "repetitions": (1, 1000),
    "axes_sets": (1, 1000),
    "runs_per_axes_set": (1, 1000),
    "workers": (0, 256),
    "seed": (0, MAX_SEED),
    "dataset.subjects": (1, 1000),
    "dataset.photos": (1, 1000),
    "dataset.seed": (0, MAX_SEED),
    "de.population": (4, MAX_DE_POPULATION),
    "de.generations": (1, 10**7),
}


@dataclass(frozen=True)
class DatasetConfig:
    """Where the dataset lies and, when it is to be generated, how.

    Attributes
    ----------
    path : Path
        Folder holding ``dataset.json`` (the layout of :mod:`lilium.synthetic.dataset`).
    generate : bool
        Generate the dataset when ``path/dataset.json`` is missing.
    subjects : int
    photos : int
        Frontal photos per subject; as many lateral ones.
    seed : int
    no_mandible_share : float
        Share of the generated skulls without the mandible, in [0, 1].
    drop_landmark_rate : float
        Probability that a visible photo landmark is left unmarked, in [0, 1).

    Both default to 0, in every preset: the paper's subjects and photos are complete
    (:mod:`lilium.synthetic.incomplete`). They apply when the dataset is generated; an existing
    dataset is used as it is.
    """

    path: Path = Path("dataset")
    generate: bool = True
    subjects: int = 5
    photos: int = 2
    seed: int = 0
    no_mandible_share: float = 0.0
    drop_landmark_rate: float = 0.0


#: Keys of a config's ``[de]`` table and the :class:`DEOptions` fields they set.
DE_KEYS = {
    "population": "population_size",
    "generations": "max_generations",
    "max_seconds": "max_seconds",
}


@dataclass(frozen=True)
class ExperimentConfig:
    """One run of the protocol (docs/method/evaluation.md).

    Attributes
    ----------
    name : str
    dataset : DatasetConfig
    experiments : tuple of str
        Subset of ``("A", "B", "C")``.
    methods : tuple of (str, str)
        ``(method, variant)``; variant ``""`` for POSEST-SFO.
    repetitions : int
        Lilium runs (seeds) per photo-skull pair in Exps. A and B.
    axes_sets : int
        Exp. C: perturbed axis sets ``axes_C1.json`` .. (POSEST-SFO runs once per set).
    runs_per_axes_set : int
        Exp. C: Lilium runs (seeds) per axis set.
    seed : int
        Lilium run ``r`` (0-based) uses the seed ``seed + r``.
    de : DEOptions
        Lilium's differential evolution (the ``[de]`` table sets population, generations and
        max_seconds; see :data:`DE_KEYS`).
    workers : int
        Local processes; 0 = all cores.
    db : Path
        SQLite results database.
    """

    name: str = "experiment"
    dataset: DatasetConfig = field(default_factory=DatasetConfig)
    experiments: tuple = EXPERIMENTS
    methods: tuple = ALL_METHODS
    repetitions: int = 5
    axes_sets: int = 5
    runs_per_axes_set: int = 5
    seed: int = 0
    de: DEOptions = field(default_factory=DEOptions)
    workers: int = 0
    db: Path = Path("results.sqlite")

    def fingerprint(self):
        """Hash of the settings that change a result (a database holds one setting only)."""
        de = {key: getattr(self.de, name) for key, name in DE_KEYS.items()}
        key = {"de": de, "seed": self.seed, "dataset_seed": self.dataset.seed}
        for name in ("no_mandible_share", "drop_landmark_rate"):  # only when set: old
            if getattr(self.dataset, name):  # databases keep their fingerprint
                key[f"dataset_{name}"] = getattr(self.dataset, name)
        return hashlib.sha256(json.dumps(key, sort_keys=True).encode()).hexdigest()[:16]


#: Presets. ``quick``: 5 subjects x 4 photos, all experiments and methods, reduced repetitions
#: (2 in A and B; 2 axis sets x 2 runs in C) and a small DE budget (population 10, 10
#: generations, 2 s per SFO at most): 3,600 SFOs, under 30 minutes on 2 cores (measured in
#: docs/experiments.md).
#: ``medium``: the identification claim at the paper's DE budget on a smaller population: 10
#: subjects x (2 frontal + 2 lateral) photos against every skull, Exp. C only (one axis set, one
#: run), POSEST-SFO and Lilium+P_skof+P_pll with DE 30 x 750 generations (500 s at most):
#: 40 photos x 10 skulls = 400 SFOs per method, 800 in all (size and measured time in
#: docs/experiments.md).
#: ``paper``: the paper's protocol (17 subjects x 60 photos, 5 repetitions, 5 x 5 runs in C,
#: DE 750 generations or 500 s).
#: Both generate complete skulls and fully marked photos (``no_mandible_share`` and
#: ``drop_landmark_rate`` 0, as in the paper); a config file can set them under ``[dataset]``.
PRESETS = {
    "quick": ExperimentConfig(
        name="quick",
        dataset=DatasetConfig(Path("lilium-quick/dataset"), True, 5, 2, 0),
        repetitions=2,
        axes_sets=2,
        runs_per_axes_set=2,
        de=DEOptions(population_size=10, max_generations=10, max_seconds=2.0),
        db=Path("lilium-quick/results.sqlite"),
    ),
    "medium": ExperimentConfig(
        name="medium",
        dataset=DatasetConfig(Path("lilium-medium/dataset"), True, 10, 2, 0),
        experiments=("C",),
        methods=(("posest-sfo", ""), ("lilium", "skof+pll")),
        repetitions=1,
        axes_sets=1,
        runs_per_axes_set=1,
        de=DEOptions(population_size=30, max_generations=750, max_seconds=500.0),
        db=Path("lilium-medium/results.sqlite"),
    ),
    "paper": ExperimentConfig(
        name="paper",
        dataset=DatasetConfig(Path("lilium-paper/dataset"), True, 17, 30, 0),
        repetitions=5,
        axes_sets=5,
        runs_per_axes_set=5,
        de=DEOptions(),
        db=Path("lilium-paper/results.sqlite"),
    ),
}

_TOP_KEYS = {
    "preset",
    "name",
    "experiments",
    "methods",
    "repetitions",
    "axes_sets",
    "runs_per_axes_set",
    "seed",
    "workers",
    "db",
    "dataset",
    "de",
}
_DATASET_KEYS = {
    "path",
    "generate",
    "subjects",
    "photos",
    "seed",
    "no_mandible_share",
    "drop_landmark_rate",
}
_DE_KEYS = {"population", "generations", "max_seconds"}


def parse_methods(entries, where="methods"):
    """``["posest-sfo", "lilium:skof", "lilium"]`` -> ``(("posest-sfo", ""), ...)``."""
    if isinstance(entries, str) or not isinstance(entries, (list, tuple)) or not entries:
        raise ValueError(f"{where} must be a non-empty list of method names")
    out = []
    for entry in entries:
        name = str(entry).strip().lower()
        if name == "posest-sfo":
            pairs = [("posest-sfo", "")]
        elif name == "lilium":
            pairs = [("lilium", v) for v in LILIUM_VARIANTS]
        elif name.startswith("lilium:") and name[7:] in LILIUM_VARIANTS:
            pairs = [("lilium", name[7:])]
        elif name == "lilium-joint":
            pairs = [("lilium-joint", v) for v in LILIUM_VARIANTS]
        elif name.startswith("lilium-joint:") and name[13:] in LILIUM_VARIANTS:
            pairs = [("lilium-joint", name[13:])]
        else:
            raise ValueError(
                f"{where}: unknown method {entry!r}; use 'posest-sfo', 'lilium', "
                f"'lilium:<variant>', 'lilium-joint' or 'lilium-joint:<variant>' with variant "
                f"among {', '.join(LILIUM_VARIANTS)}"
            )
        out.extend(p for p in pairs if p not in out)
    return tuple(out)


#: View groups of the report's tables: frontal photos, and lateral ones (left and right together).
VIEW_GROUPS = ("frontal", "lateral")


def view_group(view):
    """The view group of a photo's view (:data:`VIEW_GROUPS`)."""
    return "frontal" if view == "frontal" else "lateral"


def method_order(pairs):
    """``(method, variant)`` pairs in the protocol's order (:data:`ALL_METHODS`), others after."""
    known = [m for m in ALL_METHODS if m in pairs]
    return known + sorted(p for p in pairs if p not in known)


def method_label(method, variant):
    """Display name: ``POSEST-SFO``, ``Lilium``, ``Lilium+P_pll``, ``Lilium+P_skof+P_pll``."""
    if method == "posest-sfo":
        return "POSEST-SFO"
    name = "Lilium joint" if method == "lilium-joint" else "Lilium"
    if not variant or variant == "base":
        return name
    return name + "+" + "+".join(f"P_{part}" for part in variant.split("+"))


def check_int(where, value, key):
    """``value`` as an integer in ``LIMITS[key]``, or a ``ValueError`` naming ``where``."""
    lo, hi = LIMITS[key]
    if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
        raise ValueError(f"{where} must be an integer in [{lo}, {hi}], got {value!r}")
    return value


def _check_keys(where, data, allowed):
    if not isinstance(data, dict):
        raise ValueError(f"{where} must be a table")
    unknown = sorted(set(data) - allowed)
    if unknown:
        raise ValueError(f"{where}: unknown key(s) {', '.join(unknown)}; known: {sorted(allowed)}")


def config_from_dict(data, base_dir=Path("."), where="config"):
    """Build an :class:`ExperimentConfig` from a parsed TOML table.

    Parameters
    ----------
    data : dict
    base_dir : Path
        Folder that relative paths are relative to.
    where : str
        Name of the source, for error messages.
    """
    _check_keys(where, data, _TOP_KEYS)
    preset = data.get("preset")
    if preset is not None and (not isinstance(preset, str) or preset not in PRESETS):
        raise ValueError(f"{where}: unknown preset {preset!r}; use one of {', '.join(PRESETS)}")
    cfg = PRESETS[preset] if preset else ExperimentConfig()
    base_dir = Path(base_dir)

    def path(value, key):
        if not isinstance(value, str) or not value.strip() or "\0" in value:
            raise ValueError(f"{where}: {key} must be a non-empty path string, got {value!r}")
        p = Path(value).expanduser()
        return p if p.is_absolute() else base_dir / p

    changes = {}
    if "name" in data:
        name = data["name"]
        if not isinstance(name, str) or not name.strip() or not name.isprintable():
            raise ValueError(f"{where}: name must be a non-empty one-line string, got {name!r}")
        changes["name"] = name
    if "experiments" in data:
        exps = data["experiments"]
        if isinstance(exps, str) or not isinstance(exps, list) or not exps:
            raise ValueError(f"{where}: experiments must be a non-empty list of A, B, C")
        bad = [e for e in exps if e not in EXPERIMENTS]
        if bad:
            raise ValueError(f"{where}: unknown experiment(s) {bad}; use A, B, C")
        changes["experiments"] = tuple(e for e in EXPERIMENTS if e in exps)
    if "methods" in data:
        changes["methods"] = parse_methods(data["methods"], f"{where}: methods")
    for key in ("repetitions", "axes_sets", "runs_per_axes_set", "seed", "workers"):
        if key in data:
            changes[key] = check_int(f"{where}: {key}", data[key], key)
    changes["db"] = path(data["db"], "db") if "db" in data else base_dir / cfg.db

    ds = data.get("dataset", {})
    _check_keys(f"{where}: [dataset]", ds, _DATASET_KEYS)
    ds_changes = {
        "path": path(ds["path"], "dataset.path") if "path" in ds else base_dir / cfg.dataset.path
    }
    if "generate" in ds:
        if not isinstance(ds["generate"], bool):
            raise ValueError(f"{where}: dataset.generate must be true or false")
        ds_changes["generate"] = ds["generate"]
    for key in ("subjects", "photos", "seed"):
        if key in ds:
            ds_changes[key] = check_int(f"{where}: dataset.{key}", ds[key], f"dataset.{key}")
    for key, closed in (("no_mandible_share", True), ("drop_landmark_rate", False)):
        if key in ds:
            value = ds[key]
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                span = "[0, 1]" if closed else "[0, 1)"
                raise ValueError(
                    f"{where}: dataset.{key} must be a number in {span}, got {value!r}"
                )
            from ..synthetic.incomplete import check_fraction

            ds_changes[key] = check_fraction(value, f"{where}: dataset.{key}", closed)
    changes["dataset"] = replace(cfg.dataset, **ds_changes)

    de = data.get("de", {})
    _check_keys(f"{where}: [de]", de, _DE_KEYS)
    de_changes = {}
    for key, name in DE_KEYS.items():
        if key in de and key != "max_seconds":
            de_changes[name] = check_int(f"{where}: de.{key}", de[key], f"de.{key}")
    if "max_seconds" in de:
        value = de["max_seconds"]
        ok = isinstance(value, (int, float)) and not isinstance(value, bool)
        if not ok or not math.isfinite(value) or value < 0:
            raise ValueError(
                f"{where}: de.max_seconds must be a finite number >= 0 (0 = no limit), "
                f"got {value!r}"
            )
        de_changes["max_seconds"] = float(value) or None
    changes["de"] = replace(cfg.de, **de_changes)
    out = replace(cfg, **changes)
    runs = max(out.repetitions, out.runs_per_axes_set)
    if out.seed + runs - 1 > MAX_SEED:
        raise ValueError(
            f"{where}: seed = {out.seed} with {runs} runs gives seeds up to {out.seed + runs - 1}, "
            f"above {MAX_SEED}; lower seed"
        )
    return out


def load_config(source):
    """Read a TOML config file, or return a preset by name (``"quick"``, ``"paper"``).

    Parameters
    ----------
    source : str or Path
        A preset name, or the path of a TOML file.

    Returns
    -------
    ExperimentConfig
        Paths resolved against the file's folder (the current folder for a preset).
    """
    if str(source) in PRESETS:
        return config_from_dict({"preset": str(source)}, Path("."), where=f"preset {source}")
    path = Path(source)
    if not path.is_file():
        raise ValueError(
            f"{path}: config file not found; give a TOML file or a preset ({', '.join(PRESETS)})"
        )
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path}: not valid TOML ({exc})") from None
    except OSError as exc:
        raise ValueError(f"{path}: cannot read the config ({exc.strerror})") from None
    return config_from_dict(data, path.parent, where=str(path))
