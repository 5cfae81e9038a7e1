"""VS-Tree for Blender: clustering simplification, surface reconstruction from point clouds, and
cluster colours, through vstree's C library (ctypes binding shipped in this add-on).

Object menu: VS-Tree Simplify / Reconstruct / Show Clusters. 3D View sidebar: "VS-Tree" tab.
The native library is loaded on first use, so registering never fails; a missing or
incompatible library is reported by the operators and shown in the panel.
"""

bl_info = {
    "name": "VS-Tree",
    "author": "vstree developers",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "View3D > Object > VS-Tree; View3D > Sidebar > VS-Tree",
    "description": "Clustering simplification and surface reconstruction with VS-Trees",
    "category": "Mesh",
}

import textwrap
import threading

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from . import core

#: Test hook: when set, called as ``progress_hook(fraction, stage)`` from every progress
#: callback; returning False cancels the running operation (as Esc does in the GUI).
progress_hook = None


class _Progress:
    """The binding's progress callback: drives window_manager.progress_* and asks the hook /
    the cancel event whether to go on."""

    def __init__(self, wm, cancel=None, sink=None):
        self.wm = wm
        self.cancel = cancel
        self.sink = sink
        self.stage = ""
        self.fraction = 0.0

    def __call__(self, fraction, stage):
        self.fraction, self.stage = fraction, stage
        if self.wm is not None:
            self.wm.progress_update(fraction)
        if self.sink is not None:
            self.sink(fraction, stage)
        if progress_hook is not None and progress_hook(fraction, stage) is False:
            return False
        return not (self.cancel is not None and self.cancel.is_set())


def _is_mesh(context):
    ob = context.active_object
    return ob is not None and ob.type == 'MESH'


LABEL_KINDS = [
    ('cluster', "Clusters", "One colour per cluster (output vertex)"),
    ('t_node', "T-nodes", "One colour per T-node (2D tree root on the surface)"),
]



# Properties made from the library's parameter table (vstree.parameters()): their label,
# description, default, range and choices are the library's. The table is read when the
# add-on registers; without the library the properties are placeholders, which no operator
# reads (each first loads the library and reports why it cannot).
#: Per class: (attribute, call, parameter).
TABLE_PROPERTIES = {
    "VSTREE_OT_simplify": [
        ("error", "simplify", "error"),
        ("tree_kind", "simplify", "tree_kind"),
        ("metric", "simplify", "metric"),
        ("threads", "simplify", "threads"),
        ("keep_topology", "simplify", "keep_topology"),
    ],
    "VSTREE_OT_reconstruct": [
        ("error", "reconstruct", "error"),
        ("max_levels", "reconstruct", "max_levels"),
        ("max_grid_depth", "reconstruct", "max_grid_depth"),
        ("closure", "reconstruct", "closure"),
        ("trim", "reconstruct", "trim"),
        ("orient", "reconstruct", "orient"),
        ("neighbours", "reconstruct", "neighbours"),
        ("threads", "reconstruct", "threads"),
    ],
    "VSTREE_OT_show_clusters": [
        ("error", "simplify", "error"),
        ("tree_kind", "simplify", "tree_kind"),
        ("metric", "simplify", "metric"),
    ],
    "VSTREE_PG_settings": [
        ("error", "simplify", "error"),
        ("tree_kind", "simplify", "tree_kind"),
        ("metric", "simplify", "metric"),
        ("recon_error", "reconstruct", "error"),
        ("max_levels", "reconstruct", "max_levels"),
        ("closure", "reconstruct", "closure"),
        ("trim", "reconstruct", "trim"),
    ],
}

#: Blender's properties hold 32-bit numbers: table ends beyond these are clamped to them.
_FLOAT_LIMIT = 3.0e38
_INT_LIMIT = 2**31 - 1


def _description(p):
    if p.kind in ("real", "integer") and p.unit:
        return "%s (%s)" % (p.help, p.unit)
    return p.help


