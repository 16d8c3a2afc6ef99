"""The search for takes: the cross-entropy method over θ, run in batches on the sweep's backends,
written as it goes, resumable.

Why the cross-entropy method (Rubinstein, "The cross-entropy method for combinatorial and
continuous optimization", 1999) rather than Chenney & Forsyth's Markov chain (SIGGRAPH 2000):
each generation is a batch of independent takes, so a process pool or a Ray cluster runs a whole
generation at once, where a chain runs one take after another; and it needs only the goals'
costs, no derivative (a pile's outcome is chaotic: derivatives of where a die rests flip sign
under 1e-6 m/s changes). Each generation draws θ from a normal distribution, ranks the takes
so far (:func:`_ranking`: the goals missed, each weighted by how rarely the takes meet it; then
the total cost; then the perturbation) and moves the distribution's mean and spread toward the
best; half of each refined generation are instead local steps around the best few takes, as
Chenney & Forsyth's chain proposes (:data:`LOCAL_SHARE`). The first generation draws from the
prior N(0, I), the scales' size, and so does the first after a restart
(:data:`STALL_GENERATIONS` without a lower best cost). ``method="random"`` is the baseline the
method is measured against: every take drawn from the prior, nothing refined.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import signal
import threading
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from impulse.takes._goals import (
    MET,
    Goal,
    GoalError,
    Record,
    Shot,
    check_goals,
    check_names,
    goal_from_dict,
)
from impulse.takes._variation import Variation

TAKES_FILE = "takes.parquet"
MANIFEST_FILE = "manifest.json"
SCENE_FILE = "scene.json"
LOCK_FILE = "search.lock"
COMPLETED, STOPPED, FAILED = "completed", "stopped", "failed"
#: Weight of the new elites' mean and spread against the old (the method's smoothing).
SMOOTHING = 0.9
#: Share of each refined generation drawn as local steps around the best takes instead of from
#: the normal distribution (Metropolis-like proposals, as Chenney & Forsyth's chain makes).
LOCAL_SHARE = 0.5
#: Size of a local step: the spread of θ around a best take (unit-free, as θ).
LOCAL_STEP = 0.15
#: How many of the best takes the local steps start from (in turn).
LOCAL_CENTRES = 4
#: Smallest spread of θ per component: the search never collapses to one point.
MIN_SPREAD = 0.02
#: Generations without a lower best cost, and no take meeting every goal, after which the search
#: starts again from the prior, ranking only the takes drawn since (a restart, as for CMA-ES:
#: Auger & Hansen 2005). In a chaotic scene a near miss can sit on a plateau where every nearby
#: take has the same outcome.
STALL_GENERATIONS = 4
_FORMAT = 2  # 2: graded tilt costs, goals ranked by rarity, local steps
#: The search methods: the cross-entropy method, or plain random sampling from the prior.
METHODS = ("cross-entropy", "random")


def _canonical(value: Any) -> str:
    return json.dumps(value, sort_keys=True, separators=(",", ":"), allow_nan=False)


def take_id(digest: str, theta: np.ndarray, scene_seed: int | None = None) -> str:
    """A take's id: 16 hex digits of SHA-256 over the search's digest, θ's exact bits and the
    take's scene seed (when the variation gives takes their own)."""
    hasher = hashlib.sha256(digest.encode())
    hasher.update(np.asarray(theta, dtype="<f8").tobytes())
    if scene_seed is not None:
        hasher.update(int(scene_seed).to_bytes(8, "little"))
    return hasher.hexdigest()[:16]


def load_scene(scene: Any) -> dict[str, Any]:
    """A scene as a dict: a dict as it is, or a JSON file read with its mesh ``file`` paths made
    absolute (so the varied scene can be written anywhere).

    Raises
    ------
    ValueError
        A name that is not a file (built-in scenes: write one out with ``impulse export``
        first), or a file that is not a JSON object.
    """
    if isinstance(scene, Mapping):
        return json.loads(json.dumps(scene))
    path = os.fspath(scene)
    if not os.path.isfile(path):
        raise ValueError(
            f"scene {path!r}: not a file (for a built-in scene, write it out first: "
            f"impulse export {path} --out {path}.json)"
        )
    with open(path, encoding="utf-8") as file:
        value = json.load(file)
    if not isinstance(value, dict):
        raise ValueError(f"scene {path}: a scene is a JSON object")
    base = os.path.dirname(os.path.abspath(path))

    def absolute(node: Any) -> Any:
        if isinstance(node, dict):
            return {
                key: (
                    os.path.join(base, item)
                    if key == "file" and isinstance(item, str) and not os.path.isabs(item)
                    else absolute(item)
                )
                for key, item in node.items()
            }
        if isinstance(node, list):
            return [absolute(item) for item in node]
        return node

    return absolute(value)


def _goal_payload(goals: Sequence[Goal]) -> list[dict[str, Any]]:
    """Goals as the workers receive them: a JSON goal by its spec, a custom one as its name,
    weight and pickled function."""
    from impulse.sweep import _pickle_observe

    payload = []
    for goal in goals:
        if goal.spec is not None:
            payload.append({"spec": goal.spec})
        else:
            function = _pickle_observe(
                goal._cost, f"custom goal {goal.name!r}", "a callable taking a Record"
            )
            payload.append({"name": goal.name, "weight": goal.weight, "function": function})
    return payload


def _goals_from_payload(payload: Sequence[Mapping[str, Any]]) -> list[Goal]:
    import pickle

    return [
        goal_from_dict(item["spec"])
        if "spec" in item
        else Goal(item["name"], pickle.loads(item["function"]), item["weight"], needs_contacts=True)
        for item in payload
    ]


