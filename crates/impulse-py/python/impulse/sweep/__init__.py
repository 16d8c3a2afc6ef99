"""Parameter sweeps: many runs of one scene, on a local process pool or on Ray.

A sweep is the product of a grid of scene overrides (each key an override path such as
``materials.default.friction``, each value a list of values) and a list of seeds. Each run builds
``World.from_scene(scene, overrides=..., seed=..., jitter=..., settings=preset)`` in a worker,
steps it, and measures the summary metrics ``impulse run`` prints (same definitions), plus the
values of the user's ``observe(world)``. The results are one Parquet table, ``OUT/results.parquet``
(one row per run), and a manifest, ``OUT/manifest.json``; ``OUT`` is a local directory or any URI
pyarrow's filesystems understand (``s3://bucket/prefix``, ``gs://...``, ``hdfs://...``).

Runs are keyed by a hash of the scene's content, the run's overrides and seed, the step count and
the settings (preset, jitter): running the same sweep again into the same ``OUT`` skips every run
already written, so an interrupted sweep resumes where it stopped and a larger grid only runs what
is new. A run that fails (a bad override, a blow-up, an exception in ``observe``) is recorded with
its status and error; the others go on.

Every simulated number depends only on (scene, overrides, seed, steps, settings): the engine gives
the same result on any thread count and machine, so a sweep on the local pool and on Ray gives
equal tables, to the bit, in every column but the timings (``ms_per_step``,
``mean_ms_per_step``, ``wall_time_s``, ``cpu_time_s``) and ``worker``.

Needs ``pyarrow`` (the table), ``tqdm`` (the progress bar, optional) and, for ``backend="ray"``,
``ray``. Command line: ``python -m impulse.sweep --help``.
"""

from __future__ import annotations

import concurrent.futures
import hashlib
import itertools
import json
import math
import multiprocessing
import os
import pickle
import platform
import socket
import sys
import tempfile
import time
import uuid
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures.process import BrokenProcessPool
from typing import Any

__all__ = [
    "RESULTS_FILE",
    "MANIFEST_FILE",
    "TRAJECTORY_DIR",
    "Run",
    "expand",
    "run_key",
    "scene_digest",
    "run_one",
    "read_results",
    "sweep",
]

#: The results table inside ``out``.
RESULTS_FILE = "results.parquet"
#: The sweep's description inside ``out``.
MANIFEST_FILE = "manifest.json"
#: Directory of the per-run trajectories inside ``out`` (``<run_key>.npz``).
TRAJECTORY_DIR = "trajectories"
#: Rows of runs finished but not yet merged into ``RESULTS_FILE`` (an interrupted sweep's work).
PARTS_DIR = "parts"

#: Version of the run-key recipe: changing what a key hashes changes this, so that old results
#: are not taken for new ones.
KEY_VERSION = 1

#: Overlap and drift are measured from poses every this many steps and at the last, as
#: ``impulse run`` does.
OVERLAP_SAMPLE_EVERY = 10

#: Rows are written as a part file after this many finished runs or seconds, whichever first,
#: so that an interrupted sweep loses at most that much work.
FLUSH_ROWS = 64
FLUSH_SECONDS = 30.0

#: Columns every row has, in order, with their Arrow types (``None``: filled in lazily, to keep
#: ``pyarrow`` out of ``import impulse``). The grid's override columns come after ``run_key``; the
#: ``observe`` values after the metrics, as ``observe.<name>``.
_KEY_COLUMNS = ("run_key",)
_RUN_COLUMNS = (
    ("seed", "int64"),
    ("steps", "int64"),
    ("status", "string"),
    ("error", "string"),
    ("steps_taken", "int64"),
    ("bodies", "int64"),
    ("dt", "float64"),
    ("ms_per_step", "float64"),
    ("mean_ms_per_step", "float64"),
    ("max_overlap_m", "float64"),
    ("final_overlap_m", "float64"),
    ("top_body", "int64"),
    ("top_sink_m", "float64"),
    ("max_drift_m", "float64"),
    ("quality_error_m", "float64"),
    ("kinetic_energy_j", "float64"),
    ("max_speed_m_s", "float64"),
    ("mean_contacts", "float64"),
    ("mean_iterations", "float64"),
    ("max_natural_map_residual", "float64"),
    ("final_natural_map_residual", "float64"),
)
_TAIL_COLUMNS = (
    ("wall_time_s", "float64"),
    ("cpu_time_s", "float64"),
    ("worker", "string"),
    ("trajectory", "string"),
)
#: Columns that hold timings or where a run ran, not simulated values: they differ between two
#: executions of the same run.
TIMING_COLUMNS = ("ms_per_step", "mean_ms_per_step", "wall_time_s", "cpu_time_s", "worker")

