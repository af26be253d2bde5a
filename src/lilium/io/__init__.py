"""Case folders, meshes and result files (docs/contract.md): all file formats live here."""
