"""``lilium demo``: build the built-in case and superimpose its skull with POSEST-SFO."""

import time
from pathlib import Path


def register(subparsers):
    p = subparsers.add_parser("demo", help="run a demo SFO on built-in data", description=__doc__)
    p.add_argument("--out", type=Path, default=Path("lilium-demo"), help="output folder")
    p.add_argument("--seed", type=int, default=0)
    p.set_defaults(func=run)


def run(args):
    from ..demo import make_standin_case
    from .sfo import run_sfo

    start = time.perf_counter()
    subject_dir, photo_dir = make_standin_case(args.out / "case", seed=args.seed)
    out = args.out / "posest-sfo"
    result = run_sfo(subject_dir, photo_dir, out)
    status = "ok" if result else f"failed ({result.error})"
    print(f"Lilium demo: POSEST-SFO {status}")
    if result:
        print(
            f"  focal {result.focal_px:.0f} px, mean landmark error {result.fitness:.2f} px, "
            f"{result.seconds * 1e3:.1f} ms"
        )
    print(f"  case:    {args.out / 'case'}")
    print(f"  result:  {out / 'result.json'}")
    print(f"  overlay: {out / 'overlay.png'}")
    print(f"  total {time.perf_counter() - start:.1f} s")
    return 0 if result else 1
