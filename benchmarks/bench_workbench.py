"""The overlay workbench and the examiner's camera, end to end, on generated and real heads.

For each case (the demo's generated person, and the real CT heads' Exp. C photos when their CT
is here: ``benchmarks/datasets/headsq_case.py``, ``cranium_case.py``) and each method:

1. ``lilium sfo`` writes ``result.json`` and ``workbench.html``;
2. headless Chromium opens ``workbench.html?test`` and ``?test&yaw=5`` (WebGL through
   SwiftShader): the drawn skull's box against ``Camera.project`` of the mesh (px), the
   page's camera against the SFO's, the turn (degrees), the page's weight and first draw;
3. ``lilium sfo --camera`` scores the SFO's own ``result.json`` (its camera and soft tissue:
   fitness back, relative difference), the page's ``yaw=5`` camera with the soft tissue the page
   showed (mean landmark error and fitness: larger than the SFO's), and the SFO's camera alone
   (Lilium fits the best soft tissue under it: a lower fitness).

Run::

    PYTHONPATH=src python benchmarks/bench_workbench.py --out workbench-bench

Needs ``chromium`` (Debian package) for step 2.
"""

import argparse
import json
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent / "datasets"))

from lilium.casework.build import read_skull  # noqa: E402
from lilium.demo import build_demo_case  # noqa: E402
from lilium.geometry.camera import Camera  # noqa: E402
from lilium.geometry.rotations import geodesic_angle_deg  # noqa: E402

CHROMIUM_FLAGS = (
    "--headless", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
    "--enable-webgl", "--ignore-gpu-blocklist", "--disable-background-networking",
    "--disable-component-update", "--disable-sync", "--no-first-run",
    "--virtual-time-budget=20000", "--dump-dom",
)
METHODS = ("posest-sfo", "lilium")


def open_page(url, profile):
    """``(skull box (4,), page camera, page's JSON after the hooks)`` of ``workbench.html?...``."""
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    dom = subprocess.run(
        [chromium, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", url],
        capture_output=True, text=True, timeout=300,
    ).stdout
    box = [float(x) for x in re.search(r'<pre id="skull-box">([^<]*)</pre>', dom)[1].split()]
    camera = json.loads(re.search(r'<pre id="camera">([^<]*)</pre>', dom)[1].replace("&quot;", '"'))
    timing = re.search(r'<pre id="timing">([^<]*)</pre>', dom)
    timing = json.loads(timing[1].replace("&quot;", '"')) if timing else {}
    return box, Camera.from_dict(camera), timing


def sfo(args, out):
    run = subprocess.run(
        [sys.executable, "-m", "lilium", "sfo", *map(str, args), "--out", str(out)],
        capture_output=True, text=True,
    )
    if run.returncode != 0:
        raise RuntimeError(run.stderr.strip().splitlines()[-1])
    return json.loads((out / "result.json").read_text())


def one(name, subject, axes, photo, method, work):
    """One row: the page's figures and the scores of the three cameras."""
    base = ["--skull", subject, "--axes", axes, "--photo", photo, "--method", method]
    out = work / f"{name}-{method}"
    result = sfo(base, out)
    camera = Camera.from_dict(result["camera"])
    page = out / "workbench.html"
    started = time.perf_counter()
    box, at_sfo, timing = open_page(f"file://{page}?test", work / "chromium")
    seconds = time.perf_counter() - started
    _, turned, _ = open_page(f"file://{page}?test&yaw=5", work / "chromium")
    projected = camera.project(read_skull(subject).vertices_mm)
    expected = [*np.nanmin(projected, axis=0), *np.nanmax(projected, axis=0)]
    turned_file = work / f"{name}-{method}-yaw5.json"
    turned_file.write_text(json.dumps({**turned.to_dict(),
                                       "facial_landmarks_3d": result["facial_landmarks_3d"]}))
    bare_file = work / f"{name}-{method}-bare.json"
    bare_file.write_text(json.dumps(camera.to_dict()))
    own = sfo([*base, "--camera", out / "result.json"], work / f"{name}-{method}-own")
    yaw = sfo([*base, "--camera", turned_file], work / f"{name}-{method}-yaw5")
    bare = sfo([*base, "--camera", bare_file], work / f"{name}-{method}-bare")
    return {
        "case": name, "method": method, "page_mb": page.stat().st_size / 1e6,
        "chromium_s": seconds, "first_draw_ms": timing.get("first_draw_ms"),
        "box_px": float(np.max(np.abs(np.subtract(box, expected)))),
        "page_camera": float(np.max(np.abs(at_sfo.skull2cam - camera.skull2cam))),
        "yaw_deg": geodesic_angle_deg(turned.R, camera.R),
        "fitness": result["fitness"], "own": own["fitness"],
        "own_rel": abs(own["fitness"] - result["fitness"]) / result["fitness"],
        "error_px": result["landmark_error"]["mean_px"],
        "yaw_error_px": yaw["landmark_error"]["mean_px"], "yaw_fitness": yaw["fitness"],
        "bare_fitness": bare["fitness"],
        "lr": [r["identification"].get("log10_lr") for r in (result, own, yaw)],
    }


def cases(work):
    """``(name, subject, axes, photo)`` of the demo's photos and the real heads' first pair."""
    subject, photos, axes = build_demo_case(work / "demo", seed=0)
    out = [(f"demo-{p.name}", subject, axes, p) for p in photos]
    from bench_real_anatomy import real_datasets

    for head, root in real_datasets(work / "real", n_photos=1).items():
        for view in ("f00", "l00"):
            sid = "hq" if head == "headsq" else "cr"
            photo = root / "photos" / "C" / f"{sid}_{view}"
            subject = root / "subjects" / sid
            out.append((f"{head}-{view}", subject, subject / "axes_C1.json", photo))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="workbench-bench")
    args = parser.parse_args()
    work = Path(args.out)
    work.mkdir(parents=True, exist_ok=True)
    print("| case | method | page MB | first draw ms | box vs projection px | yaw=5 turn deg "
          "| fitness | own camera scored (rel) | mean error px: SFO / yaw 5 | yaw 5 fitness "
          "| bare camera, fitted | log10 LR: SFO / own / yaw 5 |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, subject, axes, photo in cases(work):
        for method in METHODS:
            r = one(name, subject, axes, photo, method, work)
            lr = " / ".join("-" if x is None else f"{x:+.2f}" for x in r["lr"])
            print(f"| {name} | {method} | {r['page_mb']:.1f} | {r['first_draw_ms'] or 0:.0f} "
                  f"| {r['box_px']:.2f} | {r['yaw_deg']:.3f} | {r['fitness']:.4g} "
                  f"| {r['own']:.4g} ({r['own_rel']:.0e}) | {r['error_px']:.2f} / "
                  f"{r['yaw_error_px']:.2f} | {r['yaw_fitness']:.4g} | {r['bare_fitness']:.4g} "
                  f"| {lr} |", flush=True)


if __name__ == "__main__":
    main()
