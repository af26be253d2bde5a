"""Reports a forensic practitioner reads: a self-contained HTML page per case.

The report is built in two steps, computing first and formatting second:

- :mod:`~lilium.report.records`: :class:`ReportEntry` (one SFO to report: skull, photo,
  result, labelled inputs, notes and outputs) -> :class:`SfoRecord` (:func:`sfo_record`), and
  a page's entries -> :class:`ReportRecord` (:func:`report_record`); computes the landmark
  rows, camera facts and the skull pixels outside the face mask (exact skull raster).
- :mod:`~lilium.report.record_types`: the frozen records, of numbers, strings and encoded
  pictures (summary row, landmark rows, camera facts, fitness terms, outside pixels, input
  fingerprints; a page adds the software versions, date and command).
- :mod:`~lilium.report.pictures`: the pictured region of the photo and its layers, at least
  1,000 px across (photo JPEG upscaled with Lanczos, detailed skull layer as a palette PNG,
  skull-outside-the-face PNG), and the skull alone in a frontal and a lateral view (JPEG,
  embedded once per page).
- :mod:`~lilium.report.html`: formats records into the templates of
  ``lilium/report/templates/`` (HTML, CSS and JS, read with :mod:`importlib.resources`);
  :func:`build_report` and :func:`write_report` do both steps.
- :mod:`~lilium.report.svg`: the inline SVGs (landmark marks, fitness curve, the skull-alone
  views with their labelled cranial landmarks).

Input hashing and software versions come from :mod:`lilium.io.provenance`.

:mod:`~lilium.report.workbench` writes ``workbench.html`` beside an SFO's result: the skull drawn
with WebGL through the result's camera over the photo, to turn, move and save as
``camera.json`` (scripts in ``lilium/report/web/``: ``meshgl.js``, the mesh module any page
reuses, ``page.js``, ``workbench.js``).
"""

from .html import build_report, format_report, write_report
from .pictures import skull_layer_rgba, view_box
from .record_types import ReportRecord, SfoRecord
from .records import ReportEntry, report_record, sfo_record
from .workbench import workbench_page, write_workbench

__all__ = [
    "ReportEntry",
    "ReportRecord",
    "SfoRecord",
    "build_report",
    "format_report",
    "report_record",
    "sfo_record",
    "skull_layer_rgba",
    "view_box",
    "workbench_page",
    "write_report",
    "write_workbench",
]
