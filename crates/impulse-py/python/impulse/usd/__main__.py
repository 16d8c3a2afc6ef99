"""``python -m impulse.usd``: bake a UsdPhysics stage, or turn stages and scenes into each other.

    python -m impulse.usd run stage.usda --out baked.usda [--steps N] [--every K] [--preset P]
    python -m impulse.usd export stage.usda --out scene.json     # a stage's scene (JSON; - for stdout)
    python -m impulse.usd import scene.json --out stage.usda     # a scene as a UsdPhysics stage (- for stdin)

Each prints the report of what the stage has that the scene does not simulate as authored,
one line per prim (``PATH: dropped|approximated|note: …``), on standard error; ``--strict``
makes anything dropped an error (exit status 3, nothing written). Errors print one line and exit
with status 2.
"""

from __future__ import annotations

import argparse
import json
import sys


def main(argv: list[str] | None = None) -> int:
    """The command line; returns the exit status."""
    parser = argparse.ArgumentParser(
        prog="python -m impulse.usd",
        description="UsdPhysics stages in, baked stages out (docs/usd.md).",
    )
    commands = parser.add_subparsers(dest="command", required=True)
    run = commands.add_parser("run", help="simulate a stage and write the baked layer over it")
    run.add_argument("stage", help="a .usda, .usdc or .usdz stage with UsdPhysics schemas")
    run.add_argument("--out", required=True, help="the baked layer to write (.usda or .usdc)")
    run.add_argument("--steps", type=int, help="steps to take (default: the stage's time range)")
    run.add_argument("--every", type=int, help="write every K-th step (default: one per time code)")
    run.add_argument("--preset", help="solver preset (fast, default, precise, reference)")
    export = commands.add_parser("export", help="write a stage's scene as JSON")
    export.add_argument("stage")
    export.add_argument("--out", required=True, help="the scene file to write (.json; - for standard output)")
    export.add_argument("--steps", type=int, help="the scene's steps (default: the stage's time range)")
    importing = commands.add_parser("import", help="write a scene (JSON) as a UsdPhysics stage")
    importing.add_argument("scene", help="a scene file (.json; - for standard input)")
    importing.add_argument(
        "--directory", help="the directory mesh files are relative to (default: the scene file's; for -, the current one)"
    )
    importing.add_argument("--out", required=True, help="the stage to write (.usda or .usdc)")
    for sub in (run, export):
        sub.add_argument("--strict", action="store_true", help="fail when anything is dropped")
        sub.add_argument("--quiet", action="store_true", help="print no report")
    args = parser.parse_args(argv)
    try:
        from . import bake, scene_to_stage, stage_to_scene

        if args.command == "import":
            if args.scene == "-":
                from ._write import absolute_files

                scene = json.load(sys.stdin)
                absolute_files(scene, args.directory or ".")
                scene_to_stage(scene, args.out)
            elif args.directory:
                from ._write import absolute_files

                with open(args.scene, encoding="utf-8") as file:
                    scene = json.load(file)
                absolute_files(scene, args.directory)
                scene_to_stage(scene, args.out)
            else:
                scene_to_stage(args.scene, args.out)
            return 0
        if args.command == "export":
            scene, report = stage_to_scene(args.stage, steps=args.steps)
            if args.strict and report.dropped():
                return _refuse(report, args.quiet)
            if args.out == "-":
                json.dump(scene, sys.stdout)
                sys.stdout.write("\n")
            else:
                with open(args.out, "w", encoding="utf-8") as file:
                    json.dump(scene, file, indent=1)
                    file.write("\n")
        else:
            if args.strict:
                # Refused before anything is simulated or written.
                _, report = stage_to_scene(args.stage, steps=args.steps)
                if report.dropped():
                    return _refuse(report, args.quiet)
            report = bake(args.stage, args.out, steps=args.steps, every=args.every, settings=args.preset)
    except (OSError, ValueError, RuntimeError, ImportError) as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    if args.strict and report.dropped():
        return _refuse(report, args.quiet)
    if not args.quiet:
        print(report, file=sys.stderr)
    return 0


def _refuse(report, quiet: bool) -> int:
    if not quiet:
        print(report, file=sys.stderr)
    print(f"error: {len(report.dropped())} things dropped (--strict): nothing written", file=sys.stderr)
    return 3


if __name__ == "__main__":
    sys.exit(main())