def table_property(p):
    """The Blender property of a parameter of the library's table."""
    if p.kind == "choice":
        items = [(c.name, c.label, c.help) for c in p.choices]
        return EnumProperty(name=p.label, items=items, default=p.default, description=p.help)
    if p.kind == "flag":
        return BoolProperty(name=p.label, default=bool(p.default), description=p.help)
    if p.kind == "integer":
        low, high = max(p.min, -_INT_LIMIT), min(p.max, _INT_LIMIT)
        return IntProperty(name=p.label, default=p.default, min=int(low), max=int(high), description=_description(p))
    # An open lower end of 0 (a bound must be above 0): the smallest step Blender shows.
    low = 1e-9 if p.min_open and p.min == 0 else max(p.min, -_FLOAT_LIMIT)
    high = min(p.max, _FLOAT_LIMIT)
    small = p.default != 0 and abs(p.default) < 1e-2
    return FloatProperty(
        name=p.label, default=p.default, min=low, max=high, description=_description(p),
        # Bounds like 1e-5 need digits; the slider moves by a hundredth of a unit.
        precision=7 if small else 3, step=1,
        soft_max=min(high, 1.0) if small else high,
    )


def _placeholder(attribute):
    return StringProperty(name=attribute, description="The vstree library is not loaded")


def _add_table_properties():
    """Gives each class of TABLE_PROPERTIES its properties from the library's table."""
    try:
        table = {(p.call, p.name): p for p in core.binding().parameters()}
    except core.VstreeUnavailable:
        table = {}
    for cls in classes:
        # The class's own annotations (Python 3.10 and later never hand out a base class's;
        # 3.14 evaluates them lazily and caches the dict this returns, so it is read here, not
        # looked up in the class's __dict__).
        own = cls.__annotations__
        for attribute, call, name in TABLE_PROPERTIES.get(cls.__name__, []):
            p = table.get((call, name))
            own[attribute] = table_property(p) if p is not None else _placeholder(attribute)


class _Worker:
    """Shared run logic. Each operator says how to read its input (main thread), compute
    (numpy + the library only: any thread) and write the result (main thread).

    execute() runs the three steps synchronously with window_manager progress; it is what
    scripts and INVOKE_DEFAULT in background mode run. invoke() in the GUI reads, computes on a
    worker thread (the library releases the GIL) while a timer updates the progress and Esc
    cancels, then writes. Either way the scene is written only once the library is done."""

    def _read(self, context, ob):
        raise NotImplementedError

    def _native(self, data, progress):
        raise NotImplementedError

    def _write(self, context, ob, out):
        raise NotImplementedError

    def _compute(self, context, progress):
        core.binding()
        ob = context.active_object
        return self._write(context, ob, self._native(self._read(context, ob), progress))

    def _finish(self, context, value):
        raise NotImplementedError

    def _fail(self, exc):
        vs = core._BINDING
        if vs is not None and isinstance(exc, vs.CancelledError):
            self.report({'WARNING'}, "VS-Tree: cancelled; nothing was changed")
            return {'CANCELLED'}
        self.report({'ERROR'}, "VS-Tree: %s" % exc)
        return {'CANCELLED'}

    def execute(self, context):
        wm = context.window_manager
        wm.progress_begin(0.0, 1.0)
        try:
            value = self._compute(context, _Progress(wm))
        except Exception as e:  # library errors, cancel, bad input: report, never crash
            return self._fail(e)
        finally:
            wm.progress_end()
        return self._finish(context, value)

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        ob = context.active_object
        try:
            core.binding()
            data = self._read(context, ob)
        except Exception as e:
            return self._fail(e)
        self._object_name = ob.name
        self._cancel = threading.Event()
        self._progress = _Progress(None, self._cancel)
        self._box = {}

        def run():
            try:
                self._box["out"] = self._native(data, self._progress)
            except Exception as e:  # handed to the main thread
                self._box["error"] = e

        self._thread = threading.Thread(target=run, name="vstree", daemon=True)
        self._thread.start()
        wm = context.window_manager
        wm.progress_begin(0.0, 1.0)
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        return {'RUNNING_MODAL'}

    def modal(self, context, event):
        if event.type == 'ESC':
            self._cancel.set()
            return {'RUNNING_MODAL'}
        if event.type != 'TIMER':
            return {'PASS_THROUGH'}
        wm = context.window_manager
        if self._thread.is_alive():
            wm.progress_update(self._progress.fraction)
            context.workspace.status_text_set(
                "VS-Tree: %s %d%% (Esc cancels)" % (self._progress.stage, int(100 * self._progress.fraction))
            )
            return {'RUNNING_MODAL'}
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)
        if "error" in self._box:
            return self._fail(self._box["error"])
        ob = bpy.data.objects.get(self._object_name)
        if ob is None or ob.type != 'MESH':
            self.report({'ERROR'}, "VS-Tree: '%s' was removed while computing" % self._object_name)
            return {'CANCELLED'}
        try:
            value = self._write(context, ob, self._box["out"])
        except Exception as e:
            return self._fail(e)
        return self._finish(context, value)