def as_goals(goals: Sequence[Goal | Mapping[str, Any]]) -> list[Goal]:
    """Goals given as :class:`Goal` or JSON objects, as :class:`Goal`.

    Raises
    ------
    ValueError
        No goals, two with one name, or a bad JSON goal: ``goals[k].field: what is wrong``.
    """
    if isinstance(goals, (str, bytes, Mapping)) or not isinstance(goals, Sequence):
        raise ValueError("goals: expected a list of goals (JSON objects or impulse.takes.custom)")
    out = []
    for k, goal in enumerate(goals):
        if isinstance(goal, Goal):
            out.append(goal)
            continue
        try:
            out.append(goal_from_dict(goal))
        except GoalError as error:
            raise ValueError(f"goals[{k}].{error.field}: {error.message}") from None
    if not out:
        raise ValueError("goals: at least one goal is needed")
    check_names(out)
    return out


def _goal_identity(goal: Goal) -> dict[str, Any]:
    """A goal as the search's digest and manifest hold it: a JSON goal's spec, a custom goal's
    name and the identity of its function's code."""
    if goal.spec is not None:
        return goal.spec
    return {"custom": goal.name, "code": goal.code}


def simulate_take(
    scene: Mapping[str, Any], steps: int, goals: Sequence[Goal], preset: str | None = None
) -> tuple[Record, str, str | None]:
    """Runs a varied scene ``steps`` steps and records what the goals read.

    Returns the :class:`Record`, the status (``completed``, or ``stopped`` when a step failed:
    the record then ends at the last good step) and the step's error.
    """
    import impulse

    os.environ.setdefault("RAYON_NUM_THREADS", "1")
    world = impulse.World.from_scene(dict(scene), settings=preset)
    contacts = any(goal.needs_contacts for goal in goals)
    frames: dict[str, list] = {key: [] for key in ("t", "p", "q", "v", "w")}
    touching: list[set] = []
    current: set = set()

    def record() -> None:
        state = world.state()
        frames["t"].append(state["time"])
        frames["p"].append(state["positions"])
        frames["q"].append(state["orientations"])
        frames["v"].append(state["linear_velocities"])
        frames["w"].append(state["angular_velocities"])
        touching.append(set(current))

    status, error = COMPLETED, None
    record()
    for _ in range(steps):
        try:
            world.step()
        except impulse.StepError as failure:
            status, error = STOPPED, f"{type(failure).__name__}: {failure}"
            break
        if contacts:
            for event in world.contact_events():
                a, b = world.index_of(event["body1"]), world.index_of(event["body2"])
                pair = (min(a, b), max(a, b))
                if event["type"] == "started":
                    current.add(pair)
                else:
                    current.discard(pair)
        record()
    return (
        Record(
            times=np.asarray(frames["t"], dtype=np.float64),
            positions=np.stack(frames["p"]).astype(np.float64),
            orientations=np.stack(frames["q"]).astype(np.float64),
            linear_velocities=np.stack(frames["v"]).astype(np.float64),
            angular_velocities=np.stack(frames["w"]).astype(np.float64),
            touching=touching,
            names=list(world.names),
            gravity=np.asarray(world.gravity, dtype=np.float64),
            dt=float(world.dt),
        ),
        status,
        error,
    )


def _run_take(task: dict[str, Any]) -> dict[str, Any]:
    """One take in a worker: its row. Never raises: a failure is the row's status."""
    start = time.perf_counter()
    row: dict[str, Any] = {"take_id": task["key"], "status": FAILED, "error": None}
    try:
        goals = _goals_from_payload(task["goals"])
        record, status, error = simulate_take(task["scene"], task["steps"], goals, task["preset"])
        row["status"], row["error"] = status, error
        row["costs"] = [goal.cost(record) for goal in goals]
    except Exception as failure:
        row["status"] = FAILED
        row["error"] = f"{type(failure).__name__}: {failure}"
    row["wall_time_s"] = time.perf_counter() - start
    return row


