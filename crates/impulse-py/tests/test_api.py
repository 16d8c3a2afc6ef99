"""The Python surface: pickling of shapes, builders and handles, real defaults in help() and the
stubs, errors for negative counts, and a short repr of the diagnostics."""

import ast
import inspect
import math
import pathlib
import pickle
import pydoc

import numpy as np
import pytest

import impulse
from impulse import _impulse

STUBS = pathlib.Path(impulse.__file__).with_name("_impulse.pyi")

SHAPES = [
    impulse.Shape.ball(0.5),
    impulse.Shape.cuboid(0.5, 0.25, 1.0),
    impulse.Shape.capsule(0.5, 0.2),
    impulse.Shape.cylinder(0.5, 0.3),
    impulse.Shape.cone(0.5, 0.3),
    impulse.Shape.convex_hull([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]),
    impulse.Shape.halfspace((0, 1, 0)),
    impulse.Shape.from_dict(
        {
            "type": "compound",
            "parts": [
                {"shape": {"type": "sphere", "radius": 0.25}, "position": [0.5, 0, 0]},
                {"shape": {"type": "sphere", "radius": 0.25}, "position": [-0.5, 0, 0]},
            ],
        }
    ),
]


def ground_world():
    world = impulse.World(gravity=(0, -9.81, 0), dt=1 / 60)
    world.insert(impulse.BodyBuilder.fixed(impulse.Shape.cuboid(20, 0.5, 20), translation=(0, -0.5, 0)))
    return world


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: s.to_dict()["type"])
def test_shapes_pickle(shape):
    copy = pickle.loads(pickle.dumps(shape))
    assert copy == shape
    assert copy.to_dict() == shape.to_dict()


def test_body_builders_pickle_to_the_same_body():
    builders = [
        impulse.BodyBuilder.dynamic(
            impulse.Shape.cuboid(0.5, 0.5, 0.5),
            translation=(0.0, 3.0, 0.0),
            rotation=(0.0, 0.38268343, 0.0, 0.9238795),
            linear_velocity=np.array([1.0, 0.0, 0.5]),
            angular_velocity=[0.0, 2.0, 0.0],
            friction=0.4,
            restitution=0.25,
            density=700.0,
            name="crate",
            linear_damping=0.1,
            angular_damping=0.2,
        ),
        impulse.BodyBuilder.particle(0.2, translation=(3.0, 1.0, 0.0), mass=0.5),
        impulse.BodyBuilder.kinematic(impulse.Shape.ball(0.3), translation=(-3.0, 0.3, 0.0),
                                      linear_velocity=(0.5, 0, 0)),
        impulse.BodyBuilder.fixed(impulse.Shape.ball(0.3), translation=(6.0, 0.3, 0.0)),
        impulse.BodyBuilder.dynamic(impulse.Shape.capsule(0.3, 0.2), translation=(0, 6, 0),
                                    lock_rotation=True),
    ]
    copies = [pickle.loads(pickle.dumps(b)) for b in builders]
    assert [repr(c) for c in copies] == [repr(b) for b in builders]
    assert repr(builders[0]).startswith("BodyBuilder.dynamic(Shape(")
    assert 'friction=0.4, restitution=0.25, density=700.0, name="crate"' in repr(builders[0])
    worlds = [ground_world(), ground_world()]
    for world, bodies in zip(worlds, (builders, copies), strict=True):
        for builder in bodies:
            world.insert(builder)
        world.step(40)
    assert worlds[0].names == worlds[1].names
    assert worlds[0].kinds == worlds[1].kinds == ["static", "dynamic", "particle", "kinematic",
                                                    "static", "dynamic"]
    assert worlds[0].masses.tobytes() == worlds[1].masses.tobytes()
    for name in ("positions", "orientations", "linear_velocities", "angular_velocities"):
        a, b = getattr(worlds[0], name), getattr(worlds[1], name)
        assert a.tobytes() == b.tobytes(), name
    # The bodies moved: the comparison is not of two initial states.
    assert worlds[0].positions[1, 1] < 3.0


