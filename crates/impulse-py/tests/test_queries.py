"""Queries and contacts: ray and shape casts, contact pairs and events, the contact LCP."""

import numpy as np
import pytest

import impulse


def ball_on_ground():
    world = impulse.World(gravity=(0, -9.81, 0), dt=1 / 60)
    ground = world.insert(
        impulse.BodyBuilder.fixed(impulse.Shape.cuboid(5, 0.5, 5), translation=(0, -0.5, 0))
    )
    ball = world.insert(
        impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.5), translation=(0, 0.6, 0), name="ball")
    )
    return world, ground, ball


def test_ray_cast_hits_the_top_of_the_ball():
    world, _, ball = ball_on_ground()
    hit = world.cast_ray((0, 5, 0), (0, -1, 0))
    assert hit["body"] == ball and hit["index"] == 1
    assert hit["distance"] == pytest.approx(5 - 1.1, abs=1e-5)
    assert hit["normal"] == pytest.approx([0, 1, 0], abs=1e-5)
    assert world.cast_ray((0, 5, 0), (0, 1, 0)) is None


def test_shape_cast_meets_the_ground_when_the_gap_closes():
    world, ground, _ = ball_on_ground()
    # A ball of radius 0.25 at x = 3, 1.25 m above the ground, falling at 1 m/s: touches at 1 s.
    hit = world.cast_shape(impulse.Shape.ball(0.25), (3, 1.25, 0), (0, -1, 0), max_time=5)
    assert hit["body"] == ground
    assert hit["time"] == pytest.approx(1.0, abs=1e-4)
    assert hit["normal"] == pytest.approx([0, -1, 0], abs=1e-5)
    with pytest.raises(impulse.WorldError):
        world.cast_shape(impulse.Shape.ball(-1), (0, 3, 0), (0, -1, 0), max_time=1)


def test_contact_pairs_and_events_of_a_resting_ball():
    world, ground, ball = ball_on_ground()
    world.step(60)
    pairs = [p for p in world.contact_pairs() if p["touching"]]
    assert len(pairs) == 1
    pair = pairs[0]
    assert {pair["body1"], pair["body2"]} == {ground, ball}
    points = pair["points"]
    # At rest the normal impulses carry the weight over one step: m g dt.
    mass = world.masses[1]
    assert points["normal_impulse"].sum() == pytest.approx(mass * 9.81 / 60, rel=0.05)
    assert points["position"].shape[1] == 3
    started = impulse.World(gravity=(0, -9.81, 0))
    started.insert(impulse.BodyBuilder.fixed(impulse.Shape.cuboid(5, 0.5, 5), translation=(0, -0.5, 0)))
    started.insert(impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.5), translation=(0, 1.0, 0)))
    events = []
    for _ in range(60):
        started.step()
        events += started.contact_events()
    assert [e["type"] for e in events][:1] == ["started"]


def test_contact_lcp_is_solved_by_the_engine_impulses():
    world = impulse.World(gravity=(0, -9.81, 0))
    world.insert(impulse.BodyBuilder.fixed(impulse.Shape.cuboid(5, 0.5, 5), translation=(0, -0.5, 0)))
    for level in range(3):
        world.insert(
            impulse.BodyBuilder.dynamic(
                impulse.Shape.cuboid(0.5, 0.5, 0.5), translation=(0, 0.5 + level, 0)
            )
        )
    world.step(10)
    lcp = world.contact_lcp()
    n = lcp["b"].shape[0]
    assert n > 0
    a = lcp["A"]
    try:
        import scipy.sparse  # noqa: F401

        assert a.shape == (n, n)
        dense = a.toarray()
    except ImportError:
        dense = np.zeros(a["shape"])
        dense[a["row"], a["col"]] = a["data"]
    # A = J M⁻¹ Jᵀ (plus regularisation) is symmetric positive semidefinite, to the rounding of
    # the float32 data it is assembled from.
    scale = np.abs(dense).max()
    assert np.allclose(dense, dense.T, rtol=0, atol=1e-6 * scale)
    assert np.linalg.eigvalsh((dense + dense.T) / 2).min() > -1e-6 * scale
    assert (np.diag(dense) > 0).all()
    gamma = lcp["engine_solution"]
    normal = lcp["friction_index"] < 0
    assert (gamma[normal] >= -1e-12).all(), "normal impulses push, never pull"
    assert lcp["contact_of_row"].shape == (n,)
