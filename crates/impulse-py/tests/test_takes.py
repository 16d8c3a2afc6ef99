"""Directable takes: goal costs against closed forms, variations applied exactly, a search that
finds a take whose exported scene reproduces it to the bit, resume, the command line's exit
codes and the contact sheet (in a real headless browser when Chromium is installed)."""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys

import impulse
import numpy as np
import pytest
from impulse.takes import Record, Variation, custom, evaluate, goal_from_dict, load, search, sheet
from impulse.takes._search import simulate_take
from impulse.takes.cli import main as cli_main

#: A ball on a frictionless floor, rolling nowhere: a take must give it the speed to reach a box.
SCENE = {
    "name": "roll",
    "materials": {"ice": {"friction": 0.0, "restitution": 0.0}},
    "bodies": [
        {
            "name": "ground",
            "kind": "static",
            "material": "ice",
            "shape": {"type": "half_space", "normal": [0, 1, 0]},
        },
        {
            "name": "ball",
            "kind": "dynamic",
            "material": "ice",
            "shape": {"type": "sphere", "radius": 0.1},
            "position": [0.0, 0.1, 0.0],
        },
    ],
}
STEPS = 60  # 1 s
#: Takes per worked shot in the documented searches (docs/takes.md, "Four worked shots").
SHOTS_BUDGET = 320
#: Takes of the hoop searches whose met takes are checked to the bit (5 generations).
HOOP_BUDGET = 160
#: The ball must end 0.3-0.6 m along x: a speed of 0.3-0.6 m/s, one to two scales of 0.3 m/s.
TARGET = {
    "type": "ends_inside",
    "body": "ball",
    "region": {"box": {"min": [0.3, 0.0, -0.2], "max": [0.6, 0.3, 0.2]}},
}
VARIATION = {"bodies": ["ball"], "velocity": 0.3}


def _record(positions, orientations=None, touching=None, dt=0.5):
    positions = np.asarray(positions, dtype=np.float64)
    frames, bodies = positions.shape[:2]
    if orientations is None:
        orientations = np.tile([0.0, 0.0, 0.0, 1.0], (frames, bodies, 1))
    return Record(
        times=np.arange(frames) * dt,
        positions=positions,
        orientations=np.asarray(orientations, dtype=np.float64),
        linear_velocities=np.zeros((frames, bodies, 3)),
        angular_velocities=np.zeros((frames, bodies, 3)),
        touching=touching or [set() for _ in range(frames)],
        names=[f"b{k}" for k in range(bodies)],
        gravity=np.array([0.0, -9.81, 0.0]),
        dt=dt,
    )


def test_region_goals_are_distances_to_the_region():
    # One body at x = 0, 1, 2, 3 m at t = 0, 0.5, 1, 1.5 s; the box spans x in [2.5, 4].
    record = _record([[[x, 0.0, 0.0]] for x in (0.0, 1.0, 2.0, 3.0)])
    box = {"box": {"min": [2.5, -1, -1], "max": [4, 1, 1]}}
    assert goal_from_dict({"type": "ends_inside", "body": 0, "region": box}).cost(record) == 0.0
    ends_early = {"type": "ends_inside", "body": "b0", "region": box, "at": 0.5}
    assert goal_from_dict(ends_early).cost(record) == pytest.approx(1.5)
    passes = {"type": "passes_through", "body": 0, "region": box, "between": [0, 1]}
    assert goal_from_dict(passes).cost(record) == pytest.approx(0.5)
    stays = {"type": "stays_inside", "body": 0, "region": box}
    assert goal_from_dict(stays).cost(record) == pytest.approx(2.5)
    sphere = {"sphere": {"center": [3.0, 4.0, 0.0], "radius": 1.0}}
    # At the end the body is 4 m from the centre: 3 m outside.
    assert goal_from_dict({"type": "ends_inside", "body": 0, "region": sphere}).cost(
        record
    ) == pytest.approx(3.0)


def test_axis_goals_measure_the_angle_from_up():
    # Turned 90 degrees about z: the body's y axis lies along -x, 90 degrees from up.
    q = [0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)]
    record = _record([[[0, 0, 0]]], orientations=[[q]])
    rests = goal_from_dict(
        {"type": "rests_with_axis_up", "body": 0, "axis": [0, 1, 0], "tolerance_degrees": 10}
    )
    assert rests.cost(record) == pytest.approx(math.radians(80))
    # The body's x axis points up: met.
    assert goal_from_dict({"type": "rests_with_axis_up", "body": 0, "axis": [1, 0, 0]}).cost(
        record
    ) == pytest.approx(0.0, abs=1e-7)
    assert goal_from_dict({"type": "tilted", "body": 0, "axis": [0, 1, 0]}).cost(record) == 0.0
    assert goal_from_dict({"type": "tilted", "body": 0, "axis": [1, 0, 0], "min_degrees": 30}).cost(
        record
    ) == pytest.approx(math.radians(30), abs=1e-6)


def test_a_knocked_over_goal_is_graded_by_the_largest_tilt_reached():
    # A pin that rocks to 30 degrees about z and stands again, against one that never moves and
    # one that ends at 60 degrees (met: at least 45).
    def turned(degrees):
        half = math.radians(degrees) / 2
        return [0.0, 0.0, math.sin(half), math.cos(half)]

    goal = goal_from_dict({"type": "tilted", "body": 0, "axis": [0, 1, 0], "min_degrees": 45})
    still = _record([[[0, 0, 0]]] * 3)
    rocked = _record([[[0, 0, 0]]] * 3, orientations=[[turned(a)] for a in (0, 30, 0)])
    fallen = _record([[[0, 0, 0]]] * 3, orientations=[[turned(a)] for a in (0, 30, 60)])
    # Half the final angle short of 45 degrees, half the largest one short of it.
    assert goal.cost(still) == pytest.approx(math.radians(45))
    assert goal.cost(rocked) == pytest.approx(0.5 * math.radians(45) + 0.5 * math.radians(15))
    assert goal.cost(fallen) == 0.0


def test_the_search_ranks_a_take_meeting_the_rare_goal_first():
    # Goal "rare" is met by 1 take of 4, "common" by 3: (4 + 1) / (1 + 1) = 2.5 against
    # (4 + 1) / (3 + 1) = 1.25. A take missing only the common goal (by far) ranks above one
    # missing only the rare goal (by a little), which a plain total cost would rank the other way.
    from impulse.takes._search import _ranking

    goals = [goal_from_dict({"type": "tilted", "body": 0, "name": name}) for name in ("rare", "common")]

    def row(rare, common, perturbation=1.0):
        return {"cost.rare": rare, "cost.common": common, "cost": rare + common,
                "perturbation": perturbation}

    misses_common, misses_rare = row(0.0, 3.0), row(0.1, 0.0)
    pool = [misses_common, misses_rare, row(0.2, 0.0), row(0.5, 0.0, perturbation=0.5)]
    assert misses_rare["cost"] < misses_common["cost"]
    ranked = sorted(pool, key=_ranking(pool, goals))
    assert ranked[0] is misses_common
    # Among takes missing the same goals, the lower total cost first.
    assert ranked[1:] == [misses_rare, pool[2], pool[3]]
    # A take that did not complete ranks last.
    failed = {"cost.rare": None, "cost.common": None, "cost": None, "perturbation": 0.0,
              "theta": [0.0]}
    assert sorted([failed, *pool], key=_ranking(pool, goals))[-1] is failed
    # Around a take (a refinement), ties on the goals rank by the distance from its θ, not
    # by the perturbation: θ = 0.9 is nearer 1 than θ = 0.5 is.
    near = dict(row(0.0, 0.0, perturbation=0.9), theta=[0.9])
    plausible = dict(row(0.0, 0.0, perturbation=0.5), theta=[0.5])
    assert sorted([near, plausible], key=_ranking(pool, goals)) == [plausible, near]
    assert sorted([near, plausible], key=_ranking(pool, goals, np.array([1.0]))) == [
        near, plausible,
    ]


def test_touch_goals_read_the_contacts():
    positions = [[[0, 0, 0], [3, 4, 0]], [[0, 0, 0], [0.6, 0.8, 0]], [[0, 0, 0], [3, 0, 0]]]
    apart = _record(positions)
    touches = goal_from_dict({"type": "touches", "body": 0, "other": "b1"})
    assert touches.cost(apart) == pytest.approx(1.0)  # closest approach of the positions
    together = _record(positions, touching=[set(), {(0, 1)}, {(0, 1)}])
    assert touches.cost(together) == 0.0
    never = goal_from_dict({"type": "never_touches", "body": 0, "other": 1})
    assert never.cost(apart) == 0.0
    assert never.cost(together) == pytest.approx(2 * 0.5)  # two frames of 0.5 s


def test_touches_with_times_counts_separate_contacts():
    # In contact at frames 1-2 and 4 (two episodes), apart at 0, 3 and 5.
    positions = [[[0, 0, 0], [1, 0, 0]]] * 6
    touching = [set(), {(0, 1)}, {(0, 1)}, set(), {(0, 1)}, set()]
    record = _record(positions, touching=touching)
    twice = {"type": "touches", "body": 0, "other": 1, "times": 2}
    assert goal_from_dict(twice).cost(record) == 0.0
    assert goal_from_dict(dict(twice, times=1)).cost(record) == 1.0
    assert goal_from_dict(dict(twice, times=5)).cost(record) == 3.0
    # In a window holding only the first episode.
    assert goal_from_dict(dict(twice, times=1, between=[0, 1.0])).cost(record) == 0.0
    # Never touching: one contact short, plus the closest approach of the positions (1 m).
    apart = _record(positions)
    assert goal_from_dict(dict(twice, times=1)).cost(apart) == pytest.approx(2.0)
    assert goal_from_dict(dict(twice, times=0)).cost(apart) == 0.0
    assert goal_from_dict(dict(twice, times=0)).cost(record) == 2.0


