"""Python overhead of impulse: `world.step()` from Python against the Rust step, and the cost of
reading the positions of a large world.

    python crates/impulse-py/tools/overhead.py [--cli target/release/impulse] [--rounds 5]

The Rust figures are `impulse run SCENE --steps N --summary-json F`'s median and mean time of
one `World::step` (each timed alone); the Python figures time each call of `world.step()` from a
Python loop alone, on a fresh world of the same scene and settings (the same steps: the runs are
identical to the bit). Rounds alternate the two and the medians are reported, since other work on
the machine moves single runs.
"""

import argparse
import json
import os
import statistics
import subprocess
import tempfile
import time

import impulse


def rust_ms(cli: str, scene: str, steps: int) -> tuple[float, float]:
    """`impulse run`'s own timing of each `World::step`: (median, mean) ms per step."""
    with tempfile.TemporaryDirectory() as directory:
        summary = os.path.join(directory, "summary.json")
        subprocess.run(
            [cli, "run", scene, "--steps", str(steps), "--quiet", "--summary-json", summary],
            check=True,
            capture_output=True,
        )
        with open(summary) as file:
            data = json.load(file)
    return data["ms_per_step"], data["mean_ms_per_step"]


def python_ms(scene: str, steps: int) -> tuple[float, float]:
    """Each call of `world.step()` from a Python loop timed alone: (median, mean) ms per step."""
    world = impulse.World.from_scene(scene)
    step = world.step
    clock = time.perf_counter
    times = []
    for _ in range(steps):
        start = clock()
        step()
        times.append(clock() - start)
    return statistics.median(times) * 1e3, statistics.fmean(times) * 1e3


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

    def line(label: str, values: list[tuple[float, float]]) -> str:
        medians = [m for m, _ in values]
        means = [m for _, m in values]
        return (
            f"  {label:<22} median {statistics.median(medians):.4f} ms/step, "
            f"mean {statistics.median(means):.4f} ms/step  "
            f"(per-round medians: {', '.join(f'{x:.4f}' for x in medians)}; "
            f"means: {', '.join(f'{x:.4f}' for x in means)})"
        )

    print(f"{args.scene}, {args.steps} steps, default settings, each step timed alone;")
    print(f"median over {args.rounds} alternating rounds of each round's median and mean:")
    print(line("impulse run (Rust)", rust))
    print(line("world.step() (Python)", python))
    for i, label in ((0, "median"), (1, "mean")):
        r = statistics.median(v[i] for v in rust)
        p = statistics.median(v[i] for v in python)
        print(f"  Python / Rust, {label:<6} {p / r:.3f}")

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
