"""One way to run an SFO: the method registry and :func:`run_sfo`.

Every caller (``lilium sfo``, ``lilium case``, the experiment runner, the demo, benchmarks)
runs a method through :func:`run_sfo` with one :class:`~lilium.methods.options.SfoOptions`;
:data:`METHODS` is the one list of methods and their variants.
"""

from dataclasses import dataclass, replace

from .checks import check_given_camera, check_inputs, finish_result
from .given_camera import lilium_at, posest_sfo_at
from .joint import joint_lilium_sfo
from .lilium import VARIANTS, lilium_sfo
from .lilium_terms import planned_terms_off
from .options import SfoOptions
from .pairs import correspondences
from .posest_sfo import posest_sfo


@dataclass(frozen=True)
class Method:
    """An SFO method.

    Attributes
    ----------
    name : str
        As on the command line and in ``result.json``.
    run : callable
        ``run(skull, photo, options, seed) -> SfoResult``.
    score : callable
        ``score(skull, photo, given, options, seed) -> SfoResult``: the method's result for a
        :class:`~lilium.inputs.GivenCamera`, without search (docs/method/workbench.md).
    variants : tuple of str
        Fitness variants (empty for a method without variants).
    stochastic : bool
        Whether the seed changes the result (repetitions make sense).
    run_joint : callable or None
        ``run_joint(skull, photos, options, seed) -> JointSfoResult``: one SFO of several
        photos of one person with one shared soft tissue (docs/method/joint.md); None when the
        method has no joint form.
    """

    name: str
    run: object
    score: object
    variants: tuple = ()
    stochastic: bool = False
    run_joint: object = None


def _posest_sfo(skull, photo, options, seed):
    del seed  # deterministic: RANSAC runs with its fixed seed
    return posest_sfo(skull, photo, options)


def _posest_sfo_at(skull, photo, given, options, seed):
    del seed  # deterministic; its soft tissue is always the mean one
    return posest_sfo_at(skull, photo, given.camera, options)


def _lilium(skull, photo, options, seed):
    return lilium_sfo(skull, photo, options, seed=seed)


def _lilium_at(skull, photo, given, options, seed):
    return lilium_at(skull, photo, given, options, seed=seed)


def _joint_lilium(skull, photos, options, seed):
    return joint_lilium_sfo(skull, photos, options, seed=seed)


#: The methods, by name.
METHODS = {
    "posest-sfo": Method("posest-sfo", _posest_sfo, _posest_sfo_at),
    "lilium": Method(
        "lilium", _lilium, _lilium_at, tuple(VARIANTS), stochastic=True, run_joint=_joint_lilium
    ),
}

#: The methods with a joint form (one SFO of several photos of one person).
JOINT_METHODS = tuple(name for name, m in METHODS.items() if m.run_joint is not None)


def check_method(method, variant=None):
    """Validate a method name (and variant); returns the :class:`Method`."""
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; use one of {', '.join(METHODS)}")
    m = METHODS[method]
    if m.variants and variant is not None and variant not in m.variants:
        raise ValueError(
            f"unknown {method} variant {variant!r}; use one of {', '.join(m.variants)}"
        )
    return m


def method_tag(method, variant=None):
    """Folder-safe label of a method run: ``posest-sfo``, ``lilium-skof+pll``."""
    return f"{method}-{variant}" if METHODS[method].variants and variant else method


def run_sfo(method, skull, photo, options=SfoOptions(), seed=0, camera=None):
    """Run one SFO, or score a given camera.

    Parameters
    ----------
    method : str
        A key of :data:`METHODS`.
    skull : lilium.inputs.Skull
    photo : lilium.inputs.Photo
    options : SfoOptions
        ``options.variant`` selects the variant of a method that has them.
    seed : int
        For stochastic methods; the same seed gives the same result.
    camera : GivenCamera, optional
        Score this camera instead of searching one (the method's ``score``;
        docs/method/workbench.md): ``camera_source`` ``"examiner"``. Refused when it cannot
        show the skull (:func:`~lilium.methods.checks.check_given_camera`).

    Returns
    -------
    SfoResult
        With its warnings, priors' provenance and landmark error (docs/checks.md,
        :func:`~lilium.methods.checks.finish_result`).

    Raises
    ------
    ValueError
        Unknown method or variant, mirrored skull or photo labels
        (:func:`~lilium.methods.checks.check_inputs`), or a case the method cannot run (too
        few landmarks, ...).
    """
    m = check_method(method, options.variant)
    check_inputs(skull, photo)
    if camera is None:
        return finish_result(m.run(skull, photo, options, seed), skull, photo)
    check_given_camera(camera.camera, skull, photo, camera.source)
    result = replace(m.score(skull, photo, camera, options, seed), camera_source="examiner")
    return finish_result(result, skull, photo)