def test_handles_pickle_and_name_the_same_body_and_joint():
    world = ground_world()
    a = world.insert(impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.5), translation=(0, 2, 0)))
    b = world.insert(impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.5), translation=(2, 2, 0)))
    world.remove(a)
    c = world.insert(impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.5), translation=(0, 2, 0)))
    assert c.index == a.index and c.generation == a.generation + 1
    joint = world.insert_joint(impulse.JointBuilder.distance(b, c, 1.0, 3.0))
    for handle in (b, c, joint):
        copy = pickle.loads(pickle.dumps(handle))
        assert copy == handle and hash(copy) == hash(handle)
        assert (copy.index, copy.generation) == (handle.index, handle.generation)
    assert world.index_of(pickle.loads(pickle.dumps(c))) == world.index_of(c)
    assert world.joint(pickle.loads(pickle.dumps(joint)))["handle"] == joint
    # A handle made from its parts is checked by the world like any other.
    assert impulse.BodyHandle(b.index, b.generation) == b
    with pytest.raises(impulse.WorldError):
        world.index_of(pickle.loads(pickle.dumps(a)))  # the removed body's
    with pytest.raises(impulse.WorldError):
        world.joint(impulse.JointHandle(joint.index, joint.generation + 1))


def test_negative_counts_raise_value_error():
    world = impulse.World.from_scene("pyramid20")
    with pytest.raises(ValueError, match=r"^n: must be a whole number ≥ 0, got -1$") as error:
        world.step(-1)
    assert isinstance(error.value, impulse.WorldError)
    with pytest.raises(impulse.WorldError, match=r"^steps: must be a whole number ≥ 0, got -5$"):
        world.simulate(-5)
    with pytest.raises(impulse.WorldError, match=r"^every: must be a whole number ≥ 1, got 0$"):
        world.simulate(10, every=0)
    assert world.step_count == 0
    world.step(0)
    assert world.step_count == 0


def native_callables():
    """(qualified name, object) of every class, function and method of the native module."""
    for name, value in vars(_impulse).items():
        if name.startswith("_"):
            continue
        if isinstance(value, type):
            yield name, value
            for method, member in vars(value).items():
                if callable(member) or isinstance(member, (staticmethod, classmethod)):
                    if method.startswith("__") and method != "__init__":
                        continue
                    yield f"{name}.{method}", getattr(value, method)
        elif callable(value):
            yield name, value


def test_help_shows_the_real_defaults():
    for name, value in native_callables():
        if getattr(value, "__text_signature__", None) is None and not isinstance(value, type):
            continue
        try:
            signature = inspect.signature(value)
        except ValueError:
            if isinstance(value, type) and value.__text_signature__ is None:
                continue  # a class made by its static methods only
            raise
        for parameter in signature.parameters.values():
            assert parameter.default is not Ellipsis, f"{name}: {parameter.name}"
    world = inspect.signature(impulse.World).parameters
    assert world["gravity"].default == (0.0, -9.81, 0.0)
    assert world["dt"].default == 1 / 60
    assert world["settings"].default is None
    assert inspect.signature(impulse.World.step).parameters["n"].default == 1
    ray = inspect.signature(impulse.World.cast_ray).parameters
    assert ray["max_distance"].default == float(np.finfo(np.float32).max)
    assert ray["solid"].default is True
    cast = inspect.signature(impulse.World.cast_shape).parameters
    assert cast["rotation"].default == (0.0, 0.0, 0.0, 1.0)
    assert inspect.signature(impulse.JointBuilder.breakable).parameters["torque"].default == math.inf
    text = pydoc.render_doc(impulse.World, renderer=pydoc.plaintext)
    assert "Ellipsis" not in text
    assert "gravity=(0.0, -9.81, 0.0), dt=0.016666666666666666, settings=None" in text
    assert "step(self, /, n=1)" in text


