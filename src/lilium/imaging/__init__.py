"""Pictures: overlays of the projected skull on the photo."""
