#!/usr/bin/env python3
"""Measures how the bowling shot's 7-10 split comes about (docs/takes.md, "The bowling shot's
step").

1. ``lines``: straight balls, rolling without slip and without a hop, over the line where they
   would meet the head pin (x at the head pin's z, m) and their sideways velocity (m/s): which of
   the 7 and the 10 stand after the shot's steps. One row per sideways velocity, one character
   per line: ``.`` neither, ``7`` or ``T`` (the 10) alone, ``B`` both, ``M`` the split itself
   (both, every other pin down).
2. ``around``: takes drawn around one take of a search directory at several step sizes
   (θ + size × N(0, I), the search's local steps; the take's scene seed kept): how many leave
   the 7 and the 10 standing, and how many meet every goal.
3. ``reroll``: one take of a search directory with a ``roughness`` (degrees) on the pins'
   material and scene seeds 1..N: the ball's line kept, the pins' contacts re-rolled.
4. ``steps``: the shot with other steps (``dt:substeps`` pairs, ``dt:substeps:split`` with
   split steps at ``split`` m, or ``dt:substeps:split:collision_steps`` with at most that many
   collision steps a step, else the engine's default, 4; the shot's 2.5 s each):
   a random search of N takes for each (search seed 0, so every step size gets the same θ),
   counting the takes that leave the 7, the 10, both, the split itself, and strikes.
5. ``hit``: the head pin alone, hit by the shot's ball rolled at offsets from its centre line:
   the direction the pin moves off in (degrees from straight back) at several steps, with split
   steps at ``--split-overlap`` m (0, the default: off) and at most ``--collision-steps``
   collision steps a step (the engine's default, 4, unless given; 1 is off).
6. ``pins``: two of the shot's pins alone, without gravity or ground: one flying at 5 m/s
   (upright, or lying along its path) strikes a standing one at offsets from its axis: the
   direction the struck pin moves off in (degrees from the flyer's path) and its speed, 0.3 s
   on, at several steps (at most ``--collision-steps`` collision steps a step, as for ``hit``); with
   ``--trace``, also at every step that changes its velocity.

    python3 scripts/bowling-split.py lines
    python3 scripts/bowling-split.py around takes/bowling TAKE_ID --sizes 0.003,0.03,0.1
    python3 scripts/bowling-split.py reroll takes/bowling TAKE_ID --roughness 0.3,1
    python3 scripts/bowling-split.py steps --steps 1/60:20,1/120:10,1/240:5,1/480:3,1/240:20
    python3 scripts/bowling-split.py hit --offsets 0.05,0.1,0.14 --steps 1/60:20,1/240:5,1/960:2
    python3 scripts/bowling-split.py pins --offsets 0.03,0.06,0.09 --steps 1/60:20,1/240:5,1/960:2 [--trace]

Needs the impulse package; runs on 2 processes. The counts are deterministic (the engine is).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from multiprocessing import Pool

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SHOT = os.path.join(HERE, "..", "scenes", "takes", "bowling")
CORNERS = ("pin7 standing", "pin10 standing")
#: The scene format's default step (s), the shot's.
DEFAULT_DT = 1.0 / 60.0


def _duration(spec: dict) -> float:
    """The shot's duration (s): its goals' steps at its scene's step."""
    with open(SHOT + ".json", encoding="utf-8") as file:
        return spec["steps"] * json.load(file).get("dt", DEFAULT_DT)


def _outcome(scene: dict) -> tuple[bool, bool, bool]:
    """(7 standing, 10 standing, every goal met) of one run of ``scene`` over the shot's
    duration at the scene's own step."""
    from impulse.takes import MET, evaluate

    with open(SHOT + ".goals.json", encoding="utf-8") as file:
        spec = json.load(file)
    costs = evaluate(scene, spec["goals"], round(_duration(spec) / scene.get("dt", DEFAULT_DT)))
    seven, ten = (costs[name] <= MET for name in CORNERS)
    return seven, ten, all(cost <= MET for cost in costs.values())


