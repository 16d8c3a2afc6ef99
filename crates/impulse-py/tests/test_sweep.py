"""Sweeps: grid × seeds expansion, run keys, resume, failures recorded, and the same table to the
bit from the local process pool, from a local Ray and from runs in this process."""

from __future__ import annotations

import json

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import impulse
from impulse.sweep import (
    COMPLETED,
    FAILED,
    MANIFEST_FILE,
    RESULTS_FILE,
    TIMING_COLUMNS,
    expand,
    read_results,
    run_key,
    run_one,
    scene_digest,
    sweep,
)
from impulse.sweep.cli import main as cli_main
from impulse.sweep.cli import parse_seeds, parse_values

STEPS = 24
FRICTION = "materials.default.friction"
JITTER = {"position": 0.01, "angle": 2.0, "velocity": 0.05}


def box(y: float) -> dict:
    return {
        "kind": "dynamic",
        "shape": {"type": "cuboid", "half_extents": [0.5, 0.5, 0.5]},
        "position": [0.0, y, 0.0],
    }


#: Three cubes stacked on the ground: contacts from the first step, tiny to step.
SCENE = {
    "name": "stack3",
    "gravity": [0.0, -9.81, 0.0],
    "dt": 1.0 / 60.0,
    "steps": STEPS,
    "materials": {"default": {"friction": 0.6, "restitution": 0.0, "density": 1000.0}},
    "bodies": [
        {
            "name": "ground",
            "kind": "static",
            "shape": {"type": "cuboid", "half_extents": [20.0, 0.5, 20.0]},
            "position": [0.0, -0.5, 0.0],
        },
        box(0.5),
        box(1.5),
        box(2.5),
    ],
}


def final_state(world) -> dict:
    """Observed: the final poses and velocities as bytes (hex), for comparisons to the bit."""
    return {
        "positions": np.ascontiguousarray(world.positions).tobytes().hex(),
        "orientations": np.ascontiguousarray(world.orientations).tobytes().hex(),
        "linear_velocities": np.ascontiguousarray(world.linear_velocities).tobytes().hex(),
        "top_y": float(world.positions[3, 1]),
    }


def simulated(table: pa.Table) -> list[dict]:
    """The table's rows without the timing columns, for comparisons to the bit."""
    return table.drop_columns([c for c in TIMING_COLUMNS if c in table.column_names]).to_pylist()


# ---------------------------------------------------------------------------------------------
# Pure parts: expansion, keys, command-line parsing


def test_expand_is_the_product_of_grid_and_seeds_in_order():
    runs = expand({"a": [1, 2], "b.c": ["x", "y", "z"]}, seeds=[7, 9])
    assert len(runs) == 2 * 3 * 2
    assert runs[0] == ({"a": 1, "b.c": "x"}, 7)
    assert runs[1] == ({"a": 1, "b.c": "x"}, 9)  # seeds vary fastest
    assert runs[2] == ({"a": 1, "b.c": "y"}, 7)  # then the last grid key
    assert runs[-1] == ({"a": 2, "b.c": "z"}, 9)
    assert len({json.dumps(o, sort_keys=True) + str(s) for o, s in runs}) == len(runs)
    assert expand(None, 3) == [({}, 0), ({}, 1), ({}, 2)]
    assert expand({"a": [[0, 0, -5]]}, 1) == [({"a": [0, 0, -5]}, 0)]


@pytest.mark.parametrize(
    "grid, seeds",
    [
        ({"a": []}, 1),
        ({"a": 0.5}, 1),
        ({"a": "0.5"}, 1),
        ({"a": [float("nan")]}, 1),
        ({}, 0),
        ({}, [-1]),
        ({}, []),
        ({}, True),
    ],
)
def test_expand_rejects_bad_grids_and_seeds(grid, seeds):
    with pytest.raises((ValueError, TypeError)):
        expand(grid, seeds)