@pytest.mark.parametrize(
    "spec, message",
    [
        ({"type": "lands", "body": 0}, "type: goal type 'lands'"),
        ({"type": "ends_inside", "body": 0}, "region: is required"),
        ({"type": "touches", "body": 0}, "other: is required"),
        ({"type": "ends_inside", "body": 0, "region": {"cube": {}}}, "region: unknown region"),
        ({"type": "tilted", "body": 0, "colour": 1}, "colour: unknown fields"),
        ({"type": "touches", "body": 0, "other": 1, "times": -1}, "times: 'times' must be"),
        ({"type": "touches", "body": 0, "other": 1, "times": 1.5}, "times: 'times' must be"),
        ({"type": "never_touches", "body": 0, "other": 1, "times": 1}, "times: unknown fields"),
        ({"type": "tilted", "body": True}, "body: True is not a body"),
        ({"type": "tilted", "body": -1}, "body: -1 is not a body"),
        ({"type": "tilted", "body": 0, "min_degrees": 500}, r"min_degrees: 500 degrees is out"),
        ({"type": "rests_with_axis_up", "body": 0, "tolerance_degrees": -1}, "tolerance_degrees"),
        ({"type": "rests_with_axis_up", "body": 0, "rest_speed": -0.1}, "rest_speed: -0.1"),
        ({"type": "tilted", "body": 0, "axis": [0, 0, 0]}, r"axis: \[0, 0, 0\] has no direction"),
        ({"type": "tilted", "body": 0, "up": [0, 1]}, "up: .* is not three finite numbers"),
        ({"type": "touches", "body": "a", "other": "a"}, "other: 'a' is the goal's own body"),
        ({"type": "never_touches", "body": 0, "between": [2, 1], "other": 1}, "between: .* reversed"),
        ({"type": "stays_inside", "body": 0, "between": [-1, 1], "region": {
            "sphere": {"center": [0, 0, 0], "radius": 1}}}, "between: .* before the take"),
        ({"type": "ends_inside", "body": 0, "at": -0.5, "region": {
            "sphere": {"center": [0, 0, 0], "radius": 1}}}, "at: -0.5 s is out of range"),
        ({"type": "ends_inside", "body": 0, "region": {
            "sphere": {"center": [0, 0, 0], "radius": 0}}}, "region.sphere.radius"),
        ({"type": "ends_inside", "body": 0, "region": {
            "box": {"min": [0, 0, 0], "max": [1, -1, 1]}}}, "region.box.max"),
        ({"type": "tilted", "body": 0, "weight": -2}, "weight: -2 must be"),
    ],
)
def test_bad_goals_are_refused_with_the_field(spec, message):
    with pytest.raises(ValueError, match=message):
        goal_from_dict(spec)


#: A sphere around the ball's start, for goals whose region does not matter.
HERE = {"sphere": {"center": [0.0, 0.1, 0.0], "radius": 0.5}}


@pytest.mark.parametrize(
    "goal, message",
    [
        ({"type": "ends_inside", "body": "Ball", "region": HERE},
         "goals[1].body: no body named 'Ball' in the scene: did you mean 'ball'?"),
        ({"type": "touches", "body": "ball", "other": "floor"},
         "goals[1].other: no body named 'floor' in the scene"),
        ({"type": "touches", "body": "ball", "other": 1},
         "goals[1].other: 1 is the goal's body 'ball': a body cannot touch itself"),
        ({"type": "ends_inside", "body": 5, "region": HERE},
         "goals[1].body: body index 5 is not in the scene (2 bodies)"),
        ({"type": "passes_through", "body": "ball", "region": HERE, "between": [0.5, 3]},
         "goals[1].between: 3 s is after the take's end, 1 s (60 steps of 0.0166667 s)"),
        ({"type": "passes_through", "body": "ball", "region": HERE, "between": [0.9, 0.5]},
         "goals[1].between: [0.9, 0.5] is reversed"),
        ({"type": "ends_inside", "body": "ball", "region": HERE, "at": 2},
         "goals[1].at: 2 s is after the take's end"),
        ({"type": "tilted", "body": "ball", "axis": [0, 0, 0]},
         "goals[1].axis: [0, 0, 0] has no direction"),
        ({"type": "rests_with_axis_up", "body": "ball", "tolerance_degrees": -5},
         "goals[1].tolerance_degrees: -5 degrees is out of range"),
        ({"type": "tilted", "body": "ball", "min_degrees": 500},
         "goals[1].min_degrees: 500 degrees is out of range: must be in [0, 180]"),
        ({"type": "touches", "body": "ball", "other": "ball"},
         "goals[1].other: 'ball' is the goal's own body"),
        ({"type": "tilted", "body": True}, "goals[1].body: True is not a body"),
    ],
)
def test_goals_the_scene_cannot_hold_are_refused_before_any_take_runs(
    goal, message, tmp_path, capsys
):
    # The command line: exit 2, the goals file and the goal's place and field named, and
    # nothing written to the search's directory.
    goal = dict(goal, name="checked")
    scene = tmp_path / "roll.json"
    scene.write_text(json.dumps(SCENE))
    goals = tmp_path / "goals.json"
    goals.write_text(json.dumps({"steps": STEPS, "variation": VARIATION, "goals": [TARGET, goal]}))
    out = tmp_path / "t"
    arguments = ["search", str(scene), "--goals", str(goals), "--budget", "8", "--out", str(out)]
    assert cli_main([*arguments, "--no-progress"]) == 2
    assert f"error: {goals}: {message}" in capsys.readouterr().err
    assert not out.exists()
    # In Python: the same message.
    with pytest.raises(ValueError) as refused:
        search(SCENE, [TARGET, goal], VARIATION, budget=8, steps=STEPS, out=out, progress=False)
    assert message in str(refused.value)
    assert not out.exists()


def test_a_goals_file_with_an_unknown_key_is_refused(tmp_path, capsys):
    scene = tmp_path / "roll.json"
    scene.write_text(json.dumps(SCENE))
    goals = tmp_path / "goals.json"
    goals.write_text(json.dumps({"steps": STEPS, "varation": VARIATION, "goals": [TARGET]}))
    out = tmp_path / "t"
    arguments = ["search", str(scene), "--goals", str(goals), "--budget", "8", "--out", str(out)]
    assert cli_main(arguments) == 2
    error = capsys.readouterr().err
    assert f"{goals}: unknown keys ['varation']" in error and "goals, steps, variation" in error
    assert not out.exists()
    goals.write_text(json.dumps({"steps": 0, "variation": VARIATION, "goals": [TARGET]}))
    assert cli_main(arguments) == 2
    assert f"{goals}: steps: 0 must be an integer >= 1" in capsys.readouterr().err
    assert not out.exists()


def test_a_variation_moves_each_field_by_theta_times_its_scale():
    variation = Variation(bodies=["ball"], position=0.1, angle=90.0, velocity=2.0)
    assert variation.dimension(SCENE) == 9
    theta = np.array([1.0, -0.5, 0.0, 0.0, 0.0, 1.0, 0.25, 0.0, 0.0])
    ball = variation.apply(SCENE, theta)["bodies"][1]
    assert ball["position"] == pytest.approx([0.1, 0.05, 0.0])
    assert ball["linear_velocity"] == pytest.approx([0.5, 0.0, 0.0])
    # A 90 degree turn about z.
    half = math.radians(45)
    assert ball["orientation"] == pytest.approx([0, 0, math.sin(half), math.cos(half)], abs=1e-7)
    # Values are float32, so a file and the search build the same bits.
    assert all(float(np.float32(v)) == v for v in ball["position"])
    assert SCENE["bodies"][1]["position"] == [0.0, 0.1, 0.0]  # the scene is not changed
    # Every field: θ's last three components move the angular velocity (rad/s).
    every = Variation(bodies=["ball"], position=0.1, angle=90.0, velocity=2.0, angular_velocity=3.0)
    assert every.dimension(SCENE) == 12
    spun = every.apply(SCENE, np.concatenate([theta, [0.5, -1.0, 2.0]]))["bodies"][1]
    assert spun["angular_velocity"] == [1.5, -3.0, 6.0]
    assert spun["linear_velocity"] == ball["linear_velocity"]
    with pytest.raises(ValueError, match="no body named 'cue'"):
        Variation(bodies=["cue"], velocity=1.0).dimension(SCENE)
    with pytest.raises(ValueError, match="only dynamic bodies"):
        Variation(bodies=["ground"], velocity=1.0).dimension(SCENE)
    with pytest.raises(ValueError, match="varies nothing"):
        Variation(bodies=["ball"])


def test_search_finds_a_take_whose_scene_reproduces_it_to_the_bit(tmp_path):
    takes = search(
        SCENE,
        [TARGET],
        VARIATION,
        budget=64,
        steps=STEPS,
        out=tmp_path / "t",
        workers=2,
        population=16,
        progress=False,
    )
    met = takes.met()
    assert met, f"no take met the goal in 64: best {takes.best(1)}"
    take = met[0]
    assert take.costs["ends_inside:ball"] == 0.0
    # The exported scene, read from a file, runs the same trajectory to the bit.
    path = tmp_path / "take.json"
    take.write_scene(path)
    world = impulse.World.from_scene(str(path))
    world.step(STEPS)
    x = float(world.positions[1][0])
    assert 0.3 <= x <= 0.6
    record, status, _ = simulate_take(take.scene(), STEPS, [])
    assert status == "completed"
    assert np.array_equal(record.positions[-1].astype(np.float32), world.positions)
    # Closed form on ice: x = vx * t with the varied vx.
    vx = json.loads(path.read_text())["bodies"][1]["linear_velocity"][0]
    assert x == pytest.approx(vx * 1.0, rel=1e-3)
    table = takes.table
    assert {"take_id", "met", "cost", "perturbation", "theta", "cost.ends_inside:ball"} <= set(
        table.column_names
    )
    assert table.num_rows == len(takes) <= 64


def test_random_sampling_draws_every_take_from_the_prior(tmp_path):
    common = dict(budget=32, steps=10, workers=2, population=8, stop_after=33, progress=False)
    unreachable = dict(TARGET, region={"box": {"min": [50, 0, -1], "max": [51, 1, 1]}})
    plain = search(SCENE, [unreachable], VARIATION, out=tmp_path / "r", method="random", **common)
    refined = search(SCENE, [unreachable], VARIATION, out=tmp_path / "c", **common)
    # One velocity scale, three components: θ of every random take is a standard normal draw;
    # the cross-entropy method's last generation has moved toward the far target (+x) and
    # narrowed along x.
    plain_theta = np.array([t.theta for t in plain.values()])
    refined_theta = np.array([row["theta"] for row in refined.table.to_pylist()][-8:])
    assert plain_theta.shape == (32, 3)
    assert np.all(np.abs(plain_theta.mean(axis=0)) < 0.6)
    assert np.all((0.6 < plain_theta.std(axis=0)) & (plain_theta.std(axis=0) < 1.4))
    assert refined_theta[:, 0].mean() > 1.0
    assert refined_theta[:, 0].std() < 0.5 * plain_theta[:, 0].std()
    # The first generation is the same draw for both.
    first = [row["theta"] for row in plain.table.to_pylist()][:8]
    assert first == [row["theta"] for row in refined.table.to_pylist()][:8]
    # The second generation's last half are local steps (0.15 N(0, I)) around the first
    # generation's 4 best takes in turn (one goal, missed by all: the lowest costs).
    rows = refined.table.to_pylist()
    best = sorted(rows[:8], key=lambda row: (row["cost"], row["perturbation"]))[:4]
    for k in range(4, 8):
        step = np.array(rows[8 + k]["theta"]) - np.array(best[k % 4]["theta"])
        assert np.all(np.abs(step) < 5 * 0.15), (k, step)
    with pytest.raises(ValueError, match="method = 'annealing'"):
        search(SCENE, [TARGET], VARIATION, out=tmp_path / "x", method="annealing", **common)


