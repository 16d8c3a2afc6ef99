"""The command line: ``python -m impulse.takes search | refine | scene | sheet``.

Exit codes: 0 done (``search``: at least one take meets every goal), 1 (``search``: none did
within the budget), 2 bad arguments or files (a flag's or a goal's error names it), 130
interrupted by Ctrl-C, 143 by SIGTERM (the takes finished so far kept either way).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any


def _integer(least: int):
    """An argparse type: an integer >= ``least`` (argparse names the flag in its error)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
        if value < least:
            raise argparse.ArgumentTypeError(f"{value} must be an integer >= {least}")
        return value

    return parse


def _scale(text: str) -> float:
    """An argparse type: a finite number >= 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value) or value < 0.0:
        raise argparse.ArgumentTypeError(f"{text} must be a finite number >= 0")
    return value


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
    search.add_argument("--budget", type=_integer(1), required=True, help="most takes to run")
    search.add_argument("--out", required=True, help="results directory (resumed if present)")
    search.add_argument(
        "--steps", type=_integer(1), help="steps per take (default: the goals file's)"
    )
    search.add_argument("--backend", choices=("local", "ray"), default="local")
    search.add_argument(
        "--workers", type=_integer(1), help="worker processes (default: all cores)"
    )
    search.add_argument("--address", help="Ray cluster address (ray backend)")
    search.add_argument(
        "--seed", type=_integer(0), default=0, help="seed of the search's draws"
    )
    search.add_argument(
        "--population", type=_integer(2), default=32, help="takes per generation"
    )
    search.add_argument(
        "--stop-after",
        type=_integer(1),
        default=1,
        help="stop at the take (in the order they are drawn) that is the N-th to meet every "
        "goal",
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
        type=_integer(0),
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
            f"--vary-{field}", type=_scale, help=f"scale of the {field} offsets ({unit})"
        )
    search.add_argument("--no-progress", action="store_true", help="no progress bar")

    scene = commands.add_parser("scene", help="write one take's varied scene")
    scene.add_argument("directory", help="a search's results directory")
    scene.add_argument("take_id", help="the take's id")
    scene.add_argument("--out", required=True, help="the scene file to write (JSON)")

    refine = commands.add_parser(
        "refine",
        help="search around one take, keeping the search's goals",
        description="Runs BUDGET takes drawn around the take (its θ plus --step N(0, I)), with "
        "the search's scene, goals, variation and steps. Around a take meeting every goal the "
        "step adapts (a trust region): halved after a generation in which fewer than half the "
        "takes meet every goal, grown back toward --step when most do; around one that "
        "misses, the takes are refined toward the goals. Exit codes as search.",
    )
    refine.add_argument("directory", help="a search's results directory")
    refine.add_argument("take_id", help="the take to refine around")
    refine.add_argument("--budget", type=_integer(1), required=True, help="takes to run")
    refine.add_argument(
        "--out", help="results directory (default DIRECTORY/refine/TAKE_ID; resumed if present)"
    )
    refine.add_argument(
        "--step",
        type=_scale,
        default=0.002,
        help="spread of θ around the take, the trust region's largest (unit-free)",
    )
    refine.add_argument(
        "--population", type=_integer(2), help="takes per generation (default 8)"
    )
    refine.add_argument("--backend", choices=("local", "ray"), default="local")
    refine.add_argument(
        "--workers", type=_integer(1), help="worker processes (default: all cores)"
    )
    refine.add_argument("--address", help="Ray cluster address (ray backend)")
    refine.add_argument("--seed", type=_integer(0), default=0, help="seed of the draws")
    refine.add_argument(
        "--stop-after",
        type=_integer(1),
        help="stop at the N-th take meeting every goal (default: run the whole budget)",
    )
    refine.add_argument("--no-progress", action="store_true", help="no progress bar")

    sheet = commands.add_parser("sheet", help="write the contact sheet (a static HTML page)")
    sheet.add_argument("directory", help="a search's results directory")
    sheet.add_argument("--out", help="the page to write (default DIRECTORY/sheet.html)")
    sheet.add_argument(
        "--count", type=_integer(1), default=24, help="how many takes, best first"
    )
    sheet.add_argument("--every", type=_integer(1), default=4, help="draw every K-th step")
    sheet.add_argument("--size", default="192x144", help="preview size WxH")
    sheet.add_argument(
        "--camera",
        default="goals",
        help="goals (frame the goal bodies where their goals are judged, the default), scene "
        "(impulse render's view of the moving bodies at step 0), or EX,EY,EZ:TX,TY,TZ (eye and "
        "target, m); with any camera the goals' regions are outlined in magenta",
    )
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
    from impulse.takes._goals import FILE_KEYS

    where = arguments.goals
    with open(where, encoding="utf-8") as file:
        try:
            spec = json.load(file)
        except json.JSONDecodeError as error:
            raise ValueError(f"{where}: {error}") from None
    if isinstance(spec, dict):
        unknown = sorted(set(spec) - set(FILE_KEYS))
        if unknown:
            raise ValueError(
                f"{where}: unknown keys {unknown}: a goals file is a list of goals or an "
                f"object with {', '.join(FILE_KEYS)}"
            )
        goals = spec.get("goals")
        variation = spec.get("variation", {})
        if not isinstance(variation, dict):
            raise ValueError(f"{where}: variation: expected an object, got {variation!r}")
    else:
        goals, variation = spec, {}
    if not isinstance(goals, list):
        raise ValueError(f'{where}: expected a list of goals or {{"goals": [...]}}')
    steps = arguments.steps
    if steps is None:
        steps = spec.get("steps") if isinstance(spec, dict) else None
        if steps is None:
            raise ValueError(f'give --steps, or "steps" in {where}')
        if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
            raise ValueError(f"{where}: steps: {steps!r} must be an integer >= 1")
    variation = _variation(arguments, variation)
    from impulse.takes._search import as_goals

    try:
        goals = as_goals(goals)
    except ValueError as error:
        raise ValueError(f"{where}: {error}") from None
    try:
        takes = _run_search(arguments, goals, variation, steps)
    except ValueError as error:
        if str(error).startswith("goals["):  # a goal the scene cannot hold: name the file
            raise ValueError(f"{where}: {error}") from None
        raise
    return _report(takes)


def _run_search(arguments: argparse.Namespace, goals: Any, variation: Any, steps: int) -> Any:
    from impulse.takes import search

    return search(
        arguments.scene,
        goals,
        variation,
        budget=arguments.budget,
        steps=steps,
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


def _refine(arguments: argparse.Namespace) -> int:
    from impulse.takes import refine

    if not arguments.step > 0.0:
        raise ValueError(f"--step {arguments.step}: must be > 0")
    takes = refine(
        arguments.directory,
        arguments.take_id,
        budget=arguments.budget,
        out=arguments.out,
        step=arguments.step,
        backend=arguments.backend,
        workers=arguments.workers,
        address=arguments.address,
        seed=arguments.seed,
        population=arguments.population,
        stop_after=arguments.stop_after,
        progress=not arguments.no_progress,
    )
    steps = takes.trust_region_steps()
    if steps:
        print(
            f"trust region: step {steps[0]:.3g} in the first generation, {steps[-1]:.3g} in the "
            f"last (of {len(steps)})",
            file=sys.stderr,
        )
    return _report(takes)


def _report(takes: Any) -> int:
    """Prints a search's outcome on stderr; its exit code (0: a take meets every goal)."""
    met = takes.met()
    best = takes.best(1)
    print(f"{takes.root}: {len(takes)} takes, {len(met)} meet every goal", file=sys.stderr)
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
        if arguments.command == "refine":
            return _refine(arguments)
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
            camera=arguments.camera,
        )
        print(page)
        return 0
    except (ValueError, TypeError, KeyError, OSError, RuntimeError) as error:
        message = error.args[0] if isinstance(error, KeyError) and error.args else error
        print(f"error: {message}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as interrupt:
        from impulse.takes._search import Terminated

        print("interrupted: the takes run so far are kept; run again to resume", file=sys.stderr)
        return 143 if isinstance(interrupt, Terminated) else 130
