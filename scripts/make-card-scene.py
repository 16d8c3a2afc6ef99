#!/usr/bin/env python3
"""Writes scenes/cards40.json: forty playing cards (63 x 88 mm, flat boxes without a thickness,
simulated as 2 mm slabs) in ten layers of four, 20 cm apart across and 12 cm apart up, each
turned at random (uniform over rotations, a fixed seed), dropped into a box 40 cm square of
four static walls on a static floor; friction 0.5, no restitution, 4 s at 1/60 s. The layout of
the forty-cards test (crates/impulse/tests/integration/cards_on_meshes.rs), with orientations
of its own, as a scene file for timing (docs/method.md, "Collision steps").

Usage: scripts/make-card-scene.py
"""

import json
import math
import os
import random

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes")
CARD_HALF_EXTENTS = [0.0315, 0.0, 0.044]


def wall(half_extents, position):
    return {"kind": "static", "shape": {"type": "cuboid", "half_extents": half_extents}, "position": position}


def uniform_rotation(rng):
    """A rotation uniform over SO(3) as a quaternion [x, y, z, w] (Shoemake 1992)."""
    u1, u2, u3 = rng.random(), rng.uniform(0.0, 2.0 * math.pi), rng.uniform(0.0, 2.0 * math.pi)
    a, b = math.sqrt(1.0 - u1), math.sqrt(u1)
    return [a * math.sin(u2), a * math.cos(u2), b * math.sin(u3), b * math.cos(u3)]


def main():
    rng = random.Random(3)
    bodies = [
        wall([0.3, 0.05, 0.3], [0.0, -0.05, 0.0]),
        wall([0.05, 0.3, 0.3], [0.25, 0.3, 0.0]),
        wall([0.05, 0.3, 0.3], [-0.25, 0.3, 0.0]),
        wall([0.3, 0.3, 0.05], [0.0, 0.3, 0.25]),
        wall([0.3, 0.3, 0.05], [0.0, 0.3, -0.25]),
    ]
    for k in range(40):
        position = [-0.1 if k % 2 == 0 else 0.1, 0.1 + 0.12 * (k // 4), -0.1 if k % 4 < 2 else 0.1]
        bodies.append(
            {
                "kind": "dynamic",
                "shape": {"type": "cuboid", "half_extents": CARD_HALF_EXTENTS},
                "position": position,
                "orientation": uniform_rotation(rng),
            }
        )
    scene = {
        "name": "cards40",
        "gravity": [0.0, -9.81, 0.0],
        "dt": 1.0 / 60.0,
        "steps": 240,
        "materials": {"default": {"friction": 0.5, "restitution": 0.0, "density": 1000.0}},
        "bodies": bodies,
    }
    with open(os.path.join(ROOT, "cards40.json"), "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
