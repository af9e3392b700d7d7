# SPDX-License-Identifier: Apache-2.0
"""Sweepers in Blender: level sets (.vdb), films of them and stroke scripts imported as
meshes, through the `sweepers` Python module (docs/blender.md).

Blender's own Volume to Mesh reads a level set at a threshold of 0.1 (more than the whole
band of a fine grid) and half a voxel off; this add-on meshes the zero level exactly as
`sweepers-cli mesh --up z` does, turned so that the modeler's up (y) is Blender's (z)."""

import os
import re

import bpy
from bpy.app.handlers import persistent
from bpy.props import BoolProperty, FloatProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

bl_info = {
    "name": "Sweepers",
    "author": "Sweepers developers",
    "version": (0, 2, 0),
    "blender": (3, 4, 0),
    "location": "File > Import > Sweepers level set / Sweepers stroke script",
    "description": "Import Sweepers level sets, films and stroke scripts as meshes",
    "category": "Import-Export",
}

# Custom properties an imported object keeps: where it came from, and for a film its frames.
SCRIPT, VOXEL_SIZE, FRAMES, FIRST_FRAME = ("sweepers_script", "sweepers_voxel_size",
                                          "sweepers_frames", "sweepers_first_frame")


class SweepersError(Exception):
    """A reason the import cannot go on, in the user's words: reported, nothing changed."""


def _module():
    try:
        import numpy  # noqa: F401 (the module hands its meshes over as numpy arrays)
    except ImportError:
        raise SweepersError("Sweepers needs numpy in Blender's Python "
                            "(Debian: apt install python3-numpy)") from None
    try:
        import sweepers
    except ImportError as e:
        raise SweepersError("the Python module 'sweepers' cannot be imported into Blender's "
                            f"Python ({e}); install python3-sweepers (Debian) or put the "
                            "module on Blender's path") from None
    return sweepers


def _surface(make):
    """The (vertices, triangles) of what make(sweepers) returns, z up; Sweepers' errors (a
    file it cannot read, a script it refuses) as SweepersError."""
    sweepers = _module()
    try:
        vertices, triangles = make(sweepers).mesh()
    except (OSError, ValueError, RuntimeError) as e:
        raise SweepersError(str(e)) from None
    # The modeler's y up is Blender's z up: (x, y, z) -> (x, -z, y), a rotation, as
    # `sweepers-cli mesh --up z` turns it.
    turned = vertices[:, [0, 2, 1]].copy()
    turned[:, 1] *= -1.0
    return turned, triangles


def _mesh(name, vertices, triangles):
    """A Blender mesh of the triangles, smooth shaded."""
    import numpy as np
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(vertices))
    mesh.vertices.foreach_set("co", vertices.astype(np.float32).ravel())
    count = len(triangles)
    mesh.loops.add(3 * count)
    mesh.loops.foreach_set("vertex_index", triangles.astype(np.int32).ravel())
    mesh.polygons.add(count)
    mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * count, 3, dtype=np.int32))
    mesh.polygons.foreach_set("loop_total", np.full(count, 3, dtype=np.int32))
    mesh.polygons.foreach_set("use_smooth", np.ones(count, dtype=bool))
    mesh.update(calc_edges=True)
    return mesh


def _object(context, name, mesh):
    obj = bpy.data.objects.new(name, mesh)
    context.collection.objects.link(obj)
    for other in context.selected_objects:
        other.select_set(False)
    obj.select_set(True)
    context.view_layer.objects.active = obj
    return obj


def film_frames(path):
    """The numbered files of the film `path` belongs to (NAME_0001.vdb, NAME_0002.vdb, ...:
    the last run of digits in its name), as (frame, path) in frame order; [] when its name
    holds no number."""
    folder, name = os.path.split(path)
    match = re.match(r"^(.*?)(\d+)(\D*)$", name)
    if not match:
        return []
    head, digits, tail = match.groups()
    pattern = re.compile("^" + re.escape(head) + r"(\d+)" + re.escape(tail) + "$")
    frames = []
    for other in os.listdir(folder or "."):
        found = pattern.match(other)
        if found:
            frames.append((int(found.group(1)), os.path.join(folder, other)))
    return sorted(frames)