#: Prefix of the ``observe`` columns.
OBSERVE_PREFIX = "observe."

#: Status of a run that took all its steps.
COMPLETED = "completed"
#: Status of a run stopped by a failed step (a blow-up); its metrics cover the steps taken.
STOPPED = "stopped"
#: Status of a run that could not be built or measured (bad override, exception in ``observe``).
FAILED = "failed"


class Run:
    """One run of a sweep: its overrides (path → value, the grid's order), seed and key."""

    __slots__ = ("overrides", "seed", "key")

    def __init__(self, overrides: dict[str, Any], seed: int, key: str):
        self.overrides = overrides
        self.seed = seed
        self.key = key

    def __repr__(self) -> str:
        return f"Run(overrides={self.overrides!r}, seed={self.seed}, key={self.key[:12]!r}...)"


# --------------------------------------------------------------------------------------------
# Grid, seeds and keys


def _seed_list(seeds: int | Iterable[int]) -> list[int]:
    """``seeds`` as a list: an int N means seeds 0 … N−1; an iterable is taken as it is."""
    if isinstance(seeds, bool):
        raise TypeError("seeds must be an int (a count) or an iterable of ints, not a bool")
    if isinstance(seeds, int):
        if seeds < 1:
            raise ValueError(f"seeds = {seeds}: a sweep needs at least one seed")
        return list(range(seeds))
    out = []
    for seed in seeds:
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0 or seed >= 2**64:
            raise ValueError(f"seed {seed!r} is not an integer in 0 ≤ seed < 2^64")
        out.append(int(seed))
    if not out:
        raise ValueError("seeds is empty: a sweep needs at least one seed")
    return out


def _check_grid(grid: Mapping[str, Sequence[Any]] | None) -> dict[str, list[Any]]:
    if grid is None:
        return {}
    if not isinstance(grid, Mapping):
        raise TypeError("grid must be a mapping of override path -> list of values")
    out = {}
    for path, values in grid.items():
        if not isinstance(path, str) or not path:
            raise ValueError(
                f"grid key {path!r} is not an override path (like 'materials.default.friction')"
            )
        if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
            raise ValueError(f"grid[{path!r}] must be a list of values, got {values!r}")
        values = list(values)
        if not values:
            raise ValueError(f"grid[{path!r}] is empty: the sweep would have no run")
        for value in values:
            try:
                _canonical_json(value)
            except (TypeError, ValueError) as error:
                raise ValueError(f"grid[{path!r}] value {value!r} is not JSON: {error}") from None
        out[path] = values
    return out


def expand(
    grid: Mapping[str, Sequence[Any]] | None, seeds: int | Iterable[int] = 1
) -> list[tuple[dict[str, Any], int]]:
    """The runs of a sweep as ``(overrides, seed)`` pairs: the product of the grid's values (in
    the grid's key order, the last key varying fastest) and the seeds (fastest of all).

    ``grid``: override path → list of values (JSON values: numbers, strings, lists, objects);
    ``None`` or ``{}`` is the scene as it is. ``seeds``: an int N (seeds 0 … N−1) or an iterable
    of ints. Raises ``ValueError`` for an empty value list, a non-JSON value or a bad seed.
    """
    grid = _check_grid(grid)
    seed_list = _seed_list(seeds)
    paths = list(grid)
    return [
        (dict(zip(paths, values, strict=True)), seed)
        for values in itertools.product(*(grid[p] for p in paths))
        for seed in seed_list
    ]


