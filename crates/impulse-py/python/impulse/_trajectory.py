"""Trajectories: the frames of a simulation as NumPy arrays, saved as .npz or Parquet."""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Trajectory", "load_trajectory"]


@dataclass(eq=False)
class Trajectory:
    """Frames of a simulation (``World.simulate``).

    Attributes:
        positions: (F, N, 3) float32, body frame positions (m) per frame.
        orientations: (F, N, 4) float32, unit quaternions (x, y, z, w) per frame.
        steps: (F,) int64, the world's step count at each frame (0 = before the first step).
        times: (F,) float64, simulated time (s) at each frame.
        names: the N bodies' names ("" for a body without one).
    """

    positions: np.ndarray
    orientations: np.ndarray
    steps: np.ndarray
    times: np.ndarray
    names: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.positions = np.asarray(self.positions, dtype=np.float32)
        self.orientations = np.asarray(self.orientations, dtype=np.float32)
        self.steps = np.asarray(self.steps, dtype=np.int64)
        self.times = np.asarray(self.times, dtype=np.float64)
        self.names = [str(n) for n in self.names]
        frames = self.steps.shape[0]
        bodies = len(self.names)
        expected = {
            "positions": (self.positions.shape, (frames, bodies, 3)),
            "orientations": (self.orientations.shape, (frames, bodies, 4)),
            "steps": (self.steps.shape, (frames,)),
            "times": (self.times.shape, (frames,)),
        }
        for name, (got, want) in expected.items():
            if got != want:
                raise ValueError(f"trajectory {name}: expected shape {want}, got {got}")

    @property
    def frame_count(self) -> int:
        """Number of frames F."""
        return int(self.steps.shape[0])

    @property
    def body_count(self) -> int:
        """Number of bodies N."""
        return len(self.names)

    def __len__(self) -> int:
        return self.frame_count

    def __repr__(self) -> str:
        return f"Trajectory(frames={self.frame_count}, bodies={self.body_count})"

    def save(self, path: str | os.PathLike[str]) -> None:
        """Writes the trajectory to ``path``.

        ``.npz``: NumPy's archive with arrays ``positions``, ``orientations``, ``steps``,
        ``times`` and ``names`` (no pickled objects). ``.parquet``: one row per frame and body
        with columns ``step`` (int64), ``time`` (float64), ``body`` (int32), ``name`` (string),
        ``x y z`` and ``qx qy qz qw`` (float32); needs pyarrow. Values are stored exactly
        (float32 bits kept). Raises ``ValueError`` for another suffix, ``ImportError`` for
        Parquet without pyarrow.
        """
        path = os.fspath(path)
        suffix = os.path.splitext(path)[1].lower()
        if suffix == ".npz":
            np.savez(
                path,
                positions=self.positions,
                orientations=self.orientations,
                steps=self.steps,
                times=self.times,
                names=np.asarray(self.names, dtype=np.str_),
            )
        elif suffix == ".parquet":
            pa, pq = _pyarrow()
            frames, bodies = self.frame_count, self.body_count
            p = self.positions.reshape(frames * bodies, 3)
            q = self.orientations.reshape(frames * bodies, 4)
            table = pa.table(
                {
                    "step": pa.array(np.repeat(self.steps, bodies), pa.int64()),
                    "time": pa.array(np.repeat(self.times, bodies), pa.float64()),
                    "body": pa.array(np.tile(np.arange(bodies, dtype=np.int32), frames)),
                    "name": pa.array(self.names * frames, pa.string()),
                    "x": p[:, 0],
                    "y": p[:, 1],
                    "z": p[:, 2],
                    "qx": q[:, 0],
                    "qy": q[:, 1],
                    "qz": q[:, 2],
                    "qw": q[:, 3],
                }
            )
            pq.write_table(table, path)
        else:
            raise ValueError(f"{path}: a trajectory is saved as .npz or .parquet, not {suffix!r}")


def _pyarrow():
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError as error:
        raise ImportError("Parquet trajectories need pyarrow: pip install pyarrow") from error
    return pa, pq


def load_trajectory(path: str | os.PathLike[str]) -> Trajectory:
    """Reads a trajectory written by ``Trajectory.save`` (``.npz`` or ``.parquet``).

    Raises ``ValueError`` for another suffix or a file missing a column or array,
    ``FileNotFoundError`` when there is no file.
    """
    path = os.fspath(path)
    suffix = os.path.splitext(path)[1].lower()
    if suffix == ".npz":
        with np.load(path, allow_pickle=False) as data:
            missing = {"positions", "orientations", "steps", "times", "names"} - set(data.files)
            if missing:
                raise ValueError(f"{path}: not a trajectory, missing {sorted(missing)}")
            return Trajectory(
                positions=data["positions"],
                orientations=data["orientations"],
                steps=data["steps"],
                times=data["times"],
                names=[str(n) for n in data["names"]],
            )
    if suffix == ".parquet":
        _, pq = _pyarrow()
        table = pq.read_table(path)
        columns = ["step", "time", "body", "name", "x", "y", "z", "qx", "qy", "qz", "qw"]
        missing = [c for c in columns if c not in table.column_names]
        if missing:
            raise ValueError(f"{path}: not a trajectory, missing columns {missing}")
        step = table.column("step").to_numpy()
        body = table.column("body").to_numpy()
        bodies = int(body.max()) + 1 if len(body) else 0
        frames = len(step) // bodies if bodies else 0
        if frames * bodies != len(step):
            raise ValueError(f"{path}: rows are not frames × bodies")

        def grid(names: list[str]) -> np.ndarray:
            columns = [table.column(n).to_numpy().astype(np.float32) for n in names]
            return np.stack(columns, axis=1).reshape(frames, bodies, len(names))

        return Trajectory(
            positions=grid(["x", "y", "z"]),
            orientations=grid(["qx", "qy", "qz", "qw"]),
            steps=step.reshape(frames, bodies)[:, 0] if frames else step[:0],
            times=(
                table.column("time").to_numpy().reshape(frames, bodies)[:, 0]
                if frames
                else np.zeros(0)
            ),
            names=table.column("name").to_pylist()[:bodies],
        )
    raise ValueError(f"{path}: a trajectory is read from .npz or .parquet, not {suffix!r}")
