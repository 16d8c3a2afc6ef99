#!/usr/bin/env python3
"""The joint gap alone (a chain's stretch) of a scene with joints, from `impulse-bench front --json`.

The front's E for a scene with joints is max(joint gap, overlap); this reads the joint gap by
itself, as issue targets about stretch ask:

- each engine's cheapest setting whose joint gap is at most 50, 5 and 1 mm;
- each peer setting that some impulse setting of no more time does not beat on the joint gap
  (none listed: at every peer setting's time impulse stretches less).

Usage: python3 scripts/front-joint-gap.py FRONT.json SCENE
"""

import json
import sys


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__.strip().splitlines()[-1], file=sys.stderr)
        return 2
    path, scene_name = sys.argv[1], sys.argv[2]
    with open(path, encoding="utf-8") as f:
        front = json.load(f)
    scenes = [s for s in front["scenes"] if s["scene"] == scene_name]
    if not scenes:
        print(f"{path}: no scene named {scene_name!r}", file=sys.stderr)
        return 1
    points = [
        p
        for p in scenes[0]["points"]
        if p["failed"] is None and p.get("joint_gap_mm") is not None
    ]
    if not points:
        print(f"{path}: {scene_name} has no joint gap (a scene without joints?)", file=sys.stderr)
        return 1
    engines = sorted({p["engine"] for p in points}, key=lambda e: (e != "impulse", e))
    print(f"{scene_name}: cheapest setting with joint gap <= bar (ms/step, joint gap mm)")
    for bar in (50.0, 5.0, 1.0):
        cells = []
        for engine in engines:
            meeting = [p for p in points if p["engine"] == engine and p["joint_gap_mm"] <= bar]
            if meeting:
                best = min(meeting, key=lambda p: p["ms_per_step"])
                cells.append(
                    f"{engine} {best['setting']} {best['ms_per_step']:.3g} ms "
                    f"{best['joint_gap_mm']:.3g} mm"
                )
            else:
                cells.append(f"{engine} none")
        print(f"  <= {bar:g} mm: " + "; ".join(cells))
    impulse = [p for p in points if p["engine"] == "impulse"]
    print("peer settings impulse does not beat on joint gap within their time:")
    unbeaten = 0
    for peer in sorted(
        (p for p in points if p["engine"] != "impulse"), key=lambda p: p["ms_per_step"]
    ):
        within = [p for p in impulse if p["ms_per_step"] <= peer["ms_per_step"]]
        best = min(within, key=lambda p: p["joint_gap_mm"]) if within else None
        if best is None or best["joint_gap_mm"] >= peer["joint_gap_mm"]:
            unbeaten += 1
            against = (
                f"impulse's best within it: {best['setting']} {best['ms_per_step']:.3g} ms "
                f"{best['joint_gap_mm']:.3g} mm"
                if best
                else "no impulse setting that cheap"
            )
            print(
                f"  {peer['engine']} {peer['setting']}: {peer['ms_per_step']:.3g} ms "
                f"{peer['joint_gap_mm']:.3g} mm; {against}"
            )
    if unbeaten == 0:
        print("  none")
    return 0


if __name__ == "__main__":
    sys.exit(main())
