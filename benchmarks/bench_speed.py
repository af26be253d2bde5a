"""Time per SFO, compiled kernels against the numpy reference path, with a per-term profile.

In one process and one run (so the ratios compare like with like on a noisy, shared machine):
for each photo, POSEST-SFO (median of ``--posest-repeats`` runs, in-process) and every Lilium
variant at the default DE budget (750 generations x 30) on the compiled path; then the same
SFOs on the numpy reference path (``lilium.jit.kernels("numpy")``) for ``--reference-generations``
generations, next to the compiled path at that budget, which gives the speed-up ratio; and a
per-term profile of the compiled run (where the time of an SFO goes: the set-up of the problem
and its terms, camera refinement, P_skof, P_pll, the rest). The numpy path is the one the
compiled kernels replaced: it gives the same numbers (``tests/test_kernels_mesh.py``,
``tests/test_kernels_camera.py``).

    python benchmarks/bench_speed.py                       # generated Exp. C photos
    python benchmarks/bench_speed.py --dataset DIR --dataset DIR2   # e.g. a 150k-face skull
    python benchmarks/bench_speed.py --real-size                    # issue 26's real sizes

``--real-size`` times, on the first frontal photo of the dataset, Lilium skof+pll and base with
the DE's working level (``after``, the default) and without it (``before``: every evaluation at
the photo's resolution on the full mesh, ``working_face_px=None``), in the same run, at real
sizes (:mod:`real_size`): the skull subdivided to 150k, 600k and 1.2M faces at 2 MP, and the
600k-face skull with the photo resampled to 1, 12 and 24 MP; with the per-term profile of each.

Each SFO is seeded (seed 1, perturbed axes set C1) and runs on one core. Times are the process's
CPU time (``time.process_time``, single-threaded BLAS), not wall time: on a shared machine the
wall clock also counts the time other processes hold the core.
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from collections import defaultdict  # noqa: E402
from dataclasses import replace  # noqa: E402
from pathlib import Path  # noqa: E402

import lilium.methods.lilium_outcome as lilium_outcome  # noqa: E402
import lilium.methods.lilium_terms as lilium_terms  # noqa: E402
from lilium import jit  # noqa: E402
from lilium.casework.build import read_photo, read_skull  # noqa: E402
from lilium.io.jsonio import read_json  # noqa: E402
from lilium.methods import METHODS, SfoOptions, run_sfo  # noqa: E402
from lilium.methods import lilium as lilium_method  # noqa: E402
from lilium.optimisation import DEOptions  # noqa: E402

#: The data tools (benchmarks/datasets) this script imports: ``real_size``.
sys.path.insert(0, str(Path(__file__).resolve().parent / "datasets"))

VARIANTS = METHODS["lilium"].variants


class TermClock:
    """CPU time spent in Lilium's set-up (the problem and its terms, once per SFO), the camera
    stage (refinement; compiled: from the genes to the camera terms, one call per generation)
    and image terms (wrapped functions)."""

    PARTS = {
        "setup": (lilium_method.LiliumProblem, "__init__"),
        "cameras": (lilium_method.LiliumProblem, "cameras"),  # the initial population's
        "stage": (lilium_method, "camera_terms_compiled"),  # later ones: genes to camera terms
        "p_skof": (lilium_terms.SkofTerm, "__call__"),
        "p_pll": (lilium_terms.PllTerm, "parts"),
        "final": (lilium_outcome, "full_image_terms"),
    }

    def __init__(self):
        self.seconds = defaultdict(float)
        self._saved = {}

    def __enter__(self):
        for part, (owner, name) in self.PARTS.items():
            original = getattr(owner, name)
            self._saved[part] = original

            def timed(*args, _original=original, _part=part, **kwargs):
                t0 = time.process_time()
                try:
                    return _original(*args, **kwargs)
                finally:
                    self.seconds[_part] += time.process_time() - t0

            setattr(owner, name, timed)
        return self

    def __exit__(self, *exc):
        for part, (owner, name) in self.PARTS.items():
            setattr(owner, name, self._saved[part])
        self.seconds["cameras"] += self.seconds.pop("stage", 0.0)  # one column, "cameras"


def photos_of(root):
    """``(label, skull, photo)`` of every Exp. C photo of a dataset, on its own skull."""
    index = read_json(root / "dataset.json")
    out = []
    for entry in index["photos"]:
        subject = root / "subjects" / entry["subject"]
        skull = read_skull(subject, axes_path=subject / "axes_C1.json")
        photo = read_photo(root / entry["paths"]["C"])
        view = entry["view"].split("_")[0]
        out.append((f"{entry['id']} {view} {len(skull.faces) // 1000}k", skull, photo))
    return out


def time_sfo(method, skull, photo, options=SfoOptions(), seed=1):
    t0 = time.process_time()
    result = run_sfo(method, skull, photo, options, seed)
    return time.process_time() - t0, result


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--dataset", type=Path, action="append", help="dataset folder(s)")
    p.add_argument("--variants", default=",".join(VARIANTS))
    p.add_argument("--generations", type=int, default=DEOptions().max_generations)
    p.add_argument("--population", type=int, default=DEOptions().population_size)
    p.add_argument("--reference-generations", type=int, default=40)
    p.add_argument("--posest-repeats", type=int, default=30)
    p.add_argument("--real-size", action="store_true", help="issue 26's real-size table")
    p.add_argument(
        "--aot",
        action="store_true",
        help="the kernels built ahead of time against numba's JIT, per SFO, at real sizes",
    )
    args = p.parse_args(argv)
    if not jit.NUMBA_AVAILABLE:
        p.error("numba is not installed: nothing to compare (pip install 'numba==0.68.1')")
    roots = args.dataset
    if not roots:
        from lilium.synthetic.dataset import generate_dataset

        root = Path(tempfile.mkdtemp(prefix="lilium-speed-"))
        generate_dataset(root, 1, 1, seed=0, experiments=("C",), workers=1)
        roots = [root]
    if args.real_size:
        return real_size_table(roots[0], args)
    if args.aot:
        return aot_table(roots[0], args)
    variants = [v for v in args.variants.split(",") if v]
    full = SfoOptions().with_de(
        population_size=args.population, max_generations=args.generations, max_seconds=1e9
    )
    short = full.with_de(max_generations=args.reference_generations)
    rows, profiles = [], []
    for root in roots:
        for label, skull, photo in photos_of(root):
            # Warm-up: loads the compiled kernels (numba's cache) outside the timings.
            run_sfo("lilium", skull, photo, SfoOptions("skof+pll").with_de(max_generations=2), 0)
            times = {}
            for numpy_path in (False, True):
                with jit.kernels("numpy" if numpy_path else "numba"):
                    runs = [
                        time_sfo("posest-sfo", skull, photo)[0] for _ in range(args.posest_repeats)
                    ]
                times["posest-sfo", numpy_path] = statistics.median(runs)
            rows.append(
                (label, "posest-sfo", times["posest-sfo", False], None, times["posest-sfo", True])
            )
            for variant in variants:
                with TermClock() as clock:
                    seconds, result = time_sfo(
                        "lilium", skull, photo, replace(full, variant=variant)
                    )
                profiles.append((label, variant, seconds, dict(clock.seconds)))
                compiled_short, _ = time_sfo(
                    "lilium", skull, photo, replace(short, variant=variant)
                )
                with jit.kernels("numpy"):
                    reference_short, _ = time_sfo(
                        "lilium", skull, photo, replace(short, variant=variant)
                    )
                rows.append((label, f"lilium {variant}", seconds, compiled_short, reference_short))
                print(f"  {label:<22} lilium {variant:<9} {seconds:7.2f} s", flush=True)

    g = args.reference_generations
    print(
        f"\nCPU time per SFO, one core: compiled at {args.generations} generations x "
        f"{args.population}; the ratio numpy / compiled measured at {g} generations "
        f"(POSEST-SFO: median of {args.posest_repeats} runs, whole SFO in-process)"
    )
    print(f"{'photo':<22} {'method':<18} {'compiled s':>10} {'numpy s (est.)':>14} {'ratio':>6}")
    for label, method, seconds, compiled_short, reference_short in rows:
        if compiled_short is None:
            ratio = reference_short / seconds
            estimate = reference_short
        else:
            ratio = reference_short / compiled_short
            estimate = seconds * ratio
        print(f"{label:<22} {method:<18} {seconds:10.4f} {estimate:14.2f} {ratio:6.1f}")
    print(
        "\nPer-term profile of the compiled runs (s per SFO; 'setup' = the problem and its terms, "
        "once per SFO; 'rest' = DE, decoding, P_cam)"
    )
    print(f"{'photo':<22} {'variant':<9} {'total':>7} {'setup':>7} {'cameras':>8} ", end="")
    print(f"{'p_skof':>7} {'p_pll':>7} {'rest':>7}")
    for label, variant, seconds, parts in profiles:
        setup, cams, skof, pll = (
            parts.get(k, 0.0) for k in ("setup", "cameras", "p_skof", "p_pll")
        )
        rest = seconds - setup - cams - skof - pll
        print(f"{label:<22} {variant:<9} {seconds:7.2f} {setup:7.2f} {cams:8.2f} ", end="")
        print(f"{skof:7.2f} {pll:7.2f} {rest:7.2f}")


#: (faces, megapixels) of the real-size table.
REAL_SIZES = (
    (150_000, 2.0),
    (600_000, 2.0),
    (1_200_000, 2.0),
    (600_000, 1.0),
    (600_000, 12.0),
    (600_000, 24.0),
)


def real_size_table(root, args):
    """Issue 26: s per SFO before / after the working level at real sizes, one run."""
    from real_size import photo_at, skull_at

    label, skull, photo = next(c for c in photos_of(root) if " frontal " in c[0])
    full = SfoOptions().with_de(
        population_size=args.population, max_generations=args.generations, max_seconds=1e9
    )
    rows = []
    for faces, megapixels in REAL_SIZES:
        big, image = skull_at(skull, faces), photo_at(photo, megapixels)
        run_sfo("lilium", big, image, SfoOptions("skof+pll").with_de(max_generations=2), 0)
        for variant in ("base", "skof+pll"):
            for path, face_px in (("after", full.working_face_px), ("before", None)):
                if variant == "base" and path == "before":
                    continue  # base has no image terms: no working level
                options = replace(full, variant=variant, working_face_px=face_px)
                with TermClock() as clock:
                    seconds, result = time_sfo("lilium", big, image, options)
                rows.append(
                    (
                        len(big.faces),
                        image.image_size_wh,
                        variant,
                        path,
                        seconds,
                        dict(clock.seconds),
                        result,
                    )
                )
                print(
                    f"  {len(big.faces):>8} {megapixels:5.1f} MP {variant:<9} {path:<6} "
                    f"{seconds:7.2f} s",
                    flush=True,
                )
    print(
        f"\n{label}: CPU s per SFO, one core, {args.generations} x {args.population}; "
        "'final' = the result's terms at full level"
    )
    print(
        f"{'faces':>9} {'photo':>11} {'variant':<9} {'path':<6} {'total':>7} {'setup':>6} "
        f"{'cams':>6} {'p_skof':>7} {'p_pll':>6} {'final':>6} {'rest':>6} {'ratio':>6} "
        f"{'work faces':>10} {'scale':>6}"
    )
    before = {(r[0], r[1]): r[4] for r in rows if r[3] == "before"}
    for faces, size, variant, path, seconds, parts, result in rows:
        setup, cams, skof, pll, final = (
            parts.get(k, 0.0) for k in ("setup", "cameras", "p_skof", "p_pll", "final")
        )
        rest = seconds - setup - cams - skof - pll - final
        ratio = before.get((faces, size), float("nan")) / seconds if variant != "base" else 1.0
        print(
            f"{faces:>9} {size[0]:>5}x{size[1]:<5} {variant:<9} {path:<6} {seconds:7.2f} "
            f"{setup:6.2f} {cams:6.2f} {skof:7.2f} {pll:6.2f} {final:6.2f} {rest:6.2f} "
            f"{ratio:6.1f} {result.extra.get('working_faces', 0):>10} "
            f"{result.extra.get('working_scale', 1.0):6.3f}"
        )


def aot_table(root, args, repeats=3):
    """CPU s per SFO with the kernels built ahead of time (``lilium._kernels_aot``) and with
    numba's JIT, alternating in one process (medians of ``repeats``), on the demo-sized frontal
    photo and at 600k faces / 2 and 24 MP; and how many calls found no export (they ran on the
    JIT: the signature list misses them)."""
    from real_size import photo_at, skull_at

    if not jit._aot_table():
        raise SystemExit("the kernels were not built ahead of time: python -m pip install -e .")
    label, skull, photo = next(c for c in photos_of(root) if " frontal " in c[0])
    full = SfoOptions().with_de(
        population_size=args.population, max_generations=args.generations, max_seconds=1e9
    )
    big = skull_at(skull, 600_000)
    cases = [(label, skull, photo)]
    cases += [(f"600k faces, {mp:g} MP", big, photo_at(photo, mp)) for mp in (2.0, 24.0)]
    missed = []
    jitted = jit.Kernel.dispatcher

    def dispatcher(kernel):
        if jit.backend() == "numba":
            missed.append(kernel.key)
        return jitted.fget(kernel)

    jit.Kernel.dispatcher = property(dispatcher)
    print(f"CPU s per SFO, one core, {args.generations} x {args.population}, median of {repeats}")
    print(f"{'case':<26} {'variant':<9} {'ahead of time':>13} {'JIT':>7} {'ratio':>6}")
    try:
        for name, big, image in cases:
            for variant in ("base", "skof+pll"):
                options = replace(full, variant=variant)
                times = {"numba": [], "jit": []}
                for path in times:  # warm-up: loads either path's kernels
                    with jit.kernels(path):
                        run_sfo("lilium", big, image, options.with_de(max_generations=2), 0)
                for _ in range(repeats):
                    for path in times:
                        with jit.kernels(path):
                            times[path].append(time_sfo("lilium", big, image, options)[0])
                aot, just_in_time = (statistics.median(times[k]) for k in ("numba", "jit"))
                print(
                    f"{name:<26} {variant:<9} {aot:13.3f} {just_in_time:7.3f} "
                    f"{aot / just_in_time:6.3f}",
                    flush=True,
                )
    finally:
        jit.Kernel.dispatcher = jitted
    print(f"calls that found no export: {len(missed)} ({sorted(set(missed)) or 'none'})")


if __name__ == "__main__":
    main()
