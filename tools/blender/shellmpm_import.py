# shellmpm run importer for Blender 3.4 (Debian 12's `blender`): loads the output folder of
# a `shellmpm run` (its run.json "resolved" block, the shell mesh sequences, the density
# volume sequence and the scene's cameras). See docs/blender.md.
#
# Command line (starts from an empty scene):
#   blender -b -P tools/blender/shellmpm_import.py -- RUNDIR [--render OUT.png --frame N
#       --samples S] [--bulk fog|surface] [--hide-volume] [--summary OUT.json]
#       [--save OUT.blend] ...
# Add-on: Edit > Preferences > Add-ons > Install... this file, enable it, then
#   File > Import > shellmpm run (run.json).
#
# Shell meshes are one Blender mesh object per shell whose vertex positions (and velocity
# attribute) a frame-change handler replaces from the PLY of the current frame: the caches
# keep the vertex count and order every frame, so the object, its UVs, materials and
# modifiers stay as they are and only the coordinates change.
#
# Bulk material (the density VDB sequence) loads as a fog volume (Principled Volume: smoke-
# like in Cycles) or, with bulk="surface" (--bulk surface), as its iso-surface: a mesh object
# whose Volume to Mesh modifier meshes the volume object's `density` grid at the preview
# renderer's iso level (render.iso_value, 0.5) every frame, with an opaque sand material.

import argparse
import json
import math
import os
import sys

import bpy
import numpy as np
from bpy.app.handlers import persistent
from mathutils import Matrix, Vector

bl_info = {
    "name": "shellmpm run importer",
    "author": "shellmpm",
    "version": (1, 0, 0),
    "blender": (3, 4, 0),
    "location": "File > Import > shellmpm run (run.json)",
    "description": "Shell mesh sequences, density volumes and cameras of a shellmpm run folder",
    "category": "Import-Export",
}

# Custom properties on the objects the importer makes (the handler finds shells by them).
PROP_RUN = "shellmpm_run"  # absolute path of the run folder
PROP_PATTERN = "shellmpm_pattern"  # the shell's mesh pattern, relative to the run folder
PROP_FRAMES = "shellmpm_frames"  # [first, last] frames of the run
PROP_FPS = "shellmpm_fps"  # the run's frames per second
PROP_LOADED = "shellmpm_loaded_frame"  # the frame whose positions the mesh holds

# Bulk material: how it loads, and the iso level of its surface. 0.5 is render.iso_value's
# default (io/scene_schema_table.cpp), the level at which the preview renderer draws the
# density's surface (render/scene_assembler.cpp iso_surface, OpenVDB volumeToMesh).
BULK_MODES = ("fog", "surface")
DEFAULT_ISO_VALUE = 0.5
# The preview's default sand colour (render/scene_assembler.cpp default_bulk_color).
SAND_COLOR = (0.76, 0.60, 0.38)

# Scene coordinates (Y up) to Blender's (Z up): +90 degrees about X, (x, y, z) -> (x, -z, y),
# the same rotation as Blender's glTF and OBJ importers' "Y forward / Z up" defaults.
Y_UP_TO_Z_UP = Matrix.Rotation(math.radians(90.0), 4, "X")


class ShellmpmError(Exception):
    """A problem with the run folder, reported to the user by name."""


# ---------------------------------------------------------------------------------------
# run.json


def read_run(rundir):
    """The run folder's run.json "resolved" block (a dict), checked for what the loader uses."""
    path = os.path.join(rundir, "run.json")
    if not os.path.isfile(path):
        raise ShellmpmError(f"{path}: not found (give the output folder of a `shellmpm run`)")
    try:
        with open(path, "r", encoding="utf-8") as f:
            manifest = json.load(f)
    except (OSError, ValueError) as e:
        raise ShellmpmError(f"{path}: cannot read: {e}") from e
    if manifest.get("format") != "shellmpm run manifest":
        raise ShellmpmError(f"{path}: not a shellmpm run manifest")
    res = manifest.get("resolved")
    if not isinstance(res, dict):
        raise ShellmpmError(
            f"{path}: no 'resolved' block (written by shellmpm since issue 12); "
            "run the scene again with a newer shellmpm"
        )
    for key in ("fps", "frames", "shells", "cameras"):
        if key not in res:
            raise ShellmpmError(f"{path}: resolved.{key} is missing")
    res.setdefault("up_axis", "y")  # caches before output.up_axis existed were Y up
    if res["up_axis"] not in ("y", "z"):
        raise ShellmpmError(f"{path}: resolved.up_axis must be 'y' or 'z', got {res['up_axis']!r}")
    first, last = int(res["frames"][0]), int(res["frames"][1])
    if first < 1 or last < first:
        raise ShellmpmError(f"{path}: resolved.frames {res['frames']} is not a frame range")
    res["frames"] = [first, last]
    return res


def frame_file(rundir, pattern, frame):
    """The file of `frame` in a sequence: the run of '#' in `pattern` is the zero-padded
    frame number (as shellmpm's frame_path writes it)."""
    first = pattern.find("#")
    if first < 0:
        raise ShellmpmError(f"file pattern '{pattern}' has no '#' run for the frame number")
    last = first
    while last < len(pattern) and pattern[last] == "#":
        last += 1
    return os.path.join(rundir, pattern[:first] + str(frame).zfill(last - first) + pattern[last:])


