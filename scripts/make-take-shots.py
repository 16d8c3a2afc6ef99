#!/usr/bin/env python3
"""Writes the four worked shots of docs/takes.md: scenes/takes/<shot>.json and, beside each,
<shot>.goals.json (goals, steps and the variation `python -m impulse.takes search` reads).

    python3 scripts/make-take-shots.py
"""

import json
import math
import os

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes", "takes")
GROUND = {"name": "ground", "kind": "static", "shape": {"type": "half_space", "normal": [0, 1, 0]}}
QUARTER_X = [math.sin(math.pi / 4), 0.0, 0.0, math.cos(math.pi / 4)]  # local y onto world z


def write(shot, scene, goals):
    os.makedirs(HERE, exist_ok=True)
    with open(os.path.join(HERE, f"{shot}.json"), "w", encoding="utf-8") as file:
        json.dump(scene, file, indent=1)
        file.write("\n")
    with open(os.path.join(HERE, f"{shot}.goals.json"), "w", encoding="utf-8") as file:
        json.dump(goals, file, indent=1)
        file.write("\n")


def dice():
    """Two 10 cm dice thrown onto a table: both come up six (local +y up)."""
    die = {"type": "cuboid", "half_extents": [0.05, 0.05, 0.05]}
    bodies = [GROUND]
    for k, (z, spin) in enumerate([(0.0, [4.0, 7.0, -3.0]), (0.3, [-6.0, 2.0, 5.0])]):
        bodies.append(
            {
                "name": f"die{k + 1}",
                "kind": "dynamic",
                "shape": die,
                "material": "plastic",
                "position": [0.0, 0.4, z],
                "linear_velocity": [2.0, 1.0, 0.0],
                "angular_velocity": spin,
            }
        )
    scene = {
        "name": "dice",
        "materials": {"plastic": {"density": 1000.0, "friction": 0.5, "restitution": 0.3}},
        "bodies": bodies,
    }
    goals = {
        "steps": 240,
        "variation": {"bodies": ["die1", "die2"], "velocity": 0.5, "angular_velocity": 4.0,
                      "angle": 30.0},
        "goals": [
            {"type": "rests_with_axis_up", "body": name, "axis": [0, 1, 0], "name": f"{name} six"}
            for name in ("die1", "die2")
        ],
    }
    write("dice", scene, goals)


def hoop():
    """A ball thrown at a wall bounces once on the floor and drops through a hoop."""
    rim_center, rim_radius = [-1.6, 1.0, 0.35], 0.25
    parts = []
    for k in range(24):
        angle = 2 * math.pi * k / 24
        parts.append(
            {
                "shape": {"type": "sphere", "radius": 0.015},
                "position": [rim_radius * math.cos(angle), 0.0, rim_radius * math.sin(angle)],
            }
        )
    scene = {
        "name": "hoop",
        "materials": {
            "rubber": {"density": 70.0, "friction": 0.5, "restitution": 0.8},
            "plaster": {"friction": 0.5, "restitution": 0.8},
        },
        "bodies": [
            dict(GROUND, material="plaster"),
            {"name": "wall", "kind": "static", "material": "plaster",
             "shape": {"type": "cuboid", "half_extents": [0.1, 1.5, 1.5]},
             "position": [2.1, 1.5, 0.0]},
            {"name": "hoop", "kind": "static", "shape": {"type": "compound", "parts": parts},
             "position": rim_center},
            {"name": "ball", "kind": "dynamic", "shape": {"type": "sphere", "radius": 0.1},
             "material": "rubber", "position": [0.0, 1.0, 0.0],
             "linear_velocity": [3.5, 4.5, 0.0]},
        ],
    }
    # Just under the rim's plane, inside it: the ball's centre gets there only through the hoop.
    x, y, z = rim_center
    inside = {"box": {"min": [x - 0.12, y - 0.2, z - 0.12], "max": [x + 0.12, y - 0.05, z + 0.12]}}
    goals = {
        "steps": 132,
        "variation": {"bodies": ["ball"], "velocity": 0.3},
        "goals": [
            {"type": "touches", "body": "ball", "other": "wall", "name": "hits the wall"},
            {"type": "touches", "body": "ball", "other": "ground", "times": 1,
             "name": "one bounce"},
            {"type": "passes_through", "body": "ball", "region": inside,
             "name": "through the hoop"},
        ],
    }
    write("hoop", scene, goals)


