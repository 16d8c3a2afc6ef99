#!/usr/bin/env python3
"""A pile's contacts over a run, from its island report.

    impulse run pour2000 --threads 1 --no-sleep --quiet --island-report R.jsonl
    python3 scripts/pile-report.py R.jsonl [R2.jsonl ...] [--points 1024]

For each report, over the islands of at least `--points` contact points (a pour's pile):
the deepest contact of each step (the largest `deepest_contact.depth` among them, in mm),
its mean over the steps that have such an island, its 90th percentile, its largest and its
value at the last step; and the share of SIMD lanes holding a contact point, `contacts` /
(4 × `bundles`) summed over those islands, and over the smaller islands in lanes (a pour's
landing clusters; docs/method.md, "Graph colouring and SIMD lanes"; "n/a" for a report
without `bundles`). Then the mean of the reports' means. Depths are
those of the contacts as each step found them, before its solve; they do not depend on the
machine.
"""

import argparse
import json


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("reports", nargs="+", help="island reports (JSON Lines) of `impulse run`")
    parser.add_argument("--points", type=int, default=1024, help="fewest contact points of an island counted")
    args = parser.parse_args()
    means = []
    for path in args.reports:
        deepest = []
        contacts = bundles = 0
        small_contacts = small_bundles = 0
        with open(path, encoding="utf-8") as report:
            for line in report:
                if not line.strip():
                    continue
                step = json.loads(line)
                piles = [i for i in step["islands"] if i.get("contacts", 0) >= args.points]
                depths = [i["deepest_contact"]["depth"] for i in piles if i.get("deepest_contact")]
                if depths:
                    deepest.append(1000.0 * max(depths))
                contacts += sum(i["contacts"] for i in piles if i.get("bundles"))
                bundles += sum(i.get("bundles", 0) for i in piles)
                smaller = [i for i in step["islands"] if 0 < i.get("contacts", 0) < args.points and i.get("bundles")]
                small_contacts += sum(i["contacts"] for i in smaller)
                small_bundles += sum(i["bundles"] for i in smaller)
        if not deepest:
            print(f"{path}: no island of {args.points} points or more")
            continue
        ordered = sorted(deepest)
        mean = sum(deepest) / len(deepest)
        means.append(mean)
        fill = f"{100.0 * contacts / (4 * bundles):.1f} %" if bundles else "n/a"
        small_fill = f"{100.0 * small_contacts / (4 * small_bundles):.1f} %" if small_bundles else "n/a"
        print(
            f"{path}: {len(deepest)} steps, deepest contact mean {mean:.2f} mm, "
            f"90th percentile {ordered[int(0.9 * len(ordered))]:.2f} mm, largest {ordered[-1]:.1f} mm, "
            f"last step {deepest[-1]:.2f} mm; lanes holding a point {fill}, in smaller islands {small_fill}"
        )
    if len(means) > 1:
        print(f"mean of the {len(means)} means: {sum(means) / len(means):.2f} mm")


if __name__ == "__main__":
    main()
