"""File names, key version, flush limits, column lists and run statuses of a sweep."""

from __future__ import annotations

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
    # The run's initial state after overrides and jitter, every body, flattened row-major:
    # positions (B·3, m), orientations (B·4, [x, y, z, w]), velocities (B·3, m/s; rad/s).
    ("initial_positions", "list<float32>"),
    ("initial_orientations", "list<float32>"),
    ("initial_linear_velocities", "list<float32>"),
    ("initial_angular_velocities", "list<float32>"),
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
#: Start of the error of a run that failed because its worker could not run it (the process
#: died, the task could not be sent): not the run's fault, so a resumed sweep runs it again.
WORKER_FAILURE = "worker: "
