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

from ._core import (QuadlodError, __version__, evaluate, lod_chain, read_mesh,  # noqa: E402
                    simplify, write_mesh)

__all__ = ["QuadlodError", "evaluate", "lod_chain", "read_mesh", "simplify", "write_mesh", "__version__"]


def register():
    from . import blender_addon

    blender_addon.register()


def unregister():
    from . import blender_addon

    blender_addon.unregister()
