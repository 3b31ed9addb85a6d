"""Skin with skinlab: bone weights for the selected mesh(es) from skinlab's learned predictor,
written back as vertex groups. See integrations/blender/README.md."""

bl_info = {
    "name": "skinlab: learned skin weights",
    "author": "skinlab",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "3D Viewport > Object / Pose context menu > Skin with skinlab",
    "description": "Predicts bone weights for a mesh and its armature with skinlab and writes "
                   "them as vertex groups",
    "category": "Rigging",
}

import array
import os
import shutil
import tempfile
import time

import bpy

from . import exchange
from .exchange import PredictorError


class SkinlabPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    predictor: bpy.props.StringProperty(
        name="Predictor",
        description="The predictor program: skinlab (run as 'skinlab predict') or "
                    "skinlab-predict. Empty: skinlab-predict on PATH, else skinlab",
        subtype="FILE_PATH")
    model: bpy.props.StringProperty(
        name="Model",
        description="Model directory (a bundled model or a training run). Empty: the "
                    "predictor's own default, the model installed with it",
        subtype="DIR_PATH")
    keep_files: bpy.props.BoolProperty(
        name="Keep exchange files",
        description="Keep the OBJ, rig text and predicted weights in a temporary directory and "
                    "name it in the report (for bug reports)",
        default=False)

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "predictor")
        layout.prop(self, "model")
        layout.prop(self, "keep_files")


def _world_positions(matrix, flat):
    """Points (x, y, z triples in `flat`) through the 4x4 `matrix`, in double precision, then
    from Blender's Z-up frame to the Y-up one the model was trained in: (x, z, -y), as glTF."""
    m = [list(row) for row in matrix]
    identity = all(m[r][c] == (1.0 if r == c else 0.0) for r in range(4) for c in range(4))
    out = []
    for k in range(0, len(flat), 3):
        x, y, z = flat[k], flat[k + 1], flat[k + 2]
        if not identity:
            x, y, z = (m[r][0] * x + m[r][1] * y + m[r][2] * z + m[r][3] for r in range(3))
        out.append((x, z, -y))
    return out


class Skeleton:
    """The bones sent to the predictor: deform bones only (or all), each parented to its nearest
    sent ancestor; a joint is a bone's head (what glTF and the training data call a joint)."""

    def __init__(self, armature, deform_only):
        bones = [b for b in armature.data.bones if b.use_deform or not deform_only]
        if not bones:
            raise PredictorError(f"armature '{armature.name}' has no "
                                 f"{'deform ' if deform_only else ''}bones")
        index = {b.name: j for j, b in enumerate(bones)}
        self.names = [b.name for b in bones]
        self.parents = []
        for b in bones:
            parent = b.parent
            while parent is not None and parent.name not in index:
                parent = parent.parent
            self.parents.append(-1 if parent is None else index[parent.name])
        roots = [self.names[j] for j, p in enumerate(self.parents) if p < 0]
        if len(roots) > 1:
            raise PredictorError(
                f"armature '{armature.name}': the {'deform ' if deform_only else ''}bones form "
                f"{len(roots)} trees (roots {', '.join(roots[:5])}); skinlab needs one root"
                + (" (turn off 'Deform bones only', or make a common parent a deform bone)"
                   if deform_only else ""))
        heads = []
        for b in bones:
            heads.extend(b.head_local)
        self.positions = _world_positions(armature.matrix_world, heads)
        self.rig_names = exchange.rig_names(self.names)


