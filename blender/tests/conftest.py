"""The extension's headless tests: Blender as a Python module (PyPI ``bpy``) and the ``impulse``
package installed in the same environment. Run from the repository root:

    python -m pytest blender/tests
"""

import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
for path in (HERE, HERE.parent):
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))
