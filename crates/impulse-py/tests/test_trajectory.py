"""Trajectories: shapes, frame numbering, and exact round trips through .npz and Parquet."""

import numpy as np
import pytest

import impulse


def test_simulate_frames_and_shapes():
    world = impulse.World.from_scene("pyramid20")
    n = len(world)
    trajectory = world.simulate(10, every=4)
    # The start, every 4th step, and the last.
    assert trajectory.steps.tolist() == [0, 4, 8, 10]
    assert trajectory.positions.shape == (4, n, 3) and trajectory.positions.dtype == np.float32
    assert trajectory.orientations.shape == (4, n, 4)
    assert trajectory.times.dtype == np.float64 and trajectory.steps.dtype == np.int64
    assert trajectory.times[-1] == pytest.approx(10 * world.dt)
    assert trajectory.names == world.names
    assert np.array_equal(trajectory.positions[-1], world.positions)


def test_simulate_equals_stepping():
    a = impulse.World.from_scene("pyramid20")
    b = impulse.World.from_scene("pyramid20")
    trajectory = a.simulate(25, every=5)
    for frame, step in enumerate(trajectory.steps[1:], start=1):
        b.step(int(step) - b.step_count)
        assert trajectory.positions[frame].tobytes() == b.positions.tobytes()


@pytest.mark.parametrize("suffix", [".npz", ".parquet"])
def test_save_and_load_round_trip_exactly(tmp_path, suffix):
    if suffix == ".parquet":
        pytest.importorskip("pyarrow")
    trajectory = impulse.World.from_scene("pyramid20").simulate(12, every=3)
    path = tmp_path / f"run{suffix}"
    trajectory.save(path)
    loaded = impulse.load_trajectory(path)
    assert loaded.positions.tobytes() == trajectory.positions.tobytes()
    assert loaded.orientations.tobytes() == trajectory.orientations.tobytes()
    assert loaded.steps.tolist() == trajectory.steps.tolist()
    assert loaded.times.tobytes() == trajectory.times.tobytes()
    assert loaded.names == trajectory.names


def test_bad_trajectory_files(tmp_path):
    trajectory = impulse.World.from_scene("pyramid20").simulate(2)
    with pytest.raises(ValueError, match="npz or .parquet"):
        trajectory.save(tmp_path / "run.csv")
    np.savez(tmp_path / "other.npz", a=np.zeros(3))
    with pytest.raises(ValueError, match="not a trajectory"):
        impulse.load_trajectory(tmp_path / "other.npz")
    with pytest.raises(ValueError, match="expected shape"):
        impulse.Trajectory(np.zeros((2, 3, 3)), np.zeros((2, 3, 4)), [0], [0.0], ["a", "b", "c"])
