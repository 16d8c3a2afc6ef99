"""One world shared between threads: calls take turns, the GIL is released while stepping, and
the result equals the same steps taken on one thread (steps are deterministic)."""

import sys
import threading

import numpy as np

import impulse


def pyramid():
    world = impulse.World.from_scene("pyramid20")
    # Awake throughout, so every step does the whole contact solve.
    world.settings = world.settings.replace(sleep=False)
    return world


def state_bytes(world):
    return [
        np.ascontiguousarray(getattr(world, name)).tobytes()
        for name in ("positions", "orientations", "linear_velocities", "angular_velocities")
    ]


def run_threads(targets):
    """Runs each target on its own thread; returns every exception (BaseException too) raised."""
    failures = []

    def guarded(target):
        try:
            target()
        except BaseException as error:  # noqa: BLE001 - a PanicException is a BaseException
            failures.append(error)

    threads = [threading.Thread(target=guarded, args=(t,)) for t in targets]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    return failures


def test_threads_stepping_and_reading_one_world_equal_sequential_steps():
    world = pyramid()
    steppers, calls = 4, 50
    done = threading.Event()
    seen_steps = []

    def step():
        for _ in range(calls):
            world.step()

    def read():
        # Every read-only method, over and over, while the steppers run.
        while not done.is_set():
            state = world.state()
            seen_steps.append(state["step_count"])
            assert np.isfinite(state["positions"]).all()
            assert world.positions.shape == (len(world), 3)
            world.orientations, world.linear_velocities, world.angular_velocities  # noqa: B018 (reads)
            world.diagnostics, world.profile, world.step_count, world.time, world.names  # noqa: B018
            world.quality()
            world.contact_pairs()
            world.cast_ray((0, 20, 0), (0, -1, 0))
            repr(world)

    readers = [read, read]

    def steppers_then_done():
        failures = run_threads([step] * steppers)
        done.set()
        if failures:
            raise failures[0]

    failures = run_threads([steppers_then_done, *readers])
    assert failures == []
    assert world.step_count == steppers * calls
    # Readers saw the step count only grow: no read saw a step half done or undone.
    assert seen_steps == sorted(seen_steps)
    assert len(seen_steps) > 0

    sequential = pyramid()
    sequential.step(steppers * calls)
    assert state_bytes(world) == state_bytes(sequential)
    assert world.diagnostics == sequential.diagnostics


def test_a_call_holds_the_world_for_all_its_steps():
    # `step(20)` spans two chunks of 16 steps, between which the GIL is taken back: a reader
    # still never sees a step count that is not a multiple of 20.
    world = pyramid()
    done = threading.Event()
    seen = set()

    def step():
        for _ in range(8):
            world.step(20)
        done.set()

    def read():
        while not done.is_set():
            seen.add(world.step_count)

    assert run_threads([step, read, read]) == []
    assert world.step_count == 160
    assert all(count % 20 == 0 for count in seen), sorted(seen)


def test_setters_and_edits_from_threads_take_turns():
    # Each thread inserts its own bodies and pushes them; with calls taking turns every edit
    # lands whole: the world ends with every body, and positions read back as assigned.
    world = impulse.World(gravity=(0, 0, 0))
    per_thread = 25

    def edit(column):
        def run():
            for i in range(per_thread):
                builder = impulse.BodyBuilder.dynamic(
                    impulse.Shape.ball(0.1), translation=(3.0 * column, 0.5 * i, 0.0)
                )
                handle = world.insert(builder)
                world.apply_impulse(handle, (0.0, 0.0, 1.0))
                world.step(0)

        return run

    assert run_threads([edit(c) for c in range(4)]) == []
    assert len(world) == 4 * per_thread
    state = world.state()
    assert sorted(map(tuple, state["positions"][:, :2].tolist())) == sorted(
        (3.0 * c, 0.5 * i) for c in range(4) for i in range(per_thread)
    )
    assert np.all(state["linear_velocities"][:, 2] > 0)


def test_step_releases_the_gil():
    # With a switch interval far longer than the test, a thread runs Python only when another
    # gives up the GIL on its own. The main thread waits for the stepper to start; it can
    # resume while the stepper's `step` has not returned only if `step` released the GIL.
    interval = sys.getswitchinterval()
    world = pyramid()
    started, finished = threading.Event(), threading.Event()

    def stepper():
        started.set()
        world.step(100)
        finished.set()

    sys.setswitchinterval(1000.0)
    try:
        thread = threading.Thread(target=stepper)
        thread.start()
        started.wait()
        stepping_meanwhile = not finished.is_set()
        thread.join()
    finally:
        sys.setswitchinterval(interval)
    assert stepping_meanwhile, "no other thread ran while the world stepped"
    assert world.step_count == 100


def test_python_run_inside_a_call_on_the_world_gets_runtime_error(monkeypatch):
    # `simulate` makes its Trajectory while it holds the world; code run there that uses the
    # same world would wait for itself forever, so it gets RuntimeError instead.
    world = pyramid()
    seen = []

    def trajectory(*arrays):
        try:
            world.step_count  # noqa: B018 (a read from another thread)
        except RuntimeError as error:
            seen.append(str(error))
        return arrays

    monkeypatch.setattr("impulse._trajectory.Trajectory", trajectory)
    world.simulate(3)
    assert len(seen) == 1 and "in use by a call on this same thread" in seen[0]
    # The world is free again once the call returns.
    assert world.step_count == 3