def _straight(task: tuple[float, float]) -> tuple[bool, bool, bool]:
    line, sideways = task
    with open(SHOT + ".json", encoding="utf-8") as file:
        scene = json.load(file)
    ball = next(body for body in scene["bodies"] if body.get("name") == "ball")
    radius = ball["shape"]["radius"]
    speed = -ball["linear_velocity"][2]
    flight = ball["position"][2] / speed  # s to the head pin's z (0)
    ball["position"] = [line - sideways * flight, radius, ball["position"][2]]
    ball["linear_velocity"] = [sideways, 0.0, -speed]
    ball["angular_velocity"] = [-speed / radius, 0.0, -sideways / radius]  # rolling
    return _outcome(scene)


def _varied(task: tuple[dict, dict, list[float], int | None]) -> tuple[bool, bool, bool]:
    from impulse.takes import Variation

    base, variation, theta, seed = task
    return _outcome(Variation.from_dict(variation).apply(base, theta, seed))


def _mark(seven: bool, ten: bool, met: bool) -> str:
    if met:
        return "M"
    return {(True, True): "B", (True, False): "7", (False, True): "T"}.get((seven, ten), ".")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)
    lines = commands.add_parser("lines")
    lines.add_argument("--lines", default="-0.2,0.2,0.01", help="first, last, step (m)")
    lines.add_argument("--sideways", default="-0.6,-0.4,-0.2,0,0.2,0.4,0.6", help="m/s")
    around = commands.add_parser("around")
    around.add_argument("directory")
    around.add_argument("take_id")
    around.add_argument("--sizes", default="0.003,0.01,0.03,0.1")
    around.add_argument("--takes", type=int, default=100, help="takes per step size")
    around.add_argument("--seed", type=int, default=1)
    reroll = commands.add_parser("reroll")
    reroll.add_argument("directory")
    reroll.add_argument("take_id")
    reroll.add_argument("--roughness", default="0.3,1", help="degrees, on the pins' material")
    reroll.add_argument("--material", default="maple")
    reroll.add_argument("--takes", type=int, default=60, help="scene seeds 1..N")
    steps = commands.add_parser("steps")
    steps.add_argument("--steps", default="1/60:20,1/240:5", help="dt:substeps pairs (s, -)")
    steps.add_argument("--takes", type=int, default=2000, help="random takes per step")
    hit = commands.add_parser("hit")
    hit.add_argument("--offsets", default="0.05,0.1,0.14", help="m, the ball's x at the pin")
    hit.add_argument("--steps", default="1/60:20,1/240:5,1/960:2", help="dt:substeps pairs")
    hit.add_argument("--split-overlap", type=float, default=0.0, help="m, split steps (0: off)")
    hit.add_argument("--collision-steps", type=int, default=None,
                     help="at most, a step (1: off; default: the engine's, 4)")
    pins = commands.add_parser("pins")
    pins.add_argument("--offsets", default="0.03,0.06,0.09", help="m, the flyer's x")
    pins.add_argument("--steps", default="1/60:20,1/240:5,1/960:2", help="dt:substeps pairs")
    pins.add_argument("--collision-steps", type=int, default=None,
                      help="at most, a step (1: off; default: the engine's, 4)")
    pins.add_argument("--trace", action="store_true",
                      help="also print each step that changes the struck pin's velocity")
    arguments = parser.parse_args()

    if arguments.command == "pins":
        return _pins(arguments.offsets, arguments.steps, arguments.trace,
                     arguments.collision_steps)
    if arguments.command == "steps":
        return _steps(arguments.steps, arguments.takes)
    if arguments.command == "hit":
        return _hit(arguments.offsets, arguments.steps, arguments.split_overlap,
                    arguments.collision_steps)

    with Pool(2) as pool:
        if arguments.command == "lines":
            first, last, step = (float(v) for v in arguments.lines.split(","))
            xs = np.arange(first, last + 0.5 * step, step)
            print(f"lines x = {first} .. {last} m by {step} m, left to right")
            for sideways in (float(v) for v in arguments.sideways.split(",")):
                marks = pool.map(_straight, [(float(x), sideways) for x in xs])
                print(f"{sideways:+5.2f} m/s  " + "".join(_mark(*m) for m in marks), flush=True)
            return 0
        from impulse.takes import load

        found = load(arguments.directory)
        take = found[arguments.take_id]
        if arguments.command == "reroll":
            print("| roughness (degrees) | seeds | 7 and 10 standing | every goal met |")
            print("|---|---|---|---|")
            for roughness in (float(v) for v in arguments.roughness.split(",")):
                base = json.loads(json.dumps(found.base_scene))
                base["materials"][arguments.material]["roughness"] = roughness
                tasks = [
                    (base, found.manifest["variation"], list(take.theta), seed)
                    for seed in range(1, arguments.takes + 1)
                ]
                marks = pool.map(_varied, tasks)
                both = sum(seven and ten for seven, ten, _ in marks)
                met = sum(m for _, _, m in marks)
                print(f"| {roughness:g} | {arguments.takes} | {both} | {met} |", flush=True)
            return 0
        rng = np.random.default_rng(arguments.seed)
        print("| step size | takes | 7 and 10 standing | every goal met |")
        print("|---|---|---|---|")
        for size in (float(v) for v in arguments.sizes.split(",")):
            thetas = take.theta + size * rng.standard_normal((arguments.takes, take.theta.size))
            tasks = [
                (found.base_scene, found.manifest["variation"], list(theta), take.scene_seed)
                for theta in thetas
            ]
            marks = pool.map(_varied, tasks)
            both = sum(seven and ten for seven, ten, _ in marks)
            met = sum(m for _, _, m in marks)
            print(f"| {size:g} | {arguments.takes} | {both} | {met} |", flush=True)
    return 0


