"""Startup script of desktop Blender's GUI under Xvfb (tests/hosts/run.sh): the VS-Tree operators
invoked as a user's click does (INVOKE_DEFAULT in the 3D view: the modal path, computing on a
worker thread), Esc typed by the host with xdotool, and the sidebar for a screenshot.

The script and the host take turns through two files in STATE_DIR: "state" (written here:
running, idle, sidebar, done) and "host" (written by run.sh: esc, shot, shot-done). Every check
appends "PASS name" or "FAIL name: why" to RESULTS.

usage: blender --python blender_gui.py -- RESULTS STATE_DIR [LABEL]
(LABEL, e.g. the system's name, starts every check's name.)
"""

import os
import sys
import threading
import time
import traceback

import bpy
import numpy as np

ARGS = sys.argv[sys.argv.index("--") + 1:]
RESULTS, STATE_DIR = ARGS[:2]
LABEL = (ARGS[2] + " ") if len(ARGS) > 2 else ""
MODULE = "bl_ext.user_default.vstree"
# No splash screen (it would take the first Esc); the preferences are not saved.
bpy.context.preferences.view.show_splash = False


def record(ok, name, why=""):
    line = ("PASS " if ok else "FAIL ") + LABEL + "blender gui: " + name + ("" if ok else ": " + why)
    print(("ok   " if ok else "FAIL ") + line[5:], flush=True)
    with open(RESULTS, "a") as f:
        f.write(line + "\n")


def check(ok, name, why=""):
    record(bool(ok), name, why)
    return bool(ok)


def set_state(s):
    tmp = os.path.join(STATE_DIR, "state.tmp")
    with open(tmp, "w") as f:
        f.write(s + "\n")
    os.replace(tmp, os.path.join(STATE_DIR, "state"))
    print("state:", s, flush=True)


def host_said(word):
    try:
        with open(os.path.join(STATE_DIR, "host")) as f:
            return f.read().strip() == word
    except OSError:
        return False


def view3d():
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    region = next(r for r in area.regions if r.type == 'WINDOW')
    return dict(window=win, screen=win.screen, area=area, region=region)


def invoke(op, **props):
    """The operator as the menu or the sidebar's button calls it: INVOKE_DEFAULT in the 3D view."""
    with bpy.context.temp_override(**view3d()):
        return getattr(bpy.ops.vstree, op)('INVOKE_DEFAULT', **props)


def worker_alive():
    return any(t.name == "vstree" and t.is_alive() for t in threading.enumerate())


def snapshot():
    return sorted(
        (o.name, len(o.data.vertices), len(o.data.polygons), len(o.data.color_attributes))
        for o in bpy.data.objects if o.type == 'MESH'
    ), len(bpy.data.meshes)


def select(ob):
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    ob.select_set(True)
    bpy.context.view_layer.objects.active = ob


def sphere_cloud(n):
    i = np.arange(n) + 0.5
    phi = np.arccos(1 - 2 * i / n)
    theta = np.pi * (1 + 5**0.5) * i
    d = np.stack([np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)], 1).astype(np.float32)
    me = bpy.data.meshes.new("cloud")
    me.vertices.add(n)
    me.vertices.foreach_set("co", (d + np.float32([3.0, 0.0, 0.0])).ravel())
    me.attributes.new("normal", 'FLOAT_VECTOR', 'POINT').data.foreach_set("vector", d.ravel())
    me.update()
    ob = bpy.data.objects.new("cloud", me)
    bpy.context.collection.objects.link(ob)
    return ob


def wait(cond, seconds):
    """Generator: yields timer intervals until cond() or the time is up; the result is in
    the StopIteration (use `ok = yield from wait(...)`)."""
    end = time.time() + seconds
    while time.time() < end:
        if cond():
            return True
        yield 0.25
    return cond()


def run_to_end(op, name, **props):
    """Invokes op modally, waits for its worker thread and the modal's last timer."""
    n_ops = len(bpy.context.window_manager.operators)
    result = invoke(op, **props)
    check(result == {'RUNNING_MODAL'}, "%s: invoke in the 3D view runs modal" % op, str(result))
    yield from wait(lambda: not worker_alive(), 600)
    # the modal writes the result on its next timer event (0.1 s)
    ok = yield from wait(lambda: len(bpy.context.window_manager.operators) > n_ops, 30)
    last = bpy.context.window_manager.operators[-1].bl_idname if ok else None
    check(ok and last == "VSTREE_OT_" + op, "%s: the finished run is registered (undo, redo panel)" % op,
          "last operator %s" % last)


