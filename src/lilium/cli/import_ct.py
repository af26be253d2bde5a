"""``lilium import-ct``: a CT volume to a subject folder (skull.ply, face.ply, landmarks)."""

from .argtypes import int_in
from .options import add_options


def _numbers(text, n, kind, name):
    try:
        values = [kind(v) for v in text.replace("x", ",").split(",")]
    except ValueError as exc:
        raise ValueError(f"{name} must be {n} comma-separated numbers, got {text!r}") from exc
    if len(values) not in (n if isinstance(n, tuple) else (n,)):
        raise ValueError(f"{name} must be {n} comma-separated numbers, got {text!r}")
    return values


def _crop(text):
    """``i0:i1,j0:j1,k0:k1`` -> ((i0, i1), (j0, j1), (k0, k1))."""
    try:
        parts = [p.split(":") for p in text.split(",")]
        return tuple((int(a), int(b)) for a, b in parts) if len(parts) == 3 else None
    except ValueError:
        return None


def register(subparsers):
    p = subparsers.add_parser(
        "import-ct",
        help="extract skull and skin meshes from a CT volume into a subject folder",
        description=(
            "Read a CT volume (DICOM folder, .nrrd/.nhdr, .nii/.nii.gz, .mhd/.mha, or raw slices "
            "with --raw-shape/--raw-dtype/--spacing), extract the bone and skin iso-surfaces "
            "(marching cubes, largest component) and write skull.ply, face.ply, ct_import.json "
            "and, with --landmarks, cranial_landmarks.json. Meshes and landmarks are written in "
            "LPS (right-handed patient frame: x left, y posterior, z superior, mm) whatever the "
            "file's frame (NRRD space incl. left-handed ones, DICOM orientation, NIfTI "
            "qform/sform, MetaImage TransformMatrix), so the skull is never mirrored. Warns "
            "about a skull cut by the volume's border, coarse or anisotropic voxels, an "
            "attached spine and an orientation the file does not state."
        ),
    )
    p.add_argument("volume", help="volume file, DICOM folder, or raw files / glob pattern")
    add_options(p, "out", required=("out",))
    p.add_argument(
        "--bone-iso",
        type=float,
        help="bone level (default: 300 in Hounsfield units, 1150 in scanner units)",
    )
    p.add_argument(
        "--skin-iso",
        type=float,
        help="skin level, any sign (default: -400 in Hounsfield units, 500 in scanner units)",
    )
    p.add_argument("--no-face", action="store_true", help="write no face.ply (skin surface)")
    p.add_argument(
        "--units",
        choices=["auto", "hu", "scanner"],
        default="auto",
        help="intensity units (default: HU for DICOM or when the air is near -1000)",
    )
    p.add_argument("--raw-shape", help="raw data: slices,rows,columns (or rows,columns per file)")
    p.add_argument("--raw-dtype", help="raw data: voxel type, e.g. int16")
    p.add_argument("--byte-order", default="little", choices=["little", "big"])
    p.add_argument(
        "--header-bytes", type=int_in(0), default=0, help="raw data: bytes to skip per file"
    )
    p.add_argument("--spacing", help="voxel size x,y,z in mm (raw data; overrides a header)")
    p.add_argument(
        "--allow-outside-data",
        action="store_true",
        help="let a detached .nhdr/.mhd header name data files outside its own folder",
    )
    p.add_argument(
        "--orientation",
        help="for a file that names no orientation (raw data, ...): the side of the patient "
        "each index axis (column, row, slice) points to as it grows, e.g. LPS, or LPI when the "
        "first slice is the top of the head",
    )
    p.add_argument(
        "--landmarks",
        help="cranial landmarks in the volume file's coordinates (mm), any format lilium case "
        "reads (.json, .csv, .mrk.json/.fcsv in Slicer's own LPS/RAS frame, .pp); written in LPS",
    )
    p.add_argument("--target-faces", type=int, help="decimate each mesh to about N faces")
    p.add_argument("--crop", help="voxel index ranges i0:i1,j0:j1,k0:k1 (column, row, slice)")
    p.set_defaults(func=run)


def run(args):
    from ..ct.importer import import_ct
    from ..io.paths import check_no_links

    options = {"byte_order": args.byte_order, "header_bytes": args.header_bytes}
    if args.raw_shape:
        options["raw_shape"] = _numbers(args.raw_shape, (2, 3), int, "--raw-shape")
    if args.raw_dtype:
        options["raw_dtype"] = args.raw_dtype
    if args.spacing:
        options["spacing"] = _numbers(args.spacing, 3, float, "--spacing")
    if args.target_faces is not None and args.target_faces < 4:
        raise ValueError(f"--target-faces must be at least 4, got {args.target_faces}")
    crop = None
    if args.crop:
        crop = _crop(args.crop)
        if crop is None:
            raise ValueError(f"--crop must look like i0:i1,j0:j1,k0:k1, got {args.crop!r}")
    if args.raw_shape is None and args.raw_dtype is None:
        options = {k: v for k, v in options.items() if k == "spacing"}
    if args.allow_outside_data:
        options["allow_outside_data"] = True
    check_no_links(args.out)
    result = import_ct(
        args.volume,
        args.out,
        bone_iso=args.bone_iso,
        skin_iso=args.skin_iso,
        face=not args.no_face,
        units=args.units,
        landmarks=args.landmarks,
        target_faces=args.target_faces,
        crop=crop,
        orientation=args.orientation,
        **options,
    )
    record = result["record"]
    print(
        f"frame: {record['frame_description']} (orientation {record['orientation']}; file space "
        f"{record['source_space'] or 'none'})"
    )
    levels = f"bone {record['bone_iso']:g}"
    if record["skin_iso"] is not None:
        levels += f", skin {record['skin_iso']:g}"
    print(f"units: {record['units']} ({record['units_how']}); levels {levels}")
    for warning in result["warnings"]:
        print(f"warning [{warning['code']}]: {warning['message']}")
    ext = record["skull_extent_mm"]
    size = " x ".join(f"{v:.0f}" for v in ext["size"])
    lo = ", ".join(f"{v:.0f}" for v in ext["min"])
    hi = ", ".join(f"{v:.0f}" for v in ext["max"])
    print(f"skull extent {size} mm (x, y, z), from ({lo}) to ({hi})")
    skin = result["skin"]
    print(
        f"wrote {result['folder']}: skull {len(result['skull'][1])} faces"
        + ("" if skin is None else f", skin {len(skin[1])} faces")
        + (f", {len(result['landmarks'])} landmarks" if result["landmarks"] else "")
    )
    return 0
