"""The Python API against the Rust engine: same results to the bit, arrays, setters, pickling."""

import json
import pickle
import subprocess

import numpy as np
import pytest

import impulse


def cli_frames(cli, scene, steps, tmp_path, *extra):
    """Every frame `impulse run` writes as JSON lines: (steps, (F, N, 7) float32)."""
    out = tmp_path / "frames.jsonl"
    subprocess.run(
        [cli, "run", scene, "--steps", str(steps), "--out", str(out), "--quiet", *extra],
        check=True,
        capture_output=True,
    )
    frames = [json.loads(line) for line in out.read_text().splitlines()]
    # serde_json writes each f32 widened to f64 exactly, so the cast back is exact.
    poses = np.array([f["bodies"] for f in frames], dtype=np.float64).astype(np.float32)
    return np.array([f["frame"] for f in frames]), poses


def test_pyramid_matches_the_command_line_to_the_bit(impulse_cli, tmp_path):
    steps, poses = cli_frames(impulse_cli, "pyramid20", 60, tmp_path)
    world = impulse.World.from_scene("pyramid20")
    trajectory = world.simulate(60)
    assert trajectory.steps.tolist() == steps.tolist()
    np.testing.assert_array_equal(trajectory.positions.view(np.uint32), poses[..., :3].view(np.uint32))
    np.testing.assert_array_equal(
        trajectory.orientations.view(np.uint32), poses[..., 3:].view(np.uint32)
    )
    # Something moved: the comparison is not of two initial states.
    assert not np.array_equal(trajectory.positions[0], trajectory.positions[-1])


def test_preset_matches_the_command_line_preset(impulse_cli, tmp_path):
    _, poses = cli_frames(impulse_cli, "stack30", 30, tmp_path, "--preset", "fast")
    world = impulse.World.from_scene("stack30", settings="fast")
    world.step(30)
    np.testing.assert_array_equal(world.positions.view(np.uint32), poses[-1, :, :3].view(np.uint32))


def test_scene_file_dict_and_builtin_agree(repository):
    path = repository / "scenes" / "example-three-spheres.json"
    scene = json.loads(path.read_text())
    from_file = impulse.World.from_scene(path)
    from_str = impulse.World.from_scene(str(path))
    from_dict = impulse.World.from_scene(scene)
    for world in (from_file, from_str, from_dict):
        world.step(20)
    assert from_file.positions.tobytes() == from_str.positions.tobytes()
    assert from_file.positions.tobytes() == from_dict.positions.tobytes()


def test_arrays_have_the_documented_shapes_and_dtypes():
    world = impulse.World.from_scene("pyramid20")
    n = len(world)
    assert n == world.body_count == len(world.names) > 0
    for name, columns in [
        ("positions", 3),
        ("orientations", 4),
        ("linear_velocities", 3),
        ("angular_velocities", 3),
    ]:
        array = getattr(world, name)
        assert array.shape == (n, columns), name
        assert array.dtype == np.float32, name
    # Unit quaternions, and the view agrees with a copy taken through the setter's path.
    assert np.allclose(np.linalg.norm(world.orientations, axis=1), 1.0, atol=1e-6)


def test_views_are_read_only_live_and_keep_the_world_alive():
    world = impulse.World.from_scene("pyramid20")
    positions = world.positions
    with pytest.raises(ValueError):
        positions[0, 0] = 1.0
    before = positions.copy()
    world.step(10)
    # The view shows the current state; the copy keeps the old one.
    assert not np.array_equal(positions, before)
    assert np.array_equal(positions, world.positions)
    del world
    # The view holds the world: reading after the last name is gone is safe.
    assert np.isfinite(positions).all()


def test_insert_and_remove_refuse_while_views_are_alive():
    world = impulse.World(gravity=(0, -9.81, 0))
    world.insert(impulse.BodyBuilder.fixed(impulse.Shape.cuboid(5, 0.5, 5), translation=(0, -0.5, 0)))
    ball = world.insert(impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.5), translation=(0, 2, 0)))
    column = world.positions[:, 1]  # a slice of a view is a view too
    with pytest.raises(impulse.WorldError, match="array view"):
        world.insert(impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.5), translation=(3, 2, 0)))
    with pytest.raises(impulse.WorldError, match="array view"):
        world.remove(ball)
    assert len(world) == 2
    del column
    world.insert(impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.5), translation=(3, 2, 0)))
    assert world.remove(ball) is None
    assert len(world) == 2