def stub_defaults():
    """{qualified name: {parameter: default}} of every function in the stubs."""
    tree = ast.parse(STUBS.read_text())
    found = {}

    def walk(body, prefix):
        for node in body:
            if isinstance(node, ast.ClassDef):
                walk(node.body, f"{prefix}{node.name}.")
            elif isinstance(node, ast.FunctionDef):
                if any(isinstance(d, ast.Name) and d.id == "property" or isinstance(d, ast.Attribute)
                       for d in node.decorator_list):
                    continue
                args = node.args
                positional = args.posonlyargs + args.args
                pairs = list(zip(positional[len(positional) - len(args.defaults):], args.defaults, strict=True))
                pairs += [(a, d) for a, d in zip(args.kwonlyargs, args.kw_defaults, strict=True) if d is not None]
                found[prefix + node.name] = {
                    a.arg: eval(compile(ast.Expression(d), str(STUBS), "eval"), {"math": math})
                    for a, d in pairs
                }

    walk(tree.body, "")
    return found


def test_stubs_have_the_runtime_defaults():
    stubs = stub_defaults()
    checked = 0
    for name, defaults in stubs.items():
        assert Ellipsis not in defaults.values(), name
        owner, _, method = name.rpartition(".")
        target = getattr(_impulse, owner) if owner else _impulse
        if method in ("__init__", "__new__"):
            value = target
        elif method.startswith("__") or not hasattr(target, method):
            continue
        else:
            value = getattr(target, method)
        try:
            runtime = inspect.signature(value).parameters
        except ValueError:
            continue
        for parameter, default in defaults.items():
            assert runtime[parameter].default == default, f"{name}: {parameter}"
            checked += 1
    assert checked >= 15


def test_diagnostics_print_a_short_summary():
    world = ground_world()
    for i in range(20):
        world.insert(impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.25), translation=(2.0 * i - 19, 0.2, 0)))
    world.step(5)
    diagnostics = world.diagnostics
    assert isinstance(diagnostics, dict) and isinstance(diagnostics, impulse.Diagnostics)
    assert len(diagnostics["islands"]) == 20  # each ball on the ground is an island
    text = repr(diagnostics)
    assert len(text) < 200, text
    assert text == str(diagnostics)
    assert text.startswith("Diagnostics(step=5, contacts=20, ") and "islands=20" in text
    assert len(repr(dict(diagnostics))) > 5 * len(text)
    assert pickle.loads(pickle.dumps(diagnostics)) == diagnostics


def stub_properties(class_name):
    """{property: annotation text} of a class in the stubs."""
    tree = ast.parse(STUBS.read_text())
    cls = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == class_name)
    return {
        node.name: ast.unparse(node.returns)
        for node in cls.body
        if isinstance(node, ast.FunctionDef)
        and any(isinstance(d, ast.Name) and d.id == "property" for d in node.decorator_list)
    }


def test_settings_properties_are_the_fields():
    # One typed property per field of the scene format's `solver` object, in the runtime and in
    # the stubs, each reading what to_dict() gives; a field added or renamed fails here.
    for name in ("fast", "default", "precise", "reference"):
        settings = impulse.Settings.preset(name)
        fields = settings.to_dict()
        runtime = {n for n, v in vars(impulse.Settings).items() if inspect.isdatadescriptor(v)}
        assert runtime == set(fields)
        assert set(stub_properties("Settings")) == set(fields)
        for field, value in fields.items():
            assert getattr(settings, field) == value, field
    kinds = {bool: "bool", int: "int", float: "float", dict: "dict[str, Any]"}
    for field, annotation in stub_properties("Settings").items():
        value = getattr(impulse.Settings(), field)
        if isinstance(value, str):
            assert annotation.startswith("Literal[") and repr(value) in annotation.replace('"', "'"), field
        else:
            assert annotation == kinds[type(value)], field
    with pytest.raises(AttributeError):
        impulse.Settings().no_such_field  # noqa: B018
    with pytest.raises(AttributeError):
        impulse.Settings().substeps = 3


