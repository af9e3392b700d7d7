# SPDX-License-Identifier: Apache-2.0
"""Run inside Blender (blender -b --factory-startup --python check_addon.py -- ZIP MODULE
WORK TESTS): the add-on installed from its zip and enabled as a user does, then a level set,
a three-frame film and a stroke script imported and compared with what sweepers-cli wrote
into WORK (PLY meshes, z up), the re-apply button, and the refusals."""
import os
import sys

import bpy
import numpy as np

zip_path, module_dir, work, tests_dir = sys.argv[sys.argv.index("--") + 1:]
sys.path.insert(0, module_dir)  # the module of the build tree (installed: dist-packages)
sys.path.insert(0, tests_dir)
from ply import read_ply  # noqa: E402 (the tests' own PLY reader)

bpy.ops.preferences.addon_install(filepath=zip_path)
bpy.ops.preferences.addon_enable(module="sweepers_blender")
scene = bpy.context.scene
for obj in list(scene.objects):  # the factory scene's cube, camera and light
    bpy.data.objects.remove(obj)


def arrays(mesh):
    co = np.empty(3 * len(mesh.vertices), dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    loops = np.empty(3 * len(mesh.polygons), dtype=np.int32)
    mesh.polygons.foreach_get("vertices", loops)
    return co.reshape(-1, 3).astype(float), loops.reshape(-1, 3)


def volume(v, t):
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def same_as_ply(mesh, ply, h, what):
    """The mesh is the PLY's: vertex counts, enclosed volume within 0.5%, every vertex
    within a tenth of a voxel (no half-voxel shift), outward facing as ours."""
    v, t = arrays(mesh)
    pv, pt = read_ply(ply)
    pv, pt = np.array(pv, dtype=float), np.array(pt)
    assert len(v) == len(pv) and len(t) == len(pt), (what, len(v), len(pv), len(t), len(pt))
    ours, theirs = volume(v, t), volume(pv, pt)
    assert theirs > 0 and abs(ours - theirs) <= 0.005 * theirs, (what, ours, theirs)
    shift = float(np.abs(v - pv).max())
    # Within a tenth of a voxel, and in fact the same vertices: the same grid meshed the
    # same way.
    assert shift <= 0.1 * h and shift == 0.0, (what, shift, h)
    assert all(p.use_smooth for p in mesh.polygons), what
    print(f"{what}: {len(v)} vertices, volume {ours:.6f} (ours {theirs:.6f}), "
          f"largest vertex difference {shift:.2e} ({shift / h:.2e} voxel)")


h = 0.05
# --- a level set -----------------------------------------------------------------------
assert bpy.ops.import_mesh.sweepers_vdb(filepath=os.path.join(work, "horn.vdb")) == {"FINISHED"}
horn = bpy.context.object
assert horn.name == "horn" and horn.type == "MESH", horn
same_as_ply(horn.data, os.path.join(work, "horn.ply"), h, "level set horn.vdb")

# --- a film: one object whose mesh follows the frame -----------------------------------
film = os.path.join(work, "film")
assert bpy.ops.import_mesh.sweepers_vdb(filepath=os.path.join(film, "horn_0001.vdb"),
                                        sequence=True) == {"FINISHED"}
clip = bpy.context.object
assert clip.name == "horn.001" or clip.name.startswith("horn"), clip.name
assert (scene.frame_start, scene.frame_end) == (1, 3), (scene.frame_start, scene.frame_end)
sizes = set()
for frame in (2, 3, 1, 2):
    scene.frame_set(frame)
    same_as_ply(clip.data, os.path.join(film, f"horn_{frame:04d}.ply"), h, f"film frame {frame}")
    sizes.add(len(clip.data.vertices))
assert len(sizes) == 3, sizes  # three frames, three shapes

# --- a stroke script, and re-applying it at another voxel size ----------------------------
assert bpy.ops.import_mesh.sweepers_script(filepath=os.path.join(work, "horn.json"),
                                           voxel_size=h) == {"FINISHED"}
shaped = bpy.context.object
assert shaped["sweepers_script"] == os.path.join(work, "horn.json"), dict(shaped)
assert abs(shaped["sweepers_voxel_size"] - h) < 1e-9, shaped["sweepers_voxel_size"]
same_as_ply(shaped.data, os.path.join(work, "horn.ply"), h, "script at 0.05")
shaped.sweepers_voxel_size = 0.04
assert bpy.ops.object.sweepers_reapply() == {"FINISHED"}
same_as_ply(shaped.data, os.path.join(work, "horn_04.ply"), 0.04, "script re-applied at 0.04")
assert abs(shaped["sweepers_voxel_size"] - 0.04) < 1e-9, shaped["sweepers_voxel_size"]

# --- refusals: one message, nothing added ---------------------------------------------
before = set(bpy.data.objects.keys()), set(bpy.data.meshes.keys())


def refused(expected, call):
    try:
        call()
    except RuntimeError as e:  # an operator's error report, raised into Python
        assert expected in str(e), (expected, str(e))
        assert "Traceback" not in str(e), str(e)
        assert (set(bpy.data.objects.keys()), set(bpy.data.meshes.keys())) == before
        print(f"refused: {str(e).strip()}")
        return
    raise AssertionError(f"accepted: {expected}")


refused("Sweepers: " + os.path.join(work, "broken.vdb") + ": not a readable VDB file",
        lambda: bpy.ops.import_mesh.sweepers_vdb(filepath=os.path.join(work, "broken.vdb")))
refused("no such file",
        lambda: bpy.ops.import_mesh.sweepers_script(filepath=os.path.join(work, "none.json")))
refused("unknown stroke type",
        lambda: bpy.ops.import_mesh.sweepers_script(filepath=os.path.join(work, "bad.json")))
refused("holds no frame number",
        lambda: bpy.ops.import_mesh.sweepers_vdb(filepath=os.path.join(work, "horn.vdb"),
                                                 sequence=True))
sys.modules["sweepers"] = None  # as if the module were not installed
refused("the Python module 'sweepers' cannot be imported",
        lambda: bpy.ops.import_mesh.sweepers_vdb(filepath=os.path.join(work, "horn.vdb")))
print("blender: all checks passed")
