"""The ``lilium`` command."""
