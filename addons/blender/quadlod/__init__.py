"""quadlod: quad-dominant mesh reduction that keeps edge loops.

One package, two uses:
  * the Python module: ``quadlod.simplify``, ``quadlod.lod_chain``, ``quadlod.evaluate`` and
    ``quadlod.QuadlodError``, implemented in the C++ extension ``quadlod._core`` (NumPy arrays in
    and out; see README "Python module");
  * the Blender add-on "Quad-dominant LOD" (operator in Object menu and a sidebar panel), whose
    parts are imported only by ``register()``, so the module imports without Blender.
"""

bl_info = {
    "name": "quadlod: Quad-dominant LOD",
    "author": "quadlod",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Object > Quad-dominant LOD; View3D > Sidebar > quadlod",
    "description": "LODs that keep quads, edge loops, UVs and materials (quadlod C++ core, in-process)",
    "category": "Object",
}



def _load_core():
    """Imports the extension quadlod._core. Inside Blender it is loaded from a private copy:
    Blender's "Install…" of a newer zip over an enabled add-on rewrites the installed files in
    place, and rewriting a loaded shared object crashes the process. The copy is unlinked once
    loaded (the mapping stays valid), so nothing is left behind."""
    import importlib.machinery
    import importlib.util
    import os
    import shutil
    import sys
    import tempfile

    name = __name__ + "._core"
    if name in sys.modules:
        return sys.modules[name]
    if "bpy" not in sys.modules:
        from . import _core

        return _core
    here = os.path.dirname(os.path.abspath(__file__))
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        path = os.path.join(here, "_core" + suffix)
        if os.path.exists(path):
            break
    else:
        raise ImportError(f"quadlod: the extension _core is missing in {here} (rebuild or reinstall the add-on zip)")
    folder = tempfile.mkdtemp(prefix="quadlod-")
    try:
        copy = os.path.join(folder, os.path.basename(path))
        shutil.copyfile(path, copy)
        spec = importlib.util.spec_from_file_location(name, copy)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        sys.modules[name] = module
        return module
    finally:
        shutil.rmtree(folder, ignore_errors=True)


_core = _load_core()
QuadlodError, __version__ = _core.QuadlodError, _core.__version__
evaluate, lod_chain, read_mesh, simplify, write_mesh = (
    _core.evaluate, _core.lod_chain, _core.read_mesh, _core.simplify, _core.write_mesh)

__all__ = ["QuadlodError", "evaluate", "lod_chain", "read_mesh", "simplify", "write_mesh", "__version__"]


def register():
    from . import blender_addon

    blender_addon.register()


def unregister():
    from . import blender_addon

    blender_addon.unregister()