def test_a_ball_falls_as_the_closed_form_says():
    # Free fall for 30 steps of 1/60 s from rest: the semi-implicit Euler steps put it at
    # y0 - g dt^2 (1 + 2 + ... + k) after k substep updates; check the exact value loosely and
    # the velocity exactly enough: v = -g t.
    world = impulse.World(gravity=(0, -10, 0), dt=1 / 60)
    world.insert(impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.5), translation=(0, 100, 0)))
    world.step(30)
    assert world.linear_velocities[0, 1] == pytest.approx(-10 * 0.5, rel=1e-5)
    assert world.positions[0, 1] == pytest.approx(100 - 0.5 * 10 * 0.5**2, abs=0.05)


def test_setters_validate_and_apply():
    world = impulse.World.from_scene("pyramid20")
    n = len(world)
    new = world.positions.copy()
    new[:, 0] += 10.0
    world.positions = new
    assert np.array_equal(world.positions, new)
    with pytest.raises(impulse.WorldError, match=rf"expected shape \({n}, 3\)"):
        world.positions = np.zeros((n, 4))
    with pytest.raises(impulse.WorldError, match="expected shape"):
        world.positions = np.zeros(n * 3)
    bad = new.copy()
    bad[2, 1] = np.nan
    with pytest.raises(impulse.WorldError, match="row 2, column 1: must be finite"):
        world.positions = bad
    assert np.array_equal(world.positions, new), "a refused assignment changes nothing"
    with pytest.raises(impulse.WorldError):
        world.orientations = np.zeros((n, 4))
    # A static body cannot be given a velocity; the error names it and nothing changes.
    kinds = world.kinds
    static = kinds.index("static")
    velocities = np.zeros((n, 3), np.float32)
    velocities[:, 0] = 1.0
    with pytest.raises(impulse.WorldError, match=f"body {static}"):
        world.linear_velocities = velocities
    assert not world.linear_velocities.any()
    velocities[static] = 0.0
    world.linear_velocities = velocities
    assert np.array_equal(world.linear_velocities, velocities)


def test_pickle_round_trips_to_the_bit():
    world = impulse.World.from_scene("pyramid20")
    world.step(15)
    copy = pickle.loads(pickle.dumps(world))
    assert copy.step_count == world.step_count == 15
    assert copy.positions.tobytes() == world.positions.tobytes()
    assert copy.linear_velocities.tobytes() == world.linear_velocities.tobytes()
    world.step(20)
    copy.step(20)
    assert copy.positions.tobytes() == world.positions.tobytes()
    assert copy.orientations.tobytes() == world.orientations.tobytes()
    assert copy.diagnostics == world.diagnostics


def test_snapshot_bytes_errors():
    with pytest.raises(impulse.WorldError, match="not an impulse world snapshot"):
        impulse.World.from_snapshot(b"hello")
    data = bytearray(impulse.World.from_scene("pyramid20").snapshot())
    data[-1] ^= 0xFF
    with pytest.raises(impulse.WorldError, match="corrupt"):
        impulse.World.from_snapshot(bytes(data))


def test_diagnostics_and_quality():
    world = impulse.World.from_scene("pyramid20")
    start = world.positions.copy()
    world.step(30)
    d = world.diagnostics
    assert d["step"] == 30
    for key in ("natural_map_residual", "kinetic_energy", "contacts", "iterations"):
        assert key in d
    assert d["contacts"] > 0
    q = world.quality(start)
    assert set(q) == {"max_overlap_m", "top_body", "top_sink_m", "max_drift_m", "kinetic_energy_j"}
    assert q["max_overlap_m"] >= 0 and q["max_drift_m"] >= 0
    top = q["top_body"]
    assert q["top_sink_m"] == pytest.approx(float(start[top, 1] - world.positions[top, 1]))
    assert world.kinds[top] == "dynamic"
    plain = world.quality()
    assert plain["top_sink_m"] is None and plain["max_drift_m"] is None
    with pytest.raises(impulse.WorldError, match="initial_positions"):
        world.quality(start[:3])