def check_joint_method(method, variant=None):
    """Validate a method for a joint SFO (it must have a joint form); returns the
    :class:`Method`."""
    m = check_method(method, variant)
    if m.run_joint is None:
        raise ValueError(
            f"method {method!r} has no joint SFO of several photos; use "
            f"{', '.join(JOINT_METHODS)}, or "
            "give one photo"
        )
    return m


def check_joint_methods(methods, n_photos):
    """Refuse a joint case (``lilium case --joint``) that cannot run, before the skull and the
    photos are read (when its :class:`~lilium.casework.request.CaseRequest` is made).

    Parameters
    ----------
    methods : sequence of str
        Keys of :data:`METHODS`.
    n_photos : int

    Raises
    ------
    ValueError
        Fewer than two photos, or no method with a joint form among ``methods``.
    """
    if n_photos < 2:
        raise ValueError(
            f"--joint needs two or more --photo of the same person, got {n_photos}; drop "
            "--joint for one photo"
        )
    if not set(methods) & set(JOINT_METHODS):
        raise ValueError(
            f"--joint: none of the methods ({', '.join(methods)}) has a joint SFO; add --method "
            f"{' or --method '.join(JOINT_METHODS)}"
        )


def run_joint_sfo(method, skull, photos, options=SfoOptions(), seed=0):
    """Run one joint SFO: several photos of one person, one shared soft tissue
    (docs/method/joint.md).

    Parameters
    ----------
    method : str
        A key of :data:`METHODS` whose method has a joint form (``lilium``).
    skull : lilium.inputs.Skull
    photos : sequence of lilium.inputs.Photo
        Two or more photos of the same person, distinct ids.
    options : SfoOptions
    seed : int

    Returns
    -------
    JointSfoResult
        Each photo's result with its warnings, priors' provenance and landmark error
        (:func:`~lilium.methods.checks.finish_result`, as :func:`run_sfo`).

    Raises
    ------
    ValueError
        As :func:`run_sfo` for each photo; a method without a joint form; fewer than two
        photos or a repeated photo id.
    """
    m = check_joint_method(method, options.variant)
    photos = list(photos)
    for photo in photos:
        check_inputs(skull, photo)
    result = m.run_joint(skull, photos, options, seed)
    finished = tuple(
        finish_result(r, skull, photo) for r, photo in zip(result.photos, photos, strict=True)
    )
    return replace(result, photos=finished)


def check_runnable(skull, photo, methods, variant, photo_file):
    """Check that an SFO of ``photo`` can run, before any SFO runs; say what it will switch off.

    The landmarks must pair (:func:`lilium.methods.pairs.correspondences`: at least four pairs, the
    one case no term set can run); otherwise the ``ValueError`` starts with the file to fix.
    For Lilium, a term the variant asks for whose inputs are missing (P_skof without a face
    mask; P_pll without the cranial landmarks that cut its region, e.g. a skull without its
    mandible, or without a facial curve) is switched off, not an error (docs/method/lilium.md), and
    so is each P_cam part without its prior.

    Parameters
    ----------
    skull : Skull
    photo : Photo
    methods : sequence of str
        Keys of :data:`METHODS`.
    variant : str
        Lilium's variant.
    photo_file : Path or str
        The file the photo's landmarks came from (its landmark file, else its ``photo.json``),
        named by the error.

    Returns
    -------
    dict of str -> str
        What Lilium's SFO of this photo will switch off, and why (empty when Lilium does not
        run); the same as its ``result.json``'s ``terms_off``.
    """
    try:
        correspondences(skull, photo)
    except ValueError as exc:
        raise ValueError(f"{photo_file}: {exc}") from None
    if "lilium" not in methods:
        return {}
    return planned_terms_off(skull, photo, VARIANTS[variant])
