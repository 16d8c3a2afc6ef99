"""A Blender rigid body's collision shape as an impulse shape (a dict of the scene format,
docs/scene-format.md "Shapes"), sized and placed as Blender (Bullet) sizes and places it.

- Box, Sphere, Capsule, Cylinder and Cone are sized from the object's local bounding box times
  its scale and centred on the object's origin, as Blender builds them (Bullet's primitives are
  centred on the body's origin); Sphere's radius is half the largest dimension; Capsule,
  Cylinder and Cone have the radius half the larger of x and y, the height the z dimension.
- Convex Hull is the hull of the mesh's points; Mesh is a triangle mesh (two-sided on a static
  body; on a dynamic or kinematic body the engine decomposes it into convex parts, with the
  ``decomposition`` resolution given, else the engine's default).
- Flat objects (a plane with the default Convex Hull, a Box of zero thickness) are thin shapes:
  coplanar hull points or a zero half-extent, with ``thickness`` = 2 × the collision margin when
  the object's "Collision Margin" is ticked, else :data:`DEFAULT_THICKNESS` (given explicitly,
  so that the engine has nothing to note in the scene format's words), and a note naming the
  object, the thickness and the setting that chooses it.
- A negative scale (a mirrored object) mirrors the mesh points (the triangles' winding kept
  outward).
- Source: Base is the mesh itself, Deform the mesh with the leading deform-only modifiers and
  shape keys (Blender's "deform" mesh), Final the mesh with every modifier.
"""

import numpy as np

from . import axes

#: The names the Physics panel shows for ``collision_shape``.
SHAPE_NAMES = {
    "BOX": "Box",
    "SPHERE": "Sphere",
    "CAPSULE": "Capsule",
    "CYLINDER": "Cylinder",
    "CONE": "Cone",
    "CONVEX_HULL": "Convex Hull",
    "MESH": "Mesh",
    "COMPOUND": "Compound Parent",
}

#: A shape thinner than this along an axis (m) counts as flat.
FLAT_EXTENT = 1e-6

#: The thickness (m) of a flat shape whose "Collision Margin" is not ticked: the engine's own
#: default for a thin shape (a slab centred on the shape's plane).
DEFAULT_THICKNESS = 0.002

#: Modifier types that only move vertices (Blender's ``ModifierTypeType::OnlyDeform``): Source
#: "Deform" applies the leading run of these, as Blender's rigid body reads the evaluated
#: "deform" mesh.
DEFORM_ONLY = frozenset(
    {
        "ARMATURE",
        "CAST",
        "CLOTH",
        "CORRECTIVE_SMOOTH",
        "CURVE",
        "DISPLACE",
        "HOOK",
        "LAPLACIANDEFORM",
        "LAPLACIANSMOOTH",
        "LATTICE",
        "MESH_CACHE",
        "MESH_DEFORM",
        "SHRINKWRAP",
        "SIMPLE_DEFORM",
        "SMOOTH",
        "SOFT_BODY",
        "SURFACE_DEFORM",
        "WARP",
        "WAVE",
    }
)


class Meshes:
    """The meshes (vertices (V, 3) local, triangles (T, 3)) Blender's rigid bodies of
    ``objects`` use, read at once: Source "Deform" on an object whose modifier stack has a
    constructive modifier evaluates the scene once more with the trailing modifiers turned off
    in the viewport (turned back on before returning)."""

    def __init__(self, objects, depsgraph, view_layer):
        self.data = {}
        needs = [
            o
            for o in objects
            if o.type == "MESH" and o.rigid_body.collision_shape in ("CONVEX_HULL", "MESH")
        ]
        base = [o for o in needs if o.rigid_body.mesh_source == "BASE"]
        final = [o for o in needs if o.rigid_body.mesh_source == "FINAL"]
        deform = [o for o in needs if o.rigid_body.mesh_source == "DEFORM"]
        for obj in base:
            self.data[obj.name] = _arrays(obj.data)
        trailing = {}
        for obj in deform:
            mods = [m for m in obj.modifiers if m.show_viewport]
            first = next((i for i, m in enumerate(mods) if m.type not in DEFORM_ONLY), None)
            if first is None:
                final.append(obj)
            else:
                trailing[obj.name] = mods[first:]
        self._evaluated(final, depsgraph)
        if trailing:
            for mods in trailing.values():
                for m in mods:
                    m.show_viewport = False
            try:
                view_layer.update()
                self._evaluated([o for o in deform if o.name in trailing], depsgraph)
            finally:
                for mods in trailing.values():
                    for m in mods:
                        m.show_viewport = True
                view_layer.update()

    def _evaluated(self, objects, depsgraph):
        for obj in objects:
            owner = obj.evaluated_get(depsgraph)
            mesh = owner.to_mesh()
            try:
                self.data[obj.name] = _arrays(mesh)
            finally:
                owner.to_mesh_clear()

    def get(self, name):
        return self.data.get(name)


