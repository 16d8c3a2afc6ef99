#!/usr/bin/env python3
"""Runs per second of a sweep on one worker, on the local pool and on a local Ray.

    python scripts/sweep-speed.py [--scene stack30] [--runs 256] [--steps 600] [--preset fast]
                                  [--workers 2] [--out DIR]

Each configuration sweeps the same runs (one grid point, seeds 0 … runs−1, a small position
jitter so that the runs differ) into a fresh directory. Runs per second = runs / the sweep's
wall time, pool start-up included; Ray's own start-up (`ray.init`) is timed apart, since a
cluster is started once for many sweeps, and a sweep of tiny runs goes first, which also starts
Ray's worker processes. The per-run overhead of a backend is
(wall time × workers − the runs' own wall time in their workers) / runs: what a run costs
beyond its simulation (sending, scheduling, returning the row, writing the table). On a shared
machine the runs' CPU time (`cpu_time_s`) tells what each configuration got: the cores the runs
had = their CPU seconds / the sweep's wall time.
Needs impulse, pyarrow and ray installed.
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time


def measure(label, out, workers, **options):
    from impulse.sweep import sweep

    shutil.rmtree(out, ignore_errors=True)
    start = time.perf_counter()
    table = sweep(out=out, progress=False, workers=workers, **options)
    elapsed = time.perf_counter() - start
    runs = table.num_rows
    statuses = set(table.column("status").to_pylist())
    inside = sum(table.column("wall_time_s").to_pylist())
    cpu = sum(table.column("cpu_time_s").to_pylist())
    overhead_ms = (elapsed * workers - inside) / runs * 1e3
    print(
        f"{label:<28} {runs} runs in {elapsed:7.2f} s: {runs / elapsed:7.2f} runs/s; "
        f"mean run in its worker {inside / runs * 1e3:7.1f} ms; "
        f"overhead per run {overhead_ms:6.1f} ms "
        f"(statuses {sorted(statuses)}); CPU per run {cpu / runs * 1e3:6.1f} ms, "
        f"runs per CPU-second {runs / cpu:6.2f}, cores the runs had {cpu / elapsed:4.2f}",
        flush=True,
    )
    return runs / elapsed, table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scene", default="stack30")
    parser.add_argument("--runs", type=int, default=256)
    parser.add_argument("--steps", type=int, default=600)
    parser.add_argument("--preset", default="fast")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", default=None, help="scratch directory (default: a temporary one)")
    parser.add_argument(
        "--overhead-steps",
        type=int,
        default=1,
        help="steps of the runs that measure the per-run overhead alone",
    )
    args = parser.parse_args()
    out = args.out or tempfile.mkdtemp(prefix="sweep-speed-")
    options = dict(
        scene=args.scene,
        seeds=args.runs,
        steps=args.steps,
        preset=args.preset,
        jitter={"position": 0.001},
    )
    print(
        f"{args.runs} runs of {args.scene}, {args.steps} steps, preset {args.preset}; "
        f"os.cpu_count() = {os.cpu_count()}; "
        f"load average {os.getloadavg()}",
        flush=True,
    )

    one, single = measure(
        "local, 1 worker", os.path.join(out, "one"), 1, backend="local", **options
    )
    pool, local = measure(
        f"local, {args.workers} workers",
        os.path.join(out, "local"),
        args.workers,
        backend="local",
        **options,
    )

    import ray

    start = time.perf_counter()
    ray.init(num_cpus=args.workers, include_dashboard=False, log_to_driver=False)
    print(f"ray.init(num_cpus={args.workers}): {time.perf_counter() - start:.2f} s", flush=True)
    # The tiny runs first: they also start Ray's worker processes, which a cluster keeps warm.
    tiny = dict(options, steps=args.overhead_steps)
    measure(
        f"ray, {args.workers} CPUs, {args.overhead_steps}-step runs",
        os.path.join(out, "ray-tiny"),
        args.workers,
        backend="ray",
        **tiny,
    )
    on_ray, ray_table = measure(
        f"ray, {args.workers} CPUs",
        os.path.join(out, "ray"),
        args.workers,
        backend="ray",
        **options,
    )
    ray.shutdown()
    measure(
        f"local, {args.workers} workers, {args.overhead_steps}-step runs",
        os.path.join(out, "local-tiny"),
        args.workers,
        backend="local",
        **tiny,
    )

    from impulse.sweep import TIMING_COLUMNS

    def simulated(table):
        return table.drop_columns(list(TIMING_COLUMNS)).to_pylist()

    same = simulated(single) == simulated(local) == simulated(ray_table)
    print(
        f"speed-up over one worker: local {pool / one:.2f}x, ray {on_ray / one:.2f}x; "
        f"the three tables equal to the bit: {same}; load average now {os.getloadavg()}",
        flush=True,
    )
    if args.out is None:
        shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    main()