def test_run_key_depends_on_what_changes_the_result_only():
    digest = scene_digest(SCENE)
    key = run_key(digest, {"a": 1, "b": 2.5}, 3, 100, "fast", None)
    assert key == run_key(digest, {"b": 2.5, "a": 1}, 3, 100, "fast", None)  # order of overrides
    assert key == run_key(digest, {"a": 1, "b": 2.5}, 3, 100, "fast", {})  # no jitter = zero jitter
    others = [
        run_key(digest, {"a": 1, "b": 2.5}, 4, 100, "fast", None),
        run_key(digest, {"a": 1, "b": 2.5}, 3, 101, "fast", None),
        run_key(digest, {"a": 1, "b": 2.5}, 3, 100, "default", None),
        run_key(digest, {"a": 1, "b": 2.5}, 3, 100, "fast", {"position": 0.01}),
        run_key(digest, {"a": 1, "b": 2.6}, 3, 100, "fast", None),
        run_key(digest, {"a": 1.0, "b": 2.5}, 3, 100, "fast", None),  # 1 and 1.0 differ in JSON
        run_key(digest, {"a": 1}, 3, 100, "fast", None),
        run_key(scene_digest({**SCENE, "dt": 0.01}), {"a": 1, "b": 2.5}, 3, 100, "fast", None),
    ]
    assert len({key, *others}) == 1 + len(others)


def test_scene_digest_is_the_file_content(tmp_path):
    first, second = tmp_path / "a.json", tmp_path / "b.json"
    first.write_text(json.dumps(SCENE))
    second.write_text(json.dumps(SCENE))
    assert scene_digest(first) == scene_digest(str(second))
    second.write_text(json.dumps({**SCENE, "steps": 1}))
    assert scene_digest(first) != scene_digest(second)
    assert scene_digest("stack30") != scene_digest("pyramid20")


def test_command_line_values_and_seeds():
    assert parse_values("0.2,0.5") == [0.2, 0.5]
    assert parse_values("[0,0,-5],[0,0,-10]") == [[0, 0, -5], [0, 0, -10]]
    assert parse_values("pgs,nncg") == ["pgs", "nncg"]
    assert parse_values("true,12") == [True, 12]
    assert parse_seeds("0:64") == list(range(64))
    assert parse_seeds("3") == [0, 1, 2]
    assert parse_seeds("5,9") == [5, 9]


# ---------------------------------------------------------------------------------------------
# Real runs on the local process pool


def test_resume_skips_runs_already_written(tmp_path):
    out = tmp_path / "sweep"
    grid = {FRICTION: [0.2, 0.8]}
    first = sweep(
        SCENE, grid=grid, seeds=3, steps=STEPS, jitter=JITTER, out=out, workers=2, progress=False
    )
    assert first.num_rows == 6
    assert first.column("status").to_pylist() == [COMPLETED] * 6
    assert first.column(FRICTION).to_pylist() == [0.2] * 3 + [0.8] * 3
    assert first.column("seed").to_pylist() == [0, 1, 2] * 2
    assert first.column("steps_taken").to_pylist() == [STEPS] * 6
    assert pq.read_table(out / RESULTS_FILE).equals(first)
    manifest = json.loads((out / MANIFEST_FILE).read_text())
    assert (
        manifest["runs"] == 6
        and manifest["completed"] == 6
        and manifest["grid"] == {FRICTION: [0.2, 0.8]}
    )

    # The same sweep again runs nothing: every row (with its wall time and worker) is the old one.
    again = sweep(
        SCENE, grid=grid, seeds=3, steps=STEPS, jitter=JITTER, out=out, workers=2, progress=False
    )
    assert again.equals(first)

    # A larger grid runs only what is new; the old rows stay as they were.
    larger = sweep(
        SCENE,
        grid={FRICTION: [0.2, 0.5, 0.8]},
        seeds=3,
        steps=STEPS,
        jitter=JITTER,
        out=out,
        workers=2,
        progress=False,
    )
    assert larger.num_rows == 9
    old = {row["run_key"]: row for row in first.to_pylist()}
    kept = [row for row in larger.to_pylist() if row["run_key"] in old]
    assert len(kept) == 6 and all(row == old[row["run_key"]] for row in kept)
    assert larger.column(FRICTION).to_pylist() == [0.2] * 3 + [0.5] * 3 + [0.8] * 3