class VSTREE_OT_simplify(_Worker, bpy.types.Operator):
    """Simplify the active mesh by VS-Tree clustering"""

    bl_idname = "vstree.simplify"
    bl_label = "VS-Tree Simplify"
    bl_options = {'REGISTER', 'UNDO'}

    apply_modifiers: BoolProperty(
        name="Apply Modifiers",
        default=True,
        description="Simplify the mesh with its modifiers applied (evaluated); in place, the "
        "modifiers are then removed",
    )
    in_place: BoolProperty(
        name="In Place",
        default=False,
        description="Replace the object's mesh (undoable) instead of adding a new object",
    )
    ratio: FloatProperty(
        name="Ratio",
        default=0.0,
        min=0.0,
        max=1.0,
        subtype='FACTOR',
        description="Fraction of the triangles to keep, like the Decimate modifier's ratio (the count "
        "is met within one triangle); 0 = use the error bound",
    )

    @classmethod
    def poll(cls, context):
        return _is_mesh(context)

    def _params(self):
        p = dict(error=self.error, tree_kind=self.tree_kind, metric=self.metric, threads=self.threads,
                 keep_topology=self.keep_topology)
        if self.ratio > 0.0:
            del p["error"]
            p["ratio"] = self.ratio
        return p

    def _read(self, context, ob):
        return core.read_simplify(context, ob, self.apply_modifiers)

    def _native(self, data, progress):
        return core.compute_simplify(data, self._params(), progress)

    def _write(self, context, ob, out):
        return core.write_simplify(context, ob, out, self.apply_modifiers, self.in_place), out[2]

    def _finish(self, context, value):
        target, stats = value
        if not self.in_place:
            for o in context.selected_objects:
                o.select_set(False)
            target.select_set(True)
            context.view_layer.objects.active = target
        self.report(
            {'INFO'},
            "VS-Tree: %d vertices, %d triangles (%d clusters, topology %s, %.2f s)"
            % (len(target.data.vertices), len(target.data.polygons), stats.get("clusters", 0),
               "kept" if stats.get("kept_topology") else "not kept", stats.get("seconds_total", 0.0)),
        )
        return {'FINISHED'}


class VSTREE_OT_reconstruct(_Worker, bpy.types.Operator):
    """Reconstruct a closed surface from the active point-cloud mesh (vertices only)"""

    bl_idname = "vstree.reconstruct"
    bl_label = "VS-Tree Reconstruct"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        return _is_mesh(context)

    def _read(self, context, ob):
        return core.read_cloud(ob)

    def _native(self, data, progress):
        params = dict(
            error=self.error, max_levels=self.max_levels, max_grid_depth=self.max_grid_depth,
            closure=self.closure, trim=self.trim, orient=self.orient, neighbours=self.neighbours,
            threads=self.threads,
        )
        return core.compute_reconstruct(data, params, progress)

    def _write(self, context, ob, out):
        return core.write_reconstruct(context, ob, out), out[2]

    def _finish(self, context, value):
        target, stats = value
        for o in context.selected_objects:
            o.select_set(False)
        target.select_set(True)
        context.view_layer.objects.active = target
        isolated = stats["input_points"] - stats["samples"]
        self.report(
            {'INFO'},
            "VS-Tree: surface with %d vertices, %d triangles%s"
            % (
                len(target.data.vertices),
                len(target.data.polygons),
                "; %d isolated points left out" % isolated if isolated > 0 else "",
            ),
        )
        return {'FINISHED'}


