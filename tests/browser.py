"""Headless Chromium for the tests of HTML pages (the report, the landmark review page).

Lilium has no network at run time and neither do these tests: Chromium's background
networking, component updates and sync are switched off, which otherwise can keep a headless
run waiting (seen as a 120 s timeout on a loaded machine).
"""

import shutil
import subprocess

import pytest

CHROMIUM = next(
    (shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome") if shutil.which(n)),
    None,
)

needs_chromium = pytest.mark.skipif(
    CHROMIUM is None, reason="no chromium (apt-get install chromium)"
)


#: Flags for pages that draw with WebGL: Chromium's software GPU (SwiftShader through ANGLE),
#: as headless machines have no GPU.
WEBGL_FLAGS = (
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--enable-webgl",
    "--ignore-gpu-blocklist",
)


def run_chromium(*args, tmp_path, timeout=120):
    """Run headless Chromium with ``args`` (its own profile under ``tmp_path``); the
    completed process (``stdout``: e.g. ``--dump-dom``'s page)."""
    cmd = [
        CHROMIUM,
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--no-first-run",
        f"--user-data-dir={tmp_path / 'chromium-profile'}",
        *args,
    ]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, check=True)