def test_a_search_resumes_where_it_stopped(tmp_path):
    out = tmp_path / "t"
    unreachable = dict(TARGET, region={"box": {"min": [50, 0, -1], "max": [51, 1, 1]}})
    first = search(
        SCENE,
        [unreachable],
        VARIATION,
        budget=16,
        steps=10,
        out=out,
        workers=2,
        population=8,
        progress=False,
    )
    assert len(first) == 16 and not first.met()
    again = search(
        SCENE,
        [unreachable],
        VARIATION,
        budget=24,
        steps=10,
        out=out,
        workers=2,
        population=8,
        progress=False,
    )
    assert len(again) == 24
    # The first 16 are the same takes, read back (their timings unchanged), not run again.
    before = {row["take_id"]: row["wall_time_s"] for row in first.table.to_pylist()}
    after = {row["take_id"]: row["wall_time_s"] for row in again.table.to_pylist()}
    assert all(after[key] == value for key, value in before.items())
    with pytest.raises(ValueError, match="another scene, goals"):
        search(SCENE, [TARGET], VARIATION, budget=4, steps=10, out=out, progress=False)
    # A directory an older search wrote (another format) is refused, saying so.
    manifest = json.loads((out / "manifest.json").read_text())
    manifest["format"] -= 1
    (out / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(ValueError, match="another version of impulse.takes"):
        search(
            SCENE, [unreachable], VARIATION, budget=24, steps=10, out=out, population=8,
            progress=False,
        )


def _far(record):
    return float(abs(record.positions[-1, 1, 0] - 0.45))


def test_custom_goals_are_costs_of_the_record():
    goal = custom(_far, "x near 0.45")
    assert evaluate(SCENE, [goal], steps=10) == {"x near 0.45": pytest.approx(0.45)}


def test_the_command_line_exit_codes(tmp_path, capsys):
    goals = tmp_path / "goals.json"
    goals.write_text(json.dumps({"steps": STEPS, "variation": VARIATION, "goals": [TARGET]}))
    scene = tmp_path / "roll.json"
    scene.write_text(json.dumps(SCENE))
    out = tmp_path / "t"
    args = [
        "search",
        str(scene),
        "--goals",
        str(goals),
        "--budget",
        "64",
        "--out",
        str(out),
        "--workers",
        "2",
        "--population",
        "16",
        "--no-progress",
    ]
    assert cli_main(args) == 0
    take_id = load(out).met()[0].take_id
    assert cli_main(["scene", str(out), take_id, "--out", str(tmp_path / "take.json")]) == 0
    assert json.loads((tmp_path / "take.json").read_text())["bodies"][1]["linear_velocity"][0] > 0
    assert cli_main(["scene", str(out), "0000", "--out", str(tmp_path / "x.json")]) == 2
    assert "no take '0000'" in capsys.readouterr().err
    far = tmp_path / "far.json"
    far.write_text(
        json.dumps([dict(TARGET, region={"box": {"min": [50, 0, -1], "max": [51, 1, 1]}})])
    )
    assert (
        cli_main(
            [
                "search",
                str(scene),
                "--goals",
                str(far),
                "--budget",
                "8",
                "--steps",
                "5",
                "--vary-velocity",
                "0.3",
                "--out",
                str(tmp_path / "none"),
                "--no-progress",
            ]
        )
        == 1
    )
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps([{"type": "lands", "body": "ball"}]))
    assert (
        cli_main(
            [
                "search",
                str(scene),
                "--goals",
                str(bad),
                "--budget",
                "8",
                "--steps",
                "5",
                "--vary-velocity",
                "0.3",
                "--out",
                str(tmp_path / "b"),
            ]
        )
        == 2
    )
    assert "goal type 'lands'" in capsys.readouterr().err
    assert cli_main(["sheet", str(out), "--no-previews"]) == 0
    page = (out / "sheet.html").read_text()
    assert page.count("data-take-id=") == len(load(out))


def test_the_contact_sheet_draws_previews_and_sorts_in_a_browser(
    tmp_path, impulse_cli, monkeypatch
):
    out = tmp_path / "t"
    search(
        SCENE,
        [TARGET],
        VARIATION,
        budget=32,
        steps=STEPS,
        out=out,
        workers=2,
        population=8,
        stop_after=2,
        progress=False,
    )
    monkeypatch.setenv("IMPULSE_CLI", impulse_cli)
    page = sheet(out, count=6, every=5, size="64x48")
    takes = load(out)
    shown = takes.best(6)
    for take in shown:
        (gif,) = (out / "previews").glob(f"{take.take_id}-*.gif")
        assert gif.read_bytes()[:6] in (b"GIF87a", b"GIF89a")
    chromium = shutil.which("chromium")
    missing = None
    if chromium is None or shutil.which("chromedriver") is None:
        missing = (
            "Chromium and chromedriver are not installed (apt-get install chromium chromium-driver)"
        )
    else:
        try:
            import selenium  # noqa: F401
        except ImportError:
            missing = "selenium is not installed (pip install selenium)"
    if missing:
        # CI sets IMPULSE_REQUIRE_BROWSER=1: there the page must be checked, not skipped.
        if os.environ.get("IMPULSE_REQUIRE_BROWSER") == "1":
            pytest.fail(missing)
        pytest.skip(missing)
    from selenium import webdriver
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for flag in (
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--no-first-run",
    ):
        options.add_argument(flag)
    service = webdriver.ChromeService(executable_path=shutil.which("chromedriver"))
    driver = webdriver.Chrome(options=options, service=service)
    try:
        driver.get(f"file://{page}")
        cards = driver.find_elements(By.CSS_SELECTOR, "figure.take")
        assert [c.get_attribute("data-take-id") for c in cards] == [t.take_id for t in shown]
        images = driver.find_elements(By.CSS_SELECTOR, "figure.take img")
        assert all(
            driver.execute_script("return arguments[0].naturalWidth", i) == 64 for i in images
        )
        Select(driver.find_element(By.ID, "sort")).select_by_value("perturbation")
        order = [
            c.get_attribute("data-take-id")
            for c in driver.find_elements(By.CSS_SELECTOR, "figure.take")
        ]
        assert order == [t.take_id for t in sorted(shown, key=lambda t: t.perturbation)]
        # "Only takes that meet every goal" shows exactly those.
        assert 0 < sum(t.met for t in shown) < len(shown)
        driver.find_element(By.ID, "only-met").click()
        visible = [
            c.get_attribute("data-take-id")
            for c in driver.find_elements(By.CSS_SELECTOR, "figure.take")
            if c.is_displayed()
        ]
        assert visible == [t.take_id for t in shown if t.met]
        driver.find_element(By.ID, "only-met").click()
        assert all(c.is_displayed() for c in driver.find_elements(By.CSS_SELECTOR, "figure.take"))
    finally:
        driver.quit()


