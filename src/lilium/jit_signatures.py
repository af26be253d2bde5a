"""The argument types the kernels are built for ahead of time (:mod:`lilium.jit`).

Written by ``python -m lilium.jit_aot record``; do not edit by hand. Each entry is
``(argument specs, return spec)``: ``("array", dtype, ndim, layout, readonly)``,
``("tuple", [...])`` or a scalar's name.
"""

MODULES = (
    "lilium.fitness._camera_kernels",
    "lilium.fitness._curve_kernels",
    "lilium.fitness._pll_kernels",
    "lilium.fitness._skof_kernels",
    "lilium.geometry._mesh_kernels",
    "lilium.geometry._projection_kernels",
    "lilium.geometry._rotation_kernels",
    "lilium.identification._cohort_kernels",
    "lilium.imaging._paint_kernels",
    "lilium.imaging._raster_kernels",
    "lilium.optimisation._de_kernels",
    "lilium.pose._prior_refine_kernels",
    "lilium.pose._refine_kernels",
    "lilium.softtissue._cone_kernels",
)

SIGNATURES = {
    "lilium.fitness._camera_kernels.camera_checks_kernel": [
        (
            [
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "float64", 1, "C", False),
                "float64",
                "float64",
                "float64",
                "bool",
            ],
            ("tuple", ["bool", ("array", "bool", 1, "C", False), "int64", "float64"]),
        ),
    ],
    "lilium.fitness._camera_kernels.camera_stage_kernel": [
        (
            [
                ("array", "float64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                (
                    "tuple",
                    [
                        ("array", "float64", 2, "C", False),
                        ("array", "float64", 2, "C", False),
                        ("array", "float64", 2, "C", False),
                        ("array", "float64", 1, "C", False),
                        ("array", "float64", 1, "C", False),
                        ("array", "int64", 2, "C", False),
                        "float64",
                        "float64",
                    ],
                ),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "bool", 1, "C", False),
                (
                    "tuple",
                    ["float64", "int64", "float64", "float64", "float64", "float64", "float64"],
                ),
                ("array", "float64", 1, "C", False),
                ("array", "float64", 1, "C", False),
                "float64",
                "float64",
                "float64",
                ("array", "int64", 1, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "float64", 2, "C", False),
                "float64",
            ],
            (
                "tuple",
                [
                    ("array", "float64", 3, "C", False),
                    ("array", "float64", 3, "C", False),
                    ("array", "float64", 2, "C", False),
                    ("array", "float64", 1, "C", False),
                    ("array", "float64", 1, "C", False),
                    ("array", "float64", 2, "C", False),
                    "bool",
                    ("array", "bool", 1, "C", False),
                    "int64",
                    "float64",
                    ("array", "float64", 1, "C", False),
                    ("array", "float64", 1, "C", False),
                ],
            ),
        ),
    ],
    "lilium.fitness._camera_kernels.camera_terms_kernel": [
        (
            [
                ("array", "float64", 2, "C", False),
                ("array", "bool", 1, "C", False),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "float64", 2, "C", False),
                "float64",
                "float64",
            ],
            ("tuple", [("array", "float64", 1, "C", False), ("array", "float64", 1, "C", False)]),
        ),
    ],
    "lilium.fitness._curve_kernels.boundary_kernel": [
        (
            [
                ("array", "float64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "int64", 2, "C", False),
                ("array", "int64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "int64", 1, "C", False),
                ("array", "int64", 1, "C", False),
                ("array", "int64", 2, "C", False),
                ("array", "int64", 2, "C", False),
                ("array", "bool", 1, "C", False),
                "int64",
            ],
            ("tuple", [("array", "int64", 1, "C", False), ("array", "float64", 2, "C", False)]),
        ),
    ],
    "lilium.fitness._curve_kernels.span_join_kernel": [
        (
            [
                ("array", "int64", 1, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                "bool",
                "int64",
            ],
            ("tuple", [("array", "float64", 2, "C", False), ("array", "int64", 1, "C", False)]),
        ),
    ],
    "lilium.fitness._curve_kernels.windows_kernel": [
        (
            [
                ("array", "float64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                "int64",
                "int64",
                "int64",
            ],
            (
                "tuple",
                [
                    ("array", "int64", 2, "C", False),
                    ("array", "int64", 2, "C", False),
                    ("array", "bool", 1, "C", False),
                    ("array", "bool", 1, "C", False),
                ],
            ),
        ),
    ],
    "lilium.fitness._pll_kernels.nearest_table_kernel": [
        (
            [("array", "float64", 2, "C", False), "int64", "int64", "int64", "int64"],
            ("array", "int64", 2, "C", False),
        ),
    ],
    "lilium.fitness._pll_kernels.population_kernel": [
        (
            [
                ("array", "float64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                "bool",
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 1, "C", False),
                "float64",
                "float64",
                "int64",
                "int64",
                "int64",
                ("array", "int64", 2, "C", False),
                ("array", "int64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "int64", 1, "C", False),
                ("array", "int64", 1, "C", False),
                "int64",
                ("array", "float64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                "bool",
                ("array", "int64", 2, "C", False),
                "int64",
                "int64",
                "int64",
                "float64",
            ],
            (
                "tuple",
                [
                    ("array", "float64", 1, "C", False),
                    ("array", "float64", 1, "C", False),
                    ("array", "float64", 1, "C", False),
                    ("array", "float64", 1, "C", False),
                    ("array", "int64", 1, "C", False),
                ],
            ),
        ),
    ],
    "lilium.fitness._skof_kernels._centroids": [
        (
            [("array", "float64", 2, "C", False), ("array", "int64", 2, "C", False)],
            ("array", "float64", 2, "C", False),
        ),
    ],
    "lilium.fitness._skof_kernels._kd_order": [
        ([("array", "float64", 2, "C", False), "int64"], ("array", "int64", 1, "C", False)),
    ],
    "lilium.fitness._skof_kernels._spheres": [
        (
            [
                ("array", "float64", 2, "C", False),
                ("array", "int64", 2, "C", False),
                ("array", "int64", 2, "C", False),
            ],
            ("array", "float64", 2, "C", False),
        ),
    ],
    "lilium.fitness._skof_kernels.outside_pixels_kernel": [
        (
            [
                ("array", "float64", 2, "C", False),
                ("array", "int64", 2, "C", False),
                ("array", "int64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "int64", 1, "C", False),
                ("array", "int64", 1, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "int64", 2, "C", False),
                ("array", "int64", 2, "C", False),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 1, "C", False),
                "float64",
                "float64",
                ("array", "float64", 1, "C", False),
                ("array", "int32", 2, "C", False),
                ("array", "int64", 1, "C", False),
                ("array", "int64", 1, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "int64", 1, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "float64", 1, "C", False),
                "int64",
            ],
            ("tuple", [("array", "int64", 1, "C", False), ("array", "int64", 1, "C", False)]),
        ),
    ],
    "lilium.fitness._skof_kernels.squared_distance_to_background": [
        ([("array", "bool", 2, "C", False)], ("array", "float64", 2, "C", False)),
    ],
    "lilium.geometry._mesh_kernels.cluster_kernel": [
        (
            [
                ("array", "float64", 2, "C", False),
                ("array", "int64", 2, "C", False),
                "float64",
                "float64",
            ],
            ("tuple", [("array", "float64", 2, "C", False), ("array", "int64", 2, "C", False)]),
        ),
    ],
    "lilium.geometry._mesh_kernels.component_kernel": [
        ([("array", "int64", 2, "C", False), "int64"], ("array", "int64", 1, "C", False)),
    ],
    "lilium.geometry._projection_kernels.project_kernel": [
        (
            [
                ("array", "float64", 3, "C", True),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 1, "C", True),
                "float64",
                "float64",
            ],
            ("array", "float64", 3, "C", False),
        ),
        (
            [
                ("array", "float64", 3, "C", True),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", True),
                ("array", "float64", 1, "C", True),
                "float64",
                "float64",
            ],
            ("array", "float64", 3, "C", False),
        ),
    ],
    "lilium.identification._cohort_kernels.refit_whitened_kernel": [
        (
            [
                ("array", "float64", 2, "C", False),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 1, "C", False),
                "float64",
                "float64",
                ("array", "float64", 3, "C", False),
                ("array", "float64", 4, "C", False),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 1, "C", False),
            ],
            ("array", "float64", 2, "C", False),
        ),
        (
            [
                ("array", "float64", 2, "C", False),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 1, "C", False),
                "float64",
                "float64",
                ("array", "float64", 3, "C", False),
                ("array", "float64", 4, "C", False),
                ("array", "float64", 3, "C", True),
                ("array", "float64", 1, "C", False),
            ],
            ("array", "float64", 2, "C", False),
        ),
    ],
    "lilium.imaging._paint_kernels._paint": [
        (
            [
                ("array", "float64", 2, "C", False),
                ("array", "int64", 2, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "int64", 1, "C", False),
                "int64",
                "int64",
            ],
            ("array", "int32", 2, "C", False),
        ),
    ],
    "lilium.imaging._paint_kernels.normals_kernel": [
        (
            [("array", "float64", 2, "C", False), ("array", "int64", 2, "C", False)],
            ("array", "float64", 2, "C", False),
        ),
    ],
    "lilium.imaging._paint_kernels.surface_kernel": [
        (
            [
                ("array", "int64", 1, "A", False),
                ("array", "int64", 1, "A", False),
                ("array", "int32", 1, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "int64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                "float64",
                "float64",
                "float64",
                "int64",
                "int64",
            ],
            ("tuple", [("array", "float32", 2, "C", False), ("array", "float32", 3, "C", False)]),
        ),
    ],
    "lilium.imaging._raster_kernels.edge_table_kernel": [
        (
            [("array", "int64", 1, "C", False), ("array", "int64", 1, "C", False), "int64"],
            (
                "tuple",
                [
                    ("array", "int64", 1, "C", False),
                    ("array", "int64", 1, "C", False),
                    ("array", "int64", 1, "C", False),
                ],
            ),
        ),
    ],
    "lilium.imaging._raster_kernels.incidence_kernel": [
        (
            [("array", "int64", 1, "C", False), ("array", "float64", 1, "C", False), "int64"],
            (
                "tuple",
                [
                    ("array", "int64", 1, "C", False),
                    ("array", "int64", 1, "C", False),
                    ("array", "float64", 1, "C", False),
                ],
            ),
        ),
    ],
    "lilium.imaging._raster_kernels.scan_kernel": [
        (
            [
                ("array", "float64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "int64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "int64", 1, "C", False),
                ("array", "int64", 1, "C", False),
                "int64",
                "int64",
                "int64",
                "int64",
            ],
            (
                "tuple",
                [
                    ("array", "int64", 1, "C", False),
                    ("array", "int64", 1, "C", False),
                    ("array", "int64", 1, "C", False),
                    ("array", "int64", 1, "C", False),
                ],
            ),
        ),
    ],
    "lilium.optimisation._de_kernels.trial_kernel": [
        (
            [
                ("array", "float64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "int64", 1, "C", False),
                ("array", "int64", 1, "C", False),
                "float64",
                ("array", "bool", 1, "C", False),
            ],
            ("tuple", [("array", "float64", 2, "C", False), ("array", "bool", 2, "C", False)]),
        ),
    ],
    "lilium.pose._prior_refine_kernels.prior_refine_kernel": [
        (
            [
                ("array", "float64", 3, "C", False),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "float64", 2, "C", False),
                "float64",
                "int64",
            ],
            (
                "tuple",
                [
                    ("array", "float64", 1, "C", False),
                    ("array", "int64", 1, "C", False),
                    ("array", "float64", 2, "C", False),
                ],
            ),
        ),
    ],
    "lilium.pose._refine_kernels.refine_kernel": [
        (
            [
                ("array", "float64", 3, "C", False),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 1, "C", False),
                "float64",
                "int64",
                "float64",
                "float64",
                "float64",
                "float64",
                "float64",
            ],
            (
                "tuple",
                [
                    ("array", "float64", 1, "C", False),
                    ("array", "int64", 1, "C", False),
                    ("array", "float64", 2, "C", False),
                ],
            ),
        ),
    ],
    "lilium.pose._refine_kernels.sq_errors_kernel": [
        (
            [
                ("array", "float64", 3, "C", False),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", True),
                ("array", "float64", 1, "C", True),
            ],
            ("array", "float64", 2, "C", False),
        ),
        (
            [
                ("array", "float64", 3, "C", True),
                ("array", "float64", 3, "C", True),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", True),
                ("array", "float64", 1, "C", True),
            ],
            ("array", "float64", 2, "C", False),
        ),
        (
            [
                ("array", "float64", 3, "C", True),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", True),
                ("array", "float64", 1, "C", True),
            ],
            ("array", "float64", 2, "C", False),
        ),
        (
            [
                ("array", "float64", 3, "C", False),
                ("array", "float64", 3, "C", True),
                ("array", "float64", 3, "C", False),
                ("array", "float64", 2, "C", True),
                ("array", "float64", 1, "C", True),
            ],
            ("array", "float64", 2, "C", False),
        ),
    ],
    "lilium.softtissue._cone_kernels.decode_kernel": [
        (
            [
                ("array", "float64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 2, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "float64", 1, "C", False),
                ("array", "int64", 2, "C", False),
                "float64",
                "float64",
            ],
            ("array", "float64", 3, "C", False),
        ),
    ],
}