def _canonical_json(value: Any) -> str:
    """JSON with sorted keys and no spaces; numbers as Python prints them (``0.5`` and ``0.50``
    are one value; ``1`` and ``1.0`` are not, as a scene file tells them apart)."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"), allow_nan=False)


def _impulse_version() -> str:
    try:
        import impulse

        version = getattr(impulse, "__version__", None)
        if version:
            return str(version)
    except ImportError:
        pass
    try:
        from importlib.metadata import version

        return version("impulse")
    except Exception:
        return "unknown"


def _normalise_scene(scene: Any) -> tuple[Any, str]:
    """The scene as workers receive it (an absolute path for a file, the name of a built-in, or
    the dict) and a description for the manifest."""
    if isinstance(scene, Mapping):
        return dict(scene), "<dict>"
    if isinstance(scene, os.PathLike) or (isinstance(scene, str) and os.path.exists(scene)):
        path = os.path.abspath(os.fspath(scene))
        if not os.path.isfile(path):
            raise ValueError(f"scene {path}: not a file")
        return path, path
    if isinstance(scene, str):
        return scene, scene
    raise TypeError(
        f"scene must be a file path, a built-in scene name or a dict, not {type(scene).__name__}"
    )


def scene_digest(scene: Any) -> str:
    """SHA-256 (hex) of a scene's content: a file's bytes, a dict's canonical JSON, or for a
    built-in scene its name and the package version (built-in scenes are part of the package).
    Files the scene refers to (meshes) are not hashed."""
    scene, _ = _normalise_scene(scene)
    digest = hashlib.sha256()
    if isinstance(scene, dict):
        digest.update(b"dict\0" + _canonical_json(scene).encode())
    elif os.path.isfile(scene):
        digest.update(b"file\0")
        with open(scene, "rb") as file:
            for block in iter(lambda: file.read(1 << 20), b""):
                digest.update(block)
    else:
        digest.update(f"builtin\0{scene}\0{_impulse_version()}".encode())
    return digest.hexdigest()


def _normalise_jitter(jitter: Mapping[str, float] | None) -> dict[str, float] | None:
    if jitter is None:
        return None
    if not isinstance(jitter, Mapping):
        raise TypeError(
            "jitter must be a mapping with keys 'position' (m), 'angle' (degrees), 'velocity' (m/s)"
        )
    unknown = set(jitter) - {"position", "angle", "velocity"}
    if unknown:
        raise ValueError(
            f"jitter has unknown keys {sorted(unknown)}: use 'position', 'angle', 'velocity'"
        )
    out = {}
    for name in ("position", "angle", "velocity"):
        value = float(jitter.get(name, 0.0))
        if not math.isfinite(value) or value < 0.0:
            raise ValueError(f"jitter[{name!r}] = {value}: must be finite and ≥ 0")
        out[name] = value
    return out if any(out.values()) else None  # zero jitter is no jitter


def run_key(
    digest: str,
    overrides: Mapping[str, Any],
    seed: int,
    steps: int,
    preset: str | None = None,
    jitter: Mapping[str, float] | None = None,
) -> str:
    """The key of one run (SHA-256, hex): a hash of the scene's content (``digest``, from
    :func:`scene_digest`), the overrides (as a set: their order does not matter), the seed, the
    step count and the settings (preset, jitter). Equal keys mean equal simulated results."""
    record = {
        "key_version": KEY_VERSION,
        "scene": digest,
        "overrides": sorted([path, _canonical_json(value)] for path, value in overrides.items()),
        "seed": int(seed),
        "steps": int(steps),
        "preset": preset,
        "jitter": _normalise_jitter(jitter),
    }
    return hashlib.sha256(_canonical_json(record).encode()).hexdigest()


# --------------------------------------------------------------------------------------------
# One run (in a worker)


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
    return _timed_row(
        task, lambda: pickle.loads(task["observe"]) if task.get("observe") else None
    )


def _timed_row(
    task: dict[str, Any], load_observe: Callable[[], Any]
) -> dict[str, Any]:
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


# --------------------------------------------------------------------------------------------
# Tables and files


def _filesystem(out: str) -> tuple[Any, str]:
    """pyarrow filesystem and root path of ``out`` (a local path or a URI)."""
    import pyarrow.fs

    out = os.fspath(out)
    if "://" in out:
        filesystem, path = pyarrow.fs.FileSystem.from_uri(out)
        return filesystem, path.rstrip("/")
    return pyarrow.fs.LocalFileSystem(), os.path.abspath(out).replace(os.sep, "/")


def _exists(filesystem: Any, path: str) -> bool:
    import pyarrow.fs

    return filesystem.get_file_info(path).type != pyarrow.fs.FileType.NotFound


def _table(rows: list[dict[str, Any]], override_types: Mapping[str, Any]) -> Any:
    """Rows (dicts) as an Arrow table: fixed columns with fixed types, override columns with
    the grid's types, ``observe`` columns with inferred types (all-null columns stay null-typed
    and are promoted when tables are concatenated)."""
    import pyarrow as pa

    names = ["run_key", *override_types]
    names += [name for name, _ in _RUN_COLUMNS]
    names += sorted({k for row in rows for k in row if k.startswith(OBSERVE_PREFIX)})
    names += [name for name, _ in _TAIL_COLUMNS]
    fixed = {
        "run_key": pa.string(),
        **{n: pa.type_for_alias(t) for n, t in (*_RUN_COLUMNS, *_TAIL_COLUMNS)},
    }
    columns = {}
    for name in names:
        values = [row.get(name) for row in rows]
        if name in override_types:
            kind, arrow_type = override_types[name]
            if kind == "json":
                values = [None if v is None else _canonical_json(v) for v in values]
            columns[name] = pa.array(values, type=arrow_type)
        else:
            columns[name] = pa.array(values, type=fixed.get(name))
    return pa.table(columns)


def _override_types(grid: Mapping[str, list[Any]]) -> dict[str, tuple[str, Any]]:
    """Arrow type of each override column: inferred from the grid's values, or JSON text where
    the values have no common Arrow type (a number and a list)."""
    import pyarrow as pa

    types = {}
    for path, values in grid.items():
        try:
            types[path] = ("value", pa.array(values).type)
        except (pa.ArrowInvalid, pa.ArrowTypeError, TypeError):
            types[path] = ("json", pa.string())
    return types


def _read_table(filesystem: Any, path: str) -> Any:
    import pyarrow.parquet as pq

    return pq.read_table(path, filesystem=filesystem)


def _concat(tables: list[Any]) -> Any:
    import pyarrow as pa

    tables = [t for t in tables if t is not None]
    if not tables:
        return None
    if len(tables) == 1:
        return tables[0]
    return pa.concat_tables(tables, promote_options="permissive")


def _reorder_columns(table: Any, overrides_first: Sequence[str]) -> Any:
    """Columns in the order run_key, overrides, run columns, observe columns, tail columns."""
    run = [name for name, _ in _RUN_COLUMNS]
    tail = [name for name, _ in _TAIL_COLUMNS]
    names = table.column_names
    overrides = [n for n in overrides_first if n in names]
    overrides += [
        n
        for n in names
        if n not in overrides
        and n not in run
        and n not in tail
        and n != "run_key"
        and not n.startswith(OBSERVE_PREFIX)
    ]
    observed = sorted(n for n in names if n.startswith(OBSERVE_PREFIX))
    order = [
        "run_key",
        *overrides,
        *[n for n in run if n in names],
        *observed,
        *[n for n in tail if n in names],
    ]
    return table.select(order)


def read_results(out: str) -> Any:
    """The results table of the sweep in ``out`` (a directory or URI): ``results.parquet`` with
    the rows of any runs an interrupted sweep finished but had not merged yet. ``None`` if there
    are none. Each run appears once."""
    filesystem, root = _filesystem(out)
    return _read_all(filesystem, root)


def _part_paths(filesystem: Any, root: str) -> list[str]:
    import pyarrow.fs

    directory = f"{root}/{PARTS_DIR}"
    if not _exists(filesystem, directory):
        return []
    infos = filesystem.get_file_info(pyarrow.fs.FileSelector(directory))
    return sorted(
        i.path for i in infos if i.type == pyarrow.fs.FileType.File and i.path.endswith(".parquet")
    )


def _read_all(filesystem: Any, root: str) -> Any:
    import pyarrow as pa

    tables = []
    results = f"{root}/{RESULTS_FILE}"
    if _exists(filesystem, results):
        tables.append(_read_table(filesystem, results))
    tables += [_read_table(filesystem, p) for p in _part_paths(filesystem, root)]
    table = _concat(tables)
    if table is None:
        return None
    # Each run once, its newest row: a part merged into the results just before a crash appears
    # twice, and a failed run retried has its new row in a later part.
    keys = table.column("run_key").to_pylist()
    newest = {k: i for i, k in enumerate(keys)}
    if len(newest) < len(keys):
        table = table.take(pa.array(sorted(newest.values()), type=pa.int64()))
    return table


def _write_parquet(filesystem: Any, path: str, table: Any) -> None:
    """Writes ``table`` to ``path``, whole or not at all (a temporary file moved in place)."""
    import pyarrow.parquet as pq

    temporary = f"{path}.{uuid.uuid4().hex}.tmp"
    pq.write_table(table, temporary, filesystem=filesystem)
    filesystem.move(temporary, path)


def _write_json(filesystem: Any, path: str, value: Any) -> None:
    text = json.dumps(value, indent=2, sort_keys=False, default=str) + "\n"
    temporary = f"{path}.{uuid.uuid4().hex}.tmp"
    with filesystem.open_output_stream(temporary) as stream:
        stream.write(text.encode())
    filesystem.move(temporary, path)


def _versions(backend: str) -> dict[str, str]:
    versions = {"impulse": _impulse_version(), "python": platform.python_version()}
    for module in ("numpy", "pyarrow", "ray") if backend == "ray" else ("numpy", "pyarrow"):
        try:
            versions[module] = __import__(module).__version__
        except Exception:
            pass
    return versions


# --------------------------------------------------------------------------------------------
# Backends


class _LocalBackend:
    """A process pool on this machine (``spawn`` start method, so it is safe with threads and on
    every platform)."""

    def __init__(self, workers: int):
        self.workers = workers
        self.pool = self._new_pool()

    def _new_pool(self) -> concurrent.futures.ProcessPoolExecutor:
        return concurrent.futures.ProcessPoolExecutor(
            max_workers=self.workers,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_worker_start,
        )

    def run(self, tasks: Iterable[dict[str, Any]]):
        """Yields each task's row as it finishes, at most ``4 × workers`` tasks in flight."""
        tasks = iter(tasks)
        pending: dict[concurrent.futures.Future, dict[str, Any]] = {}
        limit = 4 * self.workers
        while True:
            for task in itertools.islice(tasks, max(0, limit - len(pending))):
                pending[self.pool.submit(_run_task, task)] = task
            if not pending:
                return
            done, _ = concurrent.futures.wait(
                pending, return_when=concurrent.futures.FIRST_COMPLETED
            )
            suspects = []
            for future in done:
                task = pending.pop(future)
                try:
                    yield future.result()
                except BrokenProcessPool:
                    suspects.append(task)
                except Exception as failure:  # the task could not be sent or its row returned
                    yield _failed_row(task, failure)
            if suspects:
                # A worker process died (killed, out of memory, a crash in native code) and took
                # the pool with it: every run in flight is a suspect. Each runs again alone, in
                # its own process, so that only the culprit is recorded as failed.
                suspects += pending.values()
                pending.clear()
                self.pool.shutdown(wait=True, cancel_futures=True)
                for task in suspects:
                    yield self._run_alone(task)
                self.pool = self._new_pool()

    def _run_alone(self, task: dict[str, Any]) -> dict[str, Any]:
        pool = concurrent.futures.ProcessPoolExecutor(
            max_workers=1,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_worker_start,
        )
        try:
            return pool.submit(_run_task, task).result()
        except BrokenProcessPool:
            return _failed_row(task, RuntimeError("the worker process running this run died"))
        except Exception as failure:
            return _failed_row(task, failure)
        finally:
            pool.shutdown(wait=True)

    def close(self, cancel: bool = False) -> None:
        self.pool.shutdown(wait=True, cancel_futures=cancel)


