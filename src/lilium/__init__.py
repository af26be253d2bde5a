"""Lilium: automated skull-face overlay (SFO) for craniofacial superimposition.

Layers (one subpackage each, maths free of I/O):

- :mod:`lilium.geometry`   rotations and the pinhole camera (SPEC section 8 conventions)
- :mod:`lilium.pose`       POSEST: P4Pf minimal solver, MSAC RANSAC, Levenberg-Marquardt
- :mod:`lilium.softtissue` landmark catalogue, population depth table, soft-tissue cones
- :mod:`lilium.methods`    SFO methods (POSEST-SFO baseline)
- :mod:`lilium.imaging`    overlay pictures
- :mod:`lilium.io`         case folders, meshes, result files
- :mod:`lilium.cli`        the ``lilium`` command
"""

__version__ = "0.1.0"
