"""Photo preparation (docs/method/photo.md): from a plain photograph to a photo folder.

MediaPipe's legacy face models (shipped in ``models/``, Apache-2.0, see ``models/PROVENANCE``)
run with LiteRT (``pip install 'lilium[photo]'``): :mod:`.runtime` runs them,
:mod:`.landmarks` maps the 468-point mesh to catalogue landmarks, :mod:`.headpose` gives the head
orientation and the iris distance, :mod:`.mask` the head mask, :mod:`.analysis` puts them
together on one image, :mod:`.prepare` writes the folder and :mod:`.review` the review page.
"""