class _Store:
    """The search's directory: the manifest, the authored scene and the takes table, held
    under an exclusive lock (``search.lock``, ``fcntl.flock``) from opening to :meth:`close`,
    so a second search into the same directory is refused instead of losing takes."""

    def __init__(self, out: str | os.PathLike, manifest: dict[str, Any], scene: dict[str, Any]):
        self.root = os.path.abspath(os.fspath(out))
        self.manifest = manifest
        self.scene = scene
        self.created = not os.path.exists(self.root)
        if not self.created and not os.path.isdir(self.root):
            raise ValueError(f"out {self.root}: not a directory")
        os.makedirs(self.root, exist_ok=True)
        self.lock = _lock(self.root)
        try:
            self._read()
        except BaseException:
            self.close(written=False)
            raise

    def _read(self) -> None:
        manifest = self.manifest
        path = os.path.join(self.root, MANIFEST_FILE)
        if os.path.exists(path):
            with open(path, encoding="utf-8") as file:
                old = json.load(file)
            if old.get("format") != manifest["format"]:
                raise ValueError(
                    f"{self.root} holds a search made by another version of impulse.takes "
                    f"(search format {old.get('format')}, this version writes "
                    f"{manifest['format']}), which would continue differently: its takes still "
                    "load with impulse.takes.load; to search, choose another out directory or "
                    "remove it"
                )
            if old.get("digest") != manifest["digest"]:
                raise ValueError(
                    f"{self.root} holds a search of another scene, goals, variation or "
                    f"settings{_changed_code(old.get('goals'), manifest['goals'])}: choose "
                    "another out directory, or remove it to start again"
                )
        self.rows: dict[str, dict[str, Any]] = {}
        table_path = os.path.join(self.root, TAKES_FILE)
        if os.path.exists(table_path):
            import pyarrow.parquet as pq

            for row in pq.read_table(table_path).to_pylist():
                self.rows[row["take_id"]] = row

    def write(self) -> None:
        """Writes the scene, the table and the manifest, each whole (a temporary file replaced
        in one rename), the manifest last: a directory with a manifest has a table."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        _write_json(os.path.join(self.root, SCENE_FILE), self.scene)
        rows = sorted(self.rows.values(), key=lambda row: (row["generation"], row["index"]))
        names = self.manifest["goal_names"]
        columns: dict[str, Any] = {
            "take_id": pa.array([r["take_id"] for r in rows], pa.string()),
            "generation": pa.array([r["generation"] for r in rows], pa.int32()),
            "index": pa.array([r["index"] for r in rows], pa.int32()),
            "status": pa.array([r["status"] for r in rows], pa.string()),
            "error": pa.array([r.get("error") for r in rows], pa.string()),
            "met": pa.array([r["met"] for r in rows], pa.bool_()),
            "cost": pa.array([r["cost"] for r in rows], pa.float64()),
            "perturbation": pa.array([r["perturbation"] for r in rows], pa.float64()),
        }
        for name in names:
            columns[f"cost.{name}"] = pa.array([r.get(f"cost.{name}") for r in rows], pa.float64())
        columns["theta"] = pa.array([r["theta"] for r in rows], pa.list_(pa.float64()))
        columns["scene_seed"] = pa.array([r.get("scene_seed") for r in rows], pa.uint64())
        columns["wall_time_s"] = pa.array([r.get("wall_time_s") for r in rows], pa.float64())
        temporary = os.path.join(self.root, TAKES_FILE + ".partial")
        pq.write_table(pa.table(columns), temporary)
        os.replace(temporary, os.path.join(self.root, TAKES_FILE))
        _write_json(os.path.join(self.root, MANIFEST_FILE), self.manifest)

    def close(self, written: bool = True) -> None:
        """Releases the lock. ``written=False`` (the search ended before writing anything):
        a directory this search created is removed again."""
        if self.lock is not None:
            self.lock.close()  # closing the file releases its flock
            self.lock = None
        if not written and self.created:
            try:
                os.remove(os.path.join(self.root, LOCK_FILE))
                os.rmdir(self.root)
            except OSError:
                pass


def _write_json(path: str, value: Any) -> None:
    temporary = path + ".partial"
    with open(temporary, "w", encoding="utf-8") as file:
        json.dump(value, file, indent=1)
    os.replace(temporary, path)


def _lock(root: str) -> Any:
    """An exclusive, non-blocking lock on ``root/search.lock``: the open file holding it (the
    lock lasts until the file is closed or the process ends, however it ends). Where
    ``fcntl`` does not exist (Windows), no lock: ``None``.

    Raises
    ------
    RuntimeError
        Another search holds the lock.
    """
    try:
        import fcntl
    except ImportError:
        return None
    path = os.path.join(root, LOCK_FILE)
    file = open(path, "a+", encoding="utf-8")  # noqa: SIM115 - held open: it is the lock
    try:
        fcntl.flock(file.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        file.close()
        raise RuntimeError(
            f"{root} is in use by another search (it holds {path}): wait for that search to "
            "end, or choose another out directory"
        ) from None
    return file


def _changed_code(old: Any, new: Sequence[Mapping[str, Any]]) -> str:
    """`` (custom goal 'x' ...)`` when the only difference a message can name is a custom
    goal's function, else ``""``."""
    if not isinstance(old, list):
        return ""
    old_code = {g.get("custom"): g.get("code") for g in old if isinstance(g, dict) and "custom" in g}
    for goal in new:
        name = goal.get("custom")
        if name in old_code and old_code[name] != goal.get("code"):
            return (
                f" (custom goal {name!r}: its function's code is not the one this directory "
                "was searched with)"
            )
    return ""


def _rank(row: Mapping[str, Any]) -> tuple[float, float]:
    cost = row["cost"]
    return (math.inf if cost is None or not math.isfinite(cost) else cost, row["perturbation"])


def _ranking(
    pool: Sequence[Mapping[str, Any]],
    goals: Sequence[Goal],
    origin: np.ndarray | None = None,
):
    """The key the search ranks ``pool``'s takes by, best first: the goals each take misses,
    each weighted by its ``weight`` times how rarely the pool's takes meet it, (n + 1) / (m + 1)
    for n completed takes of which m meet it; then the total cost; then the perturbation, or
    with ``origin`` (a refinement's θ) the root mean square of θ − ``origin``.

    A goal nearly every take meets weighs about 1, one that few meet weighs up to n + 1, so a
    take that meets the rare goals ranks above one that only lowers the common goals' costs (in
    the bowling shot: a take leaving the 7 and the 10 standing with two other pins up ranks
    above a strike that leaves only the 10). Takes that did not complete rank last.
    """
    names = [f"cost.{goal.name}" for goal in goals]
    completed = [row for row in pool if row["cost"] is not None]
    weights = [
        goal.weight * (len(completed) + 1) / (sum(row[name] <= MET for row in completed) + 1)
        for goal, name in zip(goals, names, strict=True)
    ]

    def distance(row: Mapping[str, Any]) -> float:
        if origin is None:
            return row["perturbation"]
        return Variation.perturbation(np.asarray(row["theta"]) - origin)

    def key(row: Mapping[str, Any]) -> tuple[float, float, float]:
        cost = row["cost"]
        if cost is None or not math.isfinite(cost):
            return (math.inf, math.inf, distance(row))
        missed = sum(w for w, name in zip(weights, names, strict=True) if row[name] > MET)
        return (missed, cost, distance(row))

    return key


