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

import os
import pickle
import sys
import time
import uuid
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any

from impulse.sweep._backends import _LocalBackend, _RayBackend
from impulse.sweep._constants import (
    COMPLETED,
    FAILED,
    FLUSH_ROWS,
    FLUSH_SECONDS,
    KEY_VERSION,
    MANIFEST_FILE,
    PARTS_DIR,
    RESULTS_FILE,
    STOPPED,
    TIMING_COLUMNS,
    TRAJECTORY_DIR,
    WORKER_FAILURE,
)
from impulse.sweep._runs import (
    Run,
    _check_grid,
    _normalise_jitter,
    _normalise_scene,
    _seed_list,
    expand,
    run_key,
    scene_digest,
)
from impulse.sweep._store import (
    _exists,
    _filesystem,
    _override_types,
    _part_paths,
    _read_all,
    _reorder_columns,
    _table,
    _versions,
    _write_json,
    _write_parquet,
    read_results,
)
from impulse.sweep._worker import _check_steps, _task, run_one

__all__ = [
    "RESULTS_FILE",
    "MANIFEST_FILE",
    "TRAJECTORY_DIR",
    "TIMING_COLUMNS",
    "COMPLETED",
    "STOPPED",
    "FAILED",
    "Run",
    "expand",
    "run_key",
    "scene_digest",
    "run_one",
    "read_results",
    "sweep",
]


# --------------------------------------------------------------------------------------------
# The sweep


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
    if backend == "local":
        _check_workers_can_start("impulse.sweep")
    if len(seed_list) > 1 and jitter is None:
        warnings.warn(
            f"{len(seed_list)} seeds without jitter: a seed varies a run only through jitter "
            "(and the draws of rough materials, if the scene has any), so every seed of a grid "
            "point may give the same run; pass jitter={'position': m, 'angle': degrees, "
            "'velocity': m/s} to vary them",
            UserWarning,
            stacklevel=2,
        )

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
        for key, status, error in zip(
            previous.column("run_key").to_pylist(),
            previous.column("status").to_pylist(),
            previous.column("error").to_pylist(),
            strict=True,
        ):
            # A run whose worker could not run it failed for the worker's sake: run it again.
            if status == FAILED and (retry_failed or (error or "").startswith(WORKER_FAILURE)):
                continue
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


def _check_workers_can_start(caller: str) -> None:
    """Raises ``RuntimeError`` before any worker starts when the local pool's workers cannot
    run: the pool starts each worker by ``spawn``, which imports the main script again, so a
    call at the top level of a script (not under ``if __name__ == "__main__":``) would start the
    whole sweep again in every worker, and inside a worker it is refused outright."""
    import ast

    main = sys.modules.get("__main__")
    spec_name = getattr(getattr(main, "__spec__", None), "name", None) or ""
    if spec_name == "__main__" or spec_name.endswith(".__main__"):
        return  # `python -m package`: spawn does not import a package's __main__ again
    frame = sys._getframe(1)
    while frame is not None:
        if frame.f_globals.get("__name__") == "__mp_main__":
            raise RuntimeError(
                f"{caller} was started again while a worker process imported the main script: "
                'put the call under if __name__ == "__main__":'
            )
        if (
            main is not None
            and frame.f_globals is vars(main)
            and frame.f_code.co_name == "<module>"
        ):
            path = getattr(main, "__file__", None)
            if path is None:
                return  # a notebook, the REPL, python -c: spawn does not import them again
            if not os.path.isfile(path):
                # `python - <<EOF`, `cat script.py | python`: spawn would import the main
                # script again from `path` (<stdin>), which no worker can read: every run
                # would fail in its worker.
                raise RuntimeError(
                    f"{caller} runs from a script read from standard input ({path}): the local "
                    "backend's worker processes start by importing the main script again, and "
                    "a piped script cannot be read twice. Save it to a file and run that (with "
                    f'{caller} under if __name__ == "__main__":), or use backend="ray"'
                )
            with open(path, encoding="utf-8") as file:
                tree = ast.parse(file.read(), path)
            if not _under_main_guard(tree, frame.f_lineno):
                raise RuntimeError(
                    f"{caller} is called at the top level of {path} (line {frame.f_lineno}): "
                    "the local backend's worker processes start by importing that script "
                    "again, which would start the sweep again in each. Put the call under "
                    'if __name__ == "__main__": (or use backend="ray")'
                )
            return
        frame = frame.f_back


def _under_main_guard(tree: Any, line: int) -> bool:
    """Whether ``line`` of a module lies inside an ``if __name__ == "__main__":`` block (or a
    function or class body, which only runs when called)."""
    import ast

    for node in tree.body:
        start, end = node.lineno, getattr(node, "end_lineno", node.lineno)
        if not start <= line <= end:
            continue
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            return True
        test = getattr(node, "test", None)
        if isinstance(node, ast.If) and isinstance(test, ast.Compare):
            names = [test.left, *test.comparators]
            text = {getattr(n, "id", None) for n in names} | {
                getattr(n, "value", None) for n in names
            }
            if "__name__" in text and "__main__" in text:
                return True
    return False


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


def _pickle_observe(
    observe: Callable[[Any], Any],
    what: str = "observe",
    usage: str = "a callable taking the world and returning a dict",
) -> bytes:
    """``observe`` as bytes for the workers. A function of an installed package goes by
    reference (the workers import it); any other (a script's, a test's, a lambda, a closure)
    by value with cloudpickle (standalone or Ray's), since a worker process, above all one on
    another machine, may not find its module. ``what`` and ``usage`` name the callable in
    errors (a sweep's ``observe``, a custom goal's function)."""
    if not callable(observe):
        raise TypeError(f"{what} must be {usage}")
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
                f"{what} cannot be sent to the workers ({error}): define it at the top of a "
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
