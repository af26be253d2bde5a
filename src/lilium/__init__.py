"""Lilium: automated skull-face overlay (SFO) for craniofacial superimposition.

Layers, bottom to top (a module imports only from its layer or below; docs/architecture.md):

- :mod:`lilium.constants`    tolerances and limits
- :mod:`lilium.geometry`     rotations, the camera (one projection), mesh operations
- :mod:`lilium.optimisation` differential evolution with per-member payloads
- :mod:`lilium.softtissue`   landmark catalogue, population depth table, soft-tissue cones
- :mod:`lilium.pose`         POSEST: P4Pf minimal solver, MSAC RANSAC, Levenberg-Marquardt
- :mod:`lilium.fitness`      fitness terms: P_cam, the skull raster and P_skof, regions, P_pll
- :mod:`lilium.imaging`      overlay pictures
- :mod:`lilium.inputs`       the in-memory SFO inputs (skull, photo, priors, correspondences)
- :mod:`lilium.methods`      ``run_sfo`` over the method registry; POSEST-SFO and Lilium
- :mod:`lilium.evaluation`   BPE, rank, implausible-SFO metrics
- :mod:`lilium.io`           every file format: case folders, landmarks, EXIF, meshes, results
- :mod:`lilium.synthetic`    generated subjects and photos with ground truth
- :mod:`lilium.ct`           CT volumes to skull and skin meshes
- :mod:`lilium.casework`     a user's case from files to results
- :mod:`lilium.report`       the HTML case report
- :mod:`lilium.experiments`  the paper's protocol at scale
- :mod:`lilium.cli`          the ``lilium`` command
"""

__version__ = "0.1.0"
