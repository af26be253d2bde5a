"""``lilium case``: superimpose one skull on one or more photos and report them together.

Inputs are SPEC section 8 folders or the files a practitioner already has::

    lilium case --skull SUBJECT_DIR --photo PHOTO_DIR [--photo PHOTO_DIR ...] --out DIR
    lilium case --skull skull.stl --landmarks skull.mrk.json \\
        --photo front.jpg --photo-landmarks front.csv [--mask front_mask.png] --out DIR

A mesh's landmark file defaults to a sibling with the mesh's stem (``skull.fcsv``, ...); an
image's landmark file to ``<stem>.csv``/``.json`` or ``<stem>_landmarks.*`` and its mask to
``<stem>_mask.png``. Priors: ``--focal-px``/``--scd-mm`` override ``photo.json``; without
either, the focal prior comes from the photo's EXIF when it has one.

Writes ``DIR/report.html`` and, per photo, ``DIR/<photo>/result.json`` and ``overlay.png``
(``DIR/<photo>/<method>/`` when several methods run).
"""

import shlex
from dataclasses import replace
from pathlib import Path

from ..constants import VIEWS
from ..inputs import correspondences
from ..io.case import (
    IMAGE_NAMES,
    photo_from_files,
    read_depth_table,
    read_photo,
    read_skull,
    skull_from_files,
)
from ..io.formats import find_landmark_file
from ..io.mesh import MESH_SUFFIXES
from ..io.results import write_result
from ..methods.lilium import VARIANTS, lilium_sfo
from ..methods.overlay import result_overlay
from ..methods.posest_sfo import posest_sfo
from ..optimisation.de import DEOptions
from .sfo import METHODS, lilium_options

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg")


def register(subparsers):
    p = subparsers.add_parser(
        "case",
        help="superimpose a skull on one or more photos; HTML report",
        description=(
            "Run the SFO of one skull against each photo and write DIR/report.html with "
            "DIR/<photo>/result.json and overlay.png."
        ),
    )
    p.add_argument(
        "--skull",
        required=True,
        type=Path,
        help="subject folder (SPEC section 8) or a skull mesh (PLY/OBJ/STL, mm)",
    )
    p.add_argument(
        "--landmarks",
        type=Path,
        help="cranial landmarks: .mrk.json/.fcsv (3D Slicer), .pp (MeshLab), .csv, .json",
    )
    p.add_argument("--axes", type=Path, help="soft-tissue axes JSON (default: the skull's own)")
    p.add_argument(
        "--photo",
        required=True,
        action="append",
        type=Path,
        help="photo folder or image (PNG/JPEG); repeat for several photos of the person",
    )
    p.add_argument(
        "--photo-landmarks",
        action="append",
        type=Path,
        default=[],
        help="facial landmarks (CSV name,u,v or JSON) of each photo image, in --photo order",
    )
    p.add_argument(
        "--mask",
        action="append",
        type=Path,
        default=[],
        help="face mask PNG of each photo image, in --photo order",
    )
    p.add_argument(
        "--view",
        action="append",
        choices=VIEWS,
        default=[],
        help=(
            "view of each photo image (once for all images, or once per image; default "
            "frontal); photo folders take theirs from photo.json"
        ),
    )
    p.add_argument("--out", required=True, type=Path, help="output folder")
    p.add_argument(
        "--method",
        action="append",
        choices=METHODS,
        default=[],
        help="method; repeat to run several (default lilium)",
    )
    p.add_argument("--variant", default="skof+pll", choices=list(VARIANTS))
    p.add_argument("--seed", type=int, default=0, help="Lilium random seed (default 0)")
    de = DEOptions()
    p.add_argument("--generations", type=int, help=f"DE generations (default {de.max_generations})")
    p.add_argument("--population", type=int, help=f"DE population (default {de.population_size})")
    p.add_argument("--max-seconds", type=float, help=f"per SFO (default {de.max_seconds:g})")
    p.add_argument("--focal-px", type=float, nargs=2, metavar=("LO", "HI"), help="focal prior")
    p.add_argument("--scd-mm", type=float, nargs=2, metavar=("LO", "HI"), help="SCD prior (mm)")
    p.add_argument(
        "--sensor-width-mm", type=float, help="camera sensor width, for the EXIF focal prior"
    )
    p.add_argument("--no-exif", action="store_true", help="do not take a focal prior from EXIF")
    p.add_argument("--depth-table", type=Path, help="CSV: landmark,mean,sd,min,max (mm)")
    p.add_argument("--title", help="report title")
    p.set_defaults(func=run)


# --------------------------------------------------------------------------------------------
# Reading


def _first_file(folder, names):
    return next((folder / n for n in names if (folder / n).is_file()), None)