class _RayBackend:
    """Ray tasks, one per run (``num_cpus=1`` each). Starts a local Ray (``address=None``) or
    joins a cluster (``address="auto"``, ``"ray://head:10001"``) unless Ray is already
    initialised; shuts down only a Ray it started."""

    def __init__(self, workers: int | None, address: str | None):
        import ray

        self.ray = ray
        self.started = False
        if not ray.is_initialized():
            options: dict[str, Any] = {
                "address": address,
                "include_dashboard": False,
                "log_to_driver": False,
            }
            if address is None and workers is not None:
                options["num_cpus"] = workers
            ray.init(**options)
            self.started = True
        self.workers = workers or max(1, int(ray.available_resources().get("CPU", 1)))
        # No automatic retry: a run is deterministic, a failure would repeat.
        self.remote = ray.remote(num_cpus=1, max_retries=0)(_run_task)

    def run(self, tasks: Iterable[dict[str, Any]]):
        ray = self.ray
        tasks = iter(tasks)
        pending: dict[Any, dict[str, Any]] = {}
        limit = 4 * self.workers
        while True:
            for task in itertools.islice(tasks, max(0, limit - len(pending))):
                pending[self.remote.remote(task)] = task
            if not pending:
                return
            done, _ = ray.wait(list(pending), num_returns=1)
            for ref in done:
                task = pending.pop(ref)
                try:
                    yield ray.get(ref)
                except Exception as failure:  # the worker died, or the task could not run
                    yield _failed_row(task, failure)

    def close(self, cancel: bool = False) -> None:
        if self.started:
            self.ray.shutdown()


