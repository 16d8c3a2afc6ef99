"""The command line: ``python -m impulse.takes search | scene | sheet``.

Exit codes: 0 done (``search``: at least one take meets every goal), 1 (``search``: none did
within the budget), 2 bad arguments or files.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m impulse.takes",
        description="Search for takes of a scene that meet stated goals, and browse them.",
    )
    commands = parser.add_subparsers(dest="command", required=True)

    search = commands.add_parser(
        "search",
        help="search for takes that meet every goal",
        description="Exit 0 when at least one take meets every goal, 1 when none did within "
        "the budget, 2 for bad arguments or files. Progress on stderr.",
    )
    search.add_argument("scene", help="scene file (JSON)")
    search.add_argument(
        "--goals",
        required=True,
        help='goals file: a list of goals, or {"goals": [...], "steps": N, "variation": {...}}',
    )
    search.add_argument("--budget", type=int, required=True, help="most takes to run")
    search.add_argument("--out", required=True, help="results directory (resumed if present)")
    search.add_argument("--steps", type=int, help="steps per take (default: the goals file's)")
    search.add_argument("--backend", choices=("local", "ray"), default="local")
    search.add_argument("--workers", type=int, help="worker processes (default: all cores)")
    search.add_argument("--address", help="Ray cluster address (ray backend)")
    search.add_argument("--seed", type=int, default=0, help="seed of the search's draws")
    search.add_argument("--population", type=int, default=32, help="takes per generation")
    search.add_argument(
        "--stop-after", type=int, default=1, help="stop once this many takes meet every goal"
    )
    search.add_argument(
        "--method",
        choices=("cross-entropy", "random"),
        default="cross-entropy",
        help="the cross-entropy method, or plain random sampling from the prior (a baseline)",
    )
    search.add_argument("--preset", choices=("fast", "default", "precise", "reference"))
    search.add_argument("--vary-bodies", help="comma-separated body names (default: all dynamic)")
    search.add_argument(
        "--vary-seed",
        action="store_true",
        help="give each take its own scene seed (the rough surfaces' draws)",
    )
    search.add_argument(
        "--vary-roughness-draws",
        type=int,
        metavar="K",
        help="give each varied body's first K rough contacts draws from the take's θ "
        "(2K components per body) instead of the seed",
    )
    for field, unit in (
        ("position", "m"),
        ("angle", "degrees"),
        ("velocity", "m/s"),
        ("angular-velocity", "rad/s"),
    ):
        search.add_argument(
            f"--vary-{field}", type=float, help=f"scale of the {field} offsets ({unit})"
        )
    search.add_argument("--no-progress", action="store_true", help="no progress bar")

    scene = commands.add_parser("scene", help="write one take's varied scene")
    scene.add_argument("directory", help="a search's results directory")
    scene.add_argument("take_id", help="the take's id")
    scene.add_argument("--out", required=True, help="the scene file to write (JSON)")

    sheet = commands.add_parser("sheet", help="write the contact sheet (a static HTML page)")
    sheet.add_argument("directory", help="a search's results directory")
    sheet.add_argument("--out", help="the page to write (default DIRECTORY/sheet.html)")
    sheet.add_argument("--count", type=int, default=24, help="how many takes, best first")
    sheet.add_argument("--every", type=int, default=4, help="draw every K-th step")
    sheet.add_argument("--size", default="192x144", help="preview size WxH")
    sheet.add_argument("--no-previews", action="store_true", help="a page without previews")
    return parser


def _variation(arguments: argparse.Namespace, spec: dict[str, Any]) -> dict[str, Any]:
    out = dict(spec)
    if arguments.vary_bodies:
        out["bodies"] = [name.strip() for name in arguments.vary_bodies.split(",")]
    if arguments.vary_seed:
        out["seeds"] = True
    if arguments.vary_roughness_draws is not None:
        out["roughness_draws"] = arguments.vary_roughness_draws
    for field in ("position", "angle", "velocity", "angular_velocity"):
        value = getattr(arguments, f"vary_{field}")
        if value is not None:
            out[field] = value
    return out


def _search(arguments: argparse.Namespace) -> int:
    from impulse.takes import search

    with open(arguments.goals, encoding="utf-8") as file:
        try:
            spec = json.load(file)
        except json.JSONDecodeError as error:
            raise ValueError(f"{arguments.goals}: {error}") from None
    goals = spec.get("goals") if isinstance(spec, dict) else spec
    steps = arguments.steps or (spec.get("steps") if isinstance(spec, dict) else None)
    if steps is None:
        raise ValueError('give --steps, or "steps" in the goals file')
    variation = _variation(arguments, spec.get("variation", {}) if isinstance(spec, dict) else {})
    if not isinstance(goals, list):
        raise ValueError(f'{arguments.goals}: expected a list of goals or {{"goals": [...]}}')
    takes = search(
        arguments.scene,
        goals,
        variation,
        budget=arguments.budget,
        steps=int(steps),
        out=arguments.out,
        backend=arguments.backend,
        workers=arguments.workers,
        address=arguments.address,
        seed=arguments.seed,
        population=arguments.population,
        stop_after=arguments.stop_after,
        method=arguments.method,
        preset=arguments.preset,
        progress=not arguments.no_progress,
    )
    met = takes.met()
    best = takes.best(1)
    print(f"{len(takes)} takes, {len(met)} meet every goal", file=sys.stderr)
    if best:
        take = best[0]
        print(
            f"best: {take.take_id} (cost {take.cost}, perturbation {take.perturbation:.3g})",
            file=sys.stderr,
        )
    return 0 if met else 1


def main(argv: list[str] | None = None) -> int:
    """Runs the command line; returns the exit code."""
    arguments = _parser().parse_args(argv)
    try:
        if arguments.command == "search":
            return _search(arguments)
        from impulse.takes import load, sheet

        if arguments.command == "scene":
            load(arguments.directory)[arguments.take_id].write_scene(arguments.out)
            return 0
        page = sheet(
            arguments.directory,
            arguments.out,
            count=arguments.count,
            every=arguments.every,
            size=arguments.size,
            previews=not arguments.no_previews,
        )
        print(page)
        return 0
    except (ValueError, TypeError, KeyError, OSError, RuntimeError) as error:
        message = error.args[0] if isinstance(error, KeyError) and error.args else error
        print(f"error: {message}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted: the takes run so far are kept; run again to resume", file=sys.stderr)
        return 130