# ---------------------------------------------------------------------------------------
# PLY (binary, as shellmpm writes it: float vertex properties, triangle lists)

_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip


def _ply_type(path, name):
    if name not in _PLY_TYPES:
        raise ShellmpmError(f"{path}: unknown PLY property type '{name}'")
    return _PLY_TYPES[name]


def _read_ply_header(f, path):
    """(byte order '<' or '>', [element dicts: name, count, props]) after end_header."""
    if f.readline().strip() != b"ply":
        raise ShellmpmError(f"{path}: not a PLY file")
    order = None
    elements = []
    while True:
        line = f.readline()
        if not line:
            raise ShellmpmError(f"{path}: PLY header has no end_header")
        words = line.decode("ascii", "replace").split()
        if not words:
            continue
        if words[0] == "format":
            if words[1] == "binary_little_endian":
                order = "<"
            elif words[1] == "binary_big_endian":
                order = ">"
            else:
                raise ShellmpmError(f"{path}: PLY format '{words[1]}' (the loader reads binary)")
        elif words[0] == "element":
            elements.append({"name": words[1], "count": int(words[2]), "props": []})
        elif words[0] == "property":
            if not elements:
                raise ShellmpmError(f"{path}: PLY property before any element")
            if words[1] == "list":
                elements[-1]["props"].append((words[4], "list", words[2], words[3]))
            else:
                elements[-1]["props"].append((words[2], words[1]))
        elif words[0] == "end_header":
            break
    if order is None:
        raise ShellmpmError(f"{path}: PLY header has no format line")
    return order, elements


def _read_faces(f, path, order, element):
    """Triangles (M, 3) int32 of a face element with one list property."""
    props = element["props"]
    n = element["count"]
    if len(props) != 1 or props[0][1] != "list":
        raise ShellmpmError(f"{path}: face element must hold one list property")
    count_t = order + _ply_type(path, props[0][2])
    index_t = order + _ply_type(path, props[0][3])
    # Fast path: all triangles (fixed-size records).
    dt = np.dtype([("n", count_t), ("i", index_t, (3,))])
    data = f.read(n * dt.itemsize)
    if len(data) == n * dt.itemsize:
        rec = np.frombuffer(data, dtype=dt, count=n)
        if np.all(rec["n"] == 3):
            return rec["i"].astype(np.int32)
    raise ShellmpmError(f"{path}: faces must all be triangles (shellmpm writes triangles)")


def read_ply(path, faces=True):
    """Reads a shell mesh frame: dict with 'positions' (N, 3) float32, 'uvs' (N, 2) or None,
    'velocities' (N, 3) or None, 'triangles' (M, 3) int32 or None (faces=False)."""
    try:
        f = open(path, "rb")
    except OSError as e:
        raise ShellmpmError(f"{path}: cannot open: {e}") from e
    with f:
        order, elements = _read_ply_header(f, path)
        out = {"positions": None, "uvs": None, "velocities": None, "triangles": None}
        for el in elements:
            if el["name"] == "vertex":
                if any(p[1] == "list" for p in el["props"]):
                    raise ShellmpmError(f"{path}: list property in the vertex element")
                dt = np.dtype([(p[0], order + _ply_type(path, p[1])) for p in el["props"]])
                data = f.read(el["count"] * dt.itemsize)
                if len(data) != el["count"] * dt.itemsize:
                    raise ShellmpmError(f"{path}: file ends inside the vertex data")
                v = np.frombuffer(data, dtype=dt, count=el["count"])
                names = dt.names
                for key in ("x", "y", "z"):
                    if key not in names:
                        raise ShellmpmError(f"{path}: vertex element has no '{key}'")
                out["positions"] = np.stack([v["x"], v["y"], v["z"]], 1).astype(np.float32)
                if "s" in names and "t" in names:
                    out["uvs"] = np.stack([v["s"], v["t"]], 1).astype(np.float32)
                elif "u" in names and "v" in names:
                    out["uvs"] = np.stack([v["u"], v["v"]], 1).astype(np.float32)
                if "vx" in names and "vy" in names and "vz" in names:
                    out["velocities"] = np.stack([v["vx"], v["vy"], v["vz"]], 1).astype(np.float32)
                if not faces:
                    break
            elif el["name"] == "face":
                out["triangles"] = _read_faces(f, path, order, el)
            else:
                # Unknown elements: only fixed-size ones can be skipped.
                if any(p[1] == "list" for p in el["props"]):
                    raise ShellmpmError(f"{path}: cannot skip PLY element '{el['name']}'")
                size = sum(np.dtype(_ply_type(path, p[1])).itemsize for p in el["props"])
                f.seek(el["count"] * size, 1)
        if out["positions"] is None:
            raise ShellmpmError(f"{path}: no vertex element")
        if faces and out["triangles"] is None:
            raise ShellmpmError(f"{path}: no face element")
        return out


# ---------------------------------------------------------------------------------------
# Shell meshes and the frame-change handler