def _solver(substeps: int, collision_steps: int | None, **more: float) -> dict:
    """The ``solver`` object of a step: ``substeps``, ``collision_steps`` unless None (the
    engine's default), and ``more``."""
    solver = dict(more, substeps=substeps)
    if collision_steps is not None:
        solver["collision_steps"] = collision_steps
    return solver


def _hit(offsets: str, pairs: str, split_overlap: float = 0.0, collision_steps: int | None = None) -> int:
    import math
    from fractions import Fraction

    import impulse

    with open(SHOT + ".json", encoding="utf-8") as file:
        base = json.load(file)
    keep = [body for body in base["bodies"] if body["name"] in ("ground", "pin1", "ball")]
    steps = [(text, float(Fraction(text.split(":")[0])), int(text.split(":")[1]))
             for text in pairs.split(",")]
    print("| ball offset (m) | | " + " | ".join(f"dt {t.split(':')[0]} s" for t, _, _ in steps)
          + " |")
    print("|---|---|" + "---|" * len(steps))
    for offset in (float(v) for v in offsets.split(",")):
        angles = []
        for _, dt, substeps in steps:
            bodies = json.loads(json.dumps(keep))
            bodies[-1]["position"][0] = offset
            world = impulse.World.from_scene(
                dict(base, bodies=bodies, dt=dt, solver=_solver(substeps, collision_steps, split_overlap=split_overlap)))
            pin = list(world.names).index("pin1")
            for _ in range(round(0.6 / dt)):  # until the pin moves, then 10 ms on
                world.step()
                v = world.state()["linear_velocities"][pin]
                if math.hypot(v[0], v[2]) > 0.5:
                    break
            for _ in range(round(0.01 / dt)):
                world.step()
            v = world.state()["linear_velocities"][pin]
            angles.append(math.degrees(math.atan2(-v[0], -v[2])))
        print(f"| {offset:g} | the pin moves off at | "
              + " | ".join(f"{a:.1f}°" for a in angles) + " |")
    return 0


