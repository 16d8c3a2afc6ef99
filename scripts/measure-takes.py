#!/usr/bin/env python3
"""Measures the takes search on the four worked shots (docs/takes.md, "Measured"):

1. Takes to the first success: for each shot, searches with seeds 0..S-1 (budget 2,000, stopping
   at the first take that meets every goal), by the cross-entropy method and by plain random
   sampling; the first success is the take's place in the order of the draws (generation ×
   population + index + 1). Prints the median over the seeds, and each count.
2. Throughput: takes per second of one search of a fixed number of takes with 1 worker and with
   2, on the local pool (its start-up included) and on a local Ray (started before the clock);
   prints the ratio.

    python3 scripts/measure-takes.py                       # everything (long: run it once)
    python3 scripts/measure-takes.py --shots hoop --seeds 2 --no-throughput
    python3 scripts/measure-takes.py --shots bowling --first-seed 5 --no-throughput

Needs the impulse package (with pyarrow), and ray for the Ray rows (skipped without it). The
counts are deterministic (the engine is); the throughput depends on the machine and its load.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SHOTS = os.path.join(HERE, "..", "scenes", "takes")


def _shot(shot: str) -> tuple[str, dict]:
    with open(os.path.join(SHOTS, f"{shot}.goals.json"), encoding="utf-8") as file:
        return os.path.join(SHOTS, f"{shot}.json"), json.load(file)


def first_success(shot: str, method: str, seed: int, budget: int, workers: int) -> int | None:
    """The place of the first take meeting every goal in the order of the draws, or None."""
    from impulse.takes import search

    scene, spec = _shot(shot)
    with tempfile.TemporaryDirectory() as out:
        found = search(
            scene,
            spec["goals"],
            spec["variation"],
            budget=budget,
            steps=spec["steps"],
            seed=seed,
            method=method,
            stop_after=1,
            workers=workers,
            out=out,
            progress=False,
        )
        population = found.manifest["population"]
        places = [
            row["generation"] * population + row["index"] + 1
            for row in found.table.to_pylist()
            if row["met"]
        ]
    return min(places) if places else None


def takes_per_second(shot: str, backend: str, workers: int, takes: int) -> tuple[float, float]:
    """Takes per second of a random search of ``takes`` takes that never stops early, and how
    many workers were busy on average (the takes' summed run times over the wall time)."""
    from impulse.takes import search

    scene, spec = _shot(shot)
    if backend == "ray":
        import ray

        # A running Ray, as a cluster would be: its start-up is not the search's.
        ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
    try:
        with tempfile.TemporaryDirectory() as out:
            start = time.perf_counter()
            found = search(
                scene,
                spec["goals"],
                spec["variation"],
                budget=takes,
                steps=spec["steps"],
                method="random",
                stop_after=takes + 1,
                backend=backend,
                workers=workers,
                out=out,
                progress=False,
            )
            elapsed = time.perf_counter() - start
            busy = sum(found.table.column("wall_time_s").to_pylist()) / elapsed
            return takes / elapsed, busy
    finally:
        if backend == "ray":
            ray.shutdown()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--shots", default="dice,hoop,pachinko,bowling")
    parser.add_argument("--seeds", type=int, default=5, help="searches per shot and method")
    parser.add_argument("--first-seed", type=int, default=0, help="seeds first-seed.. on")
    parser.add_argument("--budget", type=int, default=2000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--methods", default="cross-entropy,random")
    parser.add_argument("--no-first-success", action="store_true")
    parser.add_argument("--no-throughput", action="store_true")
    parser.add_argument("--throughput-shot", default="bowling")
    parser.add_argument("--throughput-takes", type=int, default=256)
    arguments = parser.parse_args()
    shots = arguments.shots.split(",")

    if not arguments.no_first_success:
        first, last = arguments.first_seed, arguments.first_seed + arguments.seeds - 1
        print(f"takes to the first success (budget {arguments.budget}, seeds {first}..{last})")
        methods = arguments.methods.split(",")
        print("| shot | " + " | ".join(f"{m}: median | each" for m in methods) + " |")
        print("|---|" + "---|---|" * len(methods))
        for shot in shots:
            cells = [shot]
            for method in methods:
                counts = [
                    first_success(shot, method, seed, arguments.budget, arguments.workers)
                    for seed in range(first, last + 1)
                ]
                # A search that found none counts as more than the budget.
                ranked = [arguments.budget + 1 if c is None else c for c in counts]
                median = statistics.median(ranked)
                shown = f"> {arguments.budget}" if median > arguments.budget else f"{median:g}"
                each = ", ".join("none" if c is None else str(c) for c in counts)
                cells += [shown, each]
            print("| " + " | ".join(cells) + " |", flush=True)

    if not arguments.no_throughput:
        backends = ["local"]
        try:
            import ray  # noqa: F401

            backends.append("ray")
        except ImportError:
            print("ray is not installed: no Ray rows", file=sys.stderr)
        count = arguments.throughput_takes
        print(f"\nthroughput ({count} takes of {arguments.throughput_shot}, takes/s)")
        print("| backend | 1 worker | 2 workers | ratio | workers busy (of 2) |")
        print("|---|---|---|---|---|")
        for backend in backends:
            one, _ = takes_per_second(arguments.throughput_shot, backend, 1, count)
            two, busy = takes_per_second(arguments.throughput_shot, backend, 2, count)
            print(
                f"| {backend} | {one:.1f} | {two:.1f} | {two / one:.2f} | {busy:.2f} |", flush=True
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
