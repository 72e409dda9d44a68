"""Blender with its UI (under Xvfb): the add-on's sidebar panel, for the README (issue 22).

  xvfb-run blender --factory-startup --enable-event-simulate --python screenshot_panel.py -- ZIP PNG

Installs and enables the add-on, makes the test torus of test_addon.py, runs the operator, puts
the LODs beside the original, opens the sidebar on the "quadlod" tab (a simulated click on the tab:
Blender 3.4 has no API for the active tab) and saves a screenshot
of the 3D view area. Then what only a UI session can show: the operator invoked (modal, one LOD
level per timer tick) on a second mesh, and one undo step removing what it made. Run by
tests/blender/run_blender_tests.py.
"""

import sys
from pathlib import Path

import bpy

sys.path.insert(0, str(Path(__file__).resolve().parent))
zip_path, png_path = sys.argv[sys.argv.index("--") + 1:][:2]


def view3d():
    window = bpy.context.window_manager.windows[0]
    area = max((a for a in window.screen.areas if a.type == "VIEW_3D"), key=lambda a: a.width * a.height)
    return window, area


def prepare():
    bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
    bpy.ops.preferences.addon_enable(module="quadlod")
    from test_addon import make_test_object  # noqa: E402  (same torus, UVs, two materials)

    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    obj = make_test_object()
    obj.data.materials["Red"].diffuse_color = (0.8, 0.25, 0.2, 1)
    obj.data.materials["Blue"].diffuse_color = (0.25, 0.4, 0.8, 1)
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.quadlod_lod(levels=2, ratio=0.5)
    for k, lod in enumerate(sorted(bpy.data.collections["Ring_LODs"].objects, key=lambda o: o.name), start=1):
        lod.location.x += 2.8 * k
    bpy.context.scene.quadlod.levels = 2
    window, area = view3d()
    space = area.spaces.active
    space.show_region_ui = True
    space.show_region_toolbar = False
    space.overlay.show_wireframes = True
    space.shading.color_type = "MATERIAL"
    from mathutils import Euler, Vector

    view = space.region_3d
    view.view_perspective = "PERSP"
    view.view_location = Vector((2.8, 0.0, 0.0))  # the middle of original, LOD1, LOD2
    view.view_rotation = Euler((0.75, 0.0, 0.0)).to_quaternion()
    view.view_distance = 8.5
    # Operators called from timers push no undo step of their own: mark this state explicitly.
    bpy.ops.ed.undo_push(message="test scene")
    return 1.0


def close_splash():
    # A fresh user directory shows the Quick Setup splash; Escape closes it.
    window, _ = view3d()
    window.event_simulate(type="ESC", value="PRESS")
    window.event_simulate(type="ESC", value="RELEASE")
    return 0.5


def switch_tab():
    # Click the "quadlod" tab: the tab column runs down the sidebar's right edge, Item, Tool, View,
    # then the add-on's tab about 225 pixels below the area's top at the default UI scale.
    window, area = view3d()
    sidebar = next(r for r in area.regions if r.type == "UI")
    scale = bpy.context.preferences.system.ui_scale
    x = sidebar.x + sidebar.width - int(12 * scale)
    y = area.y + area.height - int(225 * scale)
    window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=x, y=y)
    window.event_simulate(type="LEFTMOUSE", value="PRESS", x=x, y=y)
    window.event_simulate(type="LEFTMOUSE", value="RELEASE", x=x, y=y)
    # Leave the mouse over the viewport, away from the panel's buttons.
    window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=area.x + 40, y=area.y + 40)
    return 1.5


def screenshot():
    window, area = view3d()
    with bpy.context.temp_override(window=window, area=area):
        bpy.ops.screen.screenshot_area(filepath=png_path)
    print(f"screenshot_panel: wrote {png_path}")
    return 0.2


failures = []


def check(condition, what):
    print(("ok   " if condition else "FAIL ") + what)
    if not condition:
        failures.append(what)


def invoke_modal():
    """The operator as the UI runs it (INVOKE: modal, one level per timer tick, status bar text)."""
    bpy.ops.mesh.primitive_cylinder_add(vertices=32, depth=2.0, location=(0, 4, 0))
    cylinder = bpy.context.active_object
    cylinder.name = "Tube"
    bpy.ops.object.select_all(action="DESELECT")
    cylinder.select_set(True)
    bpy.context.view_layer.objects.active = cylinder
    bpy.ops.ed.undo_push(message="tube added")
    window, area = view3d()
    region = next(r for r in area.regions if r.type == "WINDOW")
    with bpy.context.temp_override(window=window, area=area, region=region):
        result = bpy.ops.object.quadlod_lod("INVOKE_DEFAULT", levels=2, ratio=0.6)
    check(result == {"RUNNING_MODAL"}, f"invoked operator runs modal ({result})")
    return 3.0


def after_modal():
    coll = bpy.data.collections.get("Tube_LODs")
    names = sorted(o.name for o in coll.objects) if coll else []
    check(names == ["Tube_LOD1", "Tube_LOD2"], f"modal run made Tube_LOD1, Tube_LOD2 ({names})")
    window, area = view3d()
    with bpy.context.temp_override(window=window, area=area):
        bpy.ops.ed.undo()
    return 1.0


def after_undo():
    check("Tube_LOD1" not in bpy.data.objects and "Tube_LOD2" not in bpy.data.objects,
          "one undo step removes the LODs of the modal run")
    check("Tube" in bpy.data.objects and "Ring_LOD1" in bpy.data.objects,
          f"undo leaves the rest ({sorted(o.name for o in bpy.data.objects)})")
    window, area = view3d()
    with bpy.context.temp_override(window=window, area=area):
        bpy.ops.ed.redo()
    return 1.0


def after_redo():
    check("Tube_LOD1" in bpy.data.objects and "Tube_LOD2" in bpy.data.objects,
          "redo brings them back: the operator pushed its own undo step")
    print(f"screenshot_panel: {len(failures)} failure(s)")
    if failures:
        sys.exit(1)
    bpy.ops.wm.quit_blender()
    return None


steps = [close_splash, prepare, switch_tab, screenshot, invoke_modal, after_modal, after_undo, after_redo]


def run_next():
    try:
        return steps.pop(0)()
    except Exception:
        import traceback

        traceback.print_exc()
        sys.exit(1)


bpy.app.timers.register(run_next, first_interval=1.0, persistent=True)
