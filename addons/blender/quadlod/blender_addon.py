"""The Blender side of quadlod: operator "Quad-dominant LOD", its sidebar panel and settings.

The reduction runs in-process through the C++ extension (quadlod._core, bundled in the add-on
zip). Each selected mesh object gets LOD1..LODn as new objects in the collection
"<name>_LODs"; the original is never modified, so one undo step removes everything the
operator made. What travels with the mesh (docs/blender.md):
  * UV layers (all of them, by name), material slots and per-face material indices, custom split
    normals (when the mesh has them) go through the core, which protects seams and borders;
  * vertex groups are not carried by the core: each LOD vertex takes the weights of the nearest
    vertex of the source mesh (the collapse places merged vertices on the input surface);
  * smooth shading: all faces smooth when every input face is;
  * a vertex group chosen as "Protect" (as Decimate takes one) gives the protect weights of
    issue 34 (docs/protect.md): weight 1 keeps the vertex exactly and the edges between such
    vertices, between 0 and 1 collapses there cost more; vertices outside the group weigh 0.
    Each LOD level carries the previous level's weights (the core returns them).
Invoked from the UI the operator is modal: one LOD level per timer tick, so the status bar and
the progress indicator redraw between levels. Called from a script (EXEC), it runs all levels
at once. Errors become reports (and a cancelled operator), never an exception out of Blender.
"""

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from . import _core  # the package loaded it (see _load_core in __init__.py)

EFFORT_ITEMS = [
    ("FAST", "Fast", "Shape objective at effort 0.5: half the passes (deterministic)"),
    ("DEFAULT", "Default", "Shape objective with the CLI's defaults (deterministic)"),
    ("THOROUGH", "Thorough", "Shape objective at effort 2: twice the passes, slower, usually closer to the input (deterministic)"),
    ("ILP", "ILP (time limit)", "The paper's objective with the MIP search, bounded by the time limit"),
]


# The core's default (SimplifyOptions::symmetry): on, auto-detected — see docs/symmetry.md.
SYMMETRY_DEFAULT = True


def _settings_annotations():
    """The knobs shared by the operator and the panel's scene settings (a fresh dict per class)."""
    return dict(
        target_mode=EnumProperty(
            name="Target",
            items=[("RATIO", "Ratio", "Each level is this fraction of the previous one"),
                   ("COUNT", "Triangles", "LOD1 has this many triangles (Blender's Tris: quad = 2); "
                                          "further levels multiply it by the ratio")],
            default="RATIO"),
        ratio=FloatProperty(name="Ratio", description="Size of each level relative to the previous one",
                            default=0.5, min=0.01, max=0.99),
        target_triangles=IntProperty(name="Triangles", description="LOD1's size in triangles (quad = 2)",
                                     default=1000, min=1),
        levels=IntProperty(name="LOD levels", description="Number of LOD objects made per mesh",
                           default=2, min=1, max=8),
        protect_uv_seams=BoolProperty(
            name="Protect UV seams",
            description="Keep UV seams, material borders, open boundaries and hard edges in place "
                        "(off: the paper's behaviour, features only weigh in the error)",
            default=True),
        effort=EnumProperty(name="Effort", items=EFFORT_ITEMS, default="DEFAULT"),
        time_limit=FloatProperty(name="Time limit (s)", description="MIP budget per level in seconds (effort ILP)",
                                 default=5.0, min=0.0, max=600.0),
        # Issue 34: the protect weights from a vertex group (by name; objects without it: none).
        protect_group=StringProperty(
            name="Protect", default="",
            description="Vertex group whose weights protect vertices: 1 = kept exactly (with the edges between "
                        "such vertices), between 0 and 1 = reduced later; empty = none"),
        # --- symmetry (issue 34; docs/symmetry.md) ---
        symmetry=BoolProperty(
            name="Symmetry",
            description="Keep a mirror-symmetric mesh symmetric: mirrored collapses and placements about a "
                        "plane through the centre of the mesh's bounding box (local axes). A mesh that is not "
                        "symmetric is reduced without it (the LOD's report says so)",
            default=SYMMETRY_DEFAULT),
        symmetry_axis=EnumProperty(
            name="Axis",
            items=[("AUTO", "Auto", "The axis plane the mesh is mirror-symmetric about"),
                   ("X", "X", "Mirror across the local X axis"),
                   ("Y", "Y", "Mirror across the local Y axis"),
                   ("Z", "Z", "Mirror across the local Z axis")],
            default="AUTO"),
    )


