"""Pixels: the one mesh raster and the overlay pictures.

- :mod:`lilium.imaging.raster`   exact union raster of projected meshes (every mesh mask)
- :mod:`lilium.imaging.overlay`  the projected skull drawn over the photo
"""