def pachinko():
    """A ball dropped through rows of pegs lands in the middle of seven bins."""
    bodies = [GROUND]
    peg = {"type": "cylinder", "half_height": 0.1, "radius": 0.02}
    for row in range(6):
        y = 1.6 - 0.2 * row
        shift = 0.1 if row % 2 else 0.0
        for column in range(-3, 4):
            x = 0.2 * column + shift
            if abs(x) <= 0.65:
                bodies.append({"name": f"peg{row}_{column + 3}", "kind": "static", "shape": peg,
                               "position": [x, y, 0.0], "orientation": QUARTER_X})
    for k in range(8):  # dividers at x = -0.7, -0.5, ..., 0.7: seven bins, the middle at x = 0
        bodies.append({"name": f"divider{k}", "kind": "static",
                       "shape": {"type": "cuboid", "half_extents": [0.01, 0.15, 0.1]},
                       "position": [0.2 * k - 0.7, 0.15, 0.0]})
    bodies.append({"name": "ball", "kind": "dynamic", "shape": {"type": "sphere", "radius": 0.04},
                   "material": "steel", "position": [0.025, 1.9, 0.0],
                   "locked_axes": {"translation": ["z"]}})
    scene = {"name": "pachinko",
             "materials": {"steel": {"density": 7800.0, "friction": 0.3, "restitution": 0.5}},
             "bodies": bodies}
    goals = {
        "steps": 300,
        "variation": {"bodies": ["ball"], "position": 0.05, "velocity": 0.3},
        "goals": [{"type": "ends_inside", "body": "ball", "name": "middle bin",
                   "region": {"box": {"min": [-0.1, 0.0, -0.1], "max": [0.1, 0.3, 0.1]}}}],
    }
    write("pachinko", scene, goals)


def pin_shape(sides=12):
    """A bowling pin, 38.1 cm tall, as the convex hull of its profile: base radius 2.6 cm, belly
    radius 6.05 cm at 11.4 cm up, 4.5 cm at the neck, 3 cm at the top (the neck's waist is
    filled in). Its origin is half-way up."""
    points = []
    for y, radius in ((-0.19, 0.026), (-0.076, 0.0605), (0.13, 0.045), (0.19, 0.03)):
        for k in range(sides):
            angle = 2 * math.pi * k / sides
            points.append([round(radius * math.cos(angle), 5), y,
                           round(radius * math.sin(angle), 5)])
    return {"type": "convex_hull", "points": points}


def bowling():
    """A ball rolled at the ten pins leaves the 7 and 10 standing (the 7-10 split)."""
    spacing = 0.3048  # pins 12 inches apart, centre to centre, in an equilateral triangle
    bodies = [dict(GROUND, material="lane")]
    for row in range(4):
        for k in range(row + 1):
            # Numbered as on a lane: 1 the head pin, then each row left to right seen from the
            # bowler (who rolls toward -z, so left is -x): 7 and 10 are the back corners.
            bodies.append({"name": f"pin{len(bodies)}", "kind": "dynamic", "shape": pin_shape(),
                           "material": "maple",
                           "position": [spacing * (k - row / 2), 0.19,
                                        -spacing * math.sqrt(3) / 2 * row]})
    speed, radius = 7.5, 0.109
    bodies.append({"name": "ball", "kind": "dynamic", "shape": {"type": "sphere", "radius": radius},
                   "material": "resin", "position": [0.03, radius, 3.0],
                   "linear_velocity": [0.0, 0.0, -speed],
                   "angular_velocity": [-speed / radius, 0.0, 0.0]})  # rolling
    scene = {"name": "bowling",
             # At the default 1/60 s the ball moves 12.5 cm a step, two pin radii: the steps in
             # which the ball and a pin, or two pins, move against each other by more than a
             # pin's thickness are taken in up to four collision steps (the default), each
             # finding contacts again, and the outcomes are those of 1/240 s (docs/takes.md,
             # "The bowling shot's step").
             # A pin of 1.5 kg (605 kg/m³ over the hull's 2.5 l), a ball of 6.5 kg.
             "materials": {"maple": {"density": 605.0, "friction": 0.4, "restitution": 0.5},
                           "resin": {"density": 1200.0, "friction": 0.2, "restitution": 0.3},
                           "lane": {"friction": 0.2, "restitution": 0.2}},
             "bodies": bodies}
    standing = ("pin7", "pin10")
    goals = {
        "steps": 150,  # 2.5 s
        "variation": {"bodies": ["ball"], "position": 0.08, "velocity": 0.5,
                      "angular_velocity": 5.0},
        "goals": [{"type": "rests_with_axis_up", "body": name, "axis": [0, 1, 0],
                   "name": f"{name} standing", "rest_speed": 0.1} for name in standing]
        + [{"type": "tilted", "body": f"pin{k}", "axis": [0, 1, 0], "min_degrees": 45,
            "name": f"pin{k} down"} for k in range(1, 11) if f"pin{k}" not in standing],
    }
    write("bowling", scene, goals)


if __name__ == "__main__":
    dice()
    hoop()
    pachinko()
    bowling()