@persistent
def show_film_frame(scene, *_):
    """Each imported film shows the mesh of the scene's frame (the nearest one it has)."""
    for obj in scene.objects:
        names = obj.get(FRAMES)
        if not names:
            continue
        index = min(max(scene.frame_current - int(obj.get(FIRST_FRAME, 1)), 0), len(names) - 1)
        mesh = bpy.data.meshes.get(names[index])
        if mesh is not None and obj.data != mesh:
            obj.data = mesh


def _imported(operator, make):
    """An import operator's ending: the object made, or the reason in one line."""
    try:
        obj = make()
    except SweepersError as e:
        operator.report({"ERROR"}, f"Sweepers: {e}")
        return {"CANCELLED"}
    operator.report({"INFO"}, f"Sweepers: imported {obj.name}")
    return {"FINISHED"}


class IMPORT_MESH_OT_sweepers_vdb(bpy.types.Operator, ImportHelper):
    """Import a Sweepers level set (.vdb) as a mesh of its zero level, or a film of them"""
    bl_idname = "import_mesh.sweepers_vdb"
    bl_label = "Import Sweepers level set"
    bl_options = {"REGISTER", "UNDO"}
    filename_ext = ".vdb"
    filter_glob: StringProperty(default="*.vdb", options={"HIDDEN"})
    sequence: BoolProperty(
        name="Film (numbered sequence)",
        description="Import every numbered file of the film (as `sweepers-cli animate` "
        "writes it) as one object whose mesh follows the frame",
        default=False)

    def execute(self, context):
        return _imported(self, lambda: (import_film if self.sequence else import_level_set)(
            context, self.filepath))


def import_level_set(context, path):
    """A .vdb's level set as a mesh object named after the file."""
    if not os.path.isfile(path):
        raise SweepersError(f"{path}: no such file")
    name = os.path.splitext(os.path.basename(path))[0]
    vertices, triangles = _surface(lambda s: s.Sculptor(start=path))
    return _object(context, name, _mesh(name, vertices, triangles))


def import_film(context, path):
    """Every frame of the film `path` belongs to, as one object whose mesh follows the
    scene's frame; the scene's frame range set to the film's."""
    frames = film_frames(path)
    if not frames:
        raise SweepersError(f"{path}: its name holds no frame number (NAME_0001.vdb)")
    # Every frame is read before anything is added: a damaged frame changes nothing.
    surfaces = [(n, _surface(lambda s, p=p: s.Sculptor(start=p))) for n, p in frames]
    stem = re.sub(r"[_.-]*\d+$", "", os.path.splitext(os.path.basename(path))[0]) or "film"
    meshes = [_mesh(f"{stem}_{n:04d}", v, t) for n, (v, t) in surfaces]
    obj = _object(context, stem, meshes[0])
    obj[FRAMES] = [m.name for m in meshes]
    obj[FIRST_FRAME] = frames[0][0]
    context.scene.frame_start, context.scene.frame_end = frames[0][0], frames[-1][0]
    show_film_frame(context.scene)
    return obj


class IMPORT_MESH_OT_sweepers_script(bpy.types.Operator, ImportHelper):
    """Apply a Sweepers stroke script (.json) at a voxel size and import its surface"""
    bl_idname = "import_mesh.sweepers_script"
    bl_label = "Import Sweepers stroke script"
    bl_options = {"REGISTER", "UNDO"}
    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={"HIDDEN"})
    voxel_size: FloatProperty(
        name="Voxel size",
        description="The grid's voxel size (0: the script's own); finer takes longer",
        default=0.0, min=0.0, soft_max=0.1, precision=4)

    def execute(self, context):
        return _imported(self, lambda: import_script(context, self.filepath, self.voxel_size))


