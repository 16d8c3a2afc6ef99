"""Blender-side logic of the impulse extension, free of any UI: reading a scene's rigid bodies
(:mod:`.scene_reader`), simulating them with impulse and writing keyframes (:mod:`.bake`).

Blender is z up, impulse y up: :mod:`.axes` converts between the two frames.
"""