def search(
    scene: Any,
    goals: Sequence[Goal | Mapping[str, Any]],
    variation: Variation | Mapping[str, Any],
    *,
    budget: int,
    steps: int,
    out: str | os.PathLike = "takes",
    backend: str = "local",
    workers: int | None = None,
    address: str | None = None,
    seed: int = 0,
    population: int = 32,
    elite_fraction: float = 0.2,
    stop_after: int = 1,
    method: str = "cross-entropy",
    preset: str | None = None,
    progress: bool = True,
    around: Mapping[str, Any] | None = None,
) -> Takes:
    """Searches for takes of ``scene`` that meet every goal and returns them all (also written
    to ``out``).

    Parameters
    ----------
    scene : str | os.PathLike | dict
        A scene file or dict (built-in names: write the scene out with ``impulse export``).
    goals : list of Goal | dict
        Goals as JSON objects (``impulse.takes`` module documentation) or :class:`Goal` (from
        :func:`custom`). Must be non-empty.
    variation : Variation | dict
        What may vary and by how much (:class:`Variation`).
    budget : int
        Most takes to run (>= 1), resumed takes included.
    steps : int
        Steps of every take (>= 1).
    out : str | os.PathLike
        Directory of the results: ``takes.parquet`` (one row per take), ``manifest.json``,
        ``scene.json`` (the authored scene). Running again into it resumes: takes already run
        are read, not run, and the search continues as it would have.
    backend : "local" | "ray"
        The sweep's backends: a process pool (call ``search`` under ``if __name__ ==
        "__main__":`` in a script) or Ray tasks.
    workers, address
        As in :func:`impulse.sweep.sweep`.
    seed : int
        Seed of the search's draws (NumPy's PCG64, one stream per generation).
    population : int
        Takes per generation (>= 2).
    elite_fraction : float
        Share of the takes so far that move the distribution, in (0, 1].
    stop_after : int
        Stop once this many takes meet every goal (>= 1).
    method : "cross-entropy" | "random"
        The cross-entropy method (this module's documentation), or plain random sampling: every
        take's θ drawn from the prior N(0, I) and its scene seed fresh, nothing refined (the
        baseline the method is measured against; the same draws per generation and ``seed``).
    preset : str, optional
        Solver preset of every take, as ``impulse run --preset``.
    progress : bool
        A progress bar (tqdm): takes done, goals met, best cost.
    around : dict, optional
        ``{"theta": θ, "spread": s, "scene_seed": seed or None, "adapt": bool}``: search
        around one take (:func:`refine`). With ``adapt`` true, a trust region: every
        generation draws θ from N(θ, s_g² I) in the take's rough world, s_g adapted as
        :func:`refine` says; else the first generation, and the first after a restart, draw θ from
        N(θ, s² I) instead of the prior N(0, I), local steps and the least spread are s (not
        ``LOCAL_STEP`` and ``MIN_SPREAD``) when s is smaller, takes tied on the goals rank by
        their distance from θ (not their perturbation), and with ``Variation.seeds`` the
        take's seed is the first one reused.

    Returns
    -------
    Takes
        Every take run, best first by :meth:`Takes.best`.

    Raises
    ------
    ValueError
        Bad arguments, goals or variation; a scene that does not load; an ``out`` holding
        another search.
    TypeError
        A custom goal that cannot be sent to the workers (define it at module level, or
        install cloudpickle).
    RuntimeError
        The local backend's workers cannot start: the call is at the top level of a script,
        not under ``if __name__ == "__main__":``, or of a script read from standard input;
        another search holds ``out``'s lock; every take of the first generation failed (a
        custom goal that raises, say: the first error is named, the takes are written).
    """
    import impulse

    _check_integer("budget", budget, 1)
    _check_integer("steps", steps, 1)
    _check_integer("population", population, 2)
    _check_integer("stop_after", stop_after, 1)
    _check_integer("seed", seed, 0)
    if workers is not None:
        _check_integer("workers", workers, 1)
    if isinstance(elite_fraction, bool) or not 0.0 < elite_fraction <= 1.0:
        raise ValueError(f"elite_fraction = {elite_fraction!r}: must be in (0, 1]")
    if method not in METHODS:
        raise ValueError(f"method = {method!r}: use one of {', '.join(METHODS)}")
    if backend not in ("local", "ray"):
        raise ValueError(f"backend = {backend!r}: use 'local' or 'ray'")
    base = load_scene(scene)
    if not isinstance(variation, Variation):
        variation = Variation.from_dict(variation)
    goals = as_goals(goals)
    dimension = variation.dimension(base)
    start_mean, start_spread, start_seeds = np.zeros(dimension), np.ones(dimension), []
    local_step, min_spread = LOCAL_STEP, MIN_SPREAD
    origin = None  # what the ranking's last key measures the distance from (None: θ = 0)
    adapt = False  # a trust region around a take meeting every goal (refine)
    if around is not None:
        start_mean, spread_value, around_seed, adapt = _around(around, dimension)
        adapt = adapt and dimension > 0  # no θ (seeds alone): nothing for a step to vary
        start_spread = np.full(dimension, spread_value)
        local_step = min(LOCAL_STEP, spread_value)
        min_spread = min(MIN_SPREAD, spread_value)
        start_seeds = [around_seed] if around_seed is not None else []
        origin = start_mean
    world = impulse.World.from_scene(base, settings=preset)  # a bad scene is one error, here
    check_goals(goals, Shot(world.names, world.dt, steps, world.gravity))
    if backend == "local":
        from impulse.sweep import _check_workers_can_start

        _check_workers_can_start("impulse.takes.search")
    payload = _goal_payload(goals)

    search_spec = {
        "format": _FORMAT,
        "scene": base,
        "goals": [_goal_identity(goal) for goal in goals],
        "weights": [goal.weight for goal in goals],
        "variation": variation.to_dict(),
        "steps": steps,
        "preset": preset,
        "seed": seed,
        "population": population,
        "elite_fraction": elite_fraction,
        "method": method,
    }
    if around is not None:  # only then: the digests of searches from the prior are unchanged
        search_spec["around"] = {
            "theta": start_mean.tolist(),
            "spread": float(start_spread[0]) if dimension else 0.0,
            "scene_seed": start_seeds[0] if start_seeds else None,
        }
        if adapt:  # only then: the digests of earlier refinements are unchanged
            search_spec["around"]["adapt"] = True
    digest = hashlib.sha256(_canonical(search_spec).encode()).hexdigest()
    manifest = {
        "digest": digest,
        "goal_names": [goal.name for goal in goals],
        "impulse": getattr(impulse, "__version__", "unknown"),
        "dt": float(world.dt),
        **{key: value for key, value in search_spec.items() if key != "scene"},
    }
    store = _Store(out, manifest, base)  # locked until closed
    try:
        runner = _backend(backend, workers, address)
    except BaseException:
        store.close(written=False)
        raise
    bar = _Progress(budget, progress)
    mean, spread = start_mean.copy(), start_spread.copy()
    largest_step = step = float(start_spread[0]) if dimension else 0.0  # with adapt
    elites = max(2, round(elite_fraction * population))
    done: list[dict[str, Any]] = []
    elite_seeds: list[int | None] = list(start_seeds)
    local_centres: list[np.ndarray] = []  # the best takes' θ, which local steps start from
    generation = 0
    since, best_cost, stalled = 0, math.inf, 0  # the current start's first take, its best cost
    met = 0
    stop = interrupted = False
    try:
        with _terminate_as_interrupt():
            while len(done) < budget and met < stop_after:
                rng = np.random.default_rng([seed, generation])
                count = min(population, budget - len(done))
                normal = rng.standard_normal((population, dimension))
                thetas = mean + spread * normal
                if local_centres:  # the generation's last share: steps around the best takes
                    for k in range(population - round(LOCAL_SHARE * population), population):
                        thetas[k] = local_centres[k % len(local_centres)] + local_step * normal[k]
                seeds = _scene_seeds(rng, population, variation.seeds, elite_seeds)
                if adapt:
                    # The trust region: every take is the refined take's θ plus the current
                    # step times N(0, I), in the take's own rough world: the takes stay
                    # around the take the animator chose.
                    thetas = start_mean + step * normal
                    if start_seeds:
                        seeds = [start_seeds[0]] * population
                # The generation's rows in draw order: stored ones read, the others run.
                slots: list[dict[str, Any] | None] = [None] * count
                tasks, by_key = [], {}
                for index in range(count):
                    theta, scene_seed = thetas[index], seeds[index]
                    key = take_id(digest, theta, scene_seed)
                    row = store.rows.get(key)
                    if row is not None and row["status"] != FAILED:
                        slots[index] = row
                        continue
                    if key in by_key:  # the same θ and seed drawn twice: one run, two slots
                        by_key[key][3].append(index)
                        continue
                    by_key[key] = (index, theta, scene_seed, [index])
                    tasks.append(
                        {
                            "key": key,
                            "scene": variation.apply(base, theta, scene_seed, steps, world.dt),
                            "steps": steps,
                            "preset": preset,
                            "goals": payload,
                        }
                    )
                cursor = 0  # slots[:cursor] are counted in `done`
                ran: list[str] = []
                cursor, met, stop = _advance(slots, cursor, done, bar, met, stop_after)
                if not stop:
                    for result in runner.run(tasks):
                        # A task the pool could not run comes back as the sweep's failed row.
                        result.setdefault("take_id", result.get("run_key"))
                        index, theta, scene_seed, indices = by_key[result["take_id"]]
                        row = _row(result, goals, generation, index, theta)
                        row["scene_seed"] = scene_seed
                        store.rows[row["take_id"]] = row
                        ran.append(row["take_id"])
                        for place in indices:
                            slots[place] = row
                        cursor, met, stop = _advance(slots, cursor, done, bar, met, stop_after)
                        if stop:
                            break
                if stop:
                    # Takes drawn after the one that met the goals `stop_after` times are not
                    # part of the search: those run anyway (in flight) are dropped, so the
                    # table does not depend on which worker finished first.
                    for key in ran:
                        if store.rows[key]["index"] >= cursor:
                            del store.rows[key]
                store.write()
                if stop:
                    break
                if generation == 0 and all(row is not None and row["status"] == FAILED
                                           for row in slots):
                    # Nothing ran: a goal that raises, a worker that cannot import what it
                    # needs. The rest of the budget would fail the same way.
                    raise RuntimeError(
                        f"every take of the first generation failed ({count} of {count}), the "
                        f"first with: {slots[0]['error'] if slots else None}; the takes are in "
                        f"{os.path.join(store.root, TAKES_FILE)}"
                    )
                generation += 1
                if adapt:
                    step = _adapted_step(step, slots, largest_step)
                    continue
                if method == "random":
                    continue
                pool = [row for row in done[since:] if row["status"] != FAILED]
                ranked = sorted(pool, key=_ranking(pool, goals, origin))
                lowest = _rank(ranked[0])[0] if ranked else math.inf  # the best take's cost
                if lowest < best_cost:
                    best_cost, stalled = lowest, 0
                elif not any(row["met"] for row in ranked):  # never restart away from a success
                    stalled += 1
                if stalled >= STALL_GENERATIONS:
                    mean, spread = start_mean.copy(), start_spread.copy()
                    since, best_cost, stalled = len(done), math.inf, 0
                    elite_seeds = list(start_seeds)
                    local_centres = []
                    continue
                best = np.array([row["theta"] for row in ranked[:elites]])
                local_centres = [np.asarray(row["theta"]) for row in ranked[:LOCAL_CENTRES]]
                elite_seeds = [row.get("scene_seed") for row in ranked[:elites]]
                if len(best) >= 2:
                    mean = SMOOTHING * best.mean(axis=0) + (1.0 - SMOOTHING) * mean
                    spread = SMOOTHING * best.std(axis=0) + (1.0 - SMOOTHING) * spread
                    spread = np.maximum(spread, min_spread)
    except KeyboardInterrupt:
        interrupted = True
        raise
    finally:
        # Interrupted (Ctrl-C, SIGTERM) or done (stop_after met): the takes in flight are
        # abandoned and their workers ended; the takes finished so far are written.
        runner.close(cancel=stop or interrupted)
        bar.close()
        store.write()
        store.close()
    return load(store.root)