def _set_velocities(mesh, velocities):
    attr = mesh.attributes.get("velocity")
    if velocities is None:
        if attr is not None:
            mesh.attributes.remove(attr)
        return
    if attr is None or attr.data_type != "FLOAT_VECTOR" or attr.domain != "POINT":
        if attr is not None:
            mesh.attributes.remove(attr)
        attr = mesh.attributes.new("velocity", "FLOAT_VECTOR", "POINT")
    attr.data.foreach_set("vector", velocities.ravel())


def build_shell_mesh(name, frame_data):
    """A new mesh datablock with the frame's vertices, triangles, UVs and velocities."""
    x = frame_data["positions"]
    tri = frame_data["triangles"]
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(x))
    mesh.vertices.foreach_set("co", x.ravel())
    mesh.loops.add(3 * len(tri))
    mesh.loops.foreach_set("vertex_index", tri.ravel())
    mesh.polygons.add(len(tri))
    mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * len(tri), 3, dtype=np.int32))
    mesh.polygons.foreach_set("loop_total", np.full(len(tri), 3, dtype=np.int32))
    mesh.polygons.foreach_set("use_smooth", np.ones(len(tri), dtype=bool))
    if frame_data["uvs"] is not None:
        uv = mesh.uv_layers.new(name="UVMap")
        uv.data.foreach_set("uv", frame_data["uvs"][tri.ravel()].ravel())
    _set_velocities(mesh, frame_data["velocities"])
    mesh.update()
    if mesh.validate(verbose=False):
        print(f"shellmpm: mesh '{name}' needed repairs (degenerate or duplicate triangles)")
    return mesh


def _frame_positions(obj, frame):
    """The positions and velocities of the shell's PLY of `frame`, or None (reported) when
    the file is missing or does not match the object."""
    path = frame_file(obj[PROP_RUN], obj[PROP_PATTERN], frame)
    if not os.path.isfile(path):
        print(f"shellmpm: {path}: missing; '{obj.name}' keeps frame {obj.data.get(PROP_LOADED)}")
        return None
    try:
        data = read_ply(path, faces=False)
    except ShellmpmError as e:
        print(f"shellmpm: {e}")
        return None
    if len(data["positions"]) != len(obj.data.vertices):
        print(
            f"shellmpm: {path}: {len(data['positions'])} vertices, but '{obj.name}' has "
            f"{len(obj.data.vertices)} (caches keep one vertex count per shell); not loaded"
        )
        return None
    return data


def update_shell_object(obj, frame, subframe=0.0, fps=None):
    """Loads the positions of `frame` (clamped to the run's frames) into the shell object's
    mesh; returns the frame loaded, or None when the file is missing or does not match.
    Between frames (`subframe` > 0: Cycles' motion blur steps) the positions move on along
    the PLY's velocities for subframe / fps seconds when it has them (and `fps` is given),
    else straight towards the next frame's."""
    first, last = (int(v) for v in obj[PROP_FRAMES])
    clamped = min(max(int(frame), first), last)
    if clamped != int(frame) or clamped == last or subframe <= 0.0:
        subframe = 0.0
    frame = clamped
    key = frame + subframe if subframe else frame
    mesh = obj.data
    if mesh.get(PROP_LOADED) == key:
        return key
    data = _frame_positions(obj, frame)
    if data is None:
        return None
    x = data["positions"]
    if subframe:
        if data["velocities"] is not None and fps:
            x = x + data["velocities"] * (subframe / fps)
        else:
            after = _frame_positions(obj, frame + 1)
            if after is not None:
                x = (1.0 - subframe) * x + subframe * after["positions"]
    mesh.vertices.foreach_set("co", x.astype(np.float32).ravel())
    _set_velocities(mesh, data["velocities"])
    mesh.update()
    mesh[PROP_LOADED] = key
    return key


@persistent
def shellmpm_frame_change(scene, *_):
    """frame_change_pre handler: every shellmpm shell object in the scene follows the frame."""
    for obj in scene.objects:
        if obj.type == "MESH" and PROP_PATTERN in obj and PROP_RUN in obj:
            update_shell_object(
                obj,
                scene.frame_current,
                scene.frame_subframe,
                obj.get(PROP_FPS),
            )


def register_handler():
    handlers = bpy.app.handlers.frame_change_pre
    for h in list(handlers):
        if getattr(h, "__name__", "") == "shellmpm_frame_change":
            handlers.remove(h)
    handlers.append(shellmpm_frame_change)


def unregister_handler():
    handlers = bpy.app.handlers.frame_change_pre
    for h in list(handlers):
        if getattr(h, "__name__", "") == "shellmpm_frame_change":
            handlers.remove(h)


# ---------------------------------------------------------------------------------------
# Materials


def shell_material(name, front, back):
    """Principled BSDF whose base colour is `front` on the +normal side, `back` behind."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    bsdf = nt.nodes.get("Principled BSDF")
    geo = nt.nodes.new("ShaderNodeNewGeometry")
    mix = nt.nodes.new("ShaderNodeMixRGB")
    mix.inputs["Color1"].default_value = (*front, 1.0)
    mix.inputs["Color2"].default_value = (*back, 1.0)
    nt.links.new(geo.outputs["Backfacing"], mix.inputs["Fac"])
    nt.links.new(mix.outputs["Color"], bsdf.inputs["Base Color"])
    bsdf.inputs["Roughness"].default_value = 0.7
    mat.diffuse_color = (*front, 1.0)
    return mat


def volume_material(name, extinction):
    """Principled Volume on the `density` grid; density 1 has extinction `extinction` [1/m]."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    vol = nt.nodes.new("ShaderNodeVolumePrincipled")
    vol.inputs["Color"].default_value = (0.80, 0.68, 0.50, 1.0)
    vol.inputs["Density"].default_value = float(extinction)
    vol.inputs["Density Attribute"].default_value = "density"
    nt.links.new(vol.outputs["Volume"], out.inputs["Volume"])
    return mat