def _failed_row(task: dict[str, Any], failure: BaseException) -> dict[str, Any]:
    return {
        "run_key": task["key"],
        "status": FAILED,
        "error": f"{type(failure).__name__}: {failure}",
    }


class _Progress:
    """tqdm bar of runs done, failed and per second (silent when tqdm is missing or off)."""

    def __init__(self, total: int, skipped: int, enabled: bool):
        self.bar = None
        self.failed = 0
        if enabled and total:
            try:
                from tqdm.auto import tqdm
            except ImportError:
                return
            description = f"sweep ({skipped} done before)" if skipped else "sweep"
            self.bar = tqdm(
                total=total, unit="run", desc=description, dynamic_ncols=True, file=sys.stderr
            )
            self.bar.set_postfix(failed=0)

    def update(self, row: dict[str, Any]) -> None:
        if row.get("status") != COMPLETED:
            self.failed += 1
        if self.bar is not None:
            if row.get("status") != COMPLETED:
                self.bar.set_postfix(failed=self.failed, refresh=False)
            self.bar.update(1)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


# --------------------------------------------------------------------------------------------
# The sweep


def sweep(
    scene: Any,
    grid: Mapping[str, Sequence[Any]] | None = None,
    seeds: int | Iterable[int] = 1,
    steps: int | None = None,
    backend: str = "local",
    out: str | os.PathLike = "sweep",
    observe: Callable[[Any], Mapping[str, Any]] | None = None,
    save_trajectories: bool | int = False,
    preset: str | None = None,
    jitter: Mapping[str, float] | None = None,
    workers: int | None = None,
    address: str | None = None,
    progress: bool = True,
    retry_failed: bool = False,
) -> Any:
    """Runs every (grid point, seed) of ``scene`` not yet in ``out`` and returns the whole
    results table (a ``pyarrow.Table``, also written to ``out/results.parquet``).

    Parameters
    ----------
    scene : str | os.PathLike | dict
        A scene file, a built-in scene name (``impulse.scenes()``) or a scene as a dict. With Ray
        on a cluster a file must be readable at the same path on every node (or pass a dict).
    grid : dict[str, list]
        Override path → values (``{"materials.default.friction": [0.2, 0.5]}``; paths as
        ``impulse run --set`` takes them). The runs are the product of all lists and the seeds.
    seeds : int | iterable of int
        N (seeds 0 … N−1) or the seeds themselves. A seed varies a run only through ``jitter``.
    steps : int
        Steps of every run (required; the same for all).
    backend : "local" | "ray"
        ``"local"``: a process pool on this machine (``spawn``; call ``sweep`` under
        ``if __name__ == "__main__":`` in a script). ``"ray"``: one Ray task per run.
    out : str | os.PathLike
        Directory or URI (``s3://bucket/prefix``) of the results, through pyarrow's filesystems.
    observe : callable(world) -> dict, optional
        Called in the worker after the last step (also after a failed step); its values become
        columns ``observe.<name>``. Must be picklable (a module-level function; with
        ``cloudpickle`` installed, as with Ray, also a lambda or closure). An exception in it
        makes the run ``failed``.
    save_trajectories : bool | int
        ``True`` or K: also write each run's trajectory (every K-th step, ``True`` = every step)
        as ``out/trajectories/<run_key>.npz`` (``Trajectory.save``; ``impulse.load_trajectory``
        reads it): the frames ``World.simulate(steps, every=K)`` records, up to the last step
        taken.
    preset : str, optional
        ``"fast"`` | ``"default"`` | ``"precise"`` | ``"reference"``: solver effort, as
        ``impulse run --preset``.
    jitter : dict, optional
        ``{"position": m, "angle": degrees, "velocity": m/s}``: each seed's random variation of
        the dynamic bodies (``World.from_scene``'s ``jitter``).
    workers : int, optional
        Worker processes (local: default ``os.cpu_count()``; Ray: the CPUs of a local Ray it
        starts, default all; on a cluster, ignored: the cluster's CPUs are used).
    address : str, optional
        Ray only: the cluster to join (``"auto"``, ``"ray://head:10001"``); ``None`` starts a
        local Ray unless one is already initialised.
    progress : bool
        Show a progress bar (tqdm) with runs done, failed and runs per second.
    retry_failed : bool
        Also run again the runs written with status ``failed`` (a fixed ``observe``, a worker
        that died); their new rows replace the old. Runs ``stopped`` by a failed step are
        deterministic and never retried.

    Columns
    -------
    ``run_key``; one per grid key (its values); ``seed``, ``steps``; ``status`` (``completed``,
    ``stopped``: a step failed and the metrics cover the steps before it, ``failed``: no
    metrics, or ``observe`` raised) and ``error``; ``steps_taken``, ``bodies``, ``dt`` (s); the
    summary of ``impulse run``: ``ms_per_step`` (median wall time, ms), ``mean_ms_per_step``,
    ``max_overlap_m``, ``final_overlap_m``, ``top_body``, ``top_sink_m``, ``max_drift_m``,
    ``quality_error_m`` (E = max of |top sink|, overlap, drift), ``kinetic_energy_j``,
    ``max_speed_m_s``, ``mean_contacts``, ``mean_iterations``, ``max_natural_map_residual``,
    ``final_natural_map_residual``; ``observe.<name>``; ``wall_time_s`` and ``cpu_time_s``
    (the whole run in its worker, wall-clock and CPU), ``worker`` (host:pid), ``trajectory``
    (path or null).

    Raises
    ------
    ValueError / TypeError for a bad grid, seeds, steps, jitter or backend; the scene's
    ``SceneError`` when the scene itself (without overrides) does not load. Failures of single
    runs are never raised: they are rows.
    """
    if backend not in ("local", "ray"):
        raise ValueError(f"backend = {backend!r}: use 'local' or 'ray'")
    if steps is None:
        raise ValueError("steps is required: the number of steps of every run")
    steps = _check_steps(steps)
    if workers is not None and (
        isinstance(workers, bool) or not isinstance(workers, int) or workers < 1
    ):
        raise ValueError(f"workers = {workers!r}: must be an integer ≥ 1")
    trajectory_every = _trajectory_every(save_trajectories)
    scene_spec, scene_description = _normalise_scene(scene)
    jitter = _normalise_jitter(jitter)
    grid = _check_grid(grid)
    seed_list = _seed_list(seeds)
    if preset is not None and not isinstance(preset, str):
        raise TypeError("preset must be a preset name: 'fast', 'default', 'precise' or 'reference'")
    observe_bytes = _pickle_observe(observe) if observe is not None else None
    _check_scene_loads(scene_spec, preset)

    out = os.fspath(out)
    filesystem, root = _filesystem(out)
    filesystem.create_dir(root, recursive=True)
    digest = scene_digest(scene_spec)
    runs = []
    keys: set[str] = set()
    for overrides, seed in expand(grid, seed_list):
        key = run_key(digest, overrides, seed, steps, preset, jitter)
        if key not in keys:  # a value listed twice in the grid is one run
            keys.add(key)
            runs.append(Run(overrides, seed, key))
    previous = _read_all(filesystem, root)
    done = set()
    if previous is not None:
        for key, status in zip(
            previous.column("run_key").to_pylist(),
            previous.column("status").to_pylist(),
            strict=True,
        ):
            if not (retry_failed and status == FAILED):
                done.add(key)
    todo = [run for run in runs if run.key not in done]
    override_types = _override_types(grid)
    manifest = {
        "scene": scene_description if not isinstance(scene_spec, dict) else scene_spec,
        "scene_sha256": digest,
        "grid": grid,
        "seeds": seed_list,
        "steps": steps,
        "preset": preset,
        "jitter": jitter,
        "backend": backend,
        "workers": workers,
        "save_trajectories": trajectory_every,
        "key_version": KEY_VERSION,
        "runs": len(runs),
        "versions": _versions(backend),
    }
    _write_json(filesystem, f"{root}/{MANIFEST_FILE}", {**manifest, "state": "running"})

    by_key = {run.key: run for run in todo}
    tasks = (
        _task(
            scene_spec,
            run.overrides,
            run.seed,
            steps,
            preset,
            jitter,
            run.key,
            observe_bytes,
            out,
            trajectory_every,
        )
        for run in todo
    )
    buffer: list[dict[str, Any]] = []
    last_flush = time.monotonic()
    bar = _Progress(len(todo), len(runs) - len(todo), progress)
    runner = None

    def flush() -> None:
        nonlocal buffer, last_flush
        if buffer:
            table = _table(buffer, override_types)
            filesystem.create_dir(f"{root}/{PARTS_DIR}", recursive=True)
            _write_parquet(
                filesystem,
                f"{root}/{PARTS_DIR}/part-{time.time_ns()}-{uuid.uuid4().hex[:8]}.parquet",
                table,
            )
            buffer = []
        last_flush = time.monotonic()

    completed = False
    try:
        if todo:
            count = workers or os.cpu_count() or 1
            runner = (
                _LocalBackend(min(count, len(todo)))
                if backend == "local"
                else _RayBackend(workers, address)
            )
            for row in runner.run(tasks):
                run = by_key[row["run_key"]]
                row.update(run.overrides)
                row["seed"] = run.seed
                row["steps"] = steps
                buffer.append(row)
                bar.update(row)
                if len(buffer) >= FLUSH_ROWS or time.monotonic() - last_flush >= FLUSH_SECONDS:
                    flush()
        completed = True
    finally:
        bar.close()
        flush()
        if runner is not None:
            runner.close(cancel=not completed)

    table = _merge(filesystem, root, runs, [name for name in grid])
    counts = _status_counts(table, {run.key for run in runs})
    _write_json(filesystem, f"{root}/{MANIFEST_FILE}", {**manifest, "state": "finished", **counts})
    return table


