"""Synthetic ground truth: procedural subjects (skull, face, landmarks, soft tissue) and photos.

Skull frame of every synthetic subject: mm, x = the subject's left, y = up, z = anterior.
:mod:`.subjects` assembles a subject from the parts of :mod:`.anatomy` (shape, bone,
landmarks, soft tissue, skin).
"""

from .subjects import SubjectShape, SyntheticSubject, make_subject, make_subjects, write_subject

__all__ = ["SubjectShape", "SyntheticSubject", "make_subject", "make_subjects", "write_subject"]
