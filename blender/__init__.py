"""impulse for Blender: "Bake with impulse" bakes the scene's Rigid Body World with the impulse
contact solver into keyframes (docs/blender.md).

Installed as an extension (Blender 4.2+), Blender installs the bundled ``impulse`` wheel; as a
plain add-on zip, the wheel's contents sit in ``vendor/`` beside this file.
"""

import os
import sys

bl_info = {
    "name": "impulse",
    "author": "impulse developers",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "Properties > Scene > Rigid Body World, Properties > Physics",
    "description": "Bake rigid-body scenes with the impulse contact solver",
    "category": "Physics",
}

_vendor = os.path.join(os.path.dirname(__file__), "vendor")
if os.path.isdir(_vendor) and _vendor not in sys.path:
    sys.path.insert(0, _vendor)

from . import operators, takes_ui  # noqa: E402 (after the vendor path is added)


def register():
    operators.register()
    takes_ui.register()


def unregister():
    takes_ui.unregister()
    operators.unregister()