def _trajectory_every(save_trajectories: bool | int) -> int:
    if save_trajectories is False or save_trajectories is None:
        return 0
    if save_trajectories is True:
        return 1
    if isinstance(save_trajectories, int) and save_trajectories >= 1:
        return int(save_trajectories)
    raise ValueError(
        f"save_trajectories = {save_trajectories!r}: use False, True or a frame interval K ≥ 1"
    )


def _pickle_observe(observe: Callable[[Any], Any]) -> bytes:
    """``observe`` as bytes for the workers. A function of an installed package goes by
    reference (the workers import it); any other (a script's, a test's, a lambda, a closure)
    by value with cloudpickle (standalone or Ray's), since a worker process, above all one on
    another machine, may not find its module."""
    if not callable(observe):
        raise TypeError("observe must be a callable taking the world and returning a dict")
    module_name = getattr(observe, "__module__", None) or ""
    package = sys.modules.get(module_name.partition(".")[0])
    if package is not None and _is_installed(package):
        try:
            return pickle.dumps(observe)
        except Exception:
            pass
    cloudpickle = _cloudpickle()
    if cloudpickle is None:
        try:
            return pickle.dumps(observe)
        except Exception as error:
            raise TypeError(
                f"observe cannot be sent to the workers ({error}): define it at the top of a "
                "module, or install cloudpickle"
            ) from None
    if package is None or package.__name__ in ("__main__", "__mp_main__"):
        return cloudpickle.dumps(observe)
    cloudpickle.register_pickle_by_value(package)
    try:
        return cloudpickle.dumps(observe)
    finally:
        cloudpickle.unregister_pickle_by_value(package)