def surface_material(name, color):
    """Opaque, rough Principled BSDF for the bulk surface (sand, snow, solids): `color` is
    the base colour (linear RGB), no specular sheen to speak of."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes.get("Principled BSDF")
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.9
    # "Specular" in Blender 3.x (4.0 renamed it "Specular IOR Level").
    spec = bsdf.inputs.get("Specular") or bsdf.inputs.get("Specular IOR Level")
    if spec is not None:
        spec.default_value = 0.2
    mat.diffuse_color = (*color, 1.0)
    return mat


# ---------------------------------------------------------------------------------------
# Cameras


def look_at_matrix(eye, target, up):
    """Blender camera matrix (looks down local -Z, local +Y up) in scene coordinates."""
    eye, target, up = Vector(eye), Vector(target), Vector(up)
    fwd = target - eye
    if fwd.length < 1e-12:
        raise ShellmpmError("camera position equals its target")
    fwd.normalize()
    right = fwd.cross(up)
    if right.length < 1e-12:
        raise ShellmpmError("camera up is parallel to its view direction")
    right.normalize()
    true_up = right.cross(fwd)
    m = Matrix.Identity(4)
    for i in range(3):
        m[i][0], m[i][1], m[i][2], m[i][3] = right[i], true_up[i], -fwd[i], eye[i]
    return m


def auto_camera(lo, hi, width, height, fov_deg=35.0, azimuth_deg=30.0, elevation_deg=22.0):
    """The preview renderer's auto framing (render/camera.cpp auto_frame), scene coordinates:
    (eye, target, up, fov)."""
    lo, hi = Vector(lo), Vector(hi)
    target = 0.5 * (lo + hi)
    radius = max(0.5 * (hi - lo).length, 1e-3)
    half_v = math.radians(0.5 * fov_deg)
    half_h = math.atan(math.tan(half_v) * width / height)
    dist = 1.08 * radius / math.sin(min(half_v, half_h))
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    d = Vector((math.sin(az) * math.cos(el), math.sin(el), math.cos(az) * math.cos(el)))
    return target + dist * d, target, Vector((0, 1, 0)), fov_deg


def make_camera(collection, name, eye, target, up, fov_deg):
    cam = bpy.data.cameras.new(name)
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = math.radians(fov_deg)
    cam.clip_start = 0.01
    cam.clip_end = 1000.0
    obj = bpy.data.objects.new(name, cam)
    collection.objects.link(obj)
    obj.matrix_world = Y_UP_TO_Z_UP @ look_at_matrix(eye, target, up)
    return obj


# ---------------------------------------------------------------------------------------
# The importer


def _apply_scene_settings(scene, res):
    fps = float(res["fps"])
    whole = max(1, math.ceil(fps - 1e-9))
    scene.render.fps = whole
    scene.render.fps_base = whole / fps
    scene.frame_start, scene.frame_end = res["frames"]
    if "size" in res:
        scene.render.resolution_x, scene.render.resolution_y = (int(v) for v in res["size"])
        scene.render.resolution_percentage = 100


def _add_lights(scene, collection):
    """A sun and a grey world, so that a bare scene renders (the preview's look, roughly)."""
    sun = bpy.data.lights.new("shellmpm_sun", "SUN")
    sun.energy = 3.0
    sun.angle = math.radians(10.0)
    obj = bpy.data.objects.new("shellmpm_sun", sun)
    obj.rotation_euler = (math.radians(40.0), 0.0, math.radians(30.0))
    collection.objects.link(obj)
    if scene.world is None:
        scene.world = bpy.data.worlds.new("shellmpm_world")
    scene.world.use_nodes = True
    bg = scene.world.node_tree.nodes.get("Background")
    if bg is not None:
        bg.inputs["Color"].default_value = (0.25, 0.27, 0.30, 1.0)
        bg.inputs["Strength"].default_value = 0.6


def _half_voxel_shift(context, volume, grid, frame):
    """The volume object's offset (in the caches' coordinates) that puts the grid's voxels
    where shellmpm and OpenVDB put them. shellmpm's VDBs (io/density_vdb) hold the density
    of the cell centred on voxel index i at i * voxel (OpenVDB's convention, as Houdini and
    the preview's volumeToMesh read it); Blender 3.4 samples voxel i at (i + 1/2) * voxel
    in Cycles, the viewport and the Volume to Mesh modifier (measured: a box of 5 voxels
    renders, and meshes, half a voxel towards +x, +y, +z). Shifting the object back by half
    a voxel along each index axis lines the fog and its surface up with the shell meshes.
    Reads the grid's transform from `frame`'s file (the evaluated volume: the original
    datablock has no frame to load); zero, reported, when it cannot be read."""
    scene = context.scene
    current = scene.frame_current
    scene.frame_set(frame)
    try:
        ev = volume.evaluated_get(context.evaluated_depsgraph_get())
        grids = ev.data.grids
        grids.load()
        g = grids.get(grid) or (grids[0] if len(grids) else None)
        m = Matrix(g.matrix_object) if g is not None else None
        error = grids.error_message or f"no grid '{grid}'"
    finally:
        scene.frame_set(current)
    if m is None:
        print(f"shellmpm: {volume.data.filepath}: {error}; no half-voxel shift")
        return Vector((0.0, 0.0, 0.0))
    return -0.5 * (m.to_3x3() @ Vector((1.0, 1.0, 1.0)))


def _add_bulk_surface(collection, root, volume, grid, iso_value, adaptivity, color):
    """A mesh object whose Volume to Mesh modifier meshes `grid` of the volume object
    `volume` at density `iso_value` (the grid's own voxels, as the preview's volumeToMesh),
    re-evaluated whenever the volume loads another frame."""
    name = volume.name.replace("_density", "_surface")
    mesh = bpy.data.meshes.new(name)
    obj = bpy.data.objects.new(name, mesh)
    obj.parent = root
    mod = obj.modifiers.new("shellmpm iso-surface", "VOLUME_TO_MESH")
    mod.object = volume
    mod.grid_name = grid
    mod.threshold = float(iso_value)
    mod.resolution_mode = "GRID"
    mod.adaptivity = float(adaptivity)
    mod.use_smooth_shade = True
    mesh.materials.append(surface_material(f"shellmpm_{name}", color))
    collection.objects.link(obj)
    return obj


def import_run(
    context,
    rundir,
    load_volume=True,
    hide_volume=False,
    load_cameras=True,
    add_lights=False,
    scene_settings=True,
    bulk="fog",
    iso_value=None,
    adaptivity=0.0,
    surface_color=None,
):
    """Imports the run folder into context.scene; returns a summary dict (see summary()).

    Bulk material (the density VDB sequence, when `load_volume` and the run wrote one):
    bulk="fog" loads it as a volume object with a Principled Volume material; bulk="surface"
    as the iso-surface at density `iso_value` (None: the run's resolved.density.iso_value
    when run.json has it, else 0.5, render.iso_value's default): a mesh object with a Volume
    to Mesh modifier (grid resolution, `adaptivity` in [0, 1], 0 keeps every triangle) on
    the volume object, which stays as its source, hidden in renders and drawn as bounds.
    `surface_color` (linear RGB; default sand) colours the surface. `hide_volume` leaves the
    bulk (fog or surface) out of renders."""
    if bulk not in BULK_MODES:
        raise ShellmpmError(f"bulk '{bulk}': expected one of {', '.join(BULK_MODES)}")
    if iso_value is not None and not float(iso_value) > 0.0:
        raise ShellmpmError(f"iso value {iso_value}: must be > 0 (a density)")
    if not 0.0 <= float(adaptivity) <= 1.0:
        raise ShellmpmError(f"adaptivity {adaptivity}: must be in [0, 1]")
    rundir = os.path.abspath(rundir)
    res = read_run(rundir)
    scene = context.scene
    first, last = res["frames"]
    if scene_settings:
        _apply_scene_settings(scene, res)
    name = os.path.basename(os.path.normpath(rundir)) or "run"
    collection = bpy.data.collections.new(f"shellmpm {name}")
    scene.collection.children.link(collection)
    # The caches' parent: turns Y-up caches to Blender's Z up.
    root = bpy.data.objects.new(f"shellmpm_{name}", None)
    root.empty_display_type = "ARROWS"
    root.empty_display_size = 0.2
    root["shellmpm_up_axis"] = res["up_axis"]
    if res["up_axis"] == "y":
        root.matrix_world = Y_UP_TO_Z_UP
    collection.objects.link(root)

    shells = []
    for sh in res["shells"]:
        if sh.get("format", "ply") != "ply":
            raise ShellmpmError(
                f"shell '{sh['name']}': format '{sh['format']}' (the loader reads PLY; set "
                "output.shell_format: ply)"
            )
        frame = first
        path = frame_file(rundir, sh["pattern"], frame)
        data = read_ply(path)
        mesh = build_shell_mesh(sh["name"], data)
        mesh[PROP_LOADED] = frame
        obj = bpy.data.objects.new(sh["name"], mesh)
        obj[PROP_RUN] = rundir
        obj[PROP_PATTERN] = sh["pattern"]
        obj[PROP_FRAMES] = [first, last]
        obj[PROP_FPS] = float(res["fps"])
        obj.parent = root
        mesh.materials.append(
            shell_material(
                f"shellmpm_{sh['name']}",
                sh.get("front_color", (0.8, 0.3, 0.2)),
                sh.get("back_color", (0.2, 0.42, 0.8)),
            )
        )
        collection.objects.link(obj)
        shells.append(obj)

    volume = None
    surface = None
    dens = res.get("density")
    if load_volume and dens:
        path = frame_file(rundir, dens["pattern"], first)
        if not os.path.isfile(path):
            raise ShellmpmError(f"{path}: missing (the run's first density volume)")
        vol = bpy.data.volumes.new(f"{name}_density")
        vol.filepath = path
        vol.is_sequence = True
        # Blender's file number = scene frame - frame_start + 1 + frame_offset.
        vol.frame_start = first
        vol.frame_offset = first - 1
        vol.frame_duration = last - first + 1
        vol.sequence_mode = "CLIP"
        vol.materials.append(volume_material(f"shellmpm_{name}_density", dens.get("extinction", 1.0)))
        volume = bpy.data.objects.new(f"{name}_density", vol)
        volume.parent = root
        volume.hide_render = hide_volume
        collection.objects.link(volume)
        volume.location = _half_voxel_shift(context, volume, dens.get("grid", "density"), first)
        if bulk == "surface":
            iso = iso_value if iso_value is not None else dens.get("iso_value", DEFAULT_ISO_VALUE)
            surface = _add_bulk_surface(
                collection,
                root,
                volume,
                dens.get("grid", "density"),
                iso,
                adaptivity,
                tuple(surface_color) if surface_color is not None else SAND_COLOR,
            )
            surface.hide_render = hide_volume
            # The fog stays the modifier's source: evaluated, not rendered, drawn as a box.
            volume.hide_render = True
            volume.display_type = "BOUNDS"

    register_handler()
    for obj in shells:
        update_shell_object(obj, scene.frame_current)

    camera = None
    if load_cameras:
        size = res.get("size", [scene.render.resolution_x, scene.render.resolution_y])
        made = {}
        for c in res["cameras"]:
            made[c["name"]] = make_camera(
                collection, c["name"], c["position"], c["target"], c["up"], c["fov"]
            )
        wanted = res.get("camera", "auto")
        if wanted in made:
            camera = made[wanted]
        else:
            lo, hi = _content_bounds(context, shells, volume, res)
            eye, target, up, fov = auto_camera(lo, hi, size[0], size[1])
            camera = make_camera(collection, "auto", eye, target, up, fov)
        scene.camera = camera

    if add_lights:
        _add_lights(scene, collection)
    return {"rundir": rundir, "resolved": res, "shells": shells, "volume": volume,
            "surface": surface, "camera": camera, "root": root}  # fmt: skip


def _content_bounds(context, shells, volume, res):
    """Scene-coordinate box of the shells and the volume at the run's first and last frames
    (bulk material often starts empty: a source that emits, or a pile that spreads); the
    domain when there is nothing. Empty objects (a volume with no active voxels has a box of
    zero size at its origin) are left out. Returns to the current frame."""
    scene = context.scene
    current = scene.frame_current
    to_scene = Y_UP_TO_Z_UP.inverted()
    pts = []
    for frame in sorted(set(res["frames"])):
        scene.frame_set(frame)
        depsgraph = context.evaluated_depsgraph_get()
        for obj in shells + ([volume] if volume is not None else []):
            corners = [Vector(c) for c in obj.evaluated_get(depsgraph).bound_box]
            if max((c - corners[0]).length for c in corners) <= 0.0:
                continue
            pts.extend(to_scene @ (obj.matrix_world @ c) for c in corners)
    scene.frame_set(current)
    if not pts:
        return res["domain"]["min"], res["domain"]["max"]
    lo = [min(p[i] for p in pts) for i in range(3)]
    hi = [max(p[i] for p in pts) for i in range(3)]
    return lo, hi


def summary(context, imported):
    """What was loaded, as JSON-ready data: frame range and fps, per shell the vertex count
    and world-space box, the volume's settings and its image-space box (pixels from the top
    left) as seen from the scene camera, and with bulk="surface" the surface mesh's counts
    and boxes ("surface"; null otherwise)."""
    from bpy_extras.object_utils import world_to_camera_view

    scene = context.scene
    depsgraph = context.evaluated_depsgraph_get()
    out = {
        "frames": [scene.frame_start, scene.frame_end],
        "fps": scene.render.fps / scene.render.fps_base,
        "frame": scene.frame_current,
        "up_axis": imported["resolved"]["up_axis"],
        "resolution": [scene.render.resolution_x, scene.render.resolution_y],
        "shells": [],
        "volume": None,
        "surface": None,
        "camera": scene.camera.name if scene.camera else None,
    }
    for obj in imported["shells"]:
        mesh = obj.data
        co = np.empty(3 * len(mesh.vertices), dtype=np.float32)
        mesh.vertices.foreach_get("co", co)
        co = co.reshape(-1, 3).astype(np.float64)
        mw = np.array(obj.matrix_world)
        world = co @ mw[:3, :3].T + mw[:3, 3]
        out["shells"].append({
            "name": obj.name,
            "vertices": len(mesh.vertices),
            "triangles": len(mesh.polygons),
            "uvs": len(mesh.uv_layers) > 0,
            "velocity": mesh.attributes.get("velocity") is not None,
            "loaded_frame": mesh.get(PROP_LOADED),
            "world_min": world.min(0).tolist(),
            "world_max": world.max(0).tolist(),
        })  # fmt: skip
    vol = imported["volume"]
    if vol is not None:
        data = vol.data
        info = {
            "object": vol.name,
            "filepath": data.filepath,
            "frame_start": data.frame_start,
            "frame_offset": data.frame_offset,
            "frame_duration": data.frame_duration,
            "hidden": vol.hide_render,
            "location": list(vol.location),
            "grids": [],
            "image_box": None,
        }
        ev = vol.evaluated_get(depsgraph)
        try:
            ev.data.grids.load()
            info["grids"] = [g.name for g in ev.data.grids]
        except Exception as e:  # noqa: BLE001 (reported, not fatal)
            info["grids_error"] = str(e)
        if scene.camera is not None:
            w, h = scene.render.resolution_x, scene.render.resolution_y
            xs, ys = [], []
            for c in ev.bound_box:
                p = world_to_camera_view(scene, scene.camera, vol.matrix_world @ Vector(c))
                xs.append(p.x * w)
                ys.append((1.0 - p.y) * h)
            info["image_box"] = [min(xs), min(ys), max(xs), max(ys)]
        out["volume"] = info
    surf = imported.get("surface")
    if surf is not None:
        out["surface"] = _surface_summary(scene, depsgraph, surf)
    return out


def _image_box(scene, obj, corners):
    """Pixels (from the top left) of the box around `corners` (object space) in the camera."""
    from bpy_extras.object_utils import world_to_camera_view

    w, h = scene.render.resolution_x, scene.render.resolution_y
    xs, ys = [], []
    for c in corners:
        p = world_to_camera_view(scene, scene.camera, obj.matrix_world @ Vector(c))
        xs.append(p.x * w)
        ys.append((1.0 - p.y) * h)
    return [min(xs), min(ys), max(xs), max(ys)]


def _surface_summary(scene, depsgraph, obj):
    """The bulk surface at the current frame: its modifier's settings, the evaluated mesh's
    vertex, face and triangle counts, its world-space box and its box in the image."""
    mod = next(m for m in obj.modifiers if m.type == "VOLUME_TO_MESH")
    info = {
        "object": obj.name,
        "source": mod.object.name if mod.object else None,
        "grid": mod.grid_name,
        "threshold": mod.threshold,
        "resolution_mode": mod.resolution_mode,
        "adaptivity": mod.adaptivity,
        "hidden": obj.hide_render,
        "material": obj.data.materials[0].name if len(obj.data.materials) else None,
        "vertices": 0,
        "faces": 0,
        "triangles": 0,
        "world_min": None,
        "world_max": None,
        "image_box": None,
    }
    ev = obj.evaluated_get(depsgraph)
    mesh = ev.to_mesh()
    try:
        n = len(mesh.vertices)
        info["vertices"] = n
        info["faces"] = len(mesh.polygons)
        totals = np.empty(len(mesh.polygons), dtype=np.int32)
        mesh.polygons.foreach_get("loop_total", totals)
        info["triangles"] = int(np.sum(totals - 2))
        if n:
            co = np.empty(3 * n, dtype=np.float32)
            mesh.vertices.foreach_get("co", co)
            co = co.reshape(-1, 3).astype(np.float64)
            mw = np.array(ev.matrix_world)
            world = co @ mw[:3, :3].T + mw[:3, 3]
            info["world_min"] = world.min(0).tolist()
            info["world_max"] = world.max(0).tolist()
            if scene.camera is not None:
                info["image_box"] = _image_box(scene, ev, ev.bound_box)
    finally:
        ev.to_mesh_clear()
    return info


def render_frame(scene, path, samples, threads):
    """Renders the current frame with Cycles (CPU) to an 8-bit RGB PNG at `path`."""
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.seed = 0
    if threads > 0:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = threads
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.color_depth = "8"
    scene.render.filepath = os.path.abspath(path)
    scene.render.use_file_extension = False
    bpy.ops.render.render(write_still=True)


# ---------------------------------------------------------------------------------------
# Add-on: File > Import > shellmpm run

try:
    from bpy.props import BoolProperty, EnumProperty, FloatProperty, StringProperty
    from bpy_extras.io_utils import ImportHelper

    class IMPORT_OT_shellmpm_run(bpy.types.Operator, ImportHelper):
        """Import a shellmpm run folder (pick its run.json)"""

        bl_idname = "import_scene.shellmpm_run"
        bl_label = "Import shellmpm run"
        bl_options = {"REGISTER", "UNDO"}

        filename_ext = ".json"
        filter_glob: StringProperty(default="run.json", options={"HIDDEN"})
        load_volume: BoolProperty(
            name="Bulk material", description="Load the density volumes", default=True
        )
        bulk: EnumProperty(
            name="Bulk as",
            description="How bulk material (the density VDB sequence) is loaded",
            items=(
                ("FOG", "Fog volume", "Volume object, Principled Volume material (smoke-like)"),
                ("SURFACE", "Surface",
                 "The density's iso-surface (Volume to Mesh modifier), opaque sand material"),
            ),
            default="FOG",
        )  # fmt: skip
        iso_value: FloatProperty(
            name="Iso value",
            description="Density of the surface (the preview's render.iso_value, 0.5)",
            default=DEFAULT_ISO_VALUE,
            min=1e-6,
            soft_max=2.0,
        )
        adaptivity: FloatProperty(
            name="Adaptivity",
            description="Fewer triangles where the surface is flat (0: every triangle)",
            default=0.0,
            min=0.0,
            max=1.0,
        )
        load_cameras: BoolProperty(name="Cameras", default=True)
        scene_settings: BoolProperty(
            name="Frame range, fps, size", description="Set the scene's from the run", default=True
        )
        add_lights: BoolProperty(name="Sun and world", default=False)

        def execute(self, context):
            path = self.filepath
            rundir = path if os.path.isdir(path) else os.path.dirname(path)
            try:
                import_run(
                    context,
                    rundir,
                    load_volume=self.load_volume,
                    bulk=self.bulk.lower(),
                    iso_value=self.iso_value,
                    adaptivity=self.adaptivity,
                    load_cameras=self.load_cameras,
                    add_lights=self.add_lights,
                    scene_settings=self.scene_settings,
                )
            except ShellmpmError as e:
                self.report({"ERROR"}, str(e))
                return {"CANCELLED"}
            return {"FINISHED"}

    def _menu_import(self, _context):
        self.layout.operator(IMPORT_OT_shellmpm_run.bl_idname, text="shellmpm run (run.json)")

except ImportError:  # pragma: no cover (always there in Blender)
    IMPORT_OT_shellmpm_run = None


def register():
    bpy.utils.register_class(IMPORT_OT_shellmpm_run)
    bpy.types.TOPBAR_MT_file_import.append(_menu_import)
    register_handler()


def unregister():
    unregister_handler()
    bpy.types.TOPBAR_MT_file_import.remove(_menu_import)
    bpy.utils.unregister_class(IMPORT_OT_shellmpm_run)


# ---------------------------------------------------------------------------------------
# Command line: blender -b -P shellmpm_import.py -- RUNDIR [options]


def _parse_args(argv):
    p = argparse.ArgumentParser(
        prog="blender -b -P shellmpm_import.py --",
        description="Load a shellmpm run folder into an empty Blender scene.",
    )
    p.add_argument("rundir", help="output folder of `shellmpm run` (holds run.json)")
    p.add_argument("--render", metavar="OUT.png", help="render one frame with Cycles to OUT.png")
    p.add_argument("--frame", type=int, help="frame to show or render (default: the first)")
    p.add_argument("--samples", type=int, default=16, help="Cycles samples per pixel (16)")
    p.add_argument("--size", metavar="WxH", help="image size (default: the scene's render.size)")
    p.add_argument("--threads", type=int, default=0, help="render threads (0: all)")
    p.add_argument(
        "--bulk",
        choices=BULK_MODES,
        default="fog",
        help="bulk material as a fog volume (default) or as the density's iso-surface",
    )
    p.add_argument(
        "--iso-value",
        type=float,
        help="density of the --bulk surface (default 0.5, the preview's render.iso_value)",
    )
    p.add_argument(
        "--adaptivity", type=float, default=0.0, help="--bulk surface simplification in [0, 1] (0)"
    )
    p.add_argument(
        "--surface-color",
        metavar="R,G,B",
        help="--bulk surface base colour, linear RGB in [0, 1] (default sand)",
    )
    p.add_argument("--hide-volume", action="store_true", help="load the bulk, hidden in renders")
    p.add_argument("--no-volume", action="store_true", help="do not load the density volume")
    p.add_argument("--no-lights", action="store_true", help="no sun and world")
    p.add_argument("--summary", metavar="OUT.json", help="write what was loaded as JSON")
    p.add_argument("--save", metavar="OUT.blend", help="save the scene as a .blend")
    return p.parse_args(argv)


def main(argv):
    args = _parse_args(argv)
    color = None
    if args.surface_color:
        try:
            color = tuple(float(v) for v in args.surface_color.split(","))
        except ValueError:
            color = ()
        if len(color) != 3 or not all(0.0 <= c <= 1.0 for c in color):
            raise ShellmpmError(f"--surface-color {args.surface_color}: expected R,G,B in [0, 1]")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    context = bpy.context
    imported = import_run(
        context,
        args.rundir,
        load_volume=not args.no_volume,
        hide_volume=args.hide_volume,
        add_lights=not args.no_lights,
        bulk=args.bulk,
        iso_value=args.iso_value,
        adaptivity=args.adaptivity,
        surface_color=color,
    )
    scene = context.scene
    if args.size:
        try:
            w, h = (int(v) for v in args.size.lower().split("x"))
        except ValueError:
            raise ShellmpmError(f"--size {args.size}: expected WxH, e.g. 320x180") from None
        scene.render.resolution_x, scene.render.resolution_y = w, h
    frame = args.frame if args.frame is not None else scene.frame_start
    if not scene.frame_start <= frame <= scene.frame_end:
        raise ShellmpmError(
            f"--frame {frame}: outside the run's frames {scene.frame_start}-{scene.frame_end}"
        )
    scene.frame_set(frame)
    if args.save:
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.save))
    info = summary(context, imported)
    if args.render:
        render_frame(scene, args.render, args.samples, args.threads)
        info["render"] = os.path.abspath(args.render)
    text = json.dumps(info, indent=2)
    if args.summary:
        with open(args.summary, "w", encoding="utf-8") as f:
            f.write(text + "\n")
    print("shellmpm summary: " + json.dumps(info))


if __name__ == "__main__":
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    try:
        main(argv)
    except ShellmpmError as e:
        print(f"error: {e}", file=sys.stderr)
        sys.exit(2)