def test_a_builders_roughness_draws_are_the_scene_fields():
    # A frictionless elastic particle dropped on a rough floor: the builder's draws give the
    # same bits as the scene field, survive pickling, and show in the repr.
    def rough_floor():
        world = impulse.World(gravity=(0, -9.81, 0), dt=1 / 60)
        world.insert(impulse.BodyBuilder.fixed(
            impulse.Shape.cuboid(20, 0.5, 20), translation=(0, -0.5, 0), friction=0.0,
            restitution=1.0, roughness=10.0))
        return world

    builder = impulse.BodyBuilder.particle(
        0.1, translation=(0, 1.1, 0), friction=0.0, restitution=1.0,
        roughness_draws=[(0.7, -0.4), [1.5, 0.25]])
    assert "roughness_draws=[(0.7, -0.4), (1.5, 0.25)]" in repr(builder)
    scene = {
        "bodies": [
            {"kind": "static", "shape": {"type": "cuboid", "half_extents": [20, 0.5, 20]},
             "position": [0, -0.5, 0],
             "material": {"friction": 0.0, "restitution": 1.0, "roughness": 10.0}},
            {"kind": "particle", "shape": {"type": "sphere", "radius": 0.1}, "position": [0, 1.1, 0],
             "material": {"friction": 0.0, "restitution": 1.0},
             "roughness_draws": [[0.7, -0.4], [1.5, 0.25]]},
        ],
    }
    worlds = [rough_floor(), rough_floor(), impulse.World.from_scene(scene)]
    worlds[0].insert(builder)
    worlds[1].insert(pickle.loads(pickle.dumps(builder)))
    for world in worlds:
        world.step(60)
    assert worlds[0].positions.tobytes() == worlds[1].positions.tobytes()
    assert worlds[0].positions.tobytes() == worlds[2].positions.tobytes()
    assert abs(worlds[0].positions[1, 0]) > 0.01  # the draw tilted the bounce
    with pytest.raises(impulse.WorldError, match="roughness_draws"):
        impulse.BodyBuilder.particle(0.1, roughness_draws=[(1.0, 2.0, 3.0)])
    with pytest.raises(impulse.WorldError, match=r"roughness_draws\[0\]\[1\]"):
        rough_floor().insert(impulse.BodyBuilder.particle(0.1, roughness_draws=[(1.0, math.nan)]))


CUBE_VERTICES = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
CUBE_INDICES = [
    (0, 2, 3),
    (0, 3, 1),
    (4, 5, 7),
    (4, 7, 6),
    (0, 1, 5),
    (0, 5, 4),
    (2, 6, 7),
    (2, 7, 3),
    (0, 4, 6),
    (0, 6, 2),
    (1, 3, 7),
    (1, 7, 5),
]


def test_trimesh_argument_errors_name_the_argument():
    indices = [list(t) for t in CUBE_INDICES]
    indices[4][2] = -1
    with pytest.raises(ValueError, match=r"indices\[4\]\[2\]: must be ≥ 0 .* got -1"):
        impulse.Shape.trimesh(CUBE_VERTICES, indices)
    with pytest.raises(ValueError, match=r"indices\[0\]\[1\]: must be < 2³²"):
        impulse.Shape.trimesh(CUBE_VERTICES, [(0, 2**32, 3)] + CUBE_INDICES[1:])
    with pytest.raises(ValueError, match=r"vertices: must be real numbers, got dtype complex128"):
        impulse.Shape.trimesh(np.array(CUBE_VERTICES, dtype=complex), CUBE_INDICES)
    with pytest.raises(ValueError, match=r"indices: must be integers"):
        impulse.Shape.trimesh(CUBE_VERTICES, np.array(CUBE_INDICES, dtype=float))
    with pytest.raises(ValueError, match=r"vertices: must have shape \(N, 3\), got \[8, 2\]"):
        impulse.Shape.trimesh([v[:2] for v in CUBE_VERTICES], CUBE_INDICES)
    shape = impulse.Shape.trimesh(np.array(CUBE_VERTICES, dtype=np.float64), np.array(CUBE_INDICES))
    assert shape.to_dict()["indices"][0] == [0, 2, 3]


