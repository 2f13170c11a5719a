# Writes blender-scene.glb / blender-scene.gltf and blender-scene.expected.json with Blender's own
# numbers, for core/tests/gltf_peers.rs. Run from this folder:
#   PYTHONPATH=<a folder holding numpy> blender -b --factory-startup --python make_blender.py
# (Blender 3.4.1 from Debian; its glTF exporter imports numpy, e.g. from the peers venv.)
# The scene: a cube under a rotated, non-uniformly scaled empty; an icosphere with two materials
# (→ two primitives); a plane mirrored in x (negative determinant).
import bpy, json, os

here = os.path.dirname(os.path.abspath(__file__))
for o in list(bpy.data.objects):
    if o.type != 'MESH':
        bpy.data.objects.remove(o)
cube = bpy.data.objects['Cube']
bpy.ops.object.empty_add(location=(1, 2, 3))
parent = bpy.context.object
parent.name = 'Parent'
parent.rotation_euler = (0.3, 0.2, 0.1)
parent.scale = (2, 1, 0.5)
cube.parent = parent
cube.location = (0.5, 0, 0)
cube.rotation_euler = (0, 0, 0.7)

bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=1, radius=0.5, location=(-3, 0, 0))
ico = bpy.context.object
ico.name = 'Ico'
for name in ('A', 'B'):
    ico.data.materials.append(bpy.data.materials.new(name))
for i, p in enumerate(ico.data.polygons):
    p.material_index = i % 2

bpy.ops.mesh.primitive_plane_add(size=1, location=(0, -4, 0))
plane = bpy.context.object
plane.name = 'Mirrored'
plane.scale = (-1, 1, 1)
bpy.context.view_layer.update()


def yup(v):  # Blender Z-up → glTF Y-up, as the exporter does
    return [v.x, v.z, -v.y]


groups = {}
points = []
for o in (cube, ico, plane):
    me, mw = o.data, o.matrix_world
    nm = mw.to_3x3().inverted().transposed()
    tris, area, vol, nsum = 0, 0.0, 0.0, [0.0, 0.0, 0.0]
    for p in me.polygons:
        vs = [mw @ me.vertices[i].co for i in p.vertices]
        n = (nm @ p.normal).normalized()
        for k in range(1, len(vs) - 1):
            a, b, c = vs[0], vs[k], vs[k + 1]
            tri_area = (b - a).cross(c - a).length / 2
            tris += 1
            area += tri_area
            # signed volume with the face oriented by its world normal (Blender's notion of outside)
            cr = (b - a).cross(c - a)
            sign = 1.0 if cr.dot(n) >= 0 else -1.0
            vol += sign * a.dot(b.cross(c)) / 6
            for j in range(3):
                nsum[j] += yup(n)[j] * tri_area
    points += [yup(mw @ v.co) for v in me.vertices]
    groups[me.name] = {'triangles': tris, 'area': area, 'volume': vol, 'normal_area_sum': nsum}

bpy.ops.export_scene.gltf(filepath=os.path.join(here, 'blender-scene.glb'), export_format='GLB', export_yup=True)
bpy.ops.export_scene.gltf(filepath=os.path.join(here, 'blender-scene.gltf'), export_format='GLTF_EMBEDDED', export_yup=True)
with open(os.path.join(here, 'blender-scene.expected.json'), 'w') as f:
    json.dump({'objects': groups, 'points': points}, f, indent=1)