class VSTREE_OT_show_clusters(_Worker, bpy.types.Operator):
    """Colour the active mesh's vertices by VS-Tree cluster or T-node (a FLOAT_COLOR point attribute)"""

    bl_idname = "vstree.show_clusters"
    bl_label = "VS-Tree Show Clusters"
    bl_options = {'REGISTER', 'UNDO'}

    kind: EnumProperty(name="Colour By", items=LABEL_KINDS, default='cluster', description="What gets one colour")
    attribute: StringProperty(name="Attribute", default="vstree_cluster", description="Name of the colour attribute")

    @classmethod
    def poll(cls, context):
        return _is_mesh(context)

    def _read(self, context, ob):
        if not self.attribute:
            raise ValueError("the attribute name is empty")
        return core.read_labels(ob)

    def _native(self, data, progress):
        params = dict(error=self.error, tree_kind=self.tree_kind, metric=self.metric)
        return core.compute_labels(data, params, self.kind, progress)

    def _write(self, context, ob, out):
        return core.write_colors(ob, out, self.attribute)

    def _finish(self, context, value):
        attr, count = value
        self.report({'INFO'}, "VS-Tree: %d %s coloured in '%s'" % (count, self.kind, attr.name))
        return {'FINISHED'}


class VSTREE_PG_settings(bpy.types.PropertyGroup):
    """Sidebar parameters, passed to the operators by the panel's buttons."""

    apply_modifiers: BoolProperty(name="Apply Modifiers", default=True, description="Use the evaluated mesh")
    in_place: BoolProperty(name="In Place", default=False, description="Replace the object's mesh")
    kind: EnumProperty(name="Colour By", items=LABEL_KINDS, default='cluster', description="What gets one colour")


class VSTREE_PT_panel(bpy.types.Panel):
    bl_label = "VS-Tree"
    bl_idname = "VSTREE_PT_panel"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "VS-Tree"

    def draw(self, context):
        s = context.scene.vstree
        layout = self.layout
        ok, msg = core.status()
        if not ok:
            # Without the library the parameters are placeholders: only the message is shown.
            layout.label(text="Native library missing", icon='ERROR')
            for line in textwrap.wrap(msg, 60):
                layout.label(text=line)
            return
        col = layout.column(align=True)
        col.label(text="Simplify / Clusters")
        col.prop(s, "error")
        col.prop(s, "tree_kind")
        col.prop(s, "metric")
        col.prop(s, "apply_modifiers")
        col.prop(s, "in_place")
        op = col.operator(VSTREE_OT_simplify.bl_idname, text="Simplify")
        op.error, op.tree_kind, op.metric = s.error, s.tree_kind, s.metric
        op.apply_modifiers, op.in_place = s.apply_modifiers, s.in_place
        col.prop(s, "kind")
        op = col.operator(VSTREE_OT_show_clusters.bl_idname, text="Show Clusters")
        op.error, op.tree_kind, op.metric, op.kind = s.error, s.tree_kind, s.metric, s.kind
        col = layout.column(align=True)
        col.label(text="Reconstruct")
        col.prop(s, "recon_error")
        col.prop(s, "max_levels")
        col.prop(s, "closure")
        col.prop(s, "trim")
        op = col.operator(VSTREE_OT_reconstruct.bl_idname, text="Reconstruct")
        op.error, op.max_levels, op.closure, op.trim = s.recon_error, s.max_levels, s.closure, s.trim
        # The sidebar does not wrap labels: a failure's message (which names the zip to
        # install) is shown whole, a line per label.
        layout.label(text=msg)


class VSTREE_MT_menu(bpy.types.Menu):
    bl_label = "VS-Tree"
    bl_idname = "VSTREE_MT_menu"

    def draw(self, context):
        layout = self.layout
        layout.operator(VSTREE_OT_simplify.bl_idname, text="Simplify")
        layout.operator(VSTREE_OT_reconstruct.bl_idname, text="Reconstruct Surface")
        layout.operator(VSTREE_OT_show_clusters.bl_idname, text="Show Clusters")


def _menu(self, context):
    self.layout.menu(VSTREE_MT_menu.bl_idname)


classes = (
    VSTREE_OT_simplify,
    VSTREE_OT_reconstruct,
    VSTREE_OT_show_clusters,
    VSTREE_PG_settings,
    VSTREE_PT_panel,
    VSTREE_MT_menu,
)


def register():
    _add_table_properties()
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.vstree = PointerProperty(type=VSTREE_PG_settings)
    bpy.types.VIEW3D_MT_object.append(_menu)


def unregister():
    bpy.types.VIEW3D_MT_object.remove(_menu)
    del bpy.types.Scene.vstree
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
