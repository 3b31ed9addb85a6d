# The "Skin with skinlab" add-on (integrations/blender/skinlab_skin) in Blender headless, for
# tests/blender/skin_addon_test.cpp:
#
#   blender -b --factory-startup --python-exit-code 1 --python skin_addon_check.py -- \
#       ADDON_DIR CHARACTER.obj CHARACTER_rig.txt PREDICTOR OUT_DIR
#
# Builds the character in Blender from OBJ + rig text (vertex k of the OBJ is Blender's vertex k;
# Y-up file coordinates become Blender's (x, -z, y); a bone per joint, its head at the joint),
# with the rig's weights as vertex groups and a group "mask" that is no bone. Installs the add-on
# from a zip as a user would (into BLENDER_USER_SCRIPTS) and runs the operator three times:
#   1. on mesh "replace", existing groups replaced: writes OUT_DIR/replace.txt;
#   2. on mesh "keep" after its groups of every other bone were removed, existing groups kept:
#      writes OUT_DIR/keep.txt;
#   3. with a model directory that does not exist: prints ERROR_MESSAGE and must leave mesh
#      "keep"'s groups as they were (UNCHANGED_AFTER_ERROR 1);
#   4. with the root bone and its one child made non-deform, so that the deform bones form
#      several trees: prints DEFORM_ERROR and UNCHANGED_AFTER_DEFORM_ERROR.
# A written file has a line "group <name> <vertex> <weight>" per membership, for the C++ test to
# compare with the predictor's own output. Also prints BONES, GROUPS (every vertex group of
# "replace", with or without members), KEPT (the groups "keep" had before the add-on ran) and
# REPORT lines.
import sys
import zipfile
from pathlib import Path

import addon_utils
import bpy


def read_character(obj_path, rig_path):
    vertices, faces, joints, parents, skin = [], [], {}, {}, {}
    for line in Path(obj_path).read_text().splitlines():
        w = line.split()
        if w and w[0] == "v":
            x, y, z = map(float, w[1:4])
            vertices.append((x, -z, y))
        elif w and w[0] == "f":
            faces.append([int(c.split("/")[0]) - 1 for c in w[1:]])
    for line in Path(rig_path).read_text().splitlines():
        w = line.split()
        if w and w[0] == "joints":
            x, y, z = map(float, w[2:5])
            joints[w[1]] = (x, -z, y)
        elif w and w[0] == "hier":
            parents[w[2]] = w[1]
        elif w and w[0] == "skin":
            skin[int(w[1])] = [(w[k], float(w[k + 1])) for k in range(2, len(w), 2)]
    return vertices, faces, joints, parents, skin


def build(vertices, faces, joints, parents, skin):
    data = bpy.data.armatures.new("rig")
    armature = bpy.data.objects.new("rig", data)
    bpy.context.scene.collection.objects.link(armature)
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.mode_set(mode="EDIT")
    span = max(max(c) - min(c) for c in zip(*vertices))
    for name, head in joints.items():
        bone = data.edit_bones.new(name)
        bone.head = head
        bone.tail = (head[0], head[1], head[2] + 0.05 * span)  # Blender drops zero-length bones
    for child, parent in parents.items():
        data.edit_bones[child].parent = data.edit_bones[parent]
    bpy.ops.object.mode_set(mode="OBJECT")
    meshes = {}
    for name in ("replace", "keep"):
        mesh = bpy.data.meshes.new(name)
        mesh.from_pydata(vertices, [], faces)
        obj = bpy.data.objects.new(name, mesh)
        bpy.context.scene.collection.objects.link(obj)
        for v, pairs in skin.items():
            for joint, weight in pairs:
                group = obj.vertex_groups.get(joint) or obj.vertex_groups.new(name=joint)
                group.add([v], weight, "REPLACE")
        obj.vertex_groups.new(name="mask").add(list(range(0, len(vertices), 7)), 0.5, "REPLACE")
        meshes[name] = obj
    return armature, meshes


def groups_of(obj):
    names = {g.index: g.name for g in obj.vertex_groups}
    return sorted((names[g.group], v.index, g.weight) for v in obj.data.vertices for g in v.groups)


def write_groups(obj, path):
    with open(path, "w") as f:
        f.writelines(f"group {name} {v} {w!r}\n" for name, v, w in groups_of(obj))


def skin(armature, obj, existing):
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    armature.select_set(True)
    bpy.context.view_layer.objects.active = armature
    return bpy.ops.object.skinlab_skin(existing=existing)


def main():
    addon_dir, obj_path, rig_path, predictor, out_dir = sys.argv[sys.argv.index("--") + 1:]
    out = Path(out_dir)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    archive = out / "skinlab_skin.zip"
    with zipfile.ZipFile(archive, "w") as z:
        for f in sorted((Path(addon_dir) / "skinlab_skin").glob("*.py")):
            z.write(f, f"skinlab_skin/{f.name}")
    bpy.ops.preferences.addon_install(filepath=str(archive))
    addon_utils.enable("skinlab_skin", default_set=True)
    prefs = bpy.context.preferences.addons["skinlab_skin"].preferences
    prefs.predictor = predictor

    armature, meshes = build(*read_character(obj_path, rig_path))
    print("BONES", len(armature.data.bones))
    print("REPORT", skin(armature, meshes["replace"], "REPLACE"))
    write_groups(meshes["replace"], out / "replace.txt")
    print("GROUPS", " ".join(sorted(g.name for g in meshes["replace"].vertex_groups)))

    keep = meshes["keep"]
    for bone in list(armature.data.bones)[::2]:
        if keep.vertex_groups.get(bone.name) is not None:
            keep.vertex_groups.remove(keep.vertex_groups[bone.name])
    print("KEPT", " ".join(g.name for g in keep.vertex_groups if g.name != "mask"))
    print("REPORT", skin(armature, keep, "KEEP"))
    write_groups(keep, out / "keep.txt")

    before = groups_of(keep)
    prefs.model = str(out / "no_such_model")
    try:
        skin(armature, keep, "REPLACE")
        print("ERROR_MESSAGE none: the operator succeeded")
    except RuntimeError as e:  # an operator's ERROR report reaches Python as RuntimeError
        print("ERROR_MESSAGE", str(e).replace("\n", " "))
    print("UNCHANGED_AFTER_ERROR", int(groups_of(keep) == before))

    prefs.model = ""
    root = next(b for b in armature.data.bones if b.parent is None)
    root.use_deform = False  # the root, and its one child: the rest falls apart in trees
    root.children[0].use_deform = False
    try:
        skin(armature, keep, "REPLACE")
        print("DEFORM_ERROR none: the operator succeeded")
    except RuntimeError as e:
        print("DEFORM_ERROR", str(e).replace("\n", " "))
    print("UNCHANGED_AFTER_DEFORM_ERROR", int(groups_of(keep) == before))


main()
