"""Pixels: the one mesh raster and the overlay pictures.

- :mod:`lilium.imaging.raster`       exact union raster of projected meshes (every mesh mask)
- :mod:`lilium.imaging.overlay`      the projected skull drawn over the photo
- :mod:`lilium.imaging.shading`      a detailed skull render for the eye (smooth normals,
  cavity shading, crease lines), the report's skull layer
- :mod:`lilium.imaging.skull_views`  the skull alone, frontal or lateral, landmarks projected
"""