def _applied(path, voxel_size):
    # Blender keeps a FloatProperty in single precision: 0.05 typed is 0.0500000007, a grid
    # an ulp off the one `sweepers-cli apply --voxel-size 0.05` makes. The size as typed.
    voxel_size = float(f"{voxel_size:.7g}")
    if not os.path.isfile(path):
        raise SweepersError(f"{path}: no such file")
    shape = []

    def apply(sweepers):
        shape.append(sweepers.apply(path, voxel_size=voxel_size or None))
        return shape[0]
    vertices, triangles = _surface(apply)
    return vertices, triangles, shape[0].voxel_size


def import_script(context, path, voxel_size=0.0):
    """The surface of a stroke script applied at `voxel_size` (0: its own), as an object
    that keeps the script's path and voxel size for re-applying."""
    vertices, triangles, size = _applied(path, voxel_size)
    name = os.path.splitext(os.path.basename(path))[0]
    obj = _object(context, name, _mesh(name, vertices, triangles))
    obj[SCRIPT] = os.path.abspath(path)
    obj[VOXEL_SIZE] = size
    obj.sweepers_voxel_size = size
    return obj


class OBJECT_OT_sweepers_reapply(bpy.types.Operator):
    """Apply the object's stroke script again at the voxel size in the panel"""
    bl_idname = "object.sweepers_reapply"
    bl_label = "Re-apply at voxel size"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.object is not None and SCRIPT in context.object

    def execute(self, context):
        obj = context.object
        try:
            vertices, triangles, size = _applied(obj[SCRIPT], obj.sweepers_voxel_size)
        except SweepersError as e:
            self.report({"ERROR"}, f"Sweepers: {e}")
            return {"CANCELLED"}
        old = obj.data
        obj.data = _mesh(old.name, vertices, triangles)
        if old.users == 0:
            bpy.data.meshes.remove(old)
        obj[VOXEL_SIZE] = size
        self.report({"INFO"}, f"Sweepers: {obj.name} at voxel size {size:g}")
        return {"FINISHED"}


class OBJECT_PT_sweepers(bpy.types.Panel):
    """Where an object made from a stroke script came from, and its voxel size"""
    bl_label = "Sweepers"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        return context.object is not None and SCRIPT in context.object

    def draw(self, context):
        obj = context.object
        self.layout.label(text=os.path.basename(obj[SCRIPT]))
        self.layout.label(text=f"made at voxel size {obj[VOXEL_SIZE]:g}")
        self.layout.prop(obj, "sweepers_voxel_size")
        self.layout.operator(OBJECT_OT_sweepers_reapply.bl_idname)


def _menu_level_set(self, context):
    self.layout.operator(IMPORT_MESH_OT_sweepers_vdb.bl_idname,
                         text="Sweepers level set (.vdb)")


def _menu_script(self, context):
    self.layout.operator(IMPORT_MESH_OT_sweepers_script.bl_idname,
                         text="Sweepers stroke script (.json)")


CLASSES = (IMPORT_MESH_OT_sweepers_vdb, IMPORT_MESH_OT_sweepers_script,
           OBJECT_OT_sweepers_reapply, OBJECT_PT_sweepers)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Object.sweepers_voxel_size = FloatProperty(
        name="Voxel size", description="The voxel size Re-apply sculpts the script at",
        default=0.02, min=1e-4, soft_max=0.1, precision=4)
    bpy.types.TOPBAR_MT_file_import.append(_menu_level_set)
    bpy.types.TOPBAR_MT_file_import.append(_menu_script)
    if show_film_frame not in bpy.app.handlers.frame_change_post:
        bpy.app.handlers.frame_change_post.append(show_film_frame)


def unregister():
    if show_film_frame in bpy.app.handlers.frame_change_post:
        bpy.app.handlers.frame_change_post.remove(show_film_frame)
    bpy.types.TOPBAR_MT_file_import.remove(_menu_script)
    bpy.types.TOPBAR_MT_file_import.remove(_menu_level_set)
    del bpy.types.Object.sweepers_voxel_size
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
