"""Command line of :func:`impulse.sweep.sweep`:
``python -m impulse.sweep SCENE --grid ... --out DIR``."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

EXAMPLES = """\
examples:
  python -m impulse.sweep stack30 --grid materials.default.friction=0.2,0.5 \\
      --seeds 0:64 --steps 600 --preset fast --jitter-position 0.01 \\
      --backend local --out sweep-stack30
  python -m impulse.sweep scenes/pyramid20.json --grid solver.substeps=8,12,20 \\
      --grid 'bodies[3].linear_velocity=[0,0,-5],[0,0,-10]' --steps 300 --backend ray --out s3://bucket/sweep

Running the same command again skips the runs already in OUT (a resumed sweep). The results are
OUT/results.parquet (one row per run) and OUT/manifest.json.
"""


def parse_values(text: str) -> list[Any]:
    """The values of ``--grid PATH=V1,V2,...``: the list as JSON where ``[V1,V2,...]`` parses
    (numbers, ``true``, ``[0,0,-5],[0,0,-10]``, ``"quoted"``), else split at commas with each
    value as JSON where it parses and as a string where not (``pgs,nncg``)."""
    try:
        values = json.loads(f"[{text}]")
    except json.JSONDecodeError:
        values = []
        for part in text.split(","):
            try:
                values.append(json.loads(part))
            except json.JSONDecodeError:
                values.append(part)
    if not values:
        raise ValueError("no values")
    return values


def parse_grid_item(text: str) -> tuple[str, list[Any]]:
    """``PATH=V1,V2,...`` as ``(PATH, [V1, V2, ...])``."""
    path, separator, values = text.partition("=")
    path = path.strip()
    if not separator or not path or not values.strip():
        raise argparse.ArgumentTypeError(
            f"--grid {text!r}: expected PATH=V1,V2,... (like materials.default.friction=0.2,0.5)"
        )
    try:
        return path, parse_values(values)
    except ValueError as error:
        raise argparse.ArgumentTypeError(f"--grid {text!r}: {error}") from None


def parse_seeds(text: str) -> list[int]:
    """``A:B`` (seeds A … B−1), ``N`` (seeds 0 … N−1) or ``S1,S2,...`` (those seeds)."""
    try:
        if ":" in text:
            start, _, stop = text.partition(":")
            seeds = list(range(int(start), int(stop)))
        elif "," in text:
            seeds = [int(part) for part in text.split(",")]
        else:
            seeds = list(range(int(text)))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"--seeds {text!r}: expected A:B, N or S1,S2,..."
        ) from None
    if not seeds or any(seed < 0 for seed in seeds):
        raise argparse.ArgumentTypeError(f"--seeds {text!r}: no seeds, or a negative seed")
    return seeds


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m impulse.sweep",
        description="Run a scene over a grid of overrides and seeds, on a local process pool "
        "or on Ray, into one Parquet table (resumable).",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "scene",
        help="scene file (.json) or built-in scene name "
        "(python -c 'import impulse; print(impulse.scenes())')",
    )
    p.add_argument(
        "--grid",
        action="append",
        type=parse_grid_item,
        default=[],
        metavar="PATH=V1,V2,...",
        help="an override path and its values (repeat for more; the runs are the product of all)",
    )
    p.add_argument(
        "--seeds",
        type=parse_seeds,
        default=[0],
        metavar="A:B|N|S1,S2",
        help="seeds of each grid point (default: 0)",
    )
    p.add_argument("--steps", type=int, required=True, help="steps of every run")
    p.add_argument(
        "--preset",
        choices=["fast", "default", "precise", "reference"],
        help="solver effort, as `impulse run --preset`",
    )
    p.add_argument(
        "--jitter-position",
        type=float,
        default=0.0,
        metavar="M",
        help="per-seed position jitter of the dynamic bodies (m)",
    )
    p.add_argument(
        "--jitter-angle",
        type=float,
        default=0.0,
        metavar="DEG",
        help="per-seed orientation jitter (degrees)",
    )
    p.add_argument(
        "--jitter-velocity",
        type=float,
        default=0.0,
        metavar="V",
        help="per-seed velocity jitter (m/s)",
    )
    p.add_argument(
        "--backend",
        choices=["local", "ray"],
        default="local",
        help="local process pool (default) or Ray tasks",
    )
    p.add_argument(
        "--workers",
        type=int,
        help="worker processes (local) or CPUs of the local Ray it starts (default: all cores)",
    )
    p.add_argument(
        "--address", help="Ray cluster to join (auto, ray://head:10001); default: start a local Ray"
    )
    p.add_argument(
        "--out",
        required=True,
        help="results directory or URI (s3://bucket/prefix, through pyarrow's filesystems)",
    )
    p.add_argument(
        "--save-trajectories",
        type=int,
        nargs="?",
        const=1,
        default=0,
        metavar="K",
        help="also write each run's trajectory, every K-th step (default K=1)",
    )
    p.add_argument(
        "--retry-failed", action="store_true", help="run again the runs written as failed"
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


def main(argv: list[str] | None = None) -> int:
    """Runs the sweep; prints the runs by status. Exit status 0 when every run of this sweep
    completed, 1 when some stopped or failed, 2 for bad arguments or a scene that does not load,
    130 when interrupted (Ctrl-C; the finished runs are kept)."""
    from impulse.sweep import sweep

    args = parser().parse_args(argv)
    grid: dict[str, list[Any]] = {}
    for path, values in args.grid:
        if path in grid:
            parser().error(f"--grid {path} given twice")
        grid[path] = values
    jitter = None
    if args.jitter_position or args.jitter_angle or args.jitter_velocity:
        jitter = {
            "position": args.jitter_position,
            "angle": args.jitter_angle,
            "velocity": args.jitter_velocity,
        }
    try:
        table = sweep(
            args.scene,
            grid=grid,
            seeds=args.seeds,
            steps=args.steps,
            backend=args.backend,
            out=args.out,
            save_trajectories=args.save_trajectories or False,
            preset=args.preset,
            jitter=jitter,
            workers=args.workers,
            address=args.address,
            progress=not args.no_progress,
            retry_failed=args.retry_failed,
        )
    except (ValueError, TypeError, OSError) as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(
            f"interrupted: the finished runs are in {args.out}; the same command resumes the sweep",
            file=sys.stderr,
        )
        return 130
    from impulse.sweep import MANIFEST_FILE, RESULTS_FILE

    manifest = _read_manifest(args.out, MANIFEST_FILE)
    counts = {k: manifest.get(k, 0) for k in ("completed", "stopped", "failed")}
    rows = table.num_rows if table is not None else 0
    print(
        f"{manifest.get('runs', 0)} runs: {counts['completed']} completed, "
        f"{counts['stopped']} stopped, {counts['failed']} failed; "
        f"{rows} rows in {args.out}/{RESULTS_FILE}"
    )
    return 0 if counts["stopped"] == 0 and counts["failed"] == 0 else 1


def _read_manifest(out: str, name: str) -> dict[str, Any]:
    from impulse.sweep import _filesystem

    filesystem, root = _filesystem(out)
    with filesystem.open_input_stream(f"{root}/{name}") as stream:
        return json.loads(stream.read().decode())
