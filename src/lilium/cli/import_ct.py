"""``lilium import-ct``: a CT volume to a subject folder (skull.ply, face.ply, landmarks)."""

from ..ct.importer import DEFAULT_BONE_ISO, DEFAULT_SKIN_ISO


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
            "(marching cubes, largest component) and write skull.ply, face.ply and, with "
            "--landmarks, cranial_landmarks.json. Meshes are in the volume's frame, mm."
        ),
    )
    p.add_argument("volume", help="volume file, DICOM folder, or raw files / glob pattern")
    p.add_argument("--out", required=True, help="subject folder to write")
    p.add_argument("--bone-iso", type=float, default=DEFAULT_BONE_ISO)
    p.add_argument(
        "--skin-iso", type=float, default=DEFAULT_SKIN_ISO, help="negative value: no face.ply"
    )
    p.add_argument("--raw-shape", help="raw data: slices,rows,columns (or rows,columns per file)")
    p.add_argument("--raw-dtype", help="raw data: voxel type, e.g. int16")
    p.add_argument("--byte-order", default="little", choices=["little", "big"])
    p.add_argument("--header-bytes", type=int, default=0, help="raw data: bytes to skip per file")
    p.add_argument("--spacing", help="voxel size x,y,z in mm (raw data; overrides a header)")
    p.add_argument("--landmarks", help="cranial landmarks, JSON or CSV (name,x,y,z), volume mm")
    p.add_argument("--target-faces", type=int, help="decimate each mesh to about N faces")
    p.add_argument("--crop", help="voxel index ranges i0:i1,j0:j1,k0:k1 (column, row, slice)")
    p.set_defaults(func=run)


def run(args):
    from ..ct.importer import import_ct

    options = {"byte_order": args.byte_order, "header_bytes": args.header_bytes}
    if args.raw_shape:
        options["raw_shape"] = _numbers(args.raw_shape, (2, 3), int, "--raw-shape")
    if args.raw_dtype:
        options["raw_dtype"] = args.raw_dtype
    if args.spacing:
        options["spacing"] = _numbers(args.spacing, 3, float, "--spacing")
    crop = None
    if args.crop:
        crop = _crop(args.crop)
        if crop is None:
            raise ValueError(f"--crop must look like i0:i1,j0:j1,k0:k1, got {args.crop!r}")
    volume = args.volume
    if args.raw_shape is None and args.raw_dtype is None:
        options = {k: v for k, v in options.items() if k == "spacing"}
    result = import_ct(
        volume,
        args.out,
        bone_iso=args.bone_iso,
        skin_iso=None if args.skin_iso < 0 else args.skin_iso,
        landmarks=args.landmarks,
        target_faces=args.target_faces,
        crop=crop,
        **options,
    )
    skin = result["skin"]
    print(
        f"wrote {result['folder']}: skull {len(result['skull'][1])} faces"
        + ("" if skin is None else f", skin {len(skin[1])} faces")
        + (f", {len(result['landmarks'])} landmarks" if result["landmarks"] else "")
    )
    return 0
