"""The options the ``lilium`` commands share, each defined once, and the request built from them.

A command adds the shared options it takes with :func:`add_options` (``add_options(p, "skull",
"photo", "out", required=("skull", "photo", "out"))``); a bad value is argparse's one-line
error naming the option, before anything runs. ``lilium sfo``, ``case`` and ``lineup`` then
turn their arguments into one :class:`~lilium.casework.request.CaseRequest`
(:func:`case_request`), the only thing their runs take.

What differs between commands is said here, once: the default method (``lilium sfo`` runs
POSEST-SFO, the baseline, unless told otherwise; ``case`` and ``lineup`` run Lilium) and
``--workers``' default (``synth``: 2; ``experiment``: the config's). Options that mean
something else in one command keep their own definition there: ``lilium photo``'s
``--landmarks`` (reviewed facial landmarks) and ``--view`` (one view, default from the head's
yaw), ``lilium import-ct``'s ``--landmarks`` (in the volume's coordinates).
"""

import shlex
from dataclasses import replace
from pathlib import Path

from ..casework.request import Candidate, CaseRequest, PhotoSource, PriorOverrides, SkullSource
from ..constants import MAX_DE_POPULATION, VIEWS
from ..methods import METHODS, SfoOptions
from ..optimisation.de import DEOptions
from .argtypes import existing_file, int_in, output_folder, positive_float, seed

VARIANTS = METHODS["lilium"].variants
_DE = DEOptions()

#: Option name -> (flags, ``add_argument`` keywords). ``help`` may hold ``{default}``.
OPTIONS = {
    "skull": (("--skull",), dict(
        type=Path,
        help="subject folder or skull mesh (PLY/OBJ/STL, mm; its landmarks with --landmarks or "
        "beside it, else placed automatically into OUT/prepared-skull/, unreviewed)",
    )),
    "landmarks": (("--landmarks",), dict(
        type=Path,
        help="cranial landmarks of a skull mesh: .mrk.json/.fcsv (3D Slicer), .pp (MeshLab), "
        ".csv, .json (default: SKULL.* or SKULL_landmarks.* beside the mesh)",
    )),
    "axes": (("--axes",), dict(
        type=existing_file("soft-tissue axes file"),
        help="soft-tissue axes JSON to use instead of the skull's own",
    )),
    "photo": (("--photo",), dict(
        action="append", type=Path,
        help="photo folder or image (PNG/JPEG); repeat for several photos of the person",
    )),
    "photo_landmarks": (("--photo-landmarks",), dict(
        action="append", type=Path, default=[],
        help="facial landmarks (CSV name,u,v or JSON) of each photo image, in --photo order",
    )),
    "mask": (("--mask",), dict(
        action="append", type=Path, default=[],
        help="face mask PNG of each photo image, in --photo order: the head as seen (face, "
        "forehead, hair, ears, down to the upper neck)",
    )),
    "face_curve": (("--face-curve",), dict(
        action="append", type=Path, default=[],
        help="facial curve JSON (face_curve.json format) of each photo image, in --photo "
        "order; default NAME_face_curve.json beside the image, else derived from the mask",
    )),
    "view": (("--view",), dict(
        action="append", choices=VIEWS, default=[],
        help="view of each photo image (once for all images, or once per image; default "
        "frontal); photo folders take theirs from photo.json",
    )),
    "camera": (("--camera",), dict(
        action="append", default=[], metavar="[PHOTO=]FILE",
        help="score this camera without search: a camera.json (workbench.html's Save: focal_px, "
        "principal_point_px, skull2cam) or a result.json; PHOTO=FILE for one --photo (PHOTO as "
        "given or its id), FILE alone with one --photo; repeat per photo",
    )),
    "auto_landmarks": (("--auto-landmarks",), dict(
        action="store_true",
        help="prepare each --photo image that has no landmark file (none given, none beside "
        "it) with lilium photo into OUT/<photo>/prepared/ and use its tracked landmarks, head "
        "mask and priors; the report says they are automatic and unreviewed (needs pip "
        "install 'lilium[photo]')",
    )),
    "out": (("--out",), dict(type=output_folder, help="output folder")),
    "method": (("--method",), dict(
        action="append", choices=list(METHODS), default=[],
        help="method; repeat to run several (default {default})",
    )),
    "variant": (("--variant",), dict(
        default="skof+pll", choices=list(VARIANTS),
        help="Lilium fitness variant (default skof+pll)",
    )),
    "seed": (("--seed",), dict(type=seed, default=0, help="random seed (default 0)")),
    "generations": (("--generations",), dict(
        type=int_in(1), help=f"Lilium: DE generations at most (default {_DE.max_generations})"
    )),
    "population": (("--population",), dict(
        type=int_in(
            4,
            MAX_DE_POPULATION,
            " (DE/rand/1 draws three other members; the paper uses 30, and a population is "
            "evaluated at once, in memory)",
        ),
        help=f"Lilium: DE population size (default {_DE.population_size})",
    )),
    "max_seconds": (("--max-seconds",), dict(
        type=positive_float(allow_inf=True),
        help=f"Lilium: wall-clock limit per SFO in seconds (default {_DE.max_seconds:g})",
    )),
    "focal_px": (("--focal-px",), dict(
        type=float, nargs=2, metavar=("LO", "HI"), help="focal prior (px) for every photo"
    )),
    "scd_mm": (("--scd-mm",), dict(
        type=float, nargs=2, metavar=("LO", "HI"),
        help="subject-to-camera distance prior (mm) for every photo",
    )),
    "sensor_width_mm": (("--sensor-width-mm",), dict(
        type=positive_float(), help="camera sensor width (long side, mm), for the EXIF focal"
    )),
    "no_exif": (("--no-exif",), dict(
        action="store_true", help="do not take a focal prior from EXIF"
    )),
    "depth_table": (("--depth-table",), dict(
        type=existing_file("depth table"), help="CSV: landmark,mean,sd,min,max (mm)"
    )),
    "calibration": (("--calibration",), dict(
        type=existing_file("calibration file"),
        help="identification calibration written by lilium calibrate (default: the shipped one)",
    )),
    "title": (("--title",), dict(help="report title")),
    "no_progress": (("--no-progress",), dict(action="store_true", help="no progress bar")),
    "workers": (("--workers",), dict(
        type=int_in(0, 256), help="worker processes, 0 = one per core (default {default})"
    )),
}

