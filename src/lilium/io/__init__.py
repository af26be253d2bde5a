"""Case folders, meshes and result files (SPEC section 8): all file formats live here."""
