"""Record (or compare) the result.json of a handful of seeded SFOs: a regression check for
changes that must keep the numbers ("same seeds, same numbers").

It runs, through the ``lilium sfo`` command, POSEST-SFO and every Lilium variant (a small DE
budget) on the frontal and lateral Exp. C photos of two generated subjects, against the true
skull and one wrong skull, and writes every result (without the timing) to one JSON file::

    python tests/acceptance/snapshot_sfos.py --out /tmp/snap --save before.json
    python tests/acceptance/snapshot_sfos.py --out /tmp/snap --compare before.json

``--compare`` prints every numeric field that differs by more than ``--rtol`` (relative) and
exits 1 when any does. ``test_snapshot_sfos.py`` compares this tree with the snapshot committed
in ``data/sfo_snapshot.json`` (made with the defaults: ``--generations 40 --population 12``).
"""

import argparse
import json
import sys
from pathlib import Path

from lilium.cli.main import main as lilium

VARIANTS = ("base", "pll", "skof", "skof+pll")
#: Keys that depend on the machine, not on the numbers.
VOLATILE = {"seconds", "date", "versions"}
#: What stands for the installed package's folder in a recorded path (the shipped
#: calibration's), so that a snapshot compares across checkouts.
PACKAGE = "<lilium>"


def dataset(folder):
    from lilium.synthetic.dataset import generate_dataset

    index_path = folder / "dataset.json"
    if not index_path.is_file():
        generate_dataset(folder, 2, 1, seed=0, experiments=("C",), workers=1)
    return json.loads(index_path.read_text())


def run_all(out, generations, population):
    import lilium as package_module

    package = str(Path(package_module.__file__).resolve().parent)
    data = out / "data"
    index = dataset(data)
    subjects = {s["id"]: data / s["path"] for s in index["subjects"]}
    records = {}
    for photo in index["photos"]:
        photo_dir = data / photo["paths"]["C"]
        for subject, subject_dir in subjects.items():
            runs = [("posest-sfo", None)]
            if subject == photo["subject"]:
                runs += [("lilium", v) for v in VARIANTS]
            for method, variant in runs:
                tag = f"{photo['id']}/{subject}/{method}" + (f"-{variant}" if variant else "")
                target = out / "runs" / tag
                argv = ["sfo", "--method", method, "--skull", str(subject_dir)]
                argv += ["--photo", str(photo_dir), "--out", str(target), "--no-overlay"]
                argv += ["--axes", str(subject_dir / "axes_C1.json")]
                if variant:
                    argv += ["--variant", variant, "--seed", "1"]
                    argv += ["--generations", str(generations), "--population", str(population)]
                lilium(argv)
                text = (target / "result.json").read_text().replace(package, PACKAGE)
                result = json.loads(text)
                records[tag] = {k: v for k, v in result.items() if k not in VOLATILE}
    return records


def differences(before, after, rtol, path=""):
    """Yield ``(path, before, after)`` for every leaf that differs."""
    if isinstance(before, dict) and isinstance(after, dict):
        for key in sorted(set(before) | set(after)):
            if key in VOLATILE:
                continue
            yield from differences(
                before.get(key, "<absent>"), after.get(key, "<absent>"), rtol, f"{path}/{key}"
            )
    elif isinstance(before, list) and isinstance(after, list) and len(before) == len(after):
        for i, (b, a) in enumerate(zip(before, after, strict=True)):
            yield from differences(b, a, rtol, f"{path}[{i}]")
    elif isinstance(before, (int, float)) and isinstance(after, (int, float)):
        if abs(before - after) > rtol * max(abs(before), abs(after), 1e-12):
            yield path, before, after
    elif before != after:
        yield path, before, after


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("out/snapshot"))
    parser.add_argument("--generations", type=int, default=40)
    parser.add_argument("--population", type=int, default=12)
    parser.add_argument("--save", type=Path, help="write the snapshot here")
    parser.add_argument("--compare", type=Path, help="compare with this snapshot")
    parser.add_argument("--rtol", type=float, default=1e-9)
    args = parser.parse_args(argv)
    records = run_all(args.out, args.generations, args.population)
    if args.save:
        args.save.write_text(json.dumps(records, indent=1, sort_keys=True))
        print(f"{len(records)} SFOs -> {args.save}")
    if args.compare:
        before = json.loads(args.compare.read_text())
        diffs = list(differences(before, records, args.rtol))
        for where, b, a in diffs[:60]:
            print(f"{where}: {b!r} -> {a!r}")
        rel = [
            abs(b - a) / max(abs(b), abs(a), 1e-12)
            for _, b, a in diffs
            if isinstance(b, (int, float)) and isinstance(a, (int, float))
        ]
        print(
            f"{len(records)} SFOs compared, {len(diffs)} field(s) differ (rtol {args.rtol:g})"
            + (f", largest relative difference {max(rel):.2g}" if rel else "")
            + (f", {len(diffs) - len(rel)} non-numeric" if len(rel) < len(diffs) else "")
        )
        return 1 if diffs else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