def test_a_failing_run_is_recorded_and_the_others_go_on(tmp_path):
    out = (
        tmp_path / "sweep"
    ).as_uri()  # through pyarrow's filesystem by URI, as for an object store
    grid = {FRICTION: [0.5, -1.0, 0.9], "bodies[2].linear_velocity": [[0.0, 0.0, 0.0]]}
    table = sweep(
        SCENE,
        grid=grid,
        seeds=2,
        steps=STEPS,
        out=out,
        observe=final_state,
        workers=2,
        progress=False,
    )
    rows = table.to_pylist()
    assert [row[FRICTION] for row in rows] == [0.5, 0.5, -1.0, -1.0, 0.9, 0.9]
    assert [row["status"] for row in rows] == [
        COMPLETED,
        COMPLETED,
        FAILED,
        FAILED,
        COMPLETED,
        COMPLETED,
    ]
    for row in rows[2:4]:
        assert "SceneError" in row["error"] and "friction" in row["error"]
        assert row["steps_taken"] is None and row["observe.top_y"] is None
    for row in rows[:2] + rows[4:]:
        assert row["error"] is None and row["steps_taken"] == STEPS and row["observe.top_y"] > 2.0
    assert read_results(out).equals(table)

    # Failed rows are kept on a resume, and run again when asked.
    again = sweep(
        SCENE,
        grid=grid,
        seeds=2,
        steps=STEPS,
        out=out,
        observe=final_state,
        workers=2,
        progress=False,
        retry_failed=True,
    )
    assert again.num_rows == 6
    assert [r["wall_time_s"] for r in again.to_pylist()][:2] == [r["wall_time_s"] for r in rows[:2]]
    assert again.column("status").to_pylist() == table.column("status").to_pylist()


def test_an_exception_in_observe_fails_that_run_only(tmp_path):
    def observe(world):  # a closure: sent to the workers by value
        if world.positions[3, 1] > 5.0:
            raise ValueError("the top cube is still in the air")
        return {"top_y": float(world.positions[3, 1])}

    # The top cube on the stack, or 10 m above it (it falls less than a metre in 4 steps).
    grid = {"bodies[3].position": [[0.0, 2.5, 0.0], [0.0, 10.0, 0.0]]}
    table = sweep(
        SCENE,
        grid=grid,
        seeds=1,
        steps=4,
        out=tmp_path / "s",
        observe=observe,
        workers=2,
        progress=False,
    )
    statuses = table.column("status").to_pylist()
    errors = table.column("error").to_pylist()
    assert statuses[0] == COMPLETED and errors[0] is None
    assert (
        statuses[1] == FAILED
        and errors[1] == "observe: ValueError: the top cube is still in the air"
    )
    assert table.column("steps_taken").to_pylist() == [4, 4]  # the metrics stay
    assert table.column("observe.top_y").to_pylist()[1] is None


def test_trajectories_one_file_per_run(tmp_path):
    out = tmp_path / "sweep"
    table = sweep(
        SCENE,
        grid={FRICTION: [0.3]},
        seeds=2,
        steps=STEPS,
        jitter=JITTER,
        out=out,
        observe=final_state,
        save_trajectories=4,
        workers=2,
        progress=False,
    )
    for row in table.to_pylist():
        trajectory = impulse.load_trajectory(row["trajectory"])
        assert list(trajectory.steps) == list(range(0, STEPS + 1, 4))
        assert trajectory.positions.shape == (len(trajectory.steps), 4, 3)
        assert (
            np.ascontiguousarray(trajectory.positions[-1]).tobytes().hex()
            == row["observe.positions"]
        )


