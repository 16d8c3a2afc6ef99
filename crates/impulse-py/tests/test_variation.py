"""Overrides and seeded jitter: the same variation as `impulse run --set/--seed/--jitter-*`."""

import numpy as np
import pytest

import impulse
from test_world import cli_frames


def test_overrides_and_seed_match_the_command_line(impulse_cli, tmp_path):
    _, poses = cli_frames(
        impulse_cli,
        "pyramid20",
        20,
        tmp_path,
        "--set",
        "materials.default.friction=0.3",
        "--seed",
        "7",
        "--jitter-position",
        "0.01",
        "--jitter-velocity",
        "0.2",
    )
    world = impulse.World.from_scene(
        "pyramid20",
        overrides={"materials.default.friction": 0.3},
        seed=7,
        jitter={"position": 0.01, "velocity": 0.2},
    )
    trajectory = world.simulate(20)
    np.testing.assert_array_equal(
        trajectory.positions.view(np.uint32), poses[..., :3].view(np.uint32)
    )


def test_overrides_as_mapping_or_strings_agree():
    a = impulse.World.from_scene("stack30", overrides={"solver.substeps": 12, "dt": 0.01})
    b = impulse.World.from_scene("stack30", overrides=["solver.substeps=12", "dt=0.01"])
    assert a.settings.substeps == b.settings.substeps == 12
    assert a.dt == b.dt == pytest.approx(0.01)
    a.step(10)
    b.step(10)
    assert a.positions.tobytes() == b.positions.tobytes()


def test_seeds_repeat_and_differ():
    jitter = {"position": 0.02, "angle": 5.0}
    first = impulse.World.from_scene("stack30", seed=3, jitter=jitter).positions.copy()
    again = impulse.World.from_scene("stack30", seed=3, jitter=jitter).positions.copy()
    other = impulse.World.from_scene("stack30", seed=4, jitter=jitter).positions.copy()
    plain = impulse.World.from_scene("stack30").positions.copy()
    assert first.tobytes() == again.tobytes()
    assert first.tobytes() != other.tobytes()
    assert first.tobytes() != plain.tobytes()
    # Only the dynamic bodies move, each within the jitter radius.
    moved = np.linalg.norm(first - plain, axis=1)
    assert moved.max() <= 0.02 + 1e-6


def test_variation_errors_name_the_override():
    with pytest.raises(impulse.SceneError, match="solver.substeps"):
        impulse.World.from_scene("stack30", overrides={"solver.substeps": 0})
    with pytest.raises(impulse.SceneError, match="materials.default.fricton"):
        impulse.World.from_scene("stack30", overrides=["materials.default.fricton=0.2"])
    with pytest.raises(impulse.SceneError, match="no key 'spin'"):
        impulse.World.from_scene("stack30", seed=1, jitter={"spin": 1.0})
    with pytest.raises(impulse.SceneError, match="angle"):
        impulse.World.from_scene("stack30", seed=1, jitter={"angle": 400.0})
    with pytest.raises(impulse.SceneError, match="path=value"):
        impulse.World.from_scene("stack30", overrides=[3])