def test_profile_names_the_stages_and_the_solve_phases():
    stages = [
        "kinematic", "broad_phase", "narrow_phase", "islands", "assembly", "solve", "scatter",
        "continuous", "store_impulses", "finish", "end_step",
    ]
    phases = [
        "prepare", "integrate_velocities", "warm_start", "main_solve", "integrate_positions",
        "relax", "impacts", "record",
    ]
    world = impulse.World.from_scene("pyramid20")
    assert world.profile_solve_phases is False
    world.step()
    profile = world.profile
    assert list(profile) == [*stages, "total", "solve_phases"]
    assert list(profile["solve_phases"]) == phases
    assert all(ms == 0.0 for ms in profile["solve_phases"].values())
    world.profile_solve_phases = True
    world.parallel = False
    world.step()
    profile = world.profile
    assert sum(profile["solve_phases"].values()) > 0.0
    # On one thread the islands' phases are parts of the solve stage's time.
    assert sum(profile["solve_phases"].values()) <= profile["solve"] * 1.001 + 1e-4


def test_settings_presets_and_fields():
    fast = impulse.Settings.preset("fast")
    assert fast.substeps == 8
    assert impulse.Settings() == impulse.Settings.preset("default")
    assert fast.replace(substeps=12).substeps == 12
    assert pickle.loads(pickle.dumps(fast)) == fast
    with pytest.raises(impulse.WorldError, match="no preset named 'quick'"):
        impulse.Settings.preset("quick")
    with pytest.raises(impulse.WorldError, match="substeps"):
        fast.replace(substeps=0)
    with pytest.raises(impulse.WorldError, match="unknown field"):
        fast.replace(sub_steps=3)
    world = impulse.World.from_scene("stack30", settings=fast)
    assert world.settings.substeps == 8


def test_fused_multiply_adds_are_a_setting():
    # Off by default; on, the lanes round a multiply and an addition once where the CPU has FMA,
    # which moves a settling stack by far less than a millimetre.
    assert impulse.Settings().fused_multiply_add is False
    plain = impulse.Settings().replace(sleep=False)
    fused = plain.replace(fused_multiply_add=True)
    assert fused.fused_multiply_add is True
    worlds = [impulse.World.from_scene("stack30", settings=s) for s in (plain, fused)]
    for world in worlds:
        world.step(60)
    assert np.abs(worlds[0].positions - worlds[1].positions).max() < 1e-3


def test_scene_errors_name_the_file_line_and_field(tmp_path):
    path = tmp_path / "bad.json"
    path.write_text(
        '{\n  "bodies": [\n    {"kind": "dynamic", "shape": {"type": "sphere", "radius": -1},'
        ' "position": [0, 1, 0]}\n  ]\n}\n'
    )
    with pytest.raises(impulse.SceneError) as error:
        impulse.World.from_scene(path)
    message = str(error.value)
    # As `impulse run` prints it: file:line:column: field: problem.
    assert "bad.json:3:" in message and "bodies[0].shape.radius: must be > 0" in message
    with pytest.raises(impulse.SceneError, match="no scene file or built-in scene named 'nope'"):
        impulse.World.from_scene("nope")
    with pytest.raises(impulse.SceneError):
        impulse.World.from_scene(str(tmp_path / "missing.json"))
    with pytest.raises(impulse.SceneError, match="bodies"):
        impulse.World.from_scene({"bodies": [{"kind": "dynamic"}]})
    with pytest.raises(impulse.SceneError):
        impulse.World.from_scene(42)
    assert "pyramid20" in impulse.scenes()


def test_bad_arguments_raise_and_never_crash():
    world = impulse.World.from_scene("pyramid20")
    with pytest.raises(impulse.WorldError):
        impulse.World(dt=0.0)
    with pytest.raises(impulse.WorldError):
        impulse.World(gravity=(0, float("nan"), 0))
    with pytest.raises(impulse.WorldError, match="n: must be a whole number"):
        world.step(-1)
    with pytest.raises(impulse.WorldError):
        world.simulate(10, every=0)
    with pytest.raises(impulse.WorldError):
        world.dt = -1.0
    handle = world.handle_of(0)
    with pytest.raises(impulse.WorldError):
        world.apply_force(handle, (0, float("inf"), 0))
    with pytest.raises(IndexError):
        world.handle_of(10**6)
    with pytest.raises(impulse.WorldError):
        impulse.World().insert(impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.5), mass=-1.0))
    with pytest.raises(impulse.WorldError, match="radius"):
        impulse.BodyBuilder.dynamic(impulse.Shape.ball(-1.0))
    with pytest.raises(impulse.WorldError, match="no body property"):
        impulse.BodyBuilder.dynamic(impulse.Shape.ball(1.0), colour="red")


