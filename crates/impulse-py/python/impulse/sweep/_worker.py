"""One run, as a worker executes it: build the world, step it, measure it, record its row."""

from __future__ import annotations

import os
import pickle
import socket
import tempfile
import time
from collections.abc import Callable, Mapping
from typing import Any

from impulse.sweep._constants import (
    _RUN_COLUMNS,
    _TAIL_COLUMNS,
    COMPLETED,
    FAILED,
    OBSERVE_PREFIX,
    OVERLAP_SAMPLE_EVERY,
    STOPPED,
    TRAJECTORY_DIR,
)
from impulse.sweep._runs import _normalise_jitter, _normalise_scene, run_key, scene_digest
from impulse.sweep._store import _filesystem


def _finite_or_none(value: Any) -> Any:
    return None if value is None else float(value)


def _measure(
    world: Any,
    steps: int,
    step_error: type[BaseException],
    frames: dict[str, list] | None = None,
    every: int = 1,
) -> dict[str, Any]:
    """Steps ``world`` ``steps`` times and measures what ``impulse run`` prints, with the same
    definitions (crates/impulse-cli/src/run.rs): overlap and drift from poses at the start,
    every ``OVERLAP_SAMPLE_EVERY`` steps and at the last; the top body's sink; the largest
    speed of any body at any step; contacts, iterations and the natural-map residual from each
    step's diagnostics. A failed step stops the run (status ``stopped``) with the metrics of
    the steps before it. With ``frames`` (a dict of empty lists), also records the frames
    ``World.simulate(steps, every)`` would: the start, every step that is a multiple of
    ``every`` and the last."""
    import numpy as np

    def record() -> None:
        if frames is not None:
            frames["positions"].append(np.array(world.positions, dtype=np.float32, copy=True))
            frames["orientations"].append(np.array(world.orientations, dtype=np.float32, copy=True))
            frames["steps"].append(world.step_count)
            frames["times"].append(world.time)

    initial = np.array(world.positions, dtype=np.float32, copy=True)
    initial_state = {
        "initial_positions": initial.ravel().tolist(),
        "initial_orientations": np.asarray(world.orientations, dtype=np.float32).ravel().tolist(),
        "initial_linear_velocities": np.asarray(world.linear_velocities, dtype=np.float32)
        .ravel()
        .tolist(),
        "initial_angular_velocities": np.asarray(world.angular_velocities, dtype=np.float32)
        .ravel()
        .tolist(),
    }
    quality = world.quality(initial)
    top_body = quality.get("top_body")
    max_overlap = float(quality["max_overlap_m"])
    final_overlap = max_overlap
    max_drift = 0.0
    step_ms: list[float] = []
    contacts = 0
    iterations = 0
    max_residual = 0.0
    max_speed = np.float32(0.0)
    status, error = COMPLETED, None
    last = world.step_count + steps
    record()
    while world.step_count < last:
        start = time.perf_counter()
        try:
            world.step()
        except step_error as failure:
            step_ms.append((time.perf_counter() - start) * 1e3)
            status, error = STOPPED, f"{type(failure).__name__}: {failure}"
            break
        step_ms.append((time.perf_counter() - start) * 1e3)
        diagnostics = world.diagnostics
        contacts += int(diagnostics["contacts"])
        iterations += int(diagnostics["iterations"])
        max_residual = max(max_residual, float(diagnostics["natural_map_residual"]))
        velocity = world.linear_velocities
        if len(velocity):
            # |v| in float32 as the engine computes it: sqrt(x·x + y·y + z·z), summed in order.
            x, y, z = velocity[:, 0], velocity[:, 1], velocity[:, 2]
            max_speed = max(max_speed, np.sqrt(x * x + y * y + z * z).max())
        step = world.step_count
        if step % OVERLAP_SAMPLE_EVERY == 0 or step == last:
            quality = world.quality(initial)
            final_overlap = float(quality["max_overlap_m"])
            max_overlap = max(max_overlap, final_overlap)
            max_drift = max(max_drift, float(quality["max_drift_m"]))
        if step % every == 0 or step == last:
            record()
    quality = world.quality(initial)
    top_sink = quality.get("top_sink_m")
    top_sink = 0.0 if top_sink is None else float(top_sink)
    taken = max(len(step_ms), 1)
    diagnostics = world.diagnostics if step_ms else {}
    return {
        "status": status,
        "error": error,
        "steps_taken": int(world.step_count - (last - steps)),
        "bodies": int(world.body_count),
        "dt": float(world.dt),
        "ms_per_step": float(np.median(step_ms)) if step_ms else 0.0,
        "mean_ms_per_step": float(sum(step_ms) / taken),
        "max_overlap_m": max_overlap,
        "final_overlap_m": final_overlap,
        "top_body": None if top_body is None else int(top_body),
        "top_sink_m": top_sink,
        "max_drift_m": max_drift,
        "quality_error_m": max(abs(top_sink), max_overlap, max_drift),
        "kinetic_energy_j": _finite_or_none(
            diagnostics.get("kinetic_energy", quality.get("kinetic_energy_j"))
        ),
        "max_speed_m_s": float(max_speed),
        "mean_contacts": contacts / taken,
        "mean_iterations": iterations / taken,
        "max_natural_map_residual": max_residual,
        **initial_state,
        "final_natural_map_residual": _finite_or_none(diagnostics.get("natural_map_residual", 0.0)),
    }