#: The options of one SFO's inputs, method and settings (``lilium sfo``, ``case``, ``lineup``).
SFO = ("method", "variant", "seed", "generations", "population", "max_seconds")
#: The per-image options of ``--photo`` images.
PHOTO_FILES = ("photo_landmarks", "mask", "face_curve", "view")
#: The priors given on the command line.
PRIORS = ("focal_px", "scd_mm", "sensor_width_mm", "no_exif")


def add_options(parser, *names, required=(), shown=None, **defaults):
    """Add the shared options ``names`` (keys of :data:`OPTIONS`) to ``parser``.

    ``required`` names those the command needs; ``defaults`` sets a command's own default;
    ``shown`` the default the help names (``{default}`` in it) when the command applies it
    itself (``--method``: :func:`case_request`; ``--workers``: a config's).
    """
    shown = {**defaults, **(shown or {})}
    for name in names:
        flags, kwargs = OPTIONS[name]
        kwargs = dict(kwargs)
        if name in defaults:
            kwargs["default"] = defaults[name]
        if "{default}" in kwargs.get("help", ""):
            kwargs["help"] = kwargs["help"].format(default=shown.get(name, "none"))
        if name in required:
            kwargs["required"] = True
        parser.add_argument(*flags, **kwargs)


def sfo_options(args):
    """The :class:`SfoOptions` of the command-line arguments (variant, DE settings)."""
    return SfoOptions(variant=args.variant).with_de(
        max_generations=args.generations,
        population_size=args.population,
        max_seconds=args.max_seconds,
    )


def _per_image(values, n, option, allow_one=False):
    """One value per ``--photo`` image (None each when not given)."""
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