def _arrays(mesh):
    mesh.calc_loop_triangles()
    vertices = np.empty(3 * len(mesh.vertices), dtype=np.float64)
    mesh.vertices.foreach_get("co", vertices)
    triangles = np.empty(3 * len(mesh.loop_triangles), dtype=np.int64)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    return vertices.reshape(-1, 3), triangles.reshape(-1, 3)


def _to_impulse(points):
    """Blender points (N, 3) as impulse's (x, z, −y), lists of floats."""
    points = np.asarray(points, dtype=np.float64)
    return np.stack([points[:, 0], points[:, 2], -points[:, 1]], axis=1).tolist()


def _is_centred_box(points):
    """Whether the points (N, 3) are the corners of their axis-aligned bounding box, all eight,
    and nothing else, the box centred on the origin (a cube or a scaled cube added from the
    Add menu): their convex hull is then that box. To 1e-6 of the box's extent."""
    low, high = points.min(axis=0), points.max(axis=0)
    tolerance = 1e-6 * max(float(np.max(high - low)), 1e-9)
    if np.any(np.abs(low + high) > 2 * tolerance):
        return False
    at_low = np.abs(points - low) <= tolerance
    at_high = np.abs(points - high) <= tolerance
    if not np.all(at_low | at_high):
        return False
    corners = {tuple(bool(b) for b in row) for row in at_high}
    return len(corners) == 8


def _rank(points):
    """The number of independent directions the points span (0 to 3), to a relative
    tolerance of 1e-6 of their extent."""
    centred = points - points.mean(axis=0)
    singular = np.linalg.svd(centred, compute_uv=False)
    if singular[0] <= 0.0:
        return 0
    return int(np.sum(singular > 1e-6 * singular[0]))


def _thin(name, label, shape, rigid_body, what="a thin shape"):
    """(shape with its ``thickness``, the note) of a flat shape of object ``name``: 2 × its
    collision margin when "Collision Margin" is ticked, else :data:`DEFAULT_THICKNESS`."""
    if rigid_body.use_margin:
        shape["thickness"] = 2.0 * float(rigid_body.collision_margin)
        why = "twice its Collision Margin"
    else:
        shape["thickness"] = DEFAULT_THICKNESS
        why = (
            "tick Collision Margin to choose it: twice the Margin; or give the mesh thickness, "
            "a Solidify modifier with Source Final"
        )
    millimetres = f"{shape['thickness'] * 1e3:.3g}"
    return shape, f"{name}: a flat {label} — baked as {what} {millimetres} mm thick ({why})"


def _primitive(shape_type, dims):
    """An impulse primitive (y axis = Blender's local z) for Blender's ``shape_type`` with the
    scaled bounding-box dimensions ``dims`` (Blender's local x, y, z)."""
    if shape_type == "BOX":
        return {"type": "cuboid", "half_extents": axes.extents_to_impulse(dims / 2)}
    if shape_type == "SPHERE":
        return {"type": "sphere", "radius": float(max(dims)) / 2}
    radius = float(max(dims[0], dims[1])) / 2
    half_height = float(dims[2]) / 2
    if shape_type == "CAPSULE":
        return {"type": "capsule", "half_height": max(half_height - radius, 0.0), "radius": radius}
    if shape_type == "CYLINDER":
        return {"type": "cylinder", "half_height": half_height, "radius": radius}
    return {"type": "cone", "half_height": half_height, "radius": radius}