def _observe_values(observe: Callable[[Any], Mapping[str, Any]], world: Any) -> dict[str, Any]:
    """``observe(world)`` as ``observe.<name>`` columns. Values may be numbers, strings, bools,
    None, NumPy scalars or arrays (stored as lists)."""
    values = observe(world)
    if not isinstance(values, Mapping):
        raise TypeError(
            f"observe must return a dict of name -> value, returned {type(values).__name__}"
        )
    out = {}
    for name, value in values.items():
        if not isinstance(name, str):
            raise TypeError(f"observe returned a non-string key {name!r}")
        if hasattr(value, "tolist"):  # NumPy scalars and arrays
            value = value.tolist()
        out[OBSERVE_PREFIX + name] = value
    return out


def _save_trajectory(trajectory: Any, out: str, key: str) -> str:
    """Saves ``trajectory`` as ``out/trajectories/<key>.npz`` (through pyarrow's filesystems when
    ``out`` is a URI) and returns that path."""
    filesystem, root = _filesystem(out)
    directory = f"{root}/{TRAJECTORY_DIR}"
    filesystem.create_dir(directory, recursive=True)
    target = f"{directory}/{key}.npz"
    with tempfile.TemporaryDirectory() as scratch:
        local = os.path.join(scratch, f"{key}.npz")
        trajectory.save(local)
        with open(local, "rb") as source, filesystem.open_output_stream(target) as sink:
            while block := source.read(1 << 20):
                sink.write(block)
    return target


def _worker_start() -> None:
    """A local worker ignores Ctrl-C: the sweep's process handles it, keeps the finished runs
    and shuts the pool down."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _run_task(task: dict[str, Any]) -> dict[str, Any]:
    """One run in a worker: the row the sweep records. Never raises: every failure becomes the
    row's status and error."""
    # A sweep's parallelism is its workers: each run steps on its own worker's thread, so runs
    # do not compete for cores (the results are the same on any thread count).
    os.environ.setdefault("RAYON_NUM_THREADS", "1")
    return _timed_row(task, lambda: pickle.loads(task["observe"]) if task.get("observe") else None)


