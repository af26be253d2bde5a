"""``lilium demo``: build a realistic case from built-in data and superimpose it both ways."""

import time
from pathlib import Path

from .options import add_options


def register(subparsers):
    p = subparsers.add_parser("demo", help="run a demo SFO on built-in data", description=__doc__)
    add_options(p, "out", "seed", "variant", out=Path("lilium-demo"))
    p.set_defaults(func=run)


def run(args):
    from ..demo import build_demo_case, ground_truth_bpe
    from ..methods import method_tag
    from .main import main

    start = time.perf_counter()
    out = Path(args.out)
    print("Lilium demo: generating a subject and a frontal and a lateral photo ...", flush=True)
    subject_dir, photo_dirs, axes = build_demo_case(out / "data", seed=args.seed)
    argv = ["case", "--skull", str(subject_dir), "--axes", str(axes)]
    for photo in photo_dirs:
        argv += ["--photo", str(photo)]
    argv += [
        "--method",
        "posest-sfo",
        "--method",
        "lilium",
        "--variant",
        args.variant,
        "--seed",
        str(args.seed),
        "--title",
        "Lilium demo (synthetic, Exp. C noise)",
        "--out",
        str(out / "case"),
    ]
    code = main(argv)
    print("\nAgainst the known truth (back-projection error, mm; lower is better):")
    tags = (method_tag("posest-sfo"), method_tag("lilium", args.variant))
    for photo in photo_dirs:
        for tag in tags:
            result = out / "case" / photo.name / tag / "result.json"
            if result.is_file():
                bpe = ground_truth_bpe(result, subject_dir, photo)
                print(f"  {photo.name:<10} {tag:<18} {bpe:6.2f}")
    print(f"\n  report:  {out / 'case' / 'report.html'}  (open it in a browser)")
    print(
        f"  results: {out / 'case'}/<photo>/<method>[-<variant>]/result.json, overlay.png, "
        "workbench.html (turn the skull yourself, save camera.json, score it with --camera)"
    )
    print(f"  data:    {out / 'data'}")
    print(f"  total {time.perf_counter() - start:.0f} s")
    return code