def photo_sources(args):
    """The :class:`PhotoSource` of each ``--photo``, with its per-image options.

    ``--photo-landmarks``, ``--mask`` and ``--face-curve`` go to the images (not folders) in
    order; ``--view`` once goes to every photo (a folder's is checked against its
    ``photo.json``), or once per image; ``--camera PHOTO=FILE`` to the photo it names
    (:func:`_cameras`).
    """
    paths = [Path(p) for p in args.photo]
    images = [p for p in paths if not p.is_dir()]
    per_image = {
        name: _per_image(
            list(getattr(args, name, [])), len(images), OPTIONS[name][0][0], name == "view"
        )
        for name in PHOTO_FILES
    }
    views = getattr(args, "view", [])
    view_for_all = views[0] if len(views) == 1 else None
    sources, k = [], 0
    for path in paths:
        if path in images:
            sources.append(PhotoSource(
                path, per_image["photo_landmarks"][k], per_image["mask"][k],
                per_image["face_curve"][k], per_image["view"][k],
            ))
            k += 1
        else:
            sources.append(PhotoSource(path, view=view_for_all))
    cameras = _cameras(getattr(args, "camera", []), paths)
    return tuple(replace(s, camera=cameras.get(k)) for k, s in enumerate(sources))


def _cameras(values, paths):
    """``--camera [PHOTO=]FILE`` values -> ``{index of the --photo: Path}``.

    PHOTO is a ``--photo`` as typed, the same path, or its id (folder name or image stem);
    FILE alone names the camera of the only ``--photo``.
    """
    cameras = {}
    for value in values:
        photo, sep, file = value.partition("=")
        if not sep:
            if len(paths) != 1:
                raise ValueError(
                    f"--camera {value}: {len(paths)} --photo given; name the photo, "
                    "--camera PHOTO=FILE"
                )
            photo, file = str(paths[0]), value
        matches = [
            k for k, p in enumerate(paths)
            if photo in (str(p), p.name, p.stem) or Path(photo).resolve() == p.resolve()
        ]
        if len(matches) != 1:
            given = ", ".join(str(p) for p in paths)
            why = "no" if not matches else "more than one"
            raise ValueError(
                f"--camera {value}: {why} --photo is {photo!r}; name one of {given} (as given, "
                "or its folder name or image stem)"
            )
        if matches[0] in cameras:
            raise ValueError(f"--camera {value}: a second camera for --photo {photo}; give one")
        if not Path(file).is_file():
            raise ValueError(f"--camera {value}: camera file {file} not found")
        cameras[matches[0]] = Path(file)
    return cameras


def case_request(args):
    """The :class:`CaseRequest` of ``lilium sfo``, ``case`` or ``lineup``'s arguments.

    Without ``--method``, the command's default (``args.default_method``, set by its parser;
    Lilium when unset).

    Raises
    ------
    ValueError
        A per-image option given a number of times that fits neither one per image nor
        (``--view``) one for all.
    """
    candidates = tuple(
        Candidate(entry[0], tuple(PhotoSource(Path(p)) for p in entry[1:]))
        for entry in getattr(args, "candidate", None) or ()
    )
    priors = PriorOverrides(
        focal_px=_pair(getattr(args, "focal_px", None)),
        scd_mm=_pair(getattr(args, "scd_mm", None)),
        use_exif=not getattr(args, "no_exif", False),
        sensor_width_mm=getattr(args, "sensor_width_mm", None),
    )
    argv = getattr(args, "argv", None)
    skull = SkullSource(args.skull, getattr(args, "landmarks", None), getattr(args, "axes", None))
    return CaseRequest(
        skull=skull,
        out=args.out,
        photos=photo_sources(args) if getattr(args, "photo", None) else (),
        candidates=candidates,
        methods=tuple(dict.fromkeys(args.method)) or (getattr(args, "default_method", "lilium"),),
        options=sfo_options(args),
        seed=args.seed,
        priors=priors,
        depth_table=getattr(args, "depth_table", None),
        calibration=getattr(args, "calibration", None),
        auto_landmarks=getattr(args, "auto_landmarks", False),
        joint=getattr(args, "joint", False),
        overlay=not getattr(args, "no_overlay", False),
        title=getattr(args, "title", None),
        progress=not getattr(args, "no_progress", False),
        command=None if argv is None else shlex.join(["lilium", *map(str, argv)]),
    )


def _pair(values):
    return None if values is None else (float(values[0]), float(values[1]))