def _around(
    around: Mapping[str, Any], dimension: int
) -> tuple[np.ndarray, float, int | None, bool]:
    """``search``'s ``around``, checked: θ (its dimension), the spread, the scene seed and
    whether the spread adapts (a trust region, :func:`_adapted_step`)."""
    unknown = set(around) - {"theta", "spread", "scene_seed", "adapt"}
    if unknown:
        raise ValueError(
            f"around has unknown keys {sorted(unknown)}: use theta, spread, scene_seed, adapt"
        )
    theta = np.asarray(around.get("theta", []), dtype=np.float64)
    if theta.shape != (dimension,) or not np.all(np.isfinite(theta)):
        raise ValueError(
            f"around theta: {dimension} finite values needed (the variation's θ), got shape "
            f"{theta.shape}"
        )
    spread = around.get("spread")
    if isinstance(spread, bool) or not isinstance(spread, (int, float)) or not spread > 0.0:
        raise ValueError(f"around spread = {spread!r}: must be a number > 0 (unit-free, as θ)")
    if not math.isfinite(spread):
        raise ValueError(f"around spread = {spread!r}: must be finite")
    scene_seed = around.get("scene_seed")
    if scene_seed is not None:
        _check_integer("around scene_seed", scene_seed, 0)
        scene_seed = int(scene_seed)
    adapt = around.get("adapt", False)
    if not isinstance(adapt, bool):
        raise ValueError(f"around adapt = {adapt!r}: must be true or false")
    return theta, float(spread), scene_seed, adapt


