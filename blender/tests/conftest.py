"""The extension's headless tests: Blender as a Python module (PyPI ``bpy``) and the ``impulse``
package installed in the same environment. Run from the repository root:

    python -m pytest blender/tests

Blender's user data files (where the add-on keeps its decomposition cache) go to a temporary
directory, not the user's.
"""

import atexit
import os
import pathlib
import shutil
import sys
import tempfile

HERE = pathlib.Path(__file__).resolve().parent
for path in (HERE, HERE.parent):
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))

os.environ["BLENDER_USER_DATAFILES"] = tempfile.mkdtemp(prefix="impulse-blender-user-")
atexit.register(shutil.rmtree, os.environ["BLENDER_USER_DATAFILES"], ignore_errors=True)