def _pins(offsets: str, pairs: str, trace: bool = False, collision_steps: int | None = None) -> int:
    import math
    from fractions import Fraction

    import impulse

    with open(SHOT + ".json", encoding="utf-8") as file:
        base = json.load(file)
    pin = next(body for body in base["bodies"] if body["name"] == "pin1")
    steps = [(text, float(Fraction(text.split(":")[0])), int(text.split(":")[1]))
             for text in pairs.split(",")]
    print("| flying pin | offset (m) | " + " | ".join(f"dt {t.split(':')[0]} s" for t, _, _ in steps)
          + " |")
    print("|---|---|" + "---|" * len(steps))
    for lying in (False, True):
        for offset in (float(v) for v in offsets.split(",")):
            cells = []
            for _, dt, substeps in steps:
                struck = dict(json.loads(json.dumps(pin)), name="struck", position=[0, 0, 0])
                flyer = dict(json.loads(json.dumps(pin)), name="flyer",
                             position=[offset, 0, 0.5], linear_velocity=[0, 0, -5.0])
                if lying:  # its axis along its path
                    flyer["orientation"] = [math.sin(math.pi / 4), 0, 0, math.cos(math.pi / 4)]
                world = impulse.World.from_scene(dict(
                    base, bodies=[flyer, struck], dt=dt, gravity=[0, 0, 0],
                    solver=_solver(substeps, collision_steps)))
                last = None
                for step in range(round(0.3 / dt)):
                    world.step()
                    if not trace:
                        continue
                    v = world.state()["linear_velocities"][1]
                    if (last is None or math.dist(v, last) > 1e-3) and any(v):
                        print(f"  {'lying' if lying else 'upright'} {offset:g} m, dt {dt:.6g} s,"
                              f" step {step + 1}: {math.degrees(math.atan2(-v[0], -v[2])):.1f}°,"
                              f" {math.hypot(v[0], v[2]):.2f} m/s")
                    last = v
                v = world.state()["linear_velocities"][1]
                cells.append(f"{math.degrees(math.atan2(-v[0], -v[2])):.1f}°, "
                             f"{math.hypot(v[0], v[2]):.2f} m/s")
            print(f"| {'lying' if lying else 'upright'} | {offset:g} | " + " | ".join(cells)
                  + " |")
    return 0


def _steps(pairs: str, takes: int) -> int:
    import tempfile
    from fractions import Fraction

    import pyarrow.parquet as pq
    from impulse.takes import MET, search

    with open(SHOT + ".json", encoding="utf-8") as file:
        base = json.load(file)
    with open(SHOT + ".goals.json", encoding="utf-8") as file:
        spec = json.load(file)
    duration = _duration(spec)
    print("| dt (s) | substeps | takes | 7 standing | 10 standing | both | 7-10 split "
          "(every goal met) | strikes | first split |")
    print("|---|---|---|---|---|---|---|---|---|")
    for pair in pairs.split(","):
        dt_text, substeps, *split = pair.split(":")
        dt = float(Fraction(dt_text))
        solver = dict(base.get("solver", {}), substeps=int(substeps))
        if split:  # split steps at this overlap (m)
            solver["split_overlap"] = float(split[0])
        if len(split) > 1:  # at most this many collision steps a step
            solver["collision_steps"] = int(split[1])
        scene = dict(base, dt=dt, solver=solver)
        with tempfile.TemporaryDirectory() as out:
            search(scene, spec["goals"], spec["variation"], budget=takes,
                   steps=round(duration / dt), method="random", seed=0, stop_after=takes + 1,
                   workers=2, out=out, progress=False)
            table = pq.read_table(os.path.join(out, "takes.parquet")).to_pydict()
        order = sorted(range(len(table["take_id"])),
                       key=lambda k: (table["generation"][k], table["index"][k]))
        standing = {name[5:]: [table[name][k] <= MET for k in order]
                    for name in table if name.startswith("cost.")}
        seven, ten = standing[CORNERS[0]], standing[CORNERS[1]]
        others = [all(column) for column in zip(
            *(values for name, values in standing.items() if name not in CORNERS), strict=True)]
        both = sum(s and t for s, t in zip(seven, ten, strict=True))
        split = [table["met"][k] for k in order]
        strikes = sum(o and not s and not t
                      for o, s, t in zip(others, seven, ten, strict=True))
        first = next((k + 1 for k, m in enumerate(split) if m), None)
        print(f"| {dt_text} | {substeps} | {len(order)} | {sum(seven)} | {sum(ten)} | {both} | "
              f"{sum(split)} | {strikes} | {first or 'none'} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