def test_a_moving_open_mesh_warns_with_its_mass_in_the_library_and_the_scene():
    """One rule for the library and scene files: a dynamic body's open mesh (the unit cube
    without its x = 1 face) is weighed by its convex parts, and both paths say so with the
    parts' volume and the closed hull's; the closed cube weighs its solid (1,000 kg at the
    default density) without a warning."""
    import warnings

    open_cube = [t for t in CUBE_INDICES if t not in ((1, 3, 7), (1, 7, 5))]
    for indices, closed in ((CUBE_INDICES, True), (open_cube, False)):
        with warnings.catch_warnings(record=True) as library:
            warnings.simplefilter("always")
            world = impulse.World()
            world.insert(impulse.BodyBuilder.dynamic(impulse.Shape.trimesh(CUBE_VERTICES, indices)))
        shape = {"type": "trimesh", "vertices": CUBE_VERTICES, "indices": indices}
        with warnings.catch_warnings(record=True) as scene:
            warnings.simplefilter("always")
            from_scene = impulse.World.from_scene({"bodies": [{"kind": "dynamic", "shape": shape}]})
        assert world.masses[0] == from_scene.masses[0]
        if closed:
            assert world.masses[0] == pytest.approx(1000.0, rel=1e-4)
            assert [str(w.message) for w in library + scene] == []
            continue
        for caught, where in ((library, "Shape.trimesh: "), (scene, "bodies[0].shape: ")):
            messages = [str(w.message) for w in caught if issubclass(w.category, UserWarning)]
            assert len(messages) == 1, messages
            assert messages[0].startswith(where + "the mesh is not closed (4 edges"), messages[0]
            assert "its convex hull, closed, has 1.0000e0 m³" in messages[0], messages[0]


def _torus(n, m, ring=1.0, tube=0.3):
    """A closed torus of n × m quads (two triangles each), wound outward."""
    u = np.repeat(np.arange(n) * 2 * np.pi / n, m)
    v = np.tile(np.arange(m) * 2 * np.pi / m, n)
    vertices = np.stack(
        [(ring + tube * np.cos(v)) * np.cos(u), tube * np.sin(v), (ring + tube * np.cos(v)) * np.sin(u)],
        axis=1,
    )
    indices = []
    for i in range(n):
        for j in range(m):
            a, b = i * m + j, ((i + 1) % n) * m + j
            c, d = ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
            indices += [(a, d, c), (a, c, b)]
    return vertices, np.array(indices)


@pytest.mark.parametrize("path", ["builder", "scene"])
def test_ctrl_c_interrupts_a_long_decomposition(path):
    """Ctrl-C (a SIGINT to this process) during a moving mesh's convex decomposition (a
    4,608-quad torus at resolution 160, seconds of V-HACD) raises KeyboardInterrupt from the
    call that decomposes, as it does between a run's steps, from `BodyBuilder.dynamic` and from
    `World.from_scene` alike."""
    import os
    import signal
    import threading
    import time

    vertices, indices = _torus(96, 48)
    parameters = {"resolution": 160 if path == "builder" else 159}
    fired = []
    # A process started in the background of a non-interactive shell inherits SIGINT ignored,
    # and Python then installs no KeyboardInterrupt handler: install it, as an interactive
    # session has it.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)

    def interrupt():
        fired.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(0.5, interrupt)
    try:
        timer.start()
        shape = impulse.Shape.trimesh(vertices, indices, decomposition=parameters)
        scene = {"bodies": [{"kind": "dynamic", "shape": shape.to_dict()}]}
        built = None
        with pytest.raises(KeyboardInterrupt):
            # A call that ran to its end would leave `built` set: a signal only handled after
            # it returns raises at the next call, not inside this one.
            if path == "builder":
                built = impulse.BodyBuilder.dynamic(shape)
            else:
                built = impulse.World.from_scene(scene)
            time.sleep(0)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    assert fired, "the call ended before Ctrl-C"
    assert built is None, "the decomposition ran to its end before the KeyboardInterrupt"
    print(f"{path}: interrupted {time.monotonic() - fired[0]:.3f} s after Ctrl-C")