def load_skull(skull_path, landmarks=None, axes=None):
    """Read the skull from a subject folder or a mesh file.

    Returns
    -------
    skull : Skull
    inputs : dict of str -> Path
        The files used, labelled, for the provenance.
    """
    skull_path = Path(skull_path)
    if skull_path.is_dir():
        mesh = _first_file(skull_path, [f"skull{s}" for s in MESH_SUFFIXES])
        if landmarks is None:
            skull = read_skull(skull_path, axes_path=axes)
            landmarks = _first_file(skull_path, ["cranial_landmarks.json"]) or find_landmark_file(
                skull_path, ["cranial_landmarks", "skull"]
            )
        else:
            if mesh is None:
                read_skull(skull_path)  # raises its "no skull mesh" message
            axes = axes or skull_path / "soft_tissue_axes.json"
            skull = skull_from_files(mesh, landmarks, axes, skull_id=skull_path.name)
        axes = Path(axes) if axes else skull_path / "soft_tissue_axes.json"
    elif skull_path.is_file():
        mesh = skull_path
        if skull_path.suffix.lower() not in MESH_SUFFIXES:
            raise ValueError(
                f"{skull_path}: --skull must be a subject folder or a PLY/OBJ/STL mesh; convert "
                "the skull to one of those"
            )
        if landmarks is None:
            landmarks = find_landmark_file(
                skull_path.parent, [skull_path.stem, f"{skull_path.stem}_landmarks"]
            )
            if landmarks is None:
                raise ValueError(
                    f"{skull_path}: no cranial landmark file next to the mesh; give it with "
                    "--landmarks FILE (.mrk.json, .fcsv, .pp, .csv or .json)"
                )
        skull = skull_from_files(mesh, landmarks, axes)
    else:
        raise ValueError(
            f"{skull_path}: --skull not found; give a subject folder or a skull mesh file"
        )
    inputs = {"skull mesh": mesh, "cranial landmarks": landmarks}
    if axes is not None and Path(axes).is_file():
        inputs["soft-tissue axes"] = Path(axes)
    return skull, inputs


def _per_photo(values, n, option, allow_one=False):
    if not values:
        return [None] * n
    if allow_one and len(values) == 1:
        return values * n
    if len(values) != n:
        raise ValueError(
            f"command line: {option} given {len(values)} times for {n} photo image(s); give it "
            "once per --photo image (not folder), in the same order"
        )
    return list(values)


def _sibling(image_path, stems, suffixes):
    for stem in stems:
        for suffix in suffixes:
            candidate = image_path.with_name(stem + suffix)
            if candidate.is_file() and candidate != image_path:
                return candidate
    return None


def _check_interval(values, option):
    from ..validation import check_interval

    return None if values is None else check_interval(values, f"command line: {option}")


def load_photos(args):
    """Read every ``--photo`` (folders and image files) with priors; returns photo records.

    Returns
    -------
    list of (Photo, dict inputs, dict notes)
    """
    photos = [Path(p) for p in args.photo]
    image_files = [p for p in photos if not p.is_dir()]
    lm_files = _per_photo(args.photo_landmarks, len(image_files), "--photo-landmarks")
    masks = _per_photo(args.mask, len(image_files), "--mask")
    views = _per_photo(args.view, len(image_files), "--view", allow_one=True)
    focal_cli = _check_interval(args.focal_px, "--focal-px")
    scd_cli = _check_interval(args.scd_mm, "--scd-mm")
    records, k_file = [], 0
    for path in photos:
        inputs, notes = {}, {}
        if path.is_dir():
            photo = read_photo(path)
            image = _first_file(path, IMAGE_NAMES)
            inputs["photo"] = image
            inputs["photo.json"] = path / "photo.json"
            lm_file = find_landmark_file(path, ["facial_landmarks", "landmarks"])
            if lm_file is not None and "landmarks" not in _json_keys(path / "photo.json"):
                inputs["facial landmarks"] = lm_file
            for name, label in (("face_mask.png", "face mask"), ("face_curve.json", "face curve")):
                if (path / name).is_file():
                    inputs[label] = path / name
        else:
            if not path.is_file():
                raise ValueError(f"{path}: --photo not found; give a photo folder or an image")
            if path.suffix.lower() not in IMAGE_SUFFIXES:
                raise ValueError(f"{path}: --photo must be a folder or a PNG/JPEG image")
            image = path
            lm_file = lm_files[k_file] or _sibling(
                path,
                [path.stem, f"{path.stem}_landmarks", f"{path.stem}.landmarks"],
                (".csv", ".json", ".tsv", ".txt"),
            )
            if lm_file is None:
                raise ValueError(
                    f"{path}: no facial landmark file for this photo; give it with "
                    "--photo-landmarks FILE (CSV name,u,v or JSON), once per --photo image"
                )
            mask = masks[k_file] or _sibling(
                path, [f"{path.stem}_mask", f"{path.stem}.mask"], (".png",)
            )
            view = views[k_file] or "frontal"
            k_file += 1
            photo = photo_from_files(path, lm_file, view, mask)
            inputs["photo"] = path
            inputs["facial landmarks"] = lm_file
            if mask is not None:
                inputs["face mask"] = mask
        priors = photo.priors
        if focal_cli is not None:
            priors = replace(priors, focal_px=focal_cli)
            notes["focal prior"] = "command line --focal-px"
        elif priors.focal_px is not None:
            notes["focal prior"] = "photo.json"
        elif not args.no_exif:
            from ..io.exif import focal_prior_from_exif

            exif = focal_prior_from_exif(image, sensor_width_mm=args.sensor_width_mm)
            if exif is not None:
                priors = replace(priors, focal_px=exif.focal_px)
                notes["focal prior"] = exif.source
        if scd_cli is not None:
            priors = replace(priors, scd_mm=scd_cli)
            notes["SCD prior"] = "command line --scd-mm"
        elif priors.scd_mm is not None:
            notes["SCD prior"] = "photo.json"
        for key, value in (("focal prior", priors.focal_px), ("SCD prior", priors.scd_mm)):
            if value is not None:
                unit = "px" if key == "focal prior" else "mm"
                notes[key] = f"{value[0]:.0f}-{value[1]:.0f} {unit} ({notes[key]})"
            else:
                notes[key] = "none (penalty off)"
        records.append((replace(photo, priors=priors), inputs, notes))
    seen = {}
    for i, (photo, inputs, notes) in enumerate(records):  # unique photo ids for the outputs
        n = seen.get(photo.id, 0)
        seen[photo.id] = n + 1
        if n:
            records[i] = (replace(photo, id=f"{photo.id}_{n + 1}"), inputs, notes)
    return records


