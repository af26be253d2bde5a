"""Automatic cranial landmarks on a bare skull mesh (``lilium skull``).

:func:`locate_skull_landmarks` takes a mesh (mm, any pose) and returns
:class:`SkullLandmarks`: every landmark of the catalogue the skull has, each with its quality
(``"located"`` by its own definition, ``"template"`` from the fitted template skull), the
soft-tissue axes and whether the mandible is there. Placement rules: docs/method/skull.md.
"""

from .locate import SkullLandmarks, locate_skull_landmarks

__all__ = ["SkullLandmarks", "locate_skull_landmarks"]
