"""Chin-jaw soft tissue: a real head CT against generated subjects (a script).

For lateral offsets ``x = -25, -20, ..., +25`` mm from the midline it measures, in each
source's head frame, how far the mandible's inferior border rises sideways (``bone_rise_mm``),
the soft tissue depth from that border to the skin (``depth_mm``) and how far the skin under it
rises (``skin_rise_mm``); the definitions, the chin regions and the frames are in
``benchmarks/studies/chin_profile_geometry.py``. This script reads the head CT and the generated
subjects, prints the tables and draws the figure.

Output: the profile table (ray along the normal, as defined there), then a second table from
the same border points with the ray always straight down, and the normal's ``tilt`` (its angle
from straight down, positive when it leans away from the midline): where the normal leans far
sideways its ray meets the skin on the jaw's flank, the straight-down ray the skin under the
border. For the generated subjects each cell is the median [min, max] over the subjects. Summary
per source and ray: the median depth (over every subject and column), the range over ``x`` of
the per-column median depth, and the median bone / skin rises at ``x = -20`` and ``+20`` mm.

Run (about 20 s; the CT part is skipped with a message when ``../shared/data/headsq`` is
absent; ``--png`` writes a figure of frontal and sagittal views with the border points and
rays, for the CT and the first subject)::

    PYTHONPATH=src .venv/bin/python benchmarks/studies/chin_profile.py [--png chin.png] [--ct DIR]
        [--ct-bone-iso 1150] [--subjects 8] [--seed 0]
"""

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from chin_profile_geometry import (
    SUMMARY_X_MM,
    chin_profile,
    ct_region,
    lps_to_head,
    plane_section,
    profile_summary,
    subject_region,
)

#: CT levels (scanner units): the README's bone and skin levels.
CT_BONE_ISO = 1150.0
CT_SKIN_ISO = 500.0
#: The two depth rays: along the bone normal (straight down where unreliable), straight down.
RAYS = ("normal", "down")

DEFAULT_CT = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "headsq"


# --- I/O: reading, printing, plotting ------------------------------------------------------


def load_ct(folder, bone_iso=CT_BONE_ISO):
    """Import the head CT (:func:`lilium.ct.import_ct`, into a temporary folder).

    Parameters
    ----------
    folder : Path
        Holds ``quarter.nhdr``.
    bone_iso : float
        Bone level (scanner units); the skin level is :data:`CT_SKIN_ISO`.

    Returns
    -------
    bone, skin : (ndarray of shape (V, 3), ndarray of shape (F, 3))
        Head frame (:func:`lps_to_head`), mm.
    cut_y_mm : float
        ``y`` of the centre of the volume's last (lowest) slice.
    """
    from lilium.ct import import_ct

    with tempfile.TemporaryDirectory() as out:
        result = import_ct(Path(folder) / "quarter.nhdr", Path(out) / "ct", bone_iso, CT_SKIN_ISO)
    record = result["record"]
    bone = (lps_to_head(result["skull"][0]), result["skull"][1])
    skin = (lps_to_head(result["skin"][0]), result["skin"][1])
    shape_ijk = np.array(record["shape_zyx"][::-1]) - 1
    corners = np.array(np.meshgrid(*[[0, n] for n in shape_ijk], indexing="ij")).reshape(3, -1)
    index_to_lps = np.asarray(record["index_to_frame"], float)
    superior = (index_to_lps[:3, :3] @ corners + index_to_lps[:3, 3:])[2]
    return bone, skin, float(superior.min())


def _fmt(value, width=6):
    return f"{value:{width}.1f}" if np.isfinite(value) else " " * (width - 1) + "-"


def _spread(values):
    v = np.asarray(values, float)
    if not np.isfinite(v).any():
        return f"{'-':>17}"
    return f"{np.nanmedian(v):5.1f} [{np.nanmin(v):5.1f},{np.nanmax(v):5.1f}]"


def _flags(profile, k):
    flags = "n" if profile.along_normal[k] else "d"
    flags += "e" if profile.at_edge[k] else ""
    flags += "c" if profile.cut[k] else ""
    return flags


def _print_table(title, x, ct_head, ct_rows, gen_head, gen_rows):
    """One table: the CT's block (when there is one) beside the generated subjects' block."""
    print(f"\n{title}")
    gen_title = "generated subjects: median [min, max]"
    if ct_rows is None:
        print(f"{'':>5} | {gen_title:^{len(gen_head)}}")
        print(f"{'x mm':>5} | {gen_head}")
        for dx, right in zip(x, gen_rows, strict=True):
            print(f"{dx:5.0f} | {right}")
        return
    print(f"{'':>5} | {'head CT':^{len(ct_head)}} | {gen_title:^{len(gen_head)}}")
    print(f"{'x mm':>5} | {ct_head} | {gen_head}")
    for dx, left, right in zip(x, ct_rows, gen_rows, strict=True):
        print(f"{dx:5.0f} | {left} | {right}")


