"""Reads what `impulse run` wrote, for the export checks: the CSV trajectory and the scene's
body names."""

import csv
import json
import math


class Trajectory:
    """Poses per written frame from `impulse run --out FILE.csv`.

    `frames` maps the step number to a list of (translation (x, y, z), quaternion (x, y, z, w))
    per body in scene order; `times` maps it to the time in seconds.
    """

    def __init__(self, path):
        self.frames = {}
        self.times = {}
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                frame = int(row["frame"])
                body = int(row["body"])
                poses = self.frames.setdefault(frame, [])
                if body != len(poses):
                    raise ValueError(f"{path}: frame {frame}: body {body} out of order")
                poses.append(
                    (
                        tuple(float(row[k]) for k in ("x", "y", "z")),
                        tuple(float(row[k]) for k in ("qx", "qy", "qz", "qw")),
                    )
                )
                self.times[frame] = float(row["time"])
        if not self.frames:
            raise ValueError(f"{path}: no frames")
        self.steps = sorted(self.frames)
        self.bodies = len(self.frames[self.steps[0]])

    def dt(self):
        """The time step, from the last frame's time and step number."""
        last = self.steps[-1]
        return self.times[last] / last if last else math.nan


def body_names(scene_path):
    """Body names of a scene JSON file, as the exporters name them (`body_<index>` when the
    scene gives none)."""
    with open(scene_path) as f:
        scene = json.load(f)
    return [body.get("name") or f"body_{i}" for i, body in enumerate(scene["bodies"])]


def body_kinds(scene_path):
    with open(scene_path) as f:
        scene = json.load(f)
    return [body["kind"] for body in scene["bodies"]]


def close(a, b, tolerance):
    return all(abs(x - y) <= tolerance for x, y in zip(a, b, strict=True))


def same_rotation(q, r, tolerance):
    """Quaternions equal up to sign (q and -q are the same rotation; the exports keep
    consecutive keyframes in one hemisphere)."""
    return close(q, r, tolerance) or close([-c for c in q], r, tolerance)
