"""Python overhead of impulse: `world.step()` from Python against the Rust step, and the cost of
reading the positions of a large world.

    python crates/impulse-py/tools/overhead.py [--cli target/release/impulse] [--rounds 5]

The Rust figure is `impulse run SCENE --steps N --quiet`'s mean ms/step (each `World::step`
timed alone); the Python figure is the wall time of N calls of `world.step()` from a Python loop
divided by N, on a fresh world of the same scene and settings. Rounds alternate the two and the
medians are reported, since other work on the machine moves single runs.
"""

import argparse
import re
import statistics
import subprocess
import time

import impulse


def rust_ms(cli: str, scene: str, steps: int) -> float:
    out = subprocess.run(
        [cli, "run", scene, "--steps", str(steps), "--quiet"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return float(re.search(r"([0-9.]+) ms/step", out).group(1))


def python_ms(scene: str, steps: int) -> float:
    world = impulse.World.from_scene(scene)
    step = world.step
    start = time.perf_counter()
    for _ in range(steps):
        step()
    return (time.perf_counter() - start) * 1e3 / steps


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--cli", default="target/release/impulse")
    parser.add_argument("--scene", default="pyramid20")
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--large", default="balls64k")
    args = parser.parse_args()

    rust, python = [], []
    for _ in range(args.rounds):
        rust.append(rust_ms(args.cli, args.scene, args.steps))
        python.append(python_ms(args.scene, args.steps))
    r, p = statistics.median(rust), statistics.median(python)
    print(f"{args.scene}, {args.steps} steps, default settings, median of {args.rounds} rounds:")
    print(f"  Rust   World::step       {r:.4f} ms/step  (rounds: {', '.join(f'{x:.4f}' for x in rust)})")
    print(f"  Python world.step()      {p:.4f} ms/step  (rounds: {', '.join(f'{x:.4f}' for x in python)})")
    print(f"  Python / Rust            {p / r:.3f}")

    world = impulse.World.from_scene(args.large)
    n = len(world)
    reads = 1000
    start = time.perf_counter()
    for _ in range(reads):
        view = world.positions
    view_us = (time.perf_counter() - start) * 1e6 / reads
    del view
    start = time.perf_counter()
    for _ in range(reads // 10):
        copy = world.positions.copy()
    copy_us = (time.perf_counter() - start) * 1e6 / (reads // 10)
    print(f"{args.large}: {n} bodies")
    print(f"  world.positions (read-only view)        {view_us:.2f} µs per read")
    print(f"  world.positions.copy() ({n}×3 float32)  {copy_us:.1f} µs per read")
    assert copy.shape == (n, 3)


if __name__ == "__main__":
    main()
