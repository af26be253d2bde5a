"""Write the identification's reference cohort (``src/lilium/data/cohort.json``): the cranial
landmarks and soft-tissue axes of generated people no calibration database contains (their
own seed), the skulls a photo's landmark fit is read against
(:mod:`lilium.identification.cohort`).

    python benchmarks/datasets/make_cohort.py [--skulls 20] [--seed 2027] [--out PATH]
"""

import argparse

from lilium.experiments.calibrate import make_cohort
from lilium.io.calibration import SHIPPED_COHORT, shipped_path, write_cohort


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skulls", type=int, default=20)
    parser.add_argument("--seed", type=int, default=2027)
    parser.add_argument("--out", default=None, help="default: the package's own cohort file")
    args = parser.parse_args(argv)
    out = args.out or shipped_path(SHIPPED_COHORT)
    write_cohort(out, make_cohort(args.skulls, args.seed))
    print(f"{out}: {args.skulls} skulls, seed {args.seed}")


if __name__ == "__main__":
    main()
