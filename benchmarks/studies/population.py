"""Craniometric spread of the generated population against published adult values (a script).

Generates ``--subjects`` subjects (:func:`lilium.synthetic.subjects.make_subjects`, the seeds of
``lilium synth``), measures each skull (:func:`lilium.synthetic.anatomy.craniometry.measure`:
Martin / Howells measurements) and prints, per measurement, the generated mean, SD and range
beside the published pooled-sex adult mean and SD (:data:`~.craniometry.PUBLISHED`; sources in
docs/population.md), with the z-score of the generated mean and the SD ratio::

    .venv/bin/python benchmarks/studies/population.py --subjects 40 --seed 0
"""

import argparse
import time

import numpy as np

from lilium.synthetic.anatomy.craniometry import PUBLISHED, measure
from lilium.synthetic.subjects import make_subjects


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--subjects", type=int, default=40)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    start = time.perf_counter()
    subjects = make_subjects(args.subjects, seed=args.seed)
    values = {k: [] for k in PUBLISHED}
    for s in subjects:
        for k, v in measure(s.skull_vertices_mm, s.cranial_landmarks).items():
            values[k].append(v)
    print(
        f"{args.subjects} generated subjects (seed {args.seed}, "
        f"{time.perf_counter() - start:.0f} s) vs published adults (both sexes pooled), mm"
    )
    header = (
        f"{'measurement':<40} {'gen mean':>8} {'gen sd':>6} {'gen min':>7} {'gen max':>7} "
        f"{'pub mean':>8} {'pub sd':>6} {'z(mean)':>7} {'sd ratio':>8}"
    )
    print(header)
    print("-" * len(header))
    for key, ref in PUBLISHED.items():
        x = np.array(values[key])
        sd = x.std(ddof=1)
        print(
            f"{ref.label:<40} {x.mean():8.1f} {sd:6.1f} {x.min():7.1f} {x.max():7.1f} "
            f"{ref.mean_mm:8.1f} {ref.sd_mm:6.1f} {(x.mean() - ref.mean_mm) / ref.sd_mm:7.2f} "
            f"{sd / ref.sd_mm:8.2f}"
        )
    print(
        "z(mean) = (generated mean - published mean) / published SD; "
        "sd ratio = generated / published"
    )


if __name__ == "__main__":
    main()