class QuadlodSettings(bpy.types.PropertyGroup):
    __annotations__ = _settings_annotations()


def _mesh_arrays(mesh):
    """Blender mesh → the arrays quadlod.simplify takes (one foreach_get per attribute)."""
    nv, nc, nf = len(mesh.vertices), len(mesh.loops), len(mesh.polygons)
    vertices = np.empty(nv * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", vertices)
    corners = np.empty(nc, dtype=np.int32)
    mesh.loops.foreach_get("vertex_index", corners)
    sizes = np.empty(nf, dtype=np.int32)
    mesh.polygons.foreach_get("loop_total", sizes)
    starts = np.empty(nf, dtype=np.int32)
    mesh.polygons.foreach_get("loop_start", starts)
    # Polygons need not list their loops in order; the core wants them face by face.
    order = None
    if nf and not np.array_equal(starts, np.concatenate(([0], np.cumsum(sizes)[:-1]))):
        order = np.concatenate([np.arange(s, s + k) for s, k in zip(starts, sizes)])
        corners = corners[order]
    uvs = {}
    for layer in mesh.uv_layers:
        uv = np.empty(nc * 2, dtype=np.float32)
        layer.data.foreach_get("uv", uv)
        uv = uv.reshape(nc, 2)
        uvs[layer.name] = uv[order] if order is not None else uv
    materials = None
    if len(mesh.materials) > 1:
        materials = np.empty(nf, dtype=np.int32)
        mesh.polygons.foreach_get("material_index", materials)
    normals = None
    if mesh.has_custom_normals:
        mesh.calc_normals_split()
        normals = np.empty(nc * 3, dtype=np.float32)
        mesh.loops.foreach_get("normal", normals)
        normals = normals.reshape(nc, 3)
        if order is not None:
            normals = normals[order]
    return dict(vertices=vertices.reshape(nv, 3), faces=(corners, sizes), uvs=uvs or None,
                materials=materials, normals=normals, morph_targets=_shape_keys(mesh, vertices.reshape(nv, 3)))


def _shape_keys(mesh, vertices):
    """Issue 34: {name: (V, 3) key co - basis co} of the mesh's shape keys (None without any)."""
    keys = mesh.shape_keys
    if keys is None or len(keys.key_blocks) < 2:
        return None
    reference = keys.reference_key
    basis = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    reference.data.foreach_get("co", basis)
    shapes = {}
    for block in keys.key_blocks:
        if block == reference:
            continue
        co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        block.data.foreach_get("co", co)
        shapes[block.name] = (co - basis).reshape(-1, 3).astype(np.float64)
    return shapes


def _add_shape_keys(source_obj, lod_obj, level):
    """Issue 34: the LOD's carried shapes as shape keys of the LOD object, with the source's values."""
    shapes = level.get("morph_targets")
    if not shapes:
        return
    source_keys = source_obj.data.shape_keys
    vertices = np.asarray(level["vertices"], dtype=np.float64)
    lod_obj.shape_key_add(name=source_keys.reference_key.name if source_keys else "Basis", from_mix=False)
    for name, displacement in shapes.items():
        block = lod_obj.shape_key_add(name=name, from_mix=False)
        block.data.foreach_set("co", (vertices + np.asarray(displacement)).astype(np.float32).ravel())
        if source_keys is not None and name in source_keys.key_blocks:
            source = source_keys.key_blocks[name]
            block.slider_min, block.slider_max = source.slider_min, source.slider_max
            block.value = source.value


def _vertex_weights(obj):
    """{group index: (V,) weights, NaN = not in the group} of the source object's vertex groups."""
    if not obj.vertex_groups:
        return {}
    weights = {g.index: np.full(len(obj.data.vertices), np.nan) for g in obj.vertex_groups}
    for v in obj.data.vertices:
        for g in v.groups:
            if g.group in weights:
                weights[g.group][v.index] = g.weight
    return weights


def _protect_weights(obj, group_name):
    """(V,) weights of the vertex group `group_name` (0 outside it), or None without that group."""
    group = obj.vertex_groups.get(group_name) if group_name else None
    if group is None:
        return None
    weights = np.zeros(len(obj.data.vertices))
    for v in obj.data.vertices:
        for g in v.groups:
            if g.group == group.index:
                weights[v.index] = min(1.0, max(0.0, g.weight))
    return weights


def _nearest_source_vertices(source_positions, positions):
    from mathutils.kdtree import KDTree

    tree = KDTree(len(source_positions))
    for i, p in enumerate(source_positions):
        tree.insert(p, i)
    tree.balance()
    return np.array([tree.find(p)[1] for p in positions], dtype=np.int64)


def _build_mesh(name, level, source_obj, source_all_smooth):
    """A new Blender mesh from one simplify() result."""
    src = source_obj.data
    me = bpy.data.meshes.new(name)
    vertices = np.ascontiguousarray(level["vertices"], dtype=np.float32)
    corners = np.ascontiguousarray(level["faces"], dtype=np.int32)
    sizes = np.ascontiguousarray(level["face_sizes"], dtype=np.int32)
    me.vertices.add(len(vertices))
    me.vertices.foreach_set("co", vertices.ravel())
    me.loops.add(len(corners))
    me.loops.foreach_set("vertex_index", corners)
    me.polygons.add(len(sizes))
    starts = np.zeros(len(sizes), dtype=np.int32)
    if len(sizes) > 1:
        starts[1:] = np.cumsum(sizes)[:-1]
    me.polygons.foreach_set("loop_start", starts)
    me.polygons.foreach_set("loop_total", sizes)
    for mat in src.materials:
        me.materials.append(mat)
    if "materials" in level and len(src.materials) > 1:
        slots = np.clip(np.asarray(level["materials"], dtype=np.int32), 0, len(src.materials) - 1)
        me.polygons.foreach_set("material_index", slots)
    if source_all_smooth:
        me.polygons.foreach_set("use_smooth", np.ones(len(sizes), dtype=bool))
    me.update(calc_edges=True)
    uvs = level.get("uvs") or {}
    for layer_name, uv in uvs.items():
        layer = me.uv_layers.new(name=layer_name)
        values = np.nan_to_num(np.asarray(uv, dtype=np.float32), nan=0.0)
        layer.data.foreach_set("uv", values.ravel())
    if src.uv_layers.active is not None and src.uv_layers.active.name in me.uv_layers:
        me.uv_layers.active = me.uv_layers[src.uv_layers.active.name]
    if src.has_custom_normals and level.get("normals") is not None:
        me.use_auto_smooth = True
        normals = np.nan_to_num(np.asarray(level["normals"], dtype=np.float64), nan=0.0)
        me.normals_split_custom_set([tuple(n) for n in normals])
    elif src.use_auto_smooth:
        me.use_auto_smooth = True
        me.auto_smooth_angle = src.auto_smooth_angle
    me.validate(clean_customdata=False)
    return me


def _copy_vertex_groups(source_obj, lod_obj, weights, source_positions):
    if not weights:
        return
    nearest = _nearest_source_vertices(source_positions, [tuple(v.co) for v in lod_obj.data.vertices])
    for group in source_obj.vertex_groups:
        target = lod_obj.vertex_groups.new(name=group.name)
        w = weights[group.index][nearest]
        for vertex, value in enumerate(w):
            if not np.isnan(value):
                target.add([vertex], float(value), "REPLACE")


def _lod_collection(context, name):
    coll = bpy.data.collections.get(name)
    if coll is None:
        coll = bpy.data.collections.new(name)
    if coll.name not in context.scene.collection.children and not any(
            coll.name in c.children for c in context.scene.collection.children_recursive):
        context.scene.collection.children.link(coll)
    return coll


class QUADLOD_OT_make_lods(bpy.types.Operator):
    """Make quad-dominant LODs of the selected meshes (new objects in <name>_LODs)"""

    bl_idname = "object.quadlod_lod"
    bl_label = "Quad-dominant LOD"
    bl_options = {"REGISTER", "UNDO"}
    __annotations__ = _settings_annotations()

    @classmethod
    def poll(cls, context):
        return any(o.type == "MESH" for o in context.selected_objects)

    # --- planning ------------------------------------------------------------------------------
    def _plan(self, context):
        """One job per (object, level); each level is reduced from the previous level's output."""
        self._jobs = []
        for obj in sorted((o for o in context.selected_objects if o.type == "MESH"), key=lambda o: o.name):
            self._jobs.extend((obj, k) for k in range(1, self.levels + 1))
        self._state = {}
        self._made = []
        self._done = 0

    def _options(self):
        options = dict(features=self.protect_uv_seams)
        options.update(symmetry=self.symmetry_axis.lower() if self.symmetry else "off")  # issue 34
        if self.effort == "FAST":
            options.update(effort=0.5)
        elif self.effort == "THOROUGH":
            options.update(effort=2.0)
        elif self.effort == "ILP":
            options.update(objective="paper", time_limit=self.time_limit)
        return options

    def _target(self, input_size, k):
        if self.target_mode == "COUNT":
            return max(1, round(min(self.target_triangles, input_size) * self.ratio ** (k - 1)))
        return max(1, round(input_size * self.ratio ** k))

    def _step(self, context):
        """Runs one job; raises on failure."""
        obj, k = self._jobs[self._done]
        state = self._state.get(obj.name)
        if state is None:
            arrays = _mesh_arrays(obj.data)
            if len(arrays["faces"][1]) == 0:
                raise _core.QuadlodError(f"{obj.name}: the mesh has no faces")
            weights = _vertex_weights(obj)
            state = dict(arrays=arrays, previous=None, weights=weights,
                         protect=_protect_weights(obj, self.protect_group),
                         # only the vertex-group transfer needs the source positions as tuples
                         positions=[tuple(v) for v in arrays["vertices"]] if weights else None,
                         size=int(np.sum(arrays["faces"][1] - 2)),
                         all_smooth=all(p.use_smooth for p in obj.data.polygons),
                         collection=_lod_collection(context, f"{obj.name}_LODs"))
            self._state[obj.name] = state
        src = state["arrays"] if state["previous"] is None else state["previous"]
        faces = src["faces"] if state["previous"] is None else (src["faces"], src["face_sizes"])
        options = self._options()
        # Protect weights: the group's for LOD1, then the previous level's (they follow the vertices).
        protect = state["protect"] if state["previous"] is None else src.get("protect")
        if protect is not None:
            options.update(protect=protect)
        level = _core.simplify(src["vertices"], faces, faces_target=self._target(state["size"], k),
                               uvs=src.get("uvs"), normals=src.get("normals"),
                               materials=src.get("materials"), morph_targets=src.get("morph_targets"), **options)
        state["previous"] = level
        me = _build_mesh(f"{obj.name}_LOD{k}", level, obj, state["all_smooth"])
        lod = bpy.data.objects.new(f"{obj.name}_LOD{k}", me)
        lod.matrix_world = obj.matrix_world.copy()
        state["collection"].objects.link(lod)
        _copy_vertex_groups(obj, lod, state["weights"], state["positions"])
        _add_shape_keys(obj, lod, level)
        lod["quadlod_report"] = {key: level["report"][key] for key in
                                 ("input_tri_equivalent", "target", "achieved", "quads", "triangles", "ngons")}
        if "protect" in level["report"]:
            lod["quadlod_report"]["protected_vertices"] = level["report"]["protect"]["protected_vertices"]
        # issue 34: the plane this level was reduced about ("none"), and why not when it was asked for
        symmetry = level["report"].get("symmetry", {})
        lod["quadlod_report"]["symmetry"] = symmetry.get("axis", "none")
        if symmetry.get("note"):
            lod["quadlod_report"]["symmetry_note"] = symmetry["note"]
        self._made.append(lod)
        self._done += 1

    def _status(self, context, text):
        if context.workspace is not None:
            context.workspace.status_text_set(text)

    def _finish(self, context):
        self._status(context, None)
        context.window_manager.progress_end()
        summary = ", ".join(f"{o.name}: {o['quadlod_report']['achieved']} tris" for o in self._made)
        self.report({"INFO"}, f"quadlod: {len(self._made)} LOD object(s) — {summary}")
        return {"FINISHED"}

    def _fail(self, context, error):
        self._status(context, None)
        context.window_manager.progress_end()
        obj, k = self._jobs[self._done]
        message = str(error)
        if not isinstance(error, (_core.QuadlodError, ValueError, TypeError)):
            message = f"internal error ({type(error).__name__}): {message}"
        self.report({"ERROR"}, f"quadlod: {obj.name} LOD{k}: {message}")
        return {"CANCELLED"}

    # --- entry points -----------------------------------------------------------------------------
    def invoke(self, context, event):
        settings = context.scene.quadlod
        for key in QuadlodSettings.__annotations__:
            if not self.properties.is_property_set(key):
                setattr(self, key, getattr(settings, key))
        self._plan(context)
        context.window_manager.progress_begin(0, len(self._jobs))
        self._timer = context.window_manager.event_timer_add(0.01, window=context.window)
        context.window_manager.modal_handler_add(self)
        self._status(context, f"quadlod: 0/{len(self._jobs)} LOD levels")
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC":
            context.window_manager.event_timer_remove(self._timer)
            self._status(context, None)
            context.window_manager.progress_end()
            self.report({"WARNING"}, f"quadlod: stopped after {self._done} of {len(self._jobs)} levels")
            return {"FINISHED"} if self._made else {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        try:
            obj, k = self._jobs[self._done]
            self._status(context, f"quadlod: {obj.name} LOD{k} ({self._done + 1}/{len(self._jobs)}) — Esc stops")
            self._step(context)
        except Exception as error:  # every failure becomes a report, never an exception in Blender
            context.window_manager.event_timer_remove(self._timer)
            return self._fail(context, error)
        context.window_manager.progress_update(self._done)
        if self._done == len(self._jobs):
            context.window_manager.event_timer_remove(self._timer)
            return self._finish(context)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        self._plan(context)
        context.window_manager.progress_begin(0, len(self._jobs))
        while self._done < len(self._jobs):
            try:
                self._step(context)
            except Exception as error:
                return self._fail(context, error)
            context.window_manager.progress_update(self._done)
        return self._finish(context)


class QUADLOD_PT_panel(bpy.types.Panel):
    bl_label = "Quad-dominant LOD"
    bl_idname = "QUADLOD_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "quadlod"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.quadlod
        # No property split: the sidebar is narrow and split labels get cut off.
        layout.row().prop(settings, "target_mode", expand=True)
        if settings.target_mode == "COUNT":
            layout.prop(settings, "target_triangles")
        layout.prop(settings, "ratio")
        layout.prop(settings, "levels")
        layout.prop(settings, "protect_uv_seams")
        active = context.active_object
        if active is not None and active.type == "MESH":  # as Decimate picks its vertex group
            layout.prop_search(settings, "protect_group", active, "vertex_groups", text="Protect")
        else:
            layout.prop(settings, "protect_group", text="Protect")
        row = layout.row(align=True)  # issue 34: as Decimate's Symmetry toggle and axis
        row.prop(settings, "symmetry")
        sub = row.row(align=True)
        sub.enabled = settings.symmetry
        sub.prop(settings, "symmetry_axis", text="")
        layout.prop(settings, "effort")
        row = layout.row()
        row.enabled = settings.effort == "ILP"
        row.prop(settings, "time_limit")
        meshes = [o for o in context.selected_objects if o.type == "MESH"]
        layout.label(text=f"{len(meshes)} mesh object(s) selected", icon="MESH_DATA")
        layout.operator(QUADLOD_OT_make_lods.bl_idname, icon="MOD_DECIM")


def _menu(self, context):
    self.layout.separator()
    self.layout.operator(QUADLOD_OT_make_lods.bl_idname, icon="MOD_DECIM")


_classes = (QuadlodSettings, QUADLOD_OT_make_lods, QUADLOD_PT_panel)


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.quadlod = PointerProperty(type=QuadlodSettings)
    bpy.types.VIEW3D_MT_object.append(_menu)


def unregister():
    bpy.types.VIEW3D_MT_object.remove(_menu)
    del bpy.types.Scene.quadlod
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