def build(obj, kind, scale, meshes, resolution=0):
    """(shape dict or None, notes, problems) of the object's rigid body as a body of ``kind``
    with the world scale ``scale`` (3, signed: a mirrored object has negative components).
    ``resolution`` > 0: the voxels along the longest side of a moving Mesh's decomposition
    (the engine's default otherwise). Notes and problems are messages in the animator's terms,
    each led by the object's name."""
    rigid_body = obj.rigid_body
    shape_type = rigid_body.collision_shape
    label = SHAPE_NAMES.get(shape_type, shape_type)
    name = obj.name
    scale = np.asarray(scale, dtype=np.float64)
    if shape_type == "COMPOUND":
        return None, [], [f"{name}: shape {label} is built by compound()"]
    if shape_type in ("CONVEX_HULL", "MESH"):
        data = meshes.get(name)
        if data is None or len(data[0]) == 0:
            return None, [], [f"{name}: shape {label} needs a mesh object with vertices"]
        vertices, triangles = data
        points = vertices * scale
        rank = _rank(points) if len(points) >= 2 else 0
        if rank < 2:
            return None, [], [f"{name}: shape {label}: the mesh is a point or a line, it has no surface to collide with"]
        mirrored = np.prod(np.sign(scale)) < 0
        if shape_type == "MESH" and not (rank == 2 and kind != "static"):
            edges = np.cross(points[triangles[:, 1]] - points[triangles[:, 0]], points[triangles[:, 2]] - points[triangles[:, 0]])
            extent = float(np.max(np.ptp(points, axis=0)))
            kept = triangles[np.linalg.norm(edges, axis=1) > 1e-10 * max(extent, 1e-9) ** 2]
            if len(kept) == 0:
                return None, [], [f"{name}: shape {label}: the mesh has no faces"]
            if mirrored:
                kept = kept[:, [0, 2, 1]]
            shape = {"type": "trimesh", "vertices": _to_impulse(points), "indices": kept.tolist()}
            if kind == "static":
                shape["two_sided"] = True
            elif resolution > 0:
                shape["decomposition"] = {"resolution": int(resolution)}
            return shape, [], []
        notes = []
        if shape_type == "CONVEX_HULL" and rank == 3 and _is_centred_box(points):
            # The same solid as its hull, taken by the engine's exact box paths.
            return _primitive("BOX", np.ptp(points, axis=0)), [], []
        shape = {"type": "convex_hull", "points": _to_impulse(points)}
        if rank == 2:
            # A flat mesh bounds no solid to decompose: a moving one is its flat hull.
            thin = "the thin hull of its outline" if shape_type == "MESH" else "a thin shape"
            shape, note = _thin(name, label, shape, rigid_body, thin)
            notes.append(note)
        return shape, notes, []
    corners = np.array([tuple(c) for c in obj.bound_box], dtype=np.float64)
    dims = (corners.max(axis=0) - corners.min(axis=0)) * np.abs(scale)
    if shape_type == "BOX":
        if np.sum(dims >= FLAT_EXTENT) < 2:
            return None, [], [f"{name}: shape {label} has no area (dimensions {_dims(dims)} m)"]
        shape = _primitive(shape_type, dims)
        if np.min(dims) < FLAT_EXTENT:
            shape, note = _thin(name, label, shape, rigid_body)
            return shape, [note], []
        return shape, [], []
    if shape_type == "SPHERE":
        if max(dims) < FLAT_EXTENT:
            return None, [], [f"{name}: shape {label} has no size (dimensions {_dims(dims)} m)"]
        return _primitive(shape_type, dims), [], []
    if max(dims[0], dims[1]) < FLAT_EXTENT or dims[2] < FLAT_EXTENT:
        return None, [], [f"{name}: shape {label} is flat (dimensions {_dims(dims)} m): use Box or Convex Hull"]
    return _primitive(shape_type, dims), [], []


def compound(obj, children, meshes):
    """(shape dict or None, notes, problems) of a Compound Parent: the shapes of its children
    with rigid bodies (``children``), each placed where the child is relative to the parent's
    unscaled frame, as Blender builds it (the children's own settings but the shape are
    ignored; they move with the parent)."""
    import mathutils

    name = obj.name
    if not children:
        return None, [], [f"{name}: shape Compound Parent has no children with a rigid body"]
    location, rotation, _ = obj.matrix_world.decompose()
    frame = (mathutils.Matrix.Translation(location) @ rotation.to_matrix().to_4x4()).inverted_safe()
    parts, notes, problems = [], [], []
    for child in children:
        child_type = child.rigid_body.collision_shape
        if child_type in ("MESH", "COMPOUND"):
            label = SHAPE_NAMES[child_type]
            problems.append(f"{child.name}: shape {label} cannot be part of {name}'s Compound Parent: use Convex Hull")
            continue
        place, turn, scale = (frame @ child.matrix_world).decompose()
        shape, child_notes, child_problems = build(child, "dynamic", tuple(scale), meshes)
        notes += child_notes
        problems += child_problems
        if shape is not None:
            parts.append(
                {
                    "shape": shape,
                    "position": axes.vector_to_impulse(place),
                    "orientation": axes.quaternion_to_impulse(turn),
                }
            )
    if problems:
        return None, notes, problems
    return {"type": "compound", "parts": parts}, notes, []


def _dims(dims):
    return "(" + ", ".join(f"{d:g}" for d in np.round(dims, 6)) + ")"