def test_python_dash_m_runs_the_command_line(tmp_path):
    done = subprocess.run(
        [sys.executable, "-m", "impulse.takes", "--help"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0 and "search" in done.stdout


def _documented_shots(repository):
    """The worked shots' rows of docs/takes.md: shot -> (takes run, takes meeting every goal,
    best take's cost, its perturbation)."""
    rows = {}
    for line in (repository / "docs" / "takes.md").read_text().splitlines():
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        if len(cells) == 7 and cells[0] in ("dice", "hoop", "pachinko", "bowling"):
            rows[cells[0]] = (int(cells[3]), int(cells[4]), float(cells[5]), float(cells[6]))
    return rows


@pytest.mark.parametrize("shot", ["dice", "hoop", "pachinko", "bowling"])
def test_the_worked_shots_are_as_documented(shot, repository, tmp_path):
    documented = _documented_shots(repository)[shot]
    goals = json.loads((repository / "scenes" / "takes" / f"{shot}.goals.json").read_text())
    scene = repository / "scenes" / "takes" / f"{shot}.json"
    # The authored scene misses its goals.
    assert any(cost > 0 for cost in evaluate(scene, goals["goals"], goals["steps"]).values())
    found = search(
        scene,
        goals["goals"],
        goals["variation"],
        budget=SHOTS_BUDGET,
        steps=goals["steps"],
        stop_after=3,
        workers=2,
        out=tmp_path / shot,
        progress=False,
    )
    best = found.best(1)[0]
    found_row = (len(found), len(found.met()), round(best.cost, 3), round(best.perturbation, 2))
    assert found_row == documented


def _ball_over_floor(name, materials, **scene):
    """A 10 cm ball 1 m above a static floor (its top at y = 0), materials `floor` and `ball`."""
    floor = {
        "name": "floor",
        "kind": "static",
        "material": "floor",
        "shape": {"type": "cuboid", "half_extents": [20, 0.5, 20]},
        "position": [0, -0.5, 0],
    }
    ball = {
        "name": "ball",
        "kind": "dynamic",
        "material": "ball",
        "shape": {"type": "sphere", "radius": 0.1},
        "position": [0, 1.1, 0],
    }
    return {"name": name, **scene, "materials": materials, "bodies": [floor, ball]}


#: A frictionless elastic ball dropped on a rough floor: only the floor's roughness draws (the
#: scene seed) decide where it bounces.
ROUGH = _ball_over_floor(
    "rough bounce",
    {
        "floor": {"friction": 0.0, "restitution": 1.0, "roughness": 10.0},
        "ball": {"friction": 0.0, "restitution": 1.0},
    },
)


def test_takes_with_their_own_seeds_vary_the_rough_surfaces(tmp_path):
    # After 1.2 s the ball has bounced once: it must have gone off toward +x.
    goal = {
        "type": "ends_inside",
        "body": "ball",
        "region": {"box": {"min": [0.15, -1, -1], "max": [5, 5, 1]}},
    }
    takes = search(
        ROUGH,
        [goal],
        {"seeds": True},
        budget=32,
        steps=72,
        out=tmp_path / "t",
        workers=2,
        population=16,
        stop_after=33,
        progress=False,
    )
    seeds = [take.scene_seed for take in takes.values()]
    assert all(isinstance(s, int) and s > 0 for s in seeds)
    assert len(set(seeds)) > 8  # fresh seeds, and the best ones reused
    # θ is empty: a reused seed is the same take, read back however often it is drawn and
    # counted each time, so the budget of 32 is two generations.
    assert len(takes) < 32
    assert takes.table.column("generation").to_pylist()[-1] == 1
    ends = {take.take_id: take for take in takes.values()}
    met = takes.met()
    assert met, "some rough bounce goes toward +x"
    scene = met[0].scene()
    assert scene["seed"] == met[0].scene_seed
    world = impulse.World.from_scene(scene)
    assert world.seed == met[0].scene_seed
    world.step(72)
    assert world.positions[1][0] >= 0.15
    # A smooth floor sends the ball straight back up whatever the seed.
    smooth = json.loads(json.dumps(ROUGH))
    smooth["materials"]["floor"]["roughness"] = 0.0
    smooth["seed"] = 12345
    world = impulse.World.from_scene(smooth)
    world.step(72)
    assert abs(world.positions[1][0]) < 1e-6
    assert len(ends) == len(takes)
    # Refined around a take, its seed is drawn again about half the time in the first
    # generation, before it is in the refinement's table: one run, counted in every slot.
    from impulse.takes import refine

    refined = refine(tmp_path / "t", met[0].take_id, budget=16, workers=2, population=16,
                     progress=False)
    assert met[0].scene_seed in {take.scene_seed for take in refined.values()}
    assert len(refined) < 16
    assert set(refined.table.column("generation").to_pylist()) == {0}


def test_a_met_take_is_the_same_to_the_bit_on_a_ray_worker(tmp_path):
    ray = pytest.importorskip("ray")
    common = dict(budget=16, steps=STEPS, workers=2, population=16, progress=False)
    local = search(SCENE, [TARGET], VARIATION, out=tmp_path / "local", **common)
    # One Ray for the search and the rerun (the search leaves a Ray it did not start running).
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        takes = search(SCENE, [TARGET], VARIATION, out=tmp_path / "t", backend="ray", **common)
        met = takes.met()
        assert met, "some take of 16 meets the goal"
        take = met[0]
        on_worker = ray.get(ray.remote(simulate_take).remote(take.scene(), STEPS, []))
    finally:
        ray.shutdown()
    # The same takes and costs as on the local pool.
    columns = ("take_id", "met", "cost", "theta")
    assert {c: takes.table.column(c).to_pylist() for c in columns} == {
        c: local.table.column(c).to_pylist() for c in columns
    }
    here = simulate_take(take.scene(), STEPS, [])
    assert on_worker[1] == here[1] == "completed"
    for field in ("positions", "orientations", "linear_velocities", "angular_velocities"):
        assert getattr(on_worker[0], field).tobytes() == getattr(here[0], field).tobytes()


def test_a_met_hoop_take_is_the_same_to_the_bit_through_impulse_run(
    repository, tmp_path, impulse_cli
):
    goals = json.loads((repository / "scenes" / "takes" / "hoop.goals.json").read_text())
    found = search(
        repository / "scenes" / "takes" / "hoop.json",
        goals["goals"],
        goals["variation"],
        budget=HOOP_BUDGET,
        steps=goals["steps"],
        workers=2,
        out=tmp_path / "hoop",
        progress=False,
    )
    take = found.met()[0]
    path = tmp_path / "take.json"
    take.write_scene(path)
    out = tmp_path / "frames.jsonl"
    subprocess.run(
        # The take's scene carries the search's steps: no --steps.
        [impulse_cli, "run", str(path), "--out", str(out), "--quiet"],
        check=True,
        capture_output=True,
    )
    frames = [json.loads(line) for line in out.read_text().splitlines()]
    # serde_json writes each float32 widened to float64 exactly, so the cast back is exact.
    poses = np.array([f["bodies"] for f in frames], dtype=np.float64).astype(np.float32)
    record, status, _ = simulate_take(take.scene(), goals["steps"], [])
    assert status == "completed" and len(frames) == goals["steps"] + 1
    positions = record.positions.astype(np.float32)
    orientations = record.orientations.astype(np.float32)
    assert positions.view(np.uint32).tolist() == poses[..., :3].view(np.uint32).tolist()
    assert orientations.view(np.uint32).tolist() == poses[..., 3:].view(np.uint32).tolist()


#: A frictionless ball of restitution 0.5 and impact perturbation 0.4 dropped 1 m onto a floor:
#: the impact draws (the scene seed) decide how high it bounces (c_r' in [0.1, 0.9], apex
#: c_r'² × 1 m above the floor).
BOUNCY = _ball_over_floor(
    "perturbed bounce",
    {
        "floor": {"friction": 0.0},
        "ball": {"friction": 0.0, "restitution": 0.5, "impact_perturbation": 0.4},
    },
    dt=1.0 / 60.0,
)


def _highest_after_bounce(scene, steps=90):
    world = impulse.World.from_scene(scene)
    highest = 0.0
    for step in range(steps):
        world.step()
        if step >= 30:  # after the impact at 0.45 s
            highest = max(highest, float(world.positions[1][1]))
    return highest


def test_takes_with_their_own_seeds_vary_the_perturbed_impacts(tmp_path):
    # Up through y >= 0.65 m (an apex 0.55 m above the ball's resting height, c_r' > 0.74)
    # between 0.5 s and 1.5 s: about one seed in five.
    goal = {
        "type": "passes_through",
        "body": "ball",
        "region": {"box": {"min": [-1, 0.65, -1], "max": [1, 5, 1]}},
        "between": [0.5, 1.5],
    }
    takes = search(
        BOUNCY,
        [goal],
        {"seeds": True},
        budget=32,
        steps=90,
        out=tmp_path / "t",
        workers=2,
        population=16,
        progress=False,
    )
    met = takes.met()
    assert met, "some perturbed bounce goes high"
    assert len(met) < len(takes), "some perturbed bounce stays low"
    scene = met[0].scene()
    assert scene["seed"] == met[0].scene_seed
    assert scene["materials"]["ball"]["impact_perturbation"] == 0.4
    assert _highest_after_bounce(scene) >= 0.65
    # Unperturbed, the same seed bounces to c_r² × 1 m = 0.25 m above its rest (0.35 m).
    plain = json.loads(json.dumps(scene))
    plain["materials"]["ball"]["impact_perturbation"] = 0.0
    assert _highest_after_bounce(plain) == pytest.approx(0.35, abs=0.03)


def test_a_variation_with_roughness_draws_puts_them_in_theta():
    # Per varied body: its field offsets, then 2K roughness draw coordinates.
    variation = Variation(bodies=["ball"], velocity=0.3, roughness_draws=2)
    assert variation.dimension(SCENE) == 3 + 4
    theta = [1.0, 0.0, -1.0, 0.1, -2.0, 1.0 / 3.0, 0.25]
    scene = variation.apply(SCENE, theta)
    ball = scene["bodies"][1]
    point3 = float(np.float32(0.3))
    assert ball["linear_velocity"] == [point3, 0.0, -point3]
    third = float(np.float32(1.0 / 3.0))
    assert ball["roughness_draws"] == [[float(np.float32(0.1)), -2.0], [third, 0.25]]
    assert "roughness_draws" not in scene["bodies"][0] and "roughness_draws" not in SCENE["bodies"][1]
    # Through the engine: the scene reads back with the same float32 draws.
    world = impulse.World.from_scene(scene)
    world.step(2)
    with pytest.raises(ValueError, match=r"needs \(7,\)"):
        variation.apply(SCENE, theta[:6])
    # Draws alone vary something; the spec round-trips.
    alone = Variation(roughness_draws=1)
    assert alone.dimension(SCENE) == 2
    assert Variation.from_dict(alone.to_dict()).to_dict() == alone.to_dict() == {
        "bodies": None,
        "position": 0.0,
        "angle": 0.0,
        "velocity": 0.0,
        "angular_velocity": 0.0,
        "roughness_draws": 1,
    }
    assert "roughness_draws" not in Variation(velocity=1.0).to_dict()
    for bad in (-1, 1.5, True, 257, "2"):
        with pytest.raises(ValueError, match="roughness_draws"):
            Variation(velocity=1.0, roughness_draws=bad)
    with pytest.raises(ValueError, match="varies nothing"):
        Variation(roughness_draws=0)


def _rough_particle(draws):
    """A frictionless elastic particle (radius 0.1 m, no rotation, so its velocity reflects
    exactly about the normal) coming straight down at 3 m/s, without gravity, onto the rough
    floor of ``ROUGH`` (10°), with ``draws`` as its ``roughness_draws``."""
    scene = json.loads(json.dumps(ROUGH))
    scene["gravity"] = [0.0, 0.0, 0.0]
    ball = scene["bodies"][1]
    ball.update(kind="particle", position=[0.0, 0.4, 0.0], linear_velocity=[0.0, -3.0, 0.0])
    ball["roughness_draws"] = draws
    return scene


def _bounce_direction(scene):
    world = impulse.World.from_scene(scene)
    for _ in range(60):
        world.step()
        v = np.asarray(world.linear_velocities[1], dtype=np.float64)
        if v[1] > 0.0:
            return v / np.linalg.norm(v)
    raise AssertionError("no bounce")


def _closed_form_direction(a, b, roughness_degrees=10.0):
    """Twice the tilt from vertical (cos tilt = 1 − cap·(1 − cos R), cap = 1 − exp(−(a²+b²)/2)),
    towards azimuth atan2(b, a) measured from the floor's x axis about y (towards
    cos φ·x − sin φ·z)."""
    cap = 1.0 - math.exp(-(a * a + b * b) / 2.0)
    tilt = math.acos(1.0 - cap * (1.0 - math.cos(math.radians(roughness_degrees))))
    azimuth = math.atan2(b, a)
    side = math.sin(2.0 * tilt)
    return np.array([side * math.cos(azimuth), math.cos(2.0 * tilt), -side * math.sin(azimuth)])


def test_the_roughness_draws_move_the_bounce_continuously():
    # A small step of (a, b) moves the bounce a little, as the closed form says.
    previous = None
    for k in range(6):
        a, b = 0.6 + 0.002 * k, -0.9 + 0.001 * k
        direction = _bounce_direction(_rough_particle([[a, b]]))
        expected = _closed_form_direction(a, b)
        assert np.linalg.norm(direction - expected) < 1e-3, (a, b, direction, expected)
        if previous is not None:
            assert 0.0 < np.linalg.norm(direction - previous) < 5e-3
        previous = direction
    # (0, 0) bounces straight back up.
    assert np.linalg.norm(_bounce_direction(_rough_particle([[0.0, 0.0]])) - [0, 1, 0]) < 1e-6


def test_a_take_with_roughness_draws_is_the_same_to_the_bit_through_impulse_run(
    tmp_path, impulse_cli
):
    # The rough bounce of ROUGH must go toward +x: only the ball's roughness draw (θ) decides.
    goal = {
        "type": "ends_inside",
        "body": "ball",
        "region": {"box": {"min": [0.15, -1, -1], "max": [5, 5, 1]}},
    }
    steps = 72
    out = tmp_path / "t"
    scene_path, goals_path = tmp_path / "rough.json", tmp_path / "goals.json"
    scene_path.write_text(json.dumps(ROUGH))
    goals_path.write_text(json.dumps({"goals": [goal], "steps": steps, "variation": {"bodies": ["ball"]}}))
    arguments = ["search", str(scene_path), "--goals", str(goals_path), "--budget", "16"]
    arguments += ["--out", str(out), "--workers", "2", "--population", "16", "--no-progress"]
    assert cli_main([*arguments, "--vary-roughness-draws", "1"]) == 0
    takes = load(out)
    assert takes.variation.roughness_draws == 1
    met = takes.met()
    assert met, "some draw sends the ball toward +x"
    assert len(met) < len(takes), "some draw does not"
    take = met[0]
    assert len(take.theta) == 2 and take.scene_seed is None
    path = tmp_path / "take.json"
    assert cli_main(["scene", str(out), take.take_id, "--out", str(path)]) == 0
    written = json.loads(path.read_text())
    assert written["bodies"][1]["roughness_draws"] == [
        [float(np.float32(x)) for x in take.theta]
    ]
    frames_path = tmp_path / "frames.jsonl"
    subprocess.run(
        [impulse_cli, "run", str(path), "--out", str(frames_path), "--quiet"],
        check=True,
        capture_output=True,
    )
    frames = [json.loads(line) for line in frames_path.read_text().splitlines()]
    poses = np.array([f["bodies"] for f in frames], dtype=np.float64).astype(np.float32)
    record, status, _ = simulate_take(take.scene(), steps, [])
    assert status == "completed" and len(frames) == steps + 1
    positions = record.positions.astype(np.float32)
    orientations = record.orientations.astype(np.float32)
    assert positions.view(np.uint32).tolist() == poses[..., :3].view(np.uint32).tolist()
    assert orientations.view(np.uint32).tolist() == poses[..., 3:].view(np.uint32).tolist()
    assert positions[-1, 1, 0] >= 0.15


def _within_reach(record):
    """0 when the ball ends 0.3-0.6 m along x, else its distance (m) from that range."""
    x = float(record.positions[-1, 1, 0])
    return max(0.0, 0.3 - x, x - 0.6)


def _within_wider_reach(record):
    """0 when the ball ends 0.2-0.7 m along x, else its distance (m) from that range."""
    x = float(record.positions[-1, 1, 0])
    return max(0.0, 0.2 - x, x - 0.7)


def _broken(record):
    """A goal that cannot be computed."""
    raise ValueError("this goal is broken")


def test_a_search_whose_first_generation_all_fails_says_why(tmp_path):
    with pytest.raises(RuntimeError, match="every take of the first generation failed .* broken"):
        search(SCENE, [custom(_broken, "broken")], VARIATION, budget=64, steps=5,
               out=tmp_path / "t", workers=2, population=8, progress=False)
    # The failed takes are written, with their error.
    takes = load(tmp_path / "t")
    assert len(takes) == 8
    assert all("this goal is broken" in take.error for take in takes.values())


def _constant(record):
    """The same cost for every take: no take is ever better than another."""
    return 1.0


@pytest.mark.parametrize("backend", ["local", "ray"])
def test_custom_goals_search_on_both_backends(backend, tmp_path):
    if backend == "ray":
        ray = pytest.importorskip("ray")
        ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        goal = custom(_within_reach, "within reach")
        takes = search(
            SCENE,
            [goal],
            VARIATION,
            budget=64,
            steps=STEPS,
            out=tmp_path / "t",
            backend=backend,
            workers=2,
            population=16,
            progress=False,
        )
    finally:
        if backend == "ray":
            ray.shutdown()
    assert all(take.status == "completed" for take in takes.values())
    met = takes.met()
    assert met, f"no take met the goal in 64: best {takes.best(1)}"
    # Each take's cost is the function's value for its scene, run here.
    for take in [met[0], *takes.best()[-3:]]:
        assert evaluate(take.scene(), [goal], STEPS) == {"within reach": take.costs["within reach"]}
    x = impulse.World.from_scene(met[0].scene())
    x.step(STEPS)
    assert 0.3 <= float(x.positions[1][0]) <= 0.6


def test_a_custom_goal_with_changed_code_is_another_search(tmp_path):
    out = tmp_path / "t"
    common = dict(budget=8, steps=10, workers=2, population=8, stop_after=9, progress=False)
    first = search(SCENE, [custom(_within_reach, "reach")], VARIATION, out=out, **common)
    # The same function resumes: every take read back, none run again.
    again = search(SCENE, [custom(_within_reach, "reach")], VARIATION, out=out, **common)
    assert again.table.column("wall_time_s").to_pylist() == first.table.column(
        "wall_time_s"
    ).to_pylist()
    with pytest.raises(ValueError, match="custom goal 'reach': its function's code is not the"):
        search(SCENE, [custom(_within_wider_reach, "reach")], VARIATION, out=out, **common)


def test_a_custom_goals_identity_is_its_code_and_the_values_it_holds():
    from impulse.takes._goals import code_identity

    def reach(low):
        return lambda record: max(0.0, low - float(record.positions[-1, 1, 0]))

    assert code_identity(reach(0.3)) == code_identity(reach(0.3))
    assert code_identity(reach(0.3)) != code_identity(reach(0.4))
    assert code_identity(_within_reach) != code_identity(_within_wider_reach)
    with pytest.raises(TypeError, match="not callable"):
        custom("x", "reach")


def test_a_take_scene_runs_the_searchs_steps(tmp_path):
    # The authored scene runs 600 steps; the search's takes 60.
    authored = dict(SCENE, steps=600)
    takes = search(
        authored, [TARGET], VARIATION, budget=16, steps=STEPS, out=tmp_path / "t", workers=2,
        population=16, progress=False,
    )
    scene = takes.best(1)[0].scene()
    assert scene["steps"] == STEPS
    assert scene["dt"] == float(np.float32(1.0 / 60.0))


def test_a_take_is_reproduced_by_impulse_run_without_steps(tmp_path, impulse_cli):
    # `impulse run take.json`, with no --steps, ends where the search's take ended, to the bit.
    authored = dict(SCENE, steps=600)
    takes = search(
        authored, [TARGET], VARIATION, budget=16, steps=STEPS, out=tmp_path / "t", workers=2,
        population=16, progress=False,
    )
    take = takes.best(1)[0]
    path = tmp_path / "take.json"
    take.write_scene(path)
    out = tmp_path / "frames.jsonl"
    subprocess.run(
        [impulse_cli, "run", str(path), "--out", str(out), "--quiet"],
        check=True,
        capture_output=True,
    )
    frames = [json.loads(line) for line in out.read_text().splitlines()]
    assert len(frames) == STEPS + 1
    final = np.array(frames[-1]["bodies"], dtype=np.float64).astype(np.float32)
    record, status, _ = simulate_take(take.scene(), STEPS, [])
    assert status == "completed"
    assert record.positions[-1].astype(np.float32).tobytes() == final[:, :3].tobytes()
    assert record.orientations[-1].astype(np.float32).tobytes() == final[:, 3:].tobytes()


def test_a_script_piped_into_python_is_refused_before_any_worker_starts(tmp_path):
    out = tmp_path / "t"
    script = (
        "import impulse.takes as takes\n"
        f"takes.search({SCENE!r}, [{TARGET!r}], {VARIATION!r}, budget=8, steps=10,\n"
        f"             out={str(out)!r}, workers=2, progress=False)\n"
    )
    done = subprocess.run(
        [sys.executable, "-"], input=script, capture_output=True, text=True, check=False
    )
    assert done.returncode == 1
    assert "runs from a script read from standard input (<stdin>)" in done.stderr
    assert done.stderr.count("Traceback") == 1  # the refusal's alone: no worker ran
    assert not out.exists()


def _notebook_client():
    """nbclient and nbformat (with ipykernel's kernel), or a skip when they are not installed,
    a failure under ``IMPULSE_REQUIRE_NOTEBOOK=1`` (as in CI)."""
    try:
        import ipykernel  # noqa: F401 - the kernel the notebook runs in
        import nbclient
        import nbformat
    except ImportError as missing:
        if os.environ.get("IMPULSE_REQUIRE_NOTEBOOK") == "1":
            pytest.fail(f"the notebook test needs nbclient, nbformat and ipykernel: {missing}")
        pytest.skip(f"nbclient, nbformat and ipykernel are not installed: {missing}")
    return nbclient, nbformat


def test_a_notebook_builds_a_scene_with_the_python_api_and_searches_it(tmp_path):
    nbclient, nbformat = _notebook_client()
    out = tmp_path / "takes"
    # As a user types it: a scene built from the API's shapes, checked by building its world,
    # then a search from a cell (no __main__ guard: a notebook needs none) and its sheet.
    cells = [
        "import impulse\nimport impulse.takes as takes",
        "scene = {\n"
        '    "name": "roll",\n'
        '    "materials": {"ice": {"friction": 0.0, "restitution": 0.0}},\n'
        '    "bodies": [\n'
        '        {"name": "ground", "kind": "static", "material": "ice",\n'
        '         "shape": impulse.Shape.halfspace([0, 1, 0]).to_dict()},\n'
        '        {"name": "ball", "kind": "dynamic", "material": "ice", "position": [0, 0.1, 0],\n'
        '         "linear_velocity": [0.2, 0, 0], "shape": impulse.Shape.ball(0.1).to_dict()},\n'
        "    ],\n"
        "}\n"
        'impulse.World.from_scene(scene).names',
        f"found = takes.search(scene, [{TARGET!r}], {VARIATION!r}, budget=8, steps={STEPS},\n"
        f"                     population=4, workers=2, out={str(out)!r})\n"
        "print(len(found), 'takes,', len(found.met()), 'meet every goal')",
        "page = takes.sheet(found.root, previews=False)",
    ]
    notebook = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(c) for c in cells])
    nbclient.NotebookClient(
        notebook, timeout=120, kernel_name="python3",
        resources={"metadata": {"path": str(tmp_path)}},
    ).execute()  # a cell that raises fails the test with its traceback (CellExecutionError)
    assert notebook.cells[1].outputs[0]["data"]["text/plain"] == "['ground', 'ball']"
    printed = "".join(
        output.get("text", "")
        for output in notebook.cells[2].outputs
        if output.get("name") == "stdout"
    )
    takes = load(out)
    # The search ends at its first take meeting the goal (stop_after = 1), within the budget.
    assert takes.met() and len(takes) <= 8
    assert f"{len(takes)} takes, {len(takes.met())} meet every goal" in printed
    assert all(take.status == "completed" for take in takes.values())
    assert (out / "sheet.html").is_file()