def _cloudpickle() -> Any:
    try:
        import cloudpickle
    except ImportError:
        try:
            from ray import cloudpickle
        except ImportError:
            return None
    return cloudpickle


def _is_installed(module: Any) -> bool:
    """Whether ``module`` comes from the standard library or site-packages (every worker of
    the same environment can import it)."""
    import sysconfig

    file = getattr(module, "__file__", None)
    if file is None:
        return module.__name__ in sys.builtin_module_names
    file = os.path.realpath(file)
    roots = {sysconfig.get_paths()[name] for name in ("stdlib", "platstdlib", "purelib", "platlib")}
    return any(file.startswith(os.path.realpath(root) + os.sep) for root in roots)


def _check_scene_loads(scene: Any, preset: str | None) -> None:
    """Loads the scene once here, without overrides, so that a bad scene or preset is one clear
    error rather than a failed row per run."""
    try:
        import impulse
    except ImportError:
        return
    impulse.World.from_scene(scene, settings=preset)


def _merge(filesystem: Any, root: str, runs: list[Run], grid_keys: list[str]) -> Any:
    """Merges the part files into ``results.parquet``: this sweep's runs first, in the grid's
    order, then any other runs the directory held; then deletes the parts."""
    import pyarrow as pa
    import pyarrow.compute as pc

    parts = _part_paths(filesystem, root)
    table = _read_all(filesystem, root)
    if table is None:
        return None
    order = {run.key: i for i, run in enumerate(runs)}
    keys = table.column("run_key").to_pylist()
    rank = [order.get(k, len(order) + i) for i, k in enumerate(keys)]
    table = table.take(pc.sort_indices(pa.array(rank)))
    table = _reorder_columns(table, grid_keys)
    _write_parquet(filesystem, f"{root}/{RESULTS_FILE}", table)
    for part in parts:
        filesystem.delete_file(part)
    if _exists(filesystem, f"{root}/{PARTS_DIR}"):
        filesystem.delete_dir(f"{root}/{PARTS_DIR}")
    return table


def _status_counts(table: Any, keys: set[str]) -> dict[str, int]:
    counts = {"completed": 0, "stopped": 0, "failed": 0}
    if table is None:
        return counts
    for key, status in zip(
        table.column("run_key").to_pylist(), table.column("status").to_pylist(), strict=True
    ):
        if key in keys:
            counts[status] = counts.get(status, 0) + 1
    return counts
