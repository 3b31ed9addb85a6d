# Blender's own "automatic weights" (Object ▸ Parent ▸ With Automatic Weights, i.e. bone heat,
# Baran & Popović 2007) on a skinned glTF, headless:
#
#   blender -b --factory-startup --python scripts/blender_auto_weights.py -- \
#       hero.glb hero_artist_rig.txt hero_blender_rig.txt [all|weighted] [merge]
#
# Imports the glTF with Blender's defaults, writes the weights as imported (the artist's, a check
# that vertex order and joint names survive the trip), removes them and the armature binding,
# parents the mesh to the armature with automatic weights, and writes those. With `all` (the
# default, what a user gets on import) every joint is a deform bone; game skeletons carry prop,
# attachment and IK-helper joints (0 A.D.'s weapon_bow, quiver_R, elbow_L under the hip...), and
# Blender gives them weight. With `weighted` only the joints the artist weighted stay deform bones,
# as an artist would set up the rig by hand. With `merge`, the mesh is first merged by distance
# (Mesh ▸ Clean Up ▸ Merge by Distance at Blender's default 0.0001), as a user does when automatic
# weights report "failed to find solution": a glTF splits vertices at every UV seam and normal
# crease, and bone heat gives up on such a mesh of unconnected pieces (every vertex of
# Quaternius' Bull). Each original vertex then takes the weights of the merged vertex it became.
# Both files are
# RigNet rig text in the glTF's frame (Y up); vertices Blender leaves without weight get no
# `skin` line (`skinlab score --allow-unweighted` reads that). Prints IMPORT_S, SOLVE_S (the
# parent_set call alone), VERTICES, SPACED_JOINTS, MERGED_VERTICES (with merge) and UNWEIGHTED
# lines for scripts/compare_blender.
#
# Blender 3.4's glTF importer still uses numpy.bool, which numpy 1.24 (Debian 12) removed.
import numpy

if not hasattr(numpy, "bool"):
    numpy.bool = bool

import sys
import time

import bmesh
import bpy
import mathutils.kdtree

MERGE_DISTANCE = 1e-4  # Blender's default for Merge by Distance


def vertex_weights(mesh):
    """Each vertex's (joint name, weight) pairs with weight > 0."""
    groups = {g.index: g.name for g in mesh.vertex_groups}
    return [[(groups[g.group], g.weight) for g in v.groups if g.weight > 0]
            for v in mesh.data.vertices]


def write_rig(path, armature, per_vertex):
    """Joints are bone heads; Blender's Z-up world (x, y, z) is glTF's (x, z, −y)."""
    bones = armature.data.bones
    unweighted = 0
    with open(path, "w") as f:
        for b in bones:
            h = armature.matrix_world @ b.head_local
            f.write(f"joints {b.name} {h.x:.6f} {h.z:.6f} {-h.y:.6f}\n")
        roots = [b for b in bones if b.parent is None]
        f.write(f"root {roots[0].name}\n")
        for b in bones:
            if b.parent is not None:
                f.write(f"hier {b.parent.name} {b.name}\n")
        for index, weights in enumerate(per_vertex):
            if not weights:
                unweighted += 1
                continue
            total = sum(w for _, w in weights)
            pairs = " ".join(f"{name} {w / total:.7f}" for name, w in weights)
            f.write(f"skin {index} {pairs}\n")
    return unweighted


def main():
    args = sys.argv[sys.argv.index("--") + 1:]
    source, artist_out, auto_out = args[:3]
    deform = args[3] if len(args) > 3 else "all"
    if deform not in ("all", "weighted"):
        raise SystemExit(f"unknown deform set '{deform}': choose all or weighted")
    merge = len(args) > 4 and args[4] == "merge"
    if len(args) > 4 and not merge:
        raise SystemExit(f"unknown option '{args[4]}': the fifth argument can only be merge")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    start = time.perf_counter()
    bpy.ops.import_scene.gltf(filepath=source)
    print(f"IMPORT_S {time.perf_counter() - start:.4f}")
    armature = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    meshes = [o for o in bpy.data.objects if o.type == "MESH"]
    if len(meshes) != 1:
        raise SystemExit(f"{source}: {len(meshes)} meshes; expected one")
    mesh = meshes[0]
    print(f"VERTICES {len(mesh.data.vertices)}")
    # RigNet rig text separates fields by whitespace, so a joint named "Body Dorsal" (OpenClonk's
    # shark) cannot be written: say how many there are and write nothing.
    spaced = [b.name for b in armature.data.bones if any(c.isspace() for c in b.name)]
    print(f"SPACED_JOINTS {len(spaced)}")
    if spaced:
        return
    write_rig(artist_out, armature, vertex_weights(mesh))

    if deform == "weighted":
        weighted = {mesh.vertex_groups[g.group].name
                    for v in mesh.data.vertices for g in v.groups if g.weight > 0}
        for b in armature.data.bones:
            b.use_deform = b.name in weighted
        print(f"DEFORM_BONES {len(weighted)} of {len(armature.data.bones)}")
    mesh.vertex_groups.clear()
    for modifier in [m for m in mesh.modifiers if m.type == "ARMATURE"]:
        mesh.modifiers.remove(modifier)
    original = [v.co.copy() for v in mesh.data.vertices]
    if merge:
        bm = bmesh.new()
        bm.from_mesh(mesh.data)
        bmesh.ops.remove_doubles(bm, verts=bm.verts, dist=MERGE_DISTANCE)
        bm.to_mesh(mesh.data)
        bm.free()
        print(f"MERGED_VERTICES {len(mesh.data.vertices)}")
    world = mesh.matrix_world.copy()
    mesh.parent = None
    mesh.matrix_world = world
    bpy.ops.object.select_all(action="DESELECT")
    mesh.select_set(True)
    armature.select_set(True)
    bpy.context.view_layer.objects.active = armature
    start = time.perf_counter()
    bpy.ops.object.parent_set(type="ARMATURE_AUTO")
    print(f"SOLVE_S {time.perf_counter() - start:.4f}")
    weights = vertex_weights(mesh)
    if merge:
        # remove_doubles keeps one of each group of vertices within MERGE_DISTANCE where they
        # were: the nearest merged vertex of an original one is the one it became.
        tree = mathutils.kdtree.KDTree(len(mesh.data.vertices))
        for v in mesh.data.vertices:
            tree.insert(v.co, v.index)
        tree.balance()
        weights = [weights[tree.find(co)[1]] for co in original]
    print(f"UNWEIGHTED {write_rig(auto_out, armature, weights)}")


main()