def _children(pid):
    """The ids of the processes whose parent is ``pid`` (Linux /proc)."""
    found = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as file:
                    fields = file.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                found.append(int(entry))
    return found


def _running(pid):
    """Whether process ``pid`` exists and has not exited (a zombie has)."""
    try:
        with open(f"/proc/{pid}/stat") as file:
            state = file.read().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state not in ("Z", "X")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_sigterm_keeps_the_finished_takes_and_ends_the_workers(tmp_path):
    import signal
    import time

    scene, goals, out = tmp_path / "roll.json", tmp_path / "far.json", tmp_path / "t"
    scene.write_text(json.dumps(SCENE))
    far = dict(TARGET, region={"box": {"min": [50, 0, -1], "max": [51, 1, 1]}})
    goals.write_text(json.dumps({"steps": STEPS, "variation": VARIATION, "goals": [far]}))
    command = [sys.executable, "-m", "impulse.takes", "search", str(scene), "--goals", str(goals)]
    command += ["--budget", "100000", "--population", "8", "--workers", "2", "--out", str(out)]
    process = subprocess.Popen(
        [*command, "--no-progress"], stderr=subprocess.PIPE, text=True
    )
    try:
        # Wait (not a timing check) for the first generation to be written.
        deadline = time.monotonic() + 300
        while not (out / "takes.parquet").exists():
            assert process.poll() is None, process.stderr.read()
            assert time.monotonic() < deadline, "no generation written in 300 s"
            time.sleep(0.05)
        workers = _children(process.pid)
        assert workers, "the search runs worker processes"
        process.send_signal(signal.SIGTERM)
        _, error = process.communicate(timeout=300)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 143, error
    assert "interrupted: the takes run so far are kept" in error
    kept = load(out)
    assert len(kept) >= 8  # the first generation, at least
    assert all(take.status == "completed" for take in kept.values())
    deadline = time.monotonic() + 60
    while any(_running(pid) for pid in workers) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not [pid for pid in workers if _running(pid)], "worker processes left running"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fcntl locks")