def test_a_blow_up_raises_step_error_with_the_frames_so_far():
    world = impulse.World(gravity=(0, -9.81, 0), dt=1 / 60)
    world.insert(impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.5), linear_velocity=(0, 0, 0)))
    handle = world.handle_of(0)
    world.apply_impulse(handle, (0, 0, 1e12))
    with pytest.raises(impulse.StepError, match="blew up at step") as error:
        world.simulate(100)
    assert error.value.trajectory.frame_count >= 1


def test_forces_and_impulses_change_momentum_as_newton_says():
    world = impulse.World(gravity=(0, 0, 0), dt=0.01)
    handle = world.insert(
        impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.5), mass=2.0, translation=(0, 0, 0))
    )
    world.apply_impulse(handle, (4.0, 0, 0))
    assert world.linear_velocities[0, 0] == pytest.approx(2.0)
    world.apply_force(handle, (0, 20.0, 0))
    world.step()
    # F dt / m = 20 * 0.01 / 2
    assert world.linear_velocities[0, 1] == pytest.approx(0.1, rel=1e-5)
    assert world.masses[0] == pytest.approx(2.0)


def test_the_recycle_distance_is_a_setting_that_fast_raises():
    # Contacts of flat shapes are kept while their bodies move less than this relative to each
    # other: 1 mm by default, 2 cm at `fast`; refused when negative; a preset brings its own.
    assert impulse.Settings().recycle_distance == pytest.approx(0.001)
    assert impulse.Settings.preset("fast").recycle_distance == pytest.approx(0.02)
    assert impulse.Settings.preset("precise").recycle_distance == pytest.approx(0.001)
    assert impulse.Settings().replace(recycle_distance=0.0).recycle_distance == 0.0
    with pytest.raises(ValueError, match="recycle_distance"):
        impulse.Settings().replace(recycle_distance=-0.01)


def test_split_steps_are_a_setting_and_report_their_pieces():
    # The tolerance is a field of the settings like any other, refused when negative; a pyramid
    # at rest with it on steps in one piece a step.
    settings = impulse.Settings().replace(split_overlap=0.001)
    assert settings.split_overlap == 0.001
    assert impulse.Settings().split_overlap == 0.0
    with pytest.raises(ValueError, match="split_overlap"):
        impulse.Settings().replace(split_overlap=-1.0)
    world = impulse.World.from_scene("pyramid20")
    world.settings = settings
    world.step(3)
    assert world.diagnostics["step"] == 3
    assert world.diagnostics["pieces"] == 1


def test_collision_steps_are_a_setting_and_reported():
    # At most how many collision steps a step takes is a field of the settings, 4 by default
    # (1 off) and refused at 0; two balls closing at 30 m/s (50 cm a step, five radii) take
    # their step in four, one step from outside, their momentum kept; in whole steps with 1.
    assert impulse.Settings().collision_steps == 4
    with pytest.raises(ValueError, match="collision_steps"):
        impulse.Settings().replace(collision_steps=0)
    elastic = {"friction": 0.0, "restitution": 1.0, "density": 1000.0}
    scene = {
        "gravity": [0.0, 0.0, 0.0],
        "dt": 1.0 / 60.0,
        "materials": {"elastic": elastic},
        "solver": {"collision_steps": 4},
        "bodies": [
            {"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.1}, "position": [-0.6, 0.0, 0.0],
             "linear_velocity": [30.0, 0.0, 0.0], "material": "elastic"},
            {"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.1}, "position": [0.0, 0.0, 0.0],
             "material": "elastic"},
        ],
    }
    world = impulse.World.from_scene(scene)
    assert world.settings.collision_steps == 4
    world.step(2)
    assert world.diagnostics["step"] == 2
    assert world.diagnostics["collision_steps"] == 4
    assert world.diagnostics["pieces"] == 4
    velocities = world.state()["linear_velocities"]
    assert velocities[1][0] > 1.0
    assert abs(velocities[0][0] + velocities[1][0] - 30.0) < 0.03
    scene["solver"] = {"collision_steps": 1}
    whole = impulse.World.from_scene(scene)
    whole.step(2)
    assert whole.diagnostics["collision_steps"] == 1
    assert whole.diagnostics["pieces"] == 1