def _adapted_step(step: float, rows: Sequence[Mapping[str, Any]], largest: float) -> float:
    """The next generation's step of a trust-region refinement from this generation's
    ``rows``: halved (down to ``largest`` times :data:`REFINE_LEAST_STEP`) while fewer than
    half of the takes that ran meet every goal, grown by :data:`REFINE_GROWTH` (up to
    ``largest``) when at least :data:`REFINE_GROW` of them do, else kept. Failed takes (a worker's failure) do not count."""
    ran = [row for row in rows if row["status"] != FAILED]
    if not ran:
        return step
    share = sum(bool(row["met"]) for row in ran) / len(ran)
    if share < 0.5:
        return max(0.5 * step, REFINE_LEAST_STEP * largest)
    if share >= REFINE_GROW:
        return min(REFINE_GROWTH * step, largest)
    return step


def _advance(
    slots: list[dict[str, Any] | None],
    cursor: int,
    done: list[dict[str, Any]],
    bar: _Progress,
    met: int,
    stop_after: int,
) -> tuple[int, int, bool]:
    """Counts a generation's rows in draw order however they finish: from ``slots[cursor]``,
    each row known (not None) is appended to ``done``; stops at the first gap, or at the row
    that makes ``stop_after`` takes meeting every goal (the search ends there, exactly).
    Returns the new cursor, the count of met takes and whether to stop."""
    while cursor < len(slots) and slots[cursor] is not None:
        row = slots[cursor]
        cursor += 1
        done.append(row)
        bar.update(row)
        met += bool(row["met"])
        if met >= stop_after:
            return cursor, met, True
    return cursor, met, False


def _check_integer(name: str, value: Any, least: int) -> None:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < least:
        raise ValueError(f"{name} = {value!r}: must be an integer >= {least}")


class Terminated(KeyboardInterrupt):
    """The search was ended by SIGTERM (a render farm's or a scheduler's kill), handled as
    Ctrl-C is: the takes finished so far are written, the workers ended."""