def test_command_line(tmp_path, capsys):
    scene = tmp_path / "stack3.json"
    scene.write_text(json.dumps(SCENE))
    out = tmp_path / "sweep"
    args = [
        str(scene),
        "--grid",
        f"{FRICTION}=0.2,0.5",
        "--seeds",
        "0:2",
        "--steps",
        "8",
        "--out",
        str(out),
        "--workers",
        "2",
        "--jitter-position",
        "0.01",
        "--no-progress",
    ]
    assert cli_main(args) == 0
    assert "4 runs: 4 completed, 0 stopped, 0 failed" in capsys.readouterr().out
    table = pq.read_table(out / RESULTS_FILE)
    assert table.column(FRICTION).to_pylist() == [0.2, 0.2, 0.5, 0.5]
    assert cli_main(args[:2] + [f"{FRICTION}=-1"] + args[3:]) == 1
    assert cli_main(["no-such-scene", "--steps", "1", "--out", str(out)]) == 2


# ---------------------------------------------------------------------------------------------
# Local pool, local Ray and this process give the same results to the bit


@pytest.fixture(scope="module")
def local_ray():
    """One local Ray for the module (its start-up takes seconds)."""
    import ray

    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield ray
    ray.shutdown()


def test_local_and_ray_sweeps_are_equal_to_the_bit(tmp_path, local_ray):
    grid = {FRICTION: [0.3, 0.9]}
    seeds = 32  # 64 runs
    common = dict(
        grid=grid,
        seeds=seeds,
        steps=STEPS,
        jitter=JITTER,
        observe=final_state,
        preset="fast",
        progress=False,
    )
    local = impulse.sweep(SCENE, backend="local", out=tmp_path / "local", workers=2, **common)
    on_ray = sweep(SCENE, backend="ray", out=tmp_path / "ray", **common)
    assert local.num_rows == on_ray.num_rows == 64
    assert local.column("status").to_pylist() == [COMPLETED] * 64
    assert local.schema.equals(on_ray.schema)
    assert simulated(local) == simulated(on_ray)
    # Ray ran the runs in its own worker processes.
    assert set(on_ray.column("worker").to_pylist()).isdisjoint(local.column("worker").to_pylist())
    # The seeds vary the runs: the jitter moved the bodies differently in every run.
    assert len(set(local.column("observe.positions").to_pylist())) == 64

    # Equal to runs in this process: through the sweep's own measurement, and stepped directly.
    for index in (0, 33, 63):
        row = simulated(local.slice(index, 1))[0]
        overrides = {FRICTION: row[FRICTION]}
        alone = run_one(
            SCENE,
            overrides=overrides,
            seed=row["seed"],
            steps=STEPS,
            preset="fast",
            jitter=JITTER,
            observe=final_state,
        )
        assert {k: v for k, v in alone.items() if k not in TIMING_COLUMNS} == row
        world = impulse.World.from_scene(
            SCENE, overrides=overrides, seed=row["seed"], jitter=JITTER, settings="fast"
        )
        world.step(STEPS)
        assert final_state(world) == {
            k[len("observe.") :]: v for k, v in row.items() if k.startswith("observe.")
        }


# ---------------------------------------------------------------------------------------------
# Sweeps that fail loudly, before any worker starts


def test_the_table_records_each_runs_varied_initial_state(tmp_path):
    table = sweep(
        SCENE, seeds=2, steps=2, jitter=JITTER, out=tmp_path / "s", workers=2, progress=False
    )
    for row in table.to_pylist():
        world = impulse.World.from_scene(SCENE, seed=row["seed"], jitter=JITTER)
        assert row["initial_positions"] == world.positions.ravel().tolist()
        assert row["initial_orientations"] == world.orientations.ravel().tolist()
        assert row["initial_linear_velocities"] == world.linear_velocities.ravel().tolist()
    first, second = table.column("initial_positions").to_pylist()
    assert first != second  # the seeds' jitters differ


