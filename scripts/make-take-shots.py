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
    """A ball thrown at a hoop banks off the backboard and drops through the rim."""
    rim_center, rim_radius = [4.2, 3.05, 0.0], 0.23
    parts = []
    for k in range(24):
        angle = 2 * math.pi * k / 24
        parts.append(
            {
                "shape": {"type": "sphere", "radius": 0.02},
                "position": [rim_radius * math.cos(angle), 0.0, rim_radius * math.sin(angle)],
            }
        )
    scene = {
        "name": "hoop",
        "materials": {"ball": {"density": 80.0, "friction": 0.6, "restitution": 0.7}},
        "bodies": [
            GROUND,
            {"name": "backboard", "kind": "static",
             "shape": {"type": "cuboid", "half_extents": [0.02, 0.5, 0.9]},
             "position": [4.6, 3.3, 0.0]},
            {"name": "rim", "kind": "static", "shape": {"type": "compound", "parts": parts},
             "position": rim_center},
            {"name": "ball", "kind": "dynamic", "shape": {"type": "sphere", "radius": 0.12},
             "material": "ball", "position": [0.0, 2.0, 0.0],
             "linear_velocity": [5.2, 6.4, 0.0], "angular_velocity": [0.0, 0.0, 3.0]},
        ],
    }
    below = [rim_center[0], rim_center[1] - 0.25, rim_center[2]]
    goals = {
        "steps": 180,
        "variation": {"bodies": ["ball"], "velocity": 0.4, "angular_velocity": 3.0},
        "goals": [
            {"type": "touches", "body": "ball", "other": "backboard", "name": "banks"},
            {"type": "passes_through", "body": "ball", "name": "through the rim",
             "region": {"sphere": {"center": below, "radius": 0.1}}},
        ],
    }
    write("hoop", scene, goals)


def pachinko():
    """A ball dropped through rows of pegs lands in the second bin from the right."""
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
    for k in range(-3, 4):
        bodies.append({"name": f"divider{k + 3}", "kind": "static",
                       "shape": {"type": "cuboid", "half_extents": [0.01, 0.15, 0.1]},
                       "position": [0.2 * k, 0.15, 0.0]})
    bodies.append({"name": "ball", "kind": "dynamic", "shape": {"type": "sphere", "radius": 0.04},
                   "material": "steel", "position": [0.03, 1.9, 0.0],
                   "locked_axes": {"translation": ["z"]}})
    scene = {"name": "pachinko",
             "materials": {"steel": {"density": 7800.0, "friction": 0.3, "restitution": 0.5}},
             "bodies": bodies}
    goals = {
        "steps": 300,
        "variation": {"bodies": ["ball"], "position": 0.05, "velocity": 0.3},
        "goals": [{"type": "ends_inside", "body": "ball", "name": "bin 0.2-0.4 m",
                   "region": {"box": {"min": [0.2, 0.0, -0.1], "max": [0.4, 0.3, 0.1]}}}],
    }
    write("pachinko", scene, goals)


def bowling():
    """A ball rolled at six pins leaves only the back-left pin standing."""
    pin = {"type": "cylinder", "half_height": 0.19, "radius": 0.06}
    bodies = [GROUND]
    names = []
    for row in range(3):
        for k in range(row + 1):
            name = f"pin{len(names) + 1}"
            names.append(name)
            x = 0.3 * (k - row / 2)
            bodies.append({"name": name, "kind": "dynamic", "shape": pin, "material": "maple",
                           "position": [x, 0.19, -0.26 * row]})
    bodies.append({"name": "ball", "kind": "dynamic", "shape": {"type": "sphere", "radius": 0.11},
                   "material": "resin", "position": [0.05, 0.11, 4.0],
                   "linear_velocity": [0.0, 0.0, -7.0], "angular_velocity": [-63.6, 0.0, 0.0]})
    scene = {"name": "bowling",
             "materials": {"maple": {"density": 650.0, "friction": 0.4, "restitution": 0.4},
                           "resin": {"density": 1300.0, "friction": 0.2, "restitution": 0.3}},
             "bodies": bodies}
    standing = "pin4"  # back row, left
    goals = {
        "steps": 240,
        "variation": {"bodies": ["ball"], "position": 0.08, "velocity": 0.5},
        "goals": [{"type": "rests_with_axis_up", "body": standing, "axis": [0, 1, 0],
                   "name": f"{standing} standing", "rest_speed": 0.1}]
        + [{"type": "tilted", "body": name, "axis": [0, 1, 0], "min_degrees": 45,
            "name": f"{name} down"} for name in names if name != standing],
    }
    write("bowling", scene, goals)


if __name__ == "__main__":
    dice()
    hoop()
    pachinko()
    bowling()
