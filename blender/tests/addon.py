"""Loading the add-on for the tests that register it: from the zip named by
``IMPULSE_BLENDER_ADDON_ZIP`` (``.ci/run`` sets it to the plain add-on zip the build script
made), else from the source directory ``blender/``."""

import importlib
import importlib.util
import os
import pathlib
import sys
import zipfile

SOURCE = pathlib.Path(__file__).resolve().parent.parent


def load_addon(tmp_path_factory, keep_path=True):
    """The add-on module ``impulse_blender``, imported (not registered) from the zip, checked to
    be the zip's own copy, or from the source directory. ``keep_path=False`` takes the unpacked
    zip's directory off ``sys.path`` again once the module is imported."""
    archive = os.environ.get("IMPULSE_BLENDER_ADDON_ZIP")
    if archive:
        target = tmp_path_factory.mktemp("addons")
        with zipfile.ZipFile(archive) as packed:
            packed.extractall(target)
        sys.path.insert(0, str(target))
        module = importlib.import_module("impulse_blender")
        assert pathlib.Path(module.__file__).parent == target / "impulse_blender"
        if not keep_path:
            sys.path.remove(str(target))
        return module
    spec = importlib.util.spec_from_file_location(
        "impulse_blender", SOURCE / "__init__.py", submodule_search_locations=[str(SOURCE)]
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules["impulse_blender"] = module
    spec.loader.exec_module(module)
    return module