def test_seeds_without_jitter_warn_that_every_run_is_the_same(tmp_path):
    with pytest.warns(UserWarning, match="2 seeds without jitter"):
        sweep(SCENE, seeds=2, steps=1, out=tmp_path / "s", workers=1, progress=False)


def test_a_call_outside_the_main_guard_is_refused_before_any_worker_starts(tmp_path):
    import subprocess
    import sys

    script = tmp_path / "unguarded.py"
    script.write_text(
        "import impulse\n"
        f"impulse.sweep({SCENE!r}, seeds=[0], steps=1, out={str(tmp_path / 'o')!r},"
        " progress=False)\n"
    )
    done = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, check=False, timeout=120
    )
    assert done.returncode == 1
    assert 'under if __name__ == "__main__":' in done.stderr
    assert "unguarded.py (line 2)" in done.stderr
    assert not (tmp_path / "o" / RESULTS_FILE).exists()
    guarded = tmp_path / "guarded.py"
    guarded.write_text(
        "import impulse\n"
        "if __name__ == '__main__':\n"
        f"    t = impulse.sweep({SCENE!r}, seeds=[0], steps=1, out={str(tmp_path / 'g')!r},"
        " progress=False)\n"
        "    print(t.column('status').to_pylist())\n"
    )
    done = subprocess.run(
        [sys.executable, str(guarded)], capture_output=True, text=True, check=False, timeout=300
    )
    assert done.returncode == 0, done.stderr
    assert "['completed']" in done.stdout


def test_runs_whose_worker_failed_run_again_on_resume(tmp_path):
    from impulse.sweep._constants import WORKER_FAILURE

    out = tmp_path / "s"
    first = sweep(SCENE, seeds=[0, 1], steps=2, jitter=JITTER, out=out, workers=2, progress=False)
    rows = first.to_pylist()
    rows[0]["status"], rows[0]["error"] = FAILED, f"{WORKER_FAILURE}BrokenProcessPool: died"
    rows[1]["status"], rows[1]["error"] = FAILED, "observe: ValueError: the run's own failure"
    pq.write_table(pa.Table.from_pylist(rows, schema=first.schema), out / RESULTS_FILE)
    again = sweep(SCENE, seeds=[0, 1], steps=2, jitter=JITTER, out=out, workers=2, progress=False)
    statuses = dict(zip(again.column("seed").to_pylist(), again.column("status").to_pylist(), strict=True))
    # The worker's failure is run again; the run's own failure is kept (retry_failed reruns it).
    assert statuses == {0: COMPLETED, 1: FAILED}


def _sleeping_row(task):
    """A pool task that takes half a second and returns its row (never raises)."""
    import time

    time.sleep(task["seconds"])
    return {"seconds": task["seconds"]}


def test_a_cancelled_local_pool_ends_without_an_error_in_its_threads():
    # What Ctrl-C or SIGTERM does to a search with takes queued behind the running ones: the
    # workers are terminated and the pool shut down. A queued future cancelled by hand before
    # that made Python 3.11's executor thread die of InvalidStateError when the broken pool
    # set its exception (and shutdown could then wait for ever).
    import threading

    from impulse.sweep._backends import _LocalBackend

    errors = []
    previous = threading.excepthook
    threading.excepthook = lambda hook: errors.append(hook.exc_value)
    try:
        for _ in range(3):
            backend = _LocalBackend(2, function=_sleeping_row)
            rows = backend.run({"seconds": 0.5} for _ in range(40))
            assert next(rows) == {"seconds": 0.5}
            backend.close(cancel=True)
    finally:
        threading.excepthook = previous
    assert errors == []