def test_a_search_directory_is_locked_against_a_second_search(tmp_path, capsys):
    import fcntl

    scene, goals, out = tmp_path / "roll.json", tmp_path / "goals.json", tmp_path / "t"
    scene.write_text(json.dumps(SCENE))
    goals.write_text(json.dumps({"steps": 10, "variation": VARIATION, "goals": [TARGET]}))
    arguments = ["search", str(scene), "--goals", str(goals), "--budget", "8", "--out", str(out)]
    arguments += ["--workers", "2", "--population", "8", "--no-progress"]
    out.mkdir()
    with open(out / "search.lock", "a+") as held:
        fcntl.flock(held.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)  # another search's lock
        assert cli_main(arguments) == 2
        assert "is in use by another search" in capsys.readouterr().err
        assert not (out / "takes.parquet").exists()
    assert cli_main(arguments) in (0, 1)  # released: the search runs
    assert len(load(out)) >= 1


@pytest.mark.parametrize(
    "flag, value, message",
    [
        ("--steps", "0", "argument --steps: 0 must be an integer >= 1"),
        ("--workers", "0", "argument --workers: 0 must be an integer >= 1"),
        ("--workers", "-1", "argument --workers: -1 must be an integer >= 1"),
        ("--budget", "0", "argument --budget: 0 must be an integer >= 1"),
        ("--budget", "ten", "argument --budget: 'ten' is not an integer"),
        ("--stop-after", "0", "argument --stop-after: 0 must be an integer >= 1"),
        ("--population", "1", "argument --population: 1 must be an integer >= 2"),
        ("--seed", "-3", "argument --seed: -3 must be an integer >= 0"),
        ("--vary-velocity", "-1", "argument --vary-velocity: -1 must be a finite number >= 0"),
        ("--vary-angle", "nan", "argument --vary-angle: nan must be a finite number >= 0"),
        ("--vary-roughness-draws", "-2", "argument --vary-roughness-draws: -2 must be"),
    ],
)
def test_every_search_flag_is_checked_with_its_name(flag, value, message, tmp_path, capsys):
    scene, goals, out = tmp_path / "roll.json", tmp_path / "goals.json", tmp_path / "t"
    scene.write_text(json.dumps(SCENE))
    goals.write_text(json.dumps({"steps": 10, "variation": VARIATION, "goals": [TARGET]}))
    arguments = ["search", str(scene), "--goals", str(goals), "--budget", "8", "--out", str(out)]
    with pytest.raises(SystemExit) as exited:
        cli_main([*arguments, flag, value])
    assert exited.value.code == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def _in_draw_order(rows, population):
    return [(row["generation"], row["index"]) for row in rows] == [
        (k // population, k % population) for k in range(len(rows))
    ]


def test_stop_after_ends_the_search_at_that_take(tmp_path):
    takes = search(
        SCENE, [TARGET], VARIATION, budget=96, steps=STEPS, out=tmp_path / "t", workers=2,
        population=16, stop_after=3, progress=False,
    )
    rows = takes.table.to_pylist()
    # Exactly 3 meet every goal, the last take drawn is the third, and every take drawn
    # before it is in the table.
    assert sum(row["met"] for row in rows) == 3
    assert rows[-1]["met"]
    assert _in_draw_order(rows, 16)


def test_a_take_is_met_only_when_it_meets_every_goal(tmp_path):
    from impulse.takes._search import _row

    goals = [goal_from_dict({"type": "tilted", "body": 0, "name": n}) for n in ("a", "b")]
    result = {"take_id": "x", "status": "completed", "costs": [0.0, 0.25]}
    assert not _row(result, goals, 0, 0, np.zeros(3))["met"]
    assert not _row(dict(result, costs=[0.5, 0.0]), goals, 0, 0, np.zeros(3))["met"]
    assert _row(dict(result, costs=[0.0, 0.0]), goals, 0, 0, np.zeros(3))["met"]
    # In a search: takes meeting the reachable goal, none meeting both.
    far = dict(TARGET, name="far", region={"box": {"min": [50, 0, -1], "max": [51, 1, 1]}})
    takes = search(
        SCENE, [TARGET, far], VARIATION, budget=32, steps=STEPS, out=tmp_path / "t", workers=2,
        population=16, progress=False,
    )
    assert any(take.costs["ends_inside:ball"] == 0.0 for take in takes.values())
    assert not takes.met()


def test_a_resumed_search_runs_its_failed_takes_again(tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    out = tmp_path / "t"
    far = dict(TARGET, region={"box": {"min": [50, 0, -1], "max": [51, 1, 1]}})
    common = dict(budget=8, steps=10, workers=2, population=8, progress=False)
    search(SCENE, [far], VARIATION, out=out, **common)
    # Take 3 is recorded as failed (as when its worker died).
    path = out / "takes.parquet"
    table = pq.read_table(path)
    rows = table.to_pylist()
    failed = rows[3]["take_id"]
    rows[3].update(status="failed", error="WorkerFailure: killed", met=False, cost=None,
                   wall_time_s=-1.0)
    rows[3]["cost.ends_inside:ball"] = None
    pq.write_table(pa.Table.from_pylist(rows, schema=table.schema), path)
    again = search(SCENE, [far], VARIATION, out=out, **common)
    assert again[failed].status == "completed" and again[failed].cost is not None
    times = dict(zip(again.table.column("take_id").to_pylist(),
                     again.table.column("wall_time_s").to_pylist(), strict=True))
    assert times[failed] >= 0.0  # run again
    assert all(times[row["take_id"]] == row["wall_time_s"] for row in rows if row["take_id"] != failed)


def test_under_seeds_the_best_takes_seeds_are_reused(tmp_path):
    from impulse.takes._search import _ranking

    far = {"type": "ends_inside", "body": "ball",
           "region": {"box": {"min": [5, -1, -1], "max": [6, 5, 1]}}}
    # θ varies too, so a take reusing a seed is a new take (with θ empty it would be the same
    # take, read back rather than run again).
    variation = {"bodies": ["ball"], "velocity": 0.05, "seeds": True}
    takes = search(
        ROUGH, [far], variation, budget=32, steps=72, out=tmp_path / "t", workers=2,
        population=16, progress=False,
    )
    rows = takes.table.to_pylist()
    assert _in_draw_order(rows, 16)
    first, second = rows[:16], rows[16:]
    best = sorted(first, key=_ranking(first, [goal_from_dict(far)]))[:3]  # the 3 elites of 16
    reused = [row for row in second if row["scene_seed"] in {row["scene_seed"] for row in best}]
    # Half the second generation's seeds are drawn from the elites' (8 of 16 on average).
    assert 4 <= len(reused) <= 12
    fresh = {row["scene_seed"] for row in first}
    assert all(row["scene_seed"] not in fresh for row in second if row not in reused)


def test_a_search_restarts_when_its_best_cost_stalls(tmp_path):
    # Every take costs the same: the best cost never falls, so after 4 generations without a
    # lower one (STALL_GENERATIONS) the search draws its 6th generation from the prior N(0, I)
    # again, with no local steps: exactly the standard normal draw of that generation.
    takes = search(
        SCENE, [custom(_constant, "constant")], VARIATION, budget=48, steps=5,
        out=tmp_path / "t", workers=2, population=8, progress=False,
    )
    rows = takes.table.to_pylist()
    theta = np.array([row["theta"] for row in rows]).reshape(6, 8, 3)
    prior = np.random.default_rng([0, 5]).standard_normal((8, 3))
    assert np.array_equal(theta[5], prior)
    # Before it, the search had narrowed around the smallest perturbations.
    assert theta[4].std() < 0.5 * theta[0].std()


def test_the_sheet_lists_the_takes_best_first_with_tied_costs(tmp_path):
    import re

    out = tmp_path / "t"
    search(
        SCENE, [TARGET], VARIATION, budget=96, steps=STEPS, out=out, workers=2, population=16,
        stop_after=4, progress=False,
    )
    takes = load(out)
    page = (tmp_path / "sheet.html")
    sheet(out, page, count=10, previews=False)
    cards = re.findall(r'data-take-id="([0-9a-f]+)" data-rank="(\d+)"', page.read_text())
    best = takes.best(10)
    met = [take for take in best if take.met]
    assert len(met) == 4 and {take.cost for take in met} == {0.0}  # tied at cost 0
    assert best[:4] == sorted(met, key=lambda take: take.perturbation)
    assert [take_id for take_id, _ in cards] == [take.take_id for take in best]
    assert [int(rank) for _, rank in cards] == list(range(len(best)))


def test_refine_searches_around_a_take_keeping_the_goals(tmp_path, capsys):
    out = tmp_path / "t"
    found = search(
        SCENE, [TARGET], VARIATION, budget=64, steps=STEPS, out=out, workers=2, population=16,
        progress=False,
    )
    take = found.met()[0]
    assert cli_main(["refine", str(out), take.take_id, "--budget", "32", "--workers", "2",
                     "--no-progress"]) == 0
    assert "trust region: step 0.002 in the first generation" in capsys.readouterr().err
    refined = load(out / "refine" / take.take_id)
    assert refined.goal_names == found.goal_names and refined.manifest["steps"] == STEPS
    rows = refined.table.to_pylist()
    # The whole budget (stop_after = 32), in generations of 8 (a refinement's default).
    assert len(rows) == 32 and _in_draw_order(rows, 8)
    # The first generation is θ of the take plus 0.002 N(0, I): within 5 standard deviations.
    first = np.array([row["theta"] for row in rows[:8]])
    assert np.all(np.abs(first - take.theta) < 5 * 0.002)
    # The goal is a 0.3 m range of the ball's x; a step of 0.002 moves it by about 0.6 mm:
    # nearly every refined take meets it.
    assert len(refined.met()) >= 28
    # A search with custom goals is refined from Python, giving them again.
    custom_out = tmp_path / "c"
    customs = search(
        SCENE, [custom(_within_reach, "reach")], VARIATION, budget=16, steps=STEPS,
        out=custom_out, workers=2, population=16, stop_after=17, progress=False,
    )
    best = customs.best(1)[0].take_id
    assert cli_main(["refine", str(custom_out), best, "--budget", "8", "--no-progress"]) == 2
    assert "custom goals ['reach']" in capsys.readouterr().err
    from impulse.takes import refine

    again = refine(custom_out, best, budget=8, goals=[custom(_within_reach, "reach")],
                   workers=2, progress=False)
    assert len(again) == 8
    with pytest.raises(KeyError, match="no take 'ffff'"):
        refine(custom_out, "ffff", budget=8, goals=[custom(_within_reach, "reach")])


def test_a_refinement_around_a_met_take_shrinks_its_step_until_most_takes_meet_the_goals(
    tmp_path,
):
    from impulse.takes import refine

    out = tmp_path / "t"
    found = search(
        SCENE, [TARGET], VARIATION, budget=64, steps=STEPS, out=out, workers=2, population=16,
        progress=False,
    )
    take = found.met()[0]
    # A step of 2 (0.6 m/s of the ball's speed) misses the 0.3 m range most of the time: the
    # trust region halves it until most takes end in the range.
    refined = refine(out, take.take_id, budget=48, step=2.0, workers=2, progress=False)
    rows = refined.table.to_pylist()
    assert len(rows) == 48 and _in_draw_order(rows, 8)
    generations = [rows[k : k + 8] for k in range(0, 48, 8)]
    met = [sum(row["met"] for row in generation) for generation in generations]
    spread = [
        float(np.sqrt(np.mean((np.array([row["theta"] for row in generation]) - take.theta) ** 2)))
        for generation in generations
    ]
    assert met[0] < 4, met  # the first generation at the full step: most miss
    assert spread[-1] < 0.5 * spread[0], spread  # the step shrank
    # After a generation with fewer than half meeting the goal, the next is drawn with half
    # the step; the draws' root mean square (24 numbers) is within 40 % of the step.
    steps = refined.trust_region_steps()
    assert len(steps) == 6 and steps[0] == 2.0, steps
    for k in range(5):
        if met[k] < 4:
            assert steps[k + 1] == 0.5 * steps[k], (k, met, steps)
    for k in range(6):
        assert 0.6 * steps[k] < spread[k] < 1.4 * steps[k], (k, steps, spread)
    assert found.trust_region_steps() is None  # a search has none
    assert sum(met[3:]) >= 12, met  # the last three generations: most meet the goal
    # Every refined take is still drawn around the take, not from a moving mean.
    assert all(np.all(np.abs(np.array(row["theta"]) - take.theta) < 5 * 2.0) for row in rows)
    # Run again, the refinement resumes to the same takes (the step follows from the table).
    again = refine(out, take.take_id, budget=48, step=2.0, workers=2, progress=False)
    assert again.table.to_pylist() == rows


def test_a_trust_regions_step_halves_below_half_met_and_grows_back_when_most_meet():
    from impulse.takes._search import REFINE_LEAST_STEP, _adapted_step

    def rows(met, missed, failed=0):
        return ([{"status": "completed", "met": True}] * met
                + [{"status": "completed", "met": False}] * missed
                + [{"status": "failed", "met": False}] * failed)

    assert _adapted_step(0.002, rows(3, 5), 0.002) == 0.001  # fewer than half: halved
    assert _adapted_step(0.001, rows(4, 4), 0.002) == 0.001  # half: kept
    assert _adapted_step(0.001, rows(5, 3), 0.002) == 0.001  # more than half, not most: kept
    grown = _adapted_step(0.0005, rows(6, 2), 0.002)  # three quarters: grown by √2
    assert grown == pytest.approx(0.0005 * math.sqrt(2.0), rel=1e-12)
    assert _adapted_step(0.0018, rows(8, 0), 0.002) == 0.002  # never above the start
    least = REFINE_LEAST_STEP * 0.002
    assert _adapted_step(least, rows(0, 8), 0.002) == least  # never below the floor
    # A failed take (a worker's failure) says nothing of the goals.
    assert _adapted_step(0.001, rows(6, 2, failed=8), 0.002) > 0.001
    assert _adapted_step(0.001, rows(0, 0, failed=8), 0.002) == 0.001


def _read_png(path):
    """The pixels of an 8-bit RGB or RGBA PNG (what `impulse render --out` writes), (H, W, C)
    uint8: the chunks' zlib stream unfiltered row by row (the PNG specification's five
    filters)."""
    import struct
    import zlib

    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    position, compressed = 8, b""
    while position < len(data):
        length, kind = struct.unpack(">I4s", data[position : position + 8])
        body = data[position + 8 : position + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
        elif kind == b"IDAT":
            compressed += body
        position += 12 + length
    assert depth == 8 and colour in (2, 6)
    channels = 3 if colour == 2 else 4
    raw = zlib.decompress(compressed)
    stride = width * channels
    previous = np.zeros(stride, dtype=np.int64)
    rows = []
    for y in range(height):
        kind = raw[y * (stride + 1)]
        row = np.frombuffer(raw, np.uint8, stride, y * (stride + 1) + 1).astype(np.int64)
        if kind == 0:
            current = row
        elif kind == 2:
            current = (row + previous) & 255
        else:
            current = np.zeros(stride, dtype=np.int64)
            for x in range(stride):
                a = current[x - channels] if x >= channels else 0
                b = previous[x]
                c = previous[x - channels] if x >= channels else 0
                if kind == 1:
                    predicted = a
                elif kind == 3:
                    predicted = (a + b) // 2
                else:  # Paeth
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    predicted = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                current[x] = (row[x] + predicted) & 255
        rows.append(current)
        previous = current
    return np.array(rows, dtype=np.uint8).reshape(height, width, channels)


def _drawn_box(impulse_cli, scene, body, camera_arguments, tmp_path, size="192x144"):
    """The pixel box (width, height) ``body`` covers in ``scene``'s first frame
    (:func:`_drawn_pixels` of that body alone)."""
    return _drawn_pixels(impulse_cli, scene, [body], camera_arguments, tmp_path, size)[1]


#: A coin 25 mm wide dropped 1 cm onto a 1 m table, and a ball rolling 2 m away: framed with
#: the ball, the coin is a few pixels.
COIN = {
    "name": "coin on a table",
    "bodies": [
        {"name": "ground", "kind": "static", "shape": {"type": "half_space", "normal": [0, 1, 0]}},
        {"name": "table", "kind": "static", "position": [0, 0.375, 0],
         "shape": {"type": "cuboid", "half_extents": [0.5, 0.375, 0.5]}},
        {"name": "coin", "kind": "dynamic", "position": [0.2, 0.761, 0.1],
         "shape": {"type": "cylinder", "half_height": 0.001, "radius": 0.0125}},
        {"name": "ball", "kind": "dynamic", "position": [-2.0, 0.1, -1.0],
         "linear_velocity": [0.5, 0, 0], "shape": {"type": "sphere", "radius": 0.1}},
    ],
}


def test_a_preview_frames_the_goal_bodies(tmp_path, impulse_cli):
    from impulse.takes._sheet import _camera_arguments

    goal = {"type": "rests_with_axis_up", "body": "coin", "axis": [0, 1, 0]}
    out = tmp_path / "t"
    search(COIN, [goal], {"bodies": ["coin"], "velocity": 0.01}, budget=2, steps=60, out=out,
           workers=2, population=2, progress=False)
    takes = load(out)
    take = takes.best(1)[0]
    # The coin where the take ends, drawn with the sheet's cameras.
    record, _, _ = simulate_take(take.scene(), 60, [])
    posed = take.scene()
    coin = posed["bodies"][2]
    coin.update(position=record.positions[-1, 2].tolist(),
                orientation=record.orientations[-1, 2].tolist(), linear_velocity=[0, 0, 0])
    framed = _drawn_box(
        impulse_cli, posed, 2, _camera_arguments("goals", take, takes, (192, 144)), tmp_path
    )
    assert framed[0] >= 20 and framed[1] >= 20, framed
    # impulse render's own view (the sheet's camera="scene"), as it reports it.
    path = tmp_path / "posed.json"
    path.write_text(json.dumps(posed))
    done = subprocess.run(
        [impulse_cli, "render", str(path), "--out", str(tmp_path / "own"), "--steps", "0",
         "--size", "192x144"],
        check=True, capture_output=True, text=True,
    )
    import re

    eye, target = re.search(r"camera eye (\S+) target (\S+)", done.stdout + done.stderr).groups()
    own = ["--camera-eye", eye, "--camera-target", target]
    scene_view = _drawn_box(impulse_cli, posed, 2, own, tmp_path)
    assert scene_view[0] < 20 and scene_view[1] < 20, scene_view


def test_a_goals_frame_is_where_the_goals_are_judged_less_a_body_far_from_the_rest(repository):
    from impulse.takes._sheet import _without_outliers, goal_views

    hoop = json.loads((repository / "scenes" / "takes" / "hoop.goals.json").read_text())
    assert [view[:2] for view in goal_views(hoop["goals"])] == [
        ("ball", "path"), ("wall", "path"), ("ball", "path"), ("ground", "path"),
        ("ball", "closest"),
    ]
    # Five pins where they rest, one knocked 8 m away: that one is left out.
    boxes = [(np.array([x, 0.0, 0.0]) - 0.1, np.array([x, 0.0, 0.0]) + 0.1, 0.1)
             for x in (0.0, 0.3, 0.6, 0.9, 8.0)]
    kept = _without_outliers(boxes)
    assert [float(box[0][0]) for box in kept] == pytest.approx([-0.1, 0.2, 0.5, 0.8])
    # Two dice apart are both kept, however far.
    assert len(_without_outliers(boxes[::4])) == 2

#: The outline colour of ``impulse render --region`` (sRGB).
MAGENTA = (255, 0, 255)


def _drawn_pixels(impulse_cli, scene, bodies, arguments, tmp_path, size="192x144"):
    """What ``bodies`` (indices) cover in ``scene``'s first frame drawn with ``arguments``:
    the number of pixels and their box (width, height) of the pixels that differ when all of
    them are shrunk to 1 mm spheres at once, the same camera; and the frame as drawn."""
    frames = []
    for shrunk in (False, True):
        drawn = json.loads(json.dumps(scene))
        if shrunk:
            for body in bodies:
                drawn["bodies"][body].update(shape={"type": "sphere", "radius": 1e-3}, mass=1.0)
        folder = tmp_path / f"pixels-{shrunk}"
        path = tmp_path / f"pixels-{shrunk}.json"
        path.write_text(json.dumps(drawn))
        subprocess.run(
            [impulse_cli, "render", str(path), "--out", str(folder), "--steps", "0", "--size",
             size, "--quiet", *arguments],
            check=True,
            capture_output=True,
        )
        frames.append(_read_png(folder / "frame_00000.png")[..., :3])
    ys, xs = np.nonzero(np.any(frames[0] != frames[1], axis=-1))
    box = (int(np.ptp(xs)) + 1, int(np.ptp(ys)) + 1) if xs.size else (0, 0)
    return int(xs.size), box, frames[0]


def _judged_pose(scene, goals):
    """The worked shot's authored take posed where its goals are judged (the frame where the
    ball comes closest to the hoop for ``passes_through``, else the end), at rest; and the
    indices of the moving bodies its goals name."""
    record, _, _ = simulate_take(scene, goals["steps"], [])
    frame = len(record.times) - 1
    for goal in goals["goals"]:
        if goal["type"] == "passes_through":
            low, high = (np.asarray(goal["region"]["box"][k]) for k in ("min", "max"))
            centres = record.positions[:, record.body(goal["body"])]
            gap = np.maximum(np.maximum(low - centres, 0.0), centres - high)
            frame = int(np.argmin(np.linalg.norm(gap, axis=1)))
    posed = json.loads(json.dumps(scene))
    for index, body in enumerate(posed["bodies"]):
        if body.get("kind") != "static":
            body.update(position=record.positions[frame, index].tolist(),
                        orientation=record.orientations[frame, index].tolist(),
                        linear_velocity=[0, 0, 0], angular_velocity=[0, 0, 0])
    named = {record.body(goal["body"]) for goal in goals["goals"]}
    return posed, sorted(i for i in named if scene["bodies"][i].get("kind") != "static")


#: The goal bodies each worked shot's preview must frame, and how many at least: every one,
#: or (bowling: the authored take knocks the 10 pin 1.3 m from the 7, too far for both to be
#: 20 pixels wide in one picture) the first goal's pin and more besides.
FRAMED = {"dice": (["die1", "die2"], 2), "hoop": (["ball"], 1), "pachinko": (["ball"], 1),
          "bowling": (["pin7"], 3)}


@pytest.mark.parametrize("shot", ["dice", "hoop", "pachinko", "bowling"])
def test_a_worked_shots_preview_shows_each_goal_body_over_20_by_20_pixels(
    shot, repository, impulse_cli, tmp_path
):
    from impulse.takes._sheet import goal_frame, goal_views, region_arguments

    scene = json.loads((repository / "scenes" / "takes" / f"{shot}.json").read_text())
    goals = json.loads((repository / "scenes" / "takes" / f"{shot}.goals.json").read_text())
    views = goal_views(goals["goals"])
    eye, target, fov, framed = goal_frame(scene, goals["steps"], views, (192, 144))
    names = [body["name"] for body in scene["bodies"]]
    must, least = FRAMED[shot]
    assert {names.index(name) for name in must} <= set(framed) and len(framed) >= least, framed
    # The sheet's preview flags: its camera and the goals' regions.
    arguments = ["--camera-eye", ",".join(map(str, eye)), "--camera-target",
                 ",".join(map(str, target)), "--fov", str(fov), *region_arguments(views)]
    posed, bodies = _judged_pose(scene, goals)
    count, box, _ = _drawn_pixels(impulse_cli, posed, bodies, arguments, tmp_path)
    # The figures of docs/takes.md's table (`pytest -k worked_shots -s`): together, then each
    # goal body the preview frames as drawn (another body may hide part of it), and with the
    # other goal bodies shrunk to 1 mm spheres (what the camera's framing alone gives it).
    each, alone = {}, {}
    for body in framed:
        (tmp_path / str(body)).mkdir()
        each[names[body]] = _drawn_pixels(
            impulse_cli, posed, [body], arguments, tmp_path / str(body)
        )[:2]
        unhidden = json.loads(json.dumps(posed))
        for other in bodies:
            if other != body:
                unhidden["bodies"][other].update(shape={"type": "sphere", "radius": 1e-3})
        (tmp_path / f"{body}-alone").mkdir()
        alone[names[body]] = _drawn_pixels(
            impulse_cli, unhidden, [body], arguments, tmp_path / f"{body}-alone"
        )[1]
    print(f"{shot}: goal bodies together {count} px, {box[0]} × {box[1]}; "
          f"{fov}° field of view, framed {len(framed)} of {len(bodies)}, each {each}, "
          f"each unhidden {alone}")
    assert count >= 400 and box[0] >= 20 and box[1] >= 20, (count, box)
    for name, (width, height) in alone.items():
        assert width >= 20 and height >= 20, (name, width, height)


def test_a_preview_of_the_7_10_split_frames_both_pins_over_20_by_20_pixels(
    repository, impulse_cli, tmp_path
):
    from impulse.takes._sheet import goal_frame, goal_views

    # The split the bowling shot is after: the 7 and the 10 standing 0.91 m apart (here at
    # the start, where they stand; judged `at` 0 s). Framed with the knocked pins, they are
    # the first goals' bodies and must both be drawn 20 pixels across.
    scene = json.loads((repository / "scenes" / "takes" / "bowling.json").read_text())
    goals = [{"type": "rests_with_axis_up", "body": name, "axis": [0, 1, 0], "at": 0.0}
             for name in ("pin7", "pin10")]
    eye, target, fov, framed = goal_frame(scene, 1, goal_views(goals), (192, 144))
    names = [body["name"] for body in scene["bodies"]]
    assert framed == sorted([names.index("pin7"), names.index("pin10")]), framed
    arguments = ["--camera-eye", ",".join(map(str, eye)), "--camera-target",
                 ",".join(map(str, target)), "--fov", str(fov)]
    for body in framed:
        (tmp_path / str(body)).mkdir()
        width, height = _drawn_pixels(impulse_cli, scene, [body], arguments,
                                      tmp_path / str(body))[1]
        assert width >= 20 and height >= 20, (names[body], width, height, fov)


def test_a_preview_outlines_the_goals_region(repository, impulse_cli, tmp_path):
    from impulse.takes._sheet import goal_camera, goal_views, region_arguments

    scene = json.loads((repository / "scenes" / "takes" / "hoop.json").read_text())
    goals = json.loads((repository / "scenes" / "takes" / "hoop.goals.json").read_text())
    views = goal_views(goals["goals"])
    assert region_arguments(views) == [
        "--region", "box:-1.72,0.8,0.23,-1.48,0.95,0.47"
    ]
    eye, target, fov = goal_camera(scene, goals["steps"], views, (192, 144))
    camera = ["--camera-eye", ",".join(map(str, eye)), "--camera-target",
              ",".join(map(str, target)), "--fov", str(fov)]
    posed, bodies = _judged_pose(scene, goals)
    for regions, least in (([], 0), (region_arguments(views), 1)):
        _, _, frame = _drawn_pixels(impulse_cli, posed, bodies, camera + regions, tmp_path)
        ys, xs = np.nonzero(np.all(frame == MAGENTA, axis=-1))
        if not least:
            assert xs.size == 0
            continue
        # The hoop's box, 24 cm wide, is drawn as its outline around the ball going through.
        assert xs.size >= 100 and np.ptp(xs) >= 20 and np.ptp(ys) >= 20, (xs.size, xs, ys)


def test_the_sheet_passes_the_goals_regions_to_impulse_render(tmp_path, impulse_cli, monkeypatch):
    log = tmp_path / "arguments.txt"
    wrapper = tmp_path / "impulse"
    wrapper.write_text(f'#!/bin/sh\necho "$@" >> "{log}"\nexec "{impulse_cli}" "$@"\n')
    wrapper.chmod(0o755)
    monkeypatch.setenv("IMPULSE_CLI", str(wrapper))
    out = tmp_path / "t"
    search(SCENE, [TARGET], VARIATION, budget=2, steps=STEPS, out=out, workers=2,
           population=2, progress=False)
    sheet(out, count=1)
    assert "--region box:0.3,0,-0.2,0.6,0.3,0.2" in log.read_text()