def print_tables(ct, subjects):
    """The two tables: the profile (ray along the normal), then the straight-down variant.

    Parameters
    ----------
    ct : dict of str -> ChinProfile or None
        ``"normal"`` and ``"down"`` profiles of the CT; None: no CT columns.
    subjects : dict of str -> list of ChinProfile
        The same for the generated subjects.
    """
    gen, x = subjects["normal"], subjects["normal"][0].x_mm
    names = ("bone_rise_mm", "depth_mm", "skin_rise_mm", "back_mm")
    gen_rows = []
    for k in range(len(x)):
        row = " ".join(_spread([getattr(p, name)[k] for p in gen]) for name in names)
        row += f" {sum(not p.along_normal[k] for p in gen):3d}"
        edge = sum(p.at_edge[k] for p in gen)
        gen_rows.append(row + (f" e{edge}" if edge else ""))
    ct_rows = None
    if ct is not None:
        p = ct["normal"]
        ct_rows = [
            " ".join(_fmt(getattr(p, name)[k]) for name in names) + f" {_flags(p, k):>4}"
            for k in range(len(x))
        ]
    _print_table(
        "profile: depth ray along the bone normal (d: straight down, the normal unreliable)",
        x,
        f"{'bone':>6} {'depth':>6} {'skin':>6} {'back':>6} {'ray':>4}",
        ct_rows,
        f"{'bone rise':>17} {'depth':>17} {'skin rise':>17} {'back':>17} {'#d':>3}",
        gen_rows,
    )
    names = ("tilt_deg", "depth_mm", "skin_rise_mm")
    gen_rows = [
        " ".join(_spread([getattr(p, name)[k] for p in subjects["down"]]) for name in names)
        for k in range(len(x))
    ]
    if ct is not None:
        p = ct["down"]
        ct_rows = [
            " ".join(_fmt(getattr(p, name)[k]) for name in names) + f" {'c' if p.cut[k] else '':>4}"
            for k in range(len(x))
        ]
    _print_table(
        "the same border points, depth ray straight down; tilt: the normal's angle from down",
        x,
        f"{'tilt':>6} {'depth':>6} {'skin':>6} {'':>4}",
        ct_rows,
        f"{'tilt deg':>17} {'depth':>17} {'skin rise':>17}",
        gen_rows,
    )


def summary_line(name, summary):
    """The one-line summary of a source."""
    lo, hi = summary["depth_range_mm"]
    rises = ", ".join(
        f"x={xs:+.0f}: {summary['bone_rise_mm'][xs]:+.1f} / {summary['skin_rise_mm'][xs]:+.1f}"
        for xs in SUMMARY_X_MM
    )
    cut = f"; {summary['cut']} skin points on the volume's cut" if summary["cut"] else ""
    return (
        f"{name}: median depth {summary['depth_median_mm']:.1f} mm, depth over x "
        f"{lo:.1f} to {hi:.1f} mm; bone / skin rise {rises} mm{cut}"
    )


def _ray_end(profile, k):
    s = profile.skin_mm[k]
    return s if np.all(np.isfinite(s)) else profile.border_mm[k] + 30 * profile.direction[k]


def _plot_source(axes, title, bone, skin, region, profiles, cut_y_mm=None):
    """Frontal panel and sagittal sections at x = -20, 0, +20 of one head."""
    import matplotlib.cm as cm

    normal, down = profiles["normal"], profiles["down"]
    colours = cm.viridis(np.linspace(0, 0.9, len(normal.x_mm)))
    xm = region.x_mid_mm
    lo = np.nanmin(normal.border_mm[:, 1]) - 25
    hi = region.y_top_mm + 5
    z_lo, z_hi = np.nanmin(normal.border_mm[:, 2]) - 10, np.nanmax(normal.border_mm[:, 2]) + 10

    def near_chin(points):
        keep = (points[:, 2] > region.z_back_mm - 10) & (points[:, 1] < hi)
        return keep & (points[:, 1] > lo) & (np.abs(points[:, 0] - xm) < 45)

    front = axes[0]
    for pts, colour, label in ((bone[0], "0.3", "bone"), (skin[0], "tab:red", "skin")):
        p = pts[near_chin(pts) & (pts[:, 2] > z_lo) & (pts[:, 2] < z_hi)]
        front.scatter(p[:, 0] - xm, p[:, 1], s=2, c=colour, alpha=0.4, label=label, lw=0)
    front.set_title(f"{title}: frontal, vertices with {z_lo:.0f} < z < {z_hi:.0f}")
    front.set_xlabel("x - x_mid (mm, subject's left)")
    front.set_ylabel("y (mm, up)")
    for k, _dx in enumerate(normal.x_mm):
        b = normal.border_mm[k]
        if not np.all(np.isfinite(b)):
            continue
        for profile, style in ((normal, "-"), (down, ":")):
            end = _ray_end(profile, k)
            front.plot([b[0] - xm, end[0] - xm], [b[1], end[1]], style, color=colours[k], lw=1.2)
            marker = "x" if profile.cut[k] else "s"
            front.plot(end[0] - xm, end[1], marker, color=colours[k], ms=4, mfc="none")
        front.plot(b[0] - xm, b[1], "o", color=colours[k], ms=4)
    for name, point in region.marks.items():
        front.plot(point[0] - xm, point[1], "g^", ms=6)
        front.annotate(name, (point[0] - xm, point[1]), fontsize=6, color="g")
    for dx, ax in zip((-20.0, 0.0, 20.0), axes[1:], strict=True):
        for (v, f), colour in ((bone, "0.2"), (skin, "tab:red")):
            p = plane_section(v, f, xm + dx)
            p = p[near_chin(p)]
            ax.scatter(p[:, 2], p[:, 1], s=3, c=colour, lw=0)
        ax.axvline(region.z_back_mm, color="tab:green", ls=":", lw=1)
        ax.axhline(region.y_top_mm, color="tab:green", ls=":", lw=1)
        k = int(np.argmin(np.abs(normal.x_mm - dx)))
        b = normal.border_mm[k]
        if np.all(np.isfinite(b)):
            for profile, style in ((normal, "-"), (down, ":")):
                end = _ray_end(profile, k)
                ax.plot([b[2], end[2]], [b[1], end[1]], style, color=colours[k], lw=1.5)
                ax.plot(end[2], end[1], "x" if profile.cut[k] else "s", color=colours[k], ms=5)
            ax.plot(b[2], b[1], "o", color=colours[k], ms=5)
        ax.set_title(f"{title}: sagittal section x = {dx:+.0f} (mesh crossings)")
        ax.set_xlabel("z (mm, anterior)")
    for ax in axes:
        if cut_y_mm is not None:
            ax.axhline(cut_y_mm, color="k", ls="--", lw=0.8)
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
    front.legend(loc="upper right", fontsize=7, markerscale=5)


