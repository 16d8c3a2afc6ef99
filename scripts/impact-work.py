#!/usr/bin/env python3
"""Where a run's impact sweeps went, from its island report.

    impulse run pour2000 --threads 1 --no-sleep --quiet --island-report R.jsonl
    python3 scripts/impact-work.py R.jsonl [--steps A:B]

Prints, for islands of fewer than 32 contact points, 32 to 127, 128 to 1,023 and 1,024 or more, the
point updates of the impact sweeps (`impact_points`, summed over the islands, per step), the
islands' contact points per step and how many island-steps took impact sweeps; then the
step's mean wall-clock time (ms, the report's `ms`: a measure of the machine's load as much
as of the work). The point counts do not depend on the machine (docs/method.md, "Local impact
sweeps").
"""

import argparse
import json

CLASSES = [
    ("under 32", 0, 32),
    ("32-127", 32, 128),
    ("128-1,023", 128, 1024),
    ("1,024 and more", 1024, None),
]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("report", help="the island report (JSON Lines) of `impulse run`")
    parser.add_argument("--steps", default=":", help="steps A:B of the run (Python slice)")
    args = parser.parse_args()
    start, _, end = args.steps.partition(":")
    with open(args.report, encoding="utf-8") as file:
        rows = [json.loads(line) for line in file if line.strip()]
    rows = rows[int(start) if start else None : int(end) if end else None]
    if not rows:
        raise SystemExit(f"{args.report}: no steps in {args.steps}")
    print(f"{len(rows)} steps")
    print(f"{'island points':>16} {'impact points/step':>19} {'points/step':>12} {'impact islands':>15}")
    for name, low, high in CLASSES:
        impact = points = struck = 0
        for row in rows:
            for island in row["islands"]:
                contacts = island.get("contacts", 0)
                if contacts < low or (high is not None and contacts >= high):
                    continue
                impact += island.get("impact_points", 0)
                points += contacts
                struck += island.get("impact_sweeps", 0) > 0
        print(f"{name:>16} {impact / len(rows):>19,.0f} {points / len(rows):>12,.0f} {struck:>15,}")
    print(f"mean step {sum(row['ms'] for row in rows) / len(rows):.2f} ms")


if __name__ == "__main__":
    main()
