"""Reports a forensic practitioner reads: a self-contained HTML page per case."""

from .html import ReportEntry, build_report, skull_layer_rgba, write_report

__all__ = ["ReportEntry", "build_report", "skull_layer_rgba", "write_report"]