def steps():
    addon = sys.modules.get(MODULE)
    if not check(addon is not None, "the extension is enabled at startup", "no module %s" % MODULE):
        return
    ok, msg = addon.core.status()
    print("Blender", bpy.app.version_string, "|", msg, "|", bpy.context.preferences.system.__class__, flush=True)
    ctx = view3d()
    space = ctx["area"].spaces.active
    space.show_region_ui = True
    yield 0.5
    ui = next(r for r in ctx["area"].regions if r.type == 'UI')
    ui.active_panel_category = "VS-Tree"

    for ob in list(bpy.data.objects):  # the startup file's cube, camera and light
        bpy.data.objects.remove(ob)

    # --- Esc while the modal operator computes ---------------------------------------------
    bpy.ops.mesh.primitive_uv_sphere_add(segments=192, ring_count=96, location=(0.0, 0.0, 0.0))
    src = bpy.context.active_object
    src.name = "sphere"
    before = snapshot()
    n_ops = len(bpy.context.window_manager.operators)
    calls = []

    def hold_until_esc(fraction, stage):
        calls.append((fraction, stage))
        if len(calls) == 1:
            set_state("running")
        if len(calls) == 2:  # hold the worker here until the host has typed Esc
            end = time.time() + 120
            while not host_said("esc") and time.time() < end:
                time.sleep(0.1)
            time.sleep(2.0)  # the main thread takes the key in the meantime
        return True

    addon.progress_hook = hold_until_esc
    result = invoke("simplify")
    check(result == {'RUNNING_MODAL'}, "simplify: invoke in the 3D view runs modal", str(result))
    ok = yield from wait(lambda: host_said("esc"), 300)
    check(ok, "the host typed Esc")
    yield from wait(lambda: not worker_alive(), 120)
    yield 1.0  # the modal's last timer event
    addon.progress_hook = None
    check(snapshot() == before, "Esc cancels and leaves the scene unchanged", "%s != %s" % (snapshot(), before))
    check(len(bpy.context.window_manager.operators) == n_ops, "a cancelled run is not registered")
    check(len(calls) >= 2 and calls[-1][0] < 1.0, "the run was stopped before its end",
          "progress reports %s" % calls[-3:])
    print("   progress reports before Esc took effect:", calls, flush=True)
    set_state("idle")
    yield from wait(lambda: host_said("shot"), 60)

    # --- finished runs add their result -----------------------------------------------------
    select(src)
    yield from run_to_end("simplify", "simplify")
    out = bpy.data.objects.get("sphere_vstree")
    check(out is not None and 0 < len(out.data.vertices) < len(src.data.vertices)
          and bpy.context.active_object == out,
          "simplify: the finished run adds sphere_vstree, fewer vertices, active",
          "objects %s" % [o.name for o in bpy.data.objects])
    if out is not None:
        print("   sphere %d -> %d vertices" % (len(src.data.vertices), len(out.data.vertices)), flush=True)
        out.location.x = -3.0

    cloud = sphere_cloud(3000)
    select(cloud)
    yield from run_to_end("reconstruct", "reconstruct", max_levels=3)
    surf = bpy.data.objects.get("cloud_surface")
    check(surf is not None and len(surf.data.polygons) > 200,
          "reconstruct: the finished run adds cloud_surface", "objects %s" % [o.name for o in bpy.data.objects])

    select(src)
    yield from run_to_end("show_clusters", "show_clusters")
    check("vstree_cluster" in src.data.color_attributes, "show_clusters: the finished run adds the colours")

    # --- the sidebar, for the screenshot ----------------------------------------------------
    if out is not None:
        select(out)
    space.shading.type = 'SOLID'
    try:
        space.shading.color_type = 'VERTEX'  # "Attribute" in the UI of 4.x
    except TypeError:
        space.shading.color_type = 'ATTRIBUTE'

    src.data.color_attributes.active_color = src.data.color_attributes["vstree_cluster"]
    with bpy.context.temp_override(**view3d()):
        bpy.ops.view3d.view_all()
    ui.active_panel_category = "VS-Tree"
    yield 2.0
    set_state("sidebar")
    yield from wait(lambda: host_said("shot-done"), 120)


_gen = None


def tick():
    global _gen
    try:
        if _gen is None:
            _gen = steps()
        return next(_gen)
    except StopIteration:
        pass
    except Exception as e:  # noqa: BLE001
        traceback.print_exc()
        record(False, "the GUI script", "%s: %s" % (type(e).__name__, e))
    set_state("done")
    sys.stdout.flush()
    os._exit(0)


bpy.app.timers.register(tick, first_interval=3.0, persistent=True)
