"""Blender 3.4's Laplacian Smooth modifier (seed 004's own implementation), timed headless.
usage: blender -b --factory-startup --python bench/smooth_blender.py -- MESH.obj SCALE [ITERATIONS]
Prints `mesh<TAB>V=n<TAB>laplacian_smooth_modifier(scale=S)<TAB>blender<TAB>ms<TAB>max displacement`.
Modifier defaults (as a user gets them): lambda 0.01, border 0.01, normalized, preserve volume, X/Y/Z.
"""
import sys, time
import bpy
from array import array
import math

args = sys.argv[sys.argv.index("--") + 1:]
path, scale = args[0], float(args[1])
iterations = int(args[2]) if len(args) > 2 else 1
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.wm.obj_import(filepath=path)
obj = bpy.context.selected_objects[0]
bpy.context.view_layer.objects.active = obj
me = obj.data
n = len(me.vertices)
co = array('f', [0.0]) * (3 * n)
me.vertices.foreach_get("co", co)
co = array('f', (c * scale for c in co))
me.vertices.foreach_set("co", co)
me.update()
mod = obj.modifiers.new("smooth", 'LAPLACIANSMOOTH')
mod.iterations = iterations
t = time.perf_counter()
bpy.ops.object.modifier_apply(modifier=mod.name)
dt = time.perf_counter() - t
after = array('f', [0.0]) * (3 * n)
obj.data.vertices.foreach_get("co", after)
moved = [math.dist(after[3 * i:3 * i + 3], co[3 * i:3 * i + 3]) for i in range(n)]
name = path.split('/')[-1]
print(f"{name}\tV={n}\tlaplacian_smooth_modifier(scale={scale:g},iterations={iterations})\tblender\t{dt * 1000:.1f} ms"
      f"\tmax displacement {max(moved) / scale:.3g} (input units), vertices moved {sum(1 for d in moved if d > 0)}", flush=True)