def write_png(path, panels):
    """Write the figure: one row per source, panels as in :func:`_plot_source`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(panels), 4, figsize=(26, 6.5 * len(panels)), squeeze=False)
    for row, args in zip(axes, panels, strict=True):
        _plot_source(row, *args)
    fig.suptitle(
        "chin-jaw profile: o border point B; solid: ray along the bone normal, dotted: straight "
        "down; square: skin hit S, x: S on the CT's cut; green: region limits; dashed: CT's "
        "last slice",
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _both(bone, skin, region, cut_y_mm=None):
    return {r: chin_profile(bone, skin, region, cut_y_mm=cut_y_mm, ray=r) for r in RAYS}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ct", type=Path, default=DEFAULT_CT, help="headsq folder")
    parser.add_argument("--ct-bone-iso", type=float, default=CT_BONE_ISO)
    parser.add_argument("--subjects", type=int, default=8)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--png", type=Path, default=None, help="write the figure here")
    args = parser.parse_args(argv)
    from lilium.synthetic.subjects import make_subjects

    start = time.perf_counter()
    panels, ct = [], None
    if (args.ct / "quarter.nhdr").is_file():
        bone, skin, cut_y = load_ct(args.ct, args.ct_bone_iso)
        region = ct_region(bone[0])
        ct = _both(bone, skin, region, cut_y)
        panels.append(("head CT", bone, skin, region, ct, cut_y))
        print(
            f"head CT {args.ct.resolve()} (bone iso {args.ct_bone_iso:g}, skin iso "
            f"{CT_SKIN_ISO:g}): x_mid {region.x_mid_mm:.1f}, region z > {region.z_back_mm:.1f},"
            f" y < {region.y_top_mm:.1f}, last slice y {cut_y:.1f} mm"
        )
    else:
        print(f"head CT skipped: {args.ct / 'quarter.nhdr'} not found")
    subjects = make_subjects(args.subjects, seed=args.seed)
    gen = {r: [] for r in RAYS}
    for s in subjects:
        bone, skin = (s.skull_vertices_mm, s.skull_faces), (s.skin_vertices_mm, s.skin_faces)
        region = subject_region(s.cranial_landmarks)
        both = _both(bone, skin, region)
        for r in RAYS:
            gen[r].append(both[r])
        if len(panels) < 1 + (ct is not None):
            panels.append((f"generated {s.subject_id}", bone, skin, region, both))
    print(
        f"generated: {len(subjects)} subjects (make_subjects seed {args.seed}), skull frame. "
        "mm; bone / skin: rise from x = 0; back: border behind the midline border; ray: n along "
        "the normal, d straight down, e border at the region's back edge, c skin on the CT's cut "
        "(depth a lower bound); #d: subjects whose ray went straight down"
    )
    print_tables(ct, gen)
    print()
    for r, label in zip(RAYS, ("ray along the normal", "ray straight down"), strict=True):
        if ct is not None:
            print(summary_line(f"head CT, {label}", profile_summary([ct[r]])))
        print(summary_line(f"generated, {label}", profile_summary(gen[r])))
    if args.png is not None:
        write_png(args.png, panels)
        print(f"figure: {args.png}")
    print(f"({time.perf_counter() - start:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