def _json_keys(path):
    from ..io.jsonio import read_json

    data = read_json(path)
    return data.keys() if isinstance(data, dict) else ()


# --------------------------------------------------------------------------------------------
# Running


def run_case(args):
    """Read, check, run every SFO, write the outputs; returns the report entries."""
    from ..report.html import ReportEntry, write_report

    skull, skull_inputs = load_skull(args.skull, args.landmarks, args.axes)
    records = load_photos(args)
    table = read_depth_table(args.depth_table) if args.depth_table else None
    for photo, inputs, _ in records:  # every problem before any long run
        try:
            correspondences(skull, photo)
        except ValueError as exc:
            where = inputs.get("facial landmarks") or inputs.get("photo.json")
            raise ValueError(f"{where}: {exc}") from None
    methods = list(dict.fromkeys(args.method)) or ["lilium"]
    options = lilium_options(args.variant, args.generations, args.population, args.max_seconds)
    out = Path(args.out)
    entries = []
    for photo, inputs, notes in records:
        for method in methods:
            if method == "posest-sfo":
                result = posest_sfo(skull, photo, depth_table=table)
            else:
                result = lilium_sfo(skull, photo, options, seed=args.seed, depth_table=table)
            tag = method if method == "posest-sfo" else f"lilium-{args.variant}"
            folder = out / photo.id / tag if len(methods) > 1 else out / photo.id
            write_result(folder, result, result_overlay(result, skull, photo))
            rel = folder.relative_to(out)
            outputs = {"result.json": f"{rel.as_posix()}/result.json"}
            if (folder / "overlay.png").is_file():
                outputs["overlay.png"] = f"{rel.as_posix()}/overlay.png"
            name = f"{result.method}{f' {result.variant}' if result.variant else ''}"
            status = (
                f"focal {result.camera.focal_px:.0f} px, score {result.fitness:.4g}"
                if result
                else f"FAILED ({result.error})"
            )
            print(f"{photo.id}: {name}: {status}, {result.seconds:.2f} s -> {folder}")
            entries.append(
                ReportEntry(skull, photo, result, {**skull_inputs, **inputs}, notes, outputs)
            )
    report = write_report(
        out / "report.html", entries, title=args.title, command=command_line(args, methods)
    )
    print(f"report: {report}")
    return entries


def command_line(args, methods):
    """The ``lilium case`` command line equivalent to ``args`` (for the provenance)."""
    parts = ["lilium", "case", "--skull", str(args.skull)]
    for option in ("landmarks", "axes", "depth_table"):
        if getattr(args, option) is not None:
            parts += [f"--{option.replace('_', '-')}", str(getattr(args, option))]
    for photo in args.photo:
        parts += ["--photo", str(photo)]
    for option in ("photo_landmarks", "mask", "view"):
        for value in getattr(args, option):
            parts += [f"--{option.replace('_', '-')}", str(value)]
    for method in methods:
        parts += ["--method", method]
    if "lilium" in methods:
        parts += ["--variant", args.variant, "--seed", str(args.seed)]
        for option in ("generations", "population", "max_seconds"):
            if getattr(args, option) is not None:
                parts += [f"--{option.replace('_', '-')}", f"{getattr(args, option):g}"]
    for option in ("focal_px", "scd_mm"):
        if getattr(args, option) is not None:
            parts += [f"--{option.replace('_', '-')}", *(f"{x:g}" for x in getattr(args, option))]
    if args.sensor_width_mm is not None:
        parts += ["--sensor-width-mm", f"{args.sensor_width_mm:g}"]
    if args.no_exif:
        parts.append("--no-exif")
    parts += ["--out", str(args.out)]
    return " ".join(shlex.quote(p) for p in parts)


def run(args):
    entries = run_case(args)
    return 0 if all(e.result for e in entries) else 1