def _mesh_geometry(obj):
    """The mesh's own vertices (no modifiers or shape keys: vertex groups belong to these) in
    world space, Y up, and its triangles, both in Blender's vertex order."""
    mesh = obj.data
    flat = array.array("f", [0.0]) * (3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", flat)
    mesh.calc_loop_triangles()
    corners = array.array("i", [0]) * (3 * len(mesh.loop_triangles))
    mesh.loop_triangles.foreach_get("vertices", corners)
    triangles = [tuple(corners[k:k + 3]) for k in range(0, len(corners), 3)]
    if not triangles:
        raise PredictorError(f"mesh '{obj.name}' has no faces")
    return _world_positions(obj.matrix_world, flat), triangles


def _predict(obj, skeleton, prefs, program, stem):
    """Writes `obj` and the skeleton, runs the predictor and reads its weights: per vertex a
    list of (bone index, weight). `stem` is the exchange files' path without extension. Raises
    PredictorError naming the mesh."""
    positions, triangles = _mesh_geometry(obj)
    obj_path, rig_path, out_path = stem + ".obj", stem + "_rig.txt", stem + "_skinned_rig.txt"
    exchange.write_obj(obj_path, positions, triangles)
    exchange.write_rig(rig_path, skeleton.rig_names, skeleton.positions, skeleton.parents)
    model = bpy.path.abspath(prefs.model) if prefs.model else ""
    try:
        exchange.run_predictor(
            exchange.predictor_command(program, obj_path, rig_path, out_path, model))
        return exchange.read_weights(out_path, len(positions), skeleton.rig_names)
    except PredictorError as e:
        raise PredictorError(f"mesh '{obj.name}': {e}") from None


def _apply(obj, names, weights, existing):
    """Vertex groups from the predicted weights. REPLACE: a group named after a sent bone is
    removed first; KEEP: such a group stays as it is and that bone's weights are not written.
    Groups not named after a sent bone are never touched. Returns the number of groups written."""
    groups = obj.vertex_groups
    targets = []
    for name in names:
        group = groups.get(name)
        if group is not None and existing == "REPLACE":
            groups.remove(group)
            group = None
        targets.append(groups.new(name=name) if group is None else None)
    for vertex, pairs in enumerate(weights):
        for j, weight in pairs:
            if targets[j] is not None:
                targets[j].add([vertex], weight, "REPLACE")
    return sum(t is not None for t in targets)


def _armature_of(context, meshes):
    chosen = {o for o in context.selected_objects if o.type == "ARMATURE"}
    active = context.active_object
    if active is not None and active.type == "ARMATURE":
        chosen.add(active)
    if not chosen:  # the armature the meshes are bound to
        for mesh in meshes:
            chosen |= {m.object for m in mesh.modifiers if m.type == "ARMATURE" and m.object}
            if mesh.parent is not None and mesh.parent.type == "ARMATURE":
                chosen.add(mesh.parent)
    if len(chosen) != 1:
        raise PredictorError(
            "select one armature with the mesh" if not chosen else
            f"{len(chosen)} armatures ({', '.join(sorted(a.name for a in chosen))}); select one")
    return chosen.pop()


class SKINLAB_OT_skin(bpy.types.Operator):
    """Predict bone weights for the selected mesh(es) and the armature with skinlab, and write
    them as vertex groups"""

    bl_idname = "object.skinlab_skin"
    bl_label = "Skin with skinlab"
    bl_options = {"REGISTER", "UNDO"}

    existing: bpy.props.EnumProperty(
        name="Existing groups",
        items=[("REPLACE", "Replace", "Replace the vertex groups named after the armature's bones "
                                      "(other groups stay)"),
               ("KEEP", "Keep", "Keep every existing vertex group; only bones without one get "
                                "the predicted weights")],
        default="REPLACE")
    deform_only: bpy.props.BoolProperty(
        name="Deform bones only",
        description="Send only the armature's deform bones to the predictor (a bone's parent is "
                    "its nearest deform ancestor)",
        default=True)
    bind: bpy.props.BoolProperty(
        name="Add Armature modifier",
        description="Add an Armature modifier for the armature to a mesh that has none",
        default=True)

    @classmethod
    def poll(cls, context):
        return context.mode in {"OBJECT", "POSE"} and any(
            o.type == "MESH" for o in context.selected_objects)

    def execute(self, context):
        start = time.perf_counter()
        prefs = context.preferences.addons[__package__].preferences
        meshes = [o for o in context.selected_objects if o.type == "MESH"]
        workdir = tempfile.mkdtemp(prefix="skinlab-blender-")
        if context.window is not None:
            context.window.cursor_set("WAIT")
        try:
            armature = _armature_of(context, meshes)
            skeleton = Skeleton(armature, self.deform_only)
            program = exchange.find_predictor(
                bpy.path.abspath(prefs.predictor) if prefs.predictor else "",
                bpy.path.abspath(prefs.model) if prefs.model else "")
            # Every mesh is predicted and read back before any is changed.
            predicted = [(obj, _predict(obj, skeleton, prefs, program,
                                        os.path.join(workdir, f"mesh{k}")))
                         for k, obj in enumerate(meshes)]
        except (PredictorError, OSError) as e:
            self.report({"ERROR"}, f"Skin with skinlab: {e}")
            return {"CANCELLED"}
        finally:
            if context.window is not None:
                context.window.cursor_set("DEFAULT")
            if not prefs.keep_files:
                shutil.rmtree(workdir, ignore_errors=True)
        written = 0
        for obj, weights in predicted:
            written += _apply(obj, skeleton.names, weights, self.existing)
            if self.bind and not any(m.type == "ARMATURE" and m.object == armature
                                     for m in obj.modifiers):
                obj.modifiers.new(name=armature.name, type="ARMATURE").object = armature
        kept = f"; files kept in {workdir}" if prefs.keep_files else ""
        self.report({"INFO"}, f"Skin with skinlab: {len(predicted)} mesh(es), {written} vertex "
                              f"groups from {len(skeleton.names)} bones of '{armature.name}' in "
                              f"{time.perf_counter() - start:.1f} s{kept}")
        return {"FINISHED"}


def _menu(self, context):
    self.layout.separator()
    self.layout.operator(SKINLAB_OT_skin.bl_idname)


_MENUS = (bpy.types.VIEW3D_MT_object_context_menu, bpy.types.VIEW3D_MT_pose_context_menu)


def register():
    bpy.utils.register_class(SkinlabPreferences)
    bpy.utils.register_class(SKINLAB_OT_skin)
    for menu in _MENUS:
        menu.append(_menu)


def unregister():
    for menu in _MENUS:
        menu.remove(_menu)
    bpy.utils.unregister_class(SKINLAB_OT_skin)
    bpy.utils.unregister_class(SkinlabPreferences)