@contextlib.contextmanager
def _terminate_as_interrupt():
    """Within it, SIGTERM raises :class:`Terminated` in the main thread (when SIGTERM has its
    default action there: a handler the program set is kept)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    if signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL:
        yield
        return

    def terminated(signum: int, frame: Any) -> None:
        raise Terminated(f"signal {signum} (SIGTERM)")

    signal.signal(signal.SIGTERM, terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _scene_seeds(
    rng: np.random.Generator, count: int, enabled: bool, elite_seeds: Sequence[int | None]
) -> list[int | None]:
    """Each take's scene seed: ``None`` without ``Variation.seeds``; else, drawn in order, one of
    the best takes' seeds (half the time, once there are some: refining around a good rough
    world) or a fresh seed in [1, 2⁶³). Drawn whether or not they are used, so the draws of θ
    never depend on ``seeds``."""
    reuse = rng.random(count)
    pick = rng.integers(0, max(1, len(elite_seeds)), count)
    fresh = rng.integers(1, 2**63, count)
    if not enabled:
        return [None] * count
    known = [s for s in elite_seeds if s is not None]
    return [
        int(known[p % len(known)]) if known and r < 0.5 else int(f)
        for r, p, f in zip(reuse, pick, fresh, strict=True)
    ]


def _row(
    result: Mapping[str, Any],
    goals: Sequence[Goal],
    generation: int,
    index: int,
    theta: np.ndarray,
) -> dict[str, Any]:
    row = {
        "take_id": result["take_id"],
        "generation": generation,
        "index": index,
        "status": result["status"],
        "error": result.get("error"),
        "theta": [float(v) for v in theta],
        "perturbation": Variation.perturbation(theta),
        "wall_time_s": result.get("wall_time_s"),
    }
    costs = result.get("costs")
    if costs is None or result["status"] != COMPLETED:
        row.update(met=False, cost=None)
        for goal in goals:
            row[f"cost.{goal.name}"] = None
        return row
    for goal, cost in zip(goals, costs, strict=True):
        row[f"cost.{goal.name}"] = float(cost)
    row["cost"] = float(sum(goal.weight * cost for goal, cost in zip(goals, costs, strict=True)))
    row["met"] = all(cost <= MET for cost in costs)
    return row


def _backend(backend: str, workers: int | None, address: str | None) -> Any:
    from impulse.sweep._backends import _LocalBackend, _RayBackend

    if backend == "ray":
        return _RayBackend(workers, address, function=_run_take)
    return _LocalBackend(workers or os.cpu_count() or 1, function=_run_take)


class _Progress:
    def __init__(self, total: int, enabled: bool):
        self.bar = None
        self.met = 0
        self.best = math.inf
        if enabled:
            try:
                from tqdm.auto import tqdm

                self.bar = tqdm(total=total, unit="take", desc="takes")
            except ImportError:
                self.bar = None

    def update(self, row: Mapping[str, Any]) -> None:
        self.met += bool(row["met"])
        if row["cost"] is not None:
            self.best = min(self.best, row["cost"])
        if self.bar is not None:
            self.bar.update(1)
            self.bar.set_postfix(met=self.met, best=f"{self.best:.3g}")

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


class Take:
    """One take of a search: its θ, costs and the varied scene.

    Attributes: ``take_id`` (str), ``theta`` (ndarray, unit-free), ``scene_seed`` (the take's
    scene seed, or None when the variation keeps the scene's), ``met`` (bool: every goal
    met), ``cost`` (weighted total, None when the take did not complete), ``costs`` (goal name
    → cost), ``perturbation`` (size of θ; smaller is more plausible), ``status``, ``error``.
    """

    def __init__(self, row: Mapping[str, Any], takes: Takes):
        self.take_id = row["take_id"]
        self.theta = np.asarray(row["theta"], dtype=np.float64)
        self.scene_seed = row.get("scene_seed")
        self.met = bool(row["met"])
        self.cost = row["cost"]
        self.costs = {name: row.get(f"cost.{name}") for name in takes.goal_names}
        self.perturbation = row["perturbation"]
        self.status = row["status"]
        self.error = row.get("error")
        self._takes = takes

    def scene(self) -> dict[str, Any]:
        """The varied scene (a dict as in a scene file) with the search's ``steps`` and ``dt``:
        ``impulse run`` of it written to a file reproduces the take's trajectory to the bit,
        and ``impulse render`` and the exports draw the take's length."""
        manifest = self._takes.manifest
        return self._takes.variation.apply(
            self._takes.base_scene,
            self.theta,
            self.scene_seed,
            manifest.get("steps"),
            manifest.get("dt"),
        )

    def write_scene(self, path: str | os.PathLike) -> None:
        """Writes :meth:`scene` as JSON to ``path``."""
        with open(path, "w", encoding="utf-8") as file:
            json.dump(self.scene(), file, indent=1)

    def __repr__(self) -> str:
        return (
            f"Take({self.take_id!r}, met={self.met}, cost={self.cost}, "
            f"perturbation={self.perturbation:.3g})"
        )


class Takes(Mapping):
    """The takes of a search directory, by id (``takes[take_id]`` is a :class:`Take`);
    ``table`` is the ``pyarrow.Table`` of ``takes.parquet``."""

    def __init__(self, root: str):
        import pyarrow.parquet as pq

        self.root = root
        with open(os.path.join(root, MANIFEST_FILE), encoding="utf-8") as file:
            self.manifest = json.load(file)
        with open(os.path.join(root, SCENE_FILE), encoding="utf-8") as file:
            self.base_scene = json.load(file)
        self.variation = Variation.from_dict(self.manifest["variation"])
        self.goal_names = list(self.manifest["goal_names"])
        self.table = pq.read_table(os.path.join(root, TAKES_FILE))
        self._takes = {row["take_id"]: Take(row, self) for row in self.table.to_pylist()}

    def __getitem__(self, key: str) -> Take:
        try:
            return self._takes[key]
        except KeyError:
            raise KeyError(f"no take {key!r} in {self.root}") from None

    def __iter__(self):
        return iter(self._takes)

    def __len__(self) -> int:
        return len(self._takes)

    def best(self, count: int | None = None) -> list[Take]:
        """Takes best first: those meeting every goal, then by total cost, then by perturbation
        (the more plausible first); failed takes last."""
        order = sorted(
            self._takes.values(),
            key=lambda take: (
                not take.met,
                math.inf if take.cost is None else take.cost,
                take.perturbation,
            ),
        )
        return order if count is None else order[:count]

    def met(self) -> list[Take]:
        """The takes that meet every goal, most plausible first."""
        return sorted((t for t in self._takes.values() if t.met), key=lambda t: t.perturbation)

    def trust_region_steps(self) -> list[float] | None:
        """The step (unit-free, as θ) each generation of a trust-region refinement
        (:func:`refine` around a take meeting every goal) was drawn with, first generation
        first: what the refinement derives from its table as it runs. None for any other
        search."""
        around = self.manifest.get("around") or {}
        if not around.get("adapt"):
            return None
        generations: dict[int, list[dict[str, Any]]] = {}
        for row in self.table.to_pylist():
            generations.setdefault(row["generation"], []).append(row)
        largest = float(around["spread"])
        steps = [largest]
        for generation in sorted(generations)[:-1]:
            steps.append(_adapted_step(steps[-1], generations[generation], largest))
        return steps[: len(generations)]