def _timed_row(task: dict[str, Any], load_observe: Callable[[], Any]) -> dict[str, Any]:
    """The run's row with its wall and CPU time and worker; a failure (loading `observe`
    included) is recorded, never raised, so the other runs go on."""
    start = time.perf_counter()
    cpu_start = time.process_time()
    row: dict[str, Any] = {"run_key": task["key"]}
    try:
        row.update(_simulate(task, load_observe()))
    except Exception as failure:
        row["status"] = FAILED
        row["error"] = f"{type(failure).__name__}: {failure}"
    row["wall_time_s"] = time.perf_counter() - start
    row["cpu_time_s"] = time.process_time() - cpu_start
    row["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    return row


def _simulate(
    task: dict[str, Any], observe: Callable[[Any], Mapping[str, Any]] | None
) -> dict[str, Any]:
    import numpy as np

    import impulse

    world = impulse.World.from_scene(
        task["scene"],
        overrides=task["overrides"] or None,
        seed=task["seed"],
        jitter=task["jitter"],
        settings=task["preset"],
    )
    every = task.get("trajectory_every") or 0
    frames: dict[str, list] | None = (
        {"positions": [], "orientations": [], "steps": [], "times": []} if every else None
    )
    row = _measure(world, task["steps"], impulse.StepError, frames, max(every, 1))
    if observe is not None:
        try:
            row.update(_observe_values(observe, world))
        except Exception as failure:
            row["status"] = FAILED
            row["error"] = f"observe: {type(failure).__name__}: {failure}"
    if frames is not None:
        trajectory = impulse.Trajectory(
            positions=np.stack(frames["positions"]),
            orientations=np.stack(frames["orientations"]),
            steps=np.array(frames["steps"], dtype=np.int64),
            times=np.array(frames["times"], dtype=np.float64),
            names=list(world.names),
        )
        row["trajectory"] = _save_trajectory(trajectory, task["out"], task["key"])
    return row


def run_one(
    scene: Any,
    *,
    overrides: Mapping[str, Any] | None = None,
    seed: int = 0,
    steps: int,
    preset: str | None = None,
    jitter: Mapping[str, float] | None = None,
    observe: Callable[[Any], Mapping[str, Any]] | None = None,
) -> dict[str, Any]:
    """One run of a sweep in this process: the row :func:`sweep` records for it (a dict of
    column → value), with the same metrics and the same failure handling."""
    scene, _ = _normalise_scene(scene)
    steps = _check_steps(steps)
    overrides = dict(overrides or {})
    jitter = _normalise_jitter(jitter)
    key = run_key(scene_digest(scene), overrides, seed, steps, preset, jitter)
    task = _task(scene, overrides, seed, steps, preset, jitter, key, None, None, 0)
    row = _run_task_in_process(task, observe)
    row["seed"] = seed
    row["steps"] = steps
    return _columns_in_order(row, overrides)


def _run_task_in_process(task: dict[str, Any], observe: Any) -> dict[str, Any]:
    return _timed_row(task, lambda: observe)


def _task(
    scene, overrides, seed, steps, preset, jitter, key, observe_bytes, out, trajectory_every
) -> dict[str, Any]:
    return {
        "scene": scene,
        "overrides": overrides,
        "seed": seed,
        "steps": steps,
        "preset": preset,
        "jitter": jitter,
        "key": key,
        "observe": observe_bytes,
        "out": out,
        "trajectory_every": trajectory_every,
    }


def _columns_in_order(row: dict[str, Any], overrides: Mapping[str, Any]) -> dict[str, Any]:
    """The row with the override values and seed filled in, columns in the table's order."""
    out = {"run_key": row["run_key"]}
    out.update(overrides)
    for name, _ in _RUN_COLUMNS:
        out[name] = row.get(name)
    for name in sorted(k for k in row if k.startswith(OBSERVE_PREFIX)):
        out[name] = row[name]
    for name, _ in _TAIL_COLUMNS:
        out[name] = row.get(name)
    return out


def _check_steps(steps: Any) -> int:
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 0:
        raise ValueError(f"steps = {steps!r}: must be an integer ≥ 0")
    return int(steps)
