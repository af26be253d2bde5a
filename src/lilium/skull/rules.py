"""Each landmark's own definition on the normalised mesh (placeholder)."""


def apply_rules(vertices, faces, tree, estimates, anchors):
    return {}
