"""The console lines of a case's SFOs, single or joint (the case's ``log``)."""


def status_text(result):
    """One SFO's outcome for the console: camera and score (and terms off), or the failure."""
    if not result:
        return f"FAILED ({result.error})"
    off = f", off: {', '.join(result.terms_off)}" if result.terms_off else ""
    return f"focal {result.camera.focal_px:.0f} px, score {result.fitness:.4g}{off}"


def log_warnings(result, log):
    """One console line per docs/checks.md warning of an SFO."""
    for warning in result.warnings:
        log(f"  warning {warning.code}: {warning.message}")