def load(out: str | os.PathLike) -> Takes:
    """The takes a search wrote to ``out``.

    Raises
    ------
    FileNotFoundError
        ``out`` holds no search.
    """
    root = os.path.abspath(os.fspath(out))
    if not os.path.exists(os.path.join(root, TAKES_FILE)):
        raise FileNotFoundError(f"{root}: no {TAKES_FILE} (not a takes search directory)")
    return Takes(root)


#: Spread of θ around the take a refinement starts from (unit-free, as θ): in the bowling
#: shot, takes drawn this close to a split are splits about half the time (docs/takes.md).
REFINE_STEP = 0.002
#: Takes per generation of a refinement: its step adapts once a generation, so small ones
#: adapt it often within a budget of a few dozen takes.
REFINE_POPULATION = 8
#: The least step of a trust-region refinement, as a share of the step it starts from.
REFINE_LEAST_STEP = 1.0 / 1024.0
#: Share of a generation meeting every goal at which a trust-region refinement grows its
#: step (back up to the step it started from), and by how much: by less than a halving
#: undoes, so that a step just small enough is not left again at once (with a factor of 2
#: the dice refinement at step 0.005 swings between 0.005 and 0.0025 every generation).
REFINE_GROW = 0.75
REFINE_GROWTH = math.sqrt(2.0)


def refine(
    directory: str | os.PathLike,
    take_id: str,
    *,
    budget: int,
    out: str | os.PathLike | None = None,
    step: float = REFINE_STEP,
    goals: Sequence[Goal | Mapping[str, Any]] | None = None,
    backend: str = "local",
    workers: int | None = None,
    address: str | None = None,
    seed: int = 0,
    population: int | None = None,
    stop_after: int | None = None,
    progress: bool = True,
) -> Takes:
    """Searches around one take of a search (Twigg & James's browse-and-refine): the same
    scene, goals, variation, steps, preset and elite fraction, the first generation drawn
    from N(θ, step² I) around the take's θ.

    Around a take that meets every goal, the refinement is a trust region: every generation
    is drawn from N(θ, s² I) around the take, in the take's own rough world under
    ``Variation.seeds``, s starting at ``step``; s is halved (down to ``step`` times
    :data:`REFINE_LEAST_STEP`) after a generation in which fewer than half the takes meet
    every goal, and grown by :data:`REFINE_GROWTH` (up to ``step``) after one in which at least
    :data:`REFINE_GROW` of them do. So the refined takes stay as varied as the goals allow,
    and mostly meet them. Around a take that misses a goal, the later generations are refined
    as :func:`search` refines (toward the goals, staying near the take), the local steps and
    least spread no larger than ``step``, the take's scene seed reused first under
    ``Variation.seeds``; so is a refinement of a variation with ``seeds`` alone (no θ to
    step).

    Parameters
    ----------
    directory : str | os.PathLike
        A search directory (:func:`search`'s ``out``).
    take_id : str
        The take to refine around.
    budget : int
        Takes to run (>= 1).
    out : str | os.PathLike, optional
        Where the refinement is written; default ``directory/refine/<take_id>``. Resumed as a
        search is.
    step : float
        Spread of θ around the take (> 0, unit-free), the largest of a trust region.
    goals : list, optional
        The search's goals again: needed when it has :func:`custom` goals (a directory holds
        only their names and code identity); they must have the same names.
    backend, workers, address, seed, progress
        As for :func:`search`.
    population : int, optional
        Takes per generation (>= 2); default :data:`REFINE_POPULATION`.
    stop_after : int, optional
        Stop once this many takes meet every goal; default ``budget`` (run every take: a
        refinement gives alternatives to choose from).

    Raises
    ------
    KeyError
        No such take.
    ValueError
        Custom goals not given again, or given with other names; bad arguments as for
        :func:`search`.
    """
    takes = load(directory)
    take = takes[take_id]
    manifest = takes.manifest
    if goals is None:
        specs = manifest["goals"]
        customs = [spec["custom"] for spec in specs if "custom" in spec]
        if customs:
            raise ValueError(
                f"the search has custom goals {customs}: refine it from Python with "
                "impulse.takes.refine(..., goals=[...]) giving its goals again"
            )
        goals = [dict(spec) for spec in specs]
    goals = as_goals(goals)
    if [goal.name for goal in goals] != list(manifest["goal_names"]):
        raise ValueError(
            f"goals {[goal.name for goal in goals]}: a refinement keeps the search's goals, "
            f"{manifest['goal_names']}"
        )
    _check_integer("budget", budget, 1)
    return search(
        takes.base_scene,
        goals,
        takes.variation,
        budget=budget,
        steps=int(manifest["steps"]),
        out=os.path.join(takes.root, "refine", take_id) if out is None else out,
        backend=backend,
        workers=workers,
        address=address,
        seed=seed,
        population=REFINE_POPULATION if population is None else population,
        elite_fraction=float(manifest["elite_fraction"]),
        stop_after=budget if stop_after is None else stop_after,
        preset=manifest.get("preset"),
        progress=progress,
        around={
            "theta": take.theta.tolist(),
            "spread": step,
            "scene_seed": None if take.scene_seed is None else int(take.scene_seed),
            "adapt": take.met,
        },
    )


def evaluate(
    scene: Any, goals: Sequence[Goal | Mapping[str, Any]], steps: int, preset: str | None = None
) -> dict[str, float]:
    """The goals' costs of one run of ``scene`` in this process (goal name → cost): what a
    take's row records, for checking goals on a scene by hand."""
    goals = [g if isinstance(g, Goal) else goal_from_dict(g) for g in goals]
    record, status, error = simulate_take(load_scene(scene), steps, goals, preset)
    if status != COMPLETED:
        raise RuntimeError(f"the run stopped: {error}")
    return {goal.name: goal.cost(record) for goal in goals}
