"""Goals: what a take must reach, each a cost >= 0 that is 0 when met and grows with how far the
take is from meeting it (so a search can tell a near miss from a wide one).

A goal is a JSON object with a ``type`` (the format ``--goals FILE`` reads: a list of them, or
``{"goals": [...]}``), or a :func:`custom` Python callable. Bodies are named by the scene's
``name`` or by index; times are seconds from the start; a body's place is its ``position`` (its
origin, as the scene gives it); regions are ``{"box": {"min": [x, y, z], "max": [x, y, z]}}``
or ``{"sphere": {"center": [x, y, z], "radius": r}}`` (m, world frame).

======================  ===============================================  ========================
type                    fields                                           cost (0 when met)
======================  ===============================================  ========================
``ends_inside``         ``body``, ``region``, ``at`` (s, default: the     distance (m) from the
                        end)                                             region at ``at``
``passes_through``      ``body``, ``region``, ``between`` ([t0, t1] s,   closest approach (m) to
                        default the whole take)                          the region in the window
``stays_inside``        ``body``, ``region``, ``between``                farthest excursion (m)
                                                                         out of the region
``rests_with_axis_up``  ``body``, ``axis`` (body frame, e.g. a die's      angle (rad) beyond the
                        face normal), ``up`` (default against gravity),  tolerance, plus speed
                        ``tolerance_degrees`` (default 10),              (m/s, rad/s) beyond the
                        ``rest_speed`` (m/s and rad/s, default 0.05)     rest speed, at the end
``tilted``              ``body``, ``axis``, ``up``, ``min_degrees``       half the angle short of
                        (default 45): the axis ends at least that far    ``min_degrees`` at the
                        from up (a pin knocked over)                     end plus half the
                                                                         largest angle reached
                                                                         short of it (rad)
``touches``             ``body``, ``other``, ``between``, ``times``      closest approach (m) of
                        (optional: the number of separate contacts,      their positions when
                        e.g. 1 for one bounce)                           they never touch; with
                                                                         ``times``, |contacts -
                                                                         times| plus that
                                                                         approach when none
``never_touches``       ``body``, ``other``, ``between``                 time in contact (s)
======================  ===============================================  ========================

Every goal may carry ``"name"`` (the column of its cost; default ``<type>:<body>``) and
``"weight"`` (default 1; multiplies the cost in the total the search ranks by).

A goal's fields are checked when it is read (:func:`goal_from_dict`) and against the scene and
the takes' length before any take runs (:func:`check_goals`): a wrong one is a
:class:`GoalError` naming the field, reported as ``goals[k].field: what is wrong``.
"""

from __future__ import annotations

import difflib
import hashlib
import inspect
import json
import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

#: Cost at or below which a goal counts as met.
MET = 1e-9

#: The keys of a goals file's top-level object.
FILE_KEYS = ("goals", "steps", "variation")
_TYPES = (
    "ends_inside",
    "passes_through",
    "stays_inside",
    "rests_with_axis_up",
    "tilted",
    "touches",
    "never_touches",
)


class Record:
    """A take's simulated frames, as goals read them: the start and every step.

    Attributes: ``times`` (F,) s; ``positions`` (F, B, 3) m; ``orientations`` (F, B, 4)
    ``[x, y, z, w]``; ``linear_velocities`` (F, B, 3) m/s; ``angular_velocities`` (F, B, 3)
    rad/s; ``touching`` a list of F sets of body index pairs ``(a, b)``, a < b, in contact
    after each frame's step (empty sets when no goal needs contacts); ``names`` (B,);
    ``gravity`` (3,) m/s²; ``dt`` s.
    """

    def __init__(self, **fields: Any):
        self.__dict__.update(fields)

    def body(self, body: str | int) -> int:
        """The index of a body named or numbered as a goal names it.

        Raises
        ------
        ValueError
            No such body.
        """
        if isinstance(body, str):
            if body not in self.names:
                raise ValueError(f"goal: no body named {body!r} in the scene")
            return self.names.index(body)
        index = int(body)
        if not 0 <= index < len(self.names):
            raise ValueError(f"goal: body index {index} is not in the scene")
        return index

    def window(self, between: Sequence[float] | None) -> np.ndarray:
        """The frame indices with ``t0 <= t <= t1`` (every frame without a window)."""
        if between is None:
            return np.arange(len(self.times))
        t0, t1 = float(between[0]), float(between[1])
        eps = 0.5 * self.dt
        frames = np.nonzero((self.times >= t0 - eps) & (self.times <= t1 + eps))[0]
        if frames.size == 0:
            raise ValueError(f"goal: no frame between {t0} s and {t1} s")
        return frames


class Goal:
    """One goal: a name, a weight and ``cost(record) -> float`` (>= 0; 0 when met).

    ``spec`` is the JSON object of a goal from :func:`goal_from_dict` (None for a
    :func:`custom` one, whose ``code`` is then :func:`code_identity` of its function);
    ``check(shot)`` raises :class:`GoalError` when the scene cannot hold the goal.
    """

    def __init__(
        self,
        name: str,
        cost: Callable[[Record], float],
        weight: float = 1.0,
        spec: Mapping[str, Any] | None = None,
        needs_contacts: bool = False,
        check: Callable[[Shot], None] | None = None,
        code: str | None = None,
    ):
        if not math.isfinite(weight) or weight <= 0.0:
            raise ValueError(f"goal {name!r}: weight must be finite and > 0, got {weight}")
        self.name = name
        self.weight = float(weight)
        self.spec = None if spec is None else dict(spec)
        self.needs_contacts = needs_contacts
        self.code = code
        self._cost = cost
        self._check = check

    def cost(self, record: Record) -> float:
        """The goal's cost for a take (>= 0, 0 when met)."""
        value = float(self._cost(record))
        if not value >= 0.0:  # NaN as well
            raise ValueError(f"goal {self.name!r}: cost must be >= 0, got {value}")
        return value

    def check(self, shot: Shot) -> None:
        """Checks the goal against a scene and the takes' length (:class:`Shot`): the bodies it
        names exist, its times are within the take.

        Raises
        ------
        GoalError
            The field that cannot hold, and why.
        """
        if self._check is not None:
            self._check(shot)

    def __repr__(self) -> str:
        return f"Goal({self.name!r})"


def custom(function: Callable[[Record], float], name: str, weight: float = 1.0) -> Goal:
    """A goal from a Python callable ``function(record) -> cost`` (a :class:`Record`; cost >= 0,
    0 when met). The search sends it to its workers by value (cloudpickle, which Ray brings)
    or, without cloudpickle, by reference (then it must be a module-level function the workers
    can import). Its identity in a search directory is its name and :func:`code_identity`:
    changing the function makes another search, which the directory refuses to resume.

    Raises
    ------
    TypeError
        ``function`` is not callable or ``name`` not a non-empty string.
    """
    if not callable(function):
        raise TypeError(f"custom goal {name!r}: {function!r} is not callable (record -> cost)")
    if not isinstance(name, str) or not name:
        raise TypeError(f"custom goal: name {name!r} must be a non-empty string")
    return Goal(name, function, weight, needs_contacts=True, code=code_identity(function))


class GoalError(ValueError):
    """A goal written wrong, or one its scene cannot meet (a body it does not have, a window
    after the take's end): ``field`` names the goal's field (``body``, ``between``,
    ``region.box.min``, ...), ``message`` what is wrong. Its text is ``field: message``;
    :func:`goals_from_json` and :func:`check_goals` put the goal's place in front of it,
    ``goals[k].field: message``."""

    def __init__(self, field: str, message: str):
        super().__init__(f"{field}: {message}")
        self.field = field
        self.message = message


class Shot:
    """What goals are checked against before any take runs: the scene's body ``names`` (B,),
    its step ``dt`` (s), the takes' ``steps`` and ``gravity`` (3,) m/s². ``duration`` is
    ``steps × dt`` (s): the last frame's time."""

    def __init__(self, names: Sequence[str], dt: float, steps: int, gravity: Sequence[float]):
        self.names = list(names)
        self.dt = float(dt)
        self.steps = int(steps)
        self.gravity = np.asarray(gravity, dtype=np.float64)
        self.duration = self.steps * self.dt

    def body(self, field: str, value: str | int) -> int:
        """The index of the body a goal's ``field`` names (a name or an index).

        Raises
        ------
        GoalError
            No such body (a near name suggested).
        """
        if isinstance(value, str):
            if value in self.names:
                return self.names.index(value)
            named = [name for name in self.names if name]
            near = difflib.get_close_matches(value, named, n=1) or [
                name for name in named if name.lower() == value.lower()
            ]
            hint = f": did you mean {near[0]!r}?" if near else ""
            listed = ", ".join(repr(name) for name in named[:12]) + (", ..." if len(named) > 12 else "")
            raise GoalError(
                field, f"no body named {value!r} in the scene{hint} (its named bodies: {listed})"
            )
        if not 0 <= value < len(self.names):
            raise GoalError(
                field, f"body index {value} is not in the scene ({len(self.names)} bodies)"
            )
        return value

    def time(self, field: str, seconds: float) -> None:
        """Raises :class:`GoalError` when ``seconds`` is after the take's last frame (half a
        step of slack, as goals read frames)."""
        if seconds > self.duration + 0.5 * self.dt:
            raise GoalError(
                field,
                f"{seconds:g} s is after the take's end, {self.duration:.6g} s ({self.steps} "
                f"steps of {self.dt:.6g} s)",
            )


def _is_number(value: Any) -> bool:
    return not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)


def _number(
    spec: Mapping[str, Any],
    field: str,
    default: float,
    unit: str,
    low: float = 0.0,
    high: float = math.inf,
) -> float:
    """A goal's number field: finite, in [low, high]."""
    value = spec.get(field, default)
    if not _is_number(value):
        raise GoalError(field, f"{value!r} is not a finite number ({unit})")
    if not low <= value <= high:
        bound = f"in [{low:g}, {high:g}]" if math.isfinite(high) else f">= {low:g}"
        raise GoalError(field, f"{value!r} {unit} is out of range: must be {bound}")
    return float(value)


def _vector(spec: Mapping[str, Any], field: str, default: Sequence[float] | None = None) -> Any:
    """A goal's non-zero vector field of three finite numbers (``None`` when absent and no
    default)."""
    value = spec.get(field, default)
    if value is None:
        return None
    if (
        not isinstance(value, (list, tuple))
        or len(value) != 3
        or not all(_is_number(v) for v in value)
    ):
        raise GoalError(field, f"{value!r} is not three finite numbers [x, y, z]")
    if not any(value):
        raise GoalError(field, "[0, 0, 0] has no direction: give a non-zero vector")
    return [float(v) for v in value]


def _body_ref(spec: Mapping[str, Any], field: str) -> str | int:
    """A goal's body field: a body's name (a non-empty string) or index (an integer >= 0)."""
    if field not in spec:
        raise GoalError(field, "is required (a body's name or index)")
    value = spec[field]
    if isinstance(value, str) and value:
        return value
    if isinstance(value, int) and not isinstance(value, bool) and value >= 0:
        return value
    raise GoalError(field, f"{value!r} is not a body: give its name (a string) or index (>= 0)")


def _window(spec: Mapping[str, Any]) -> list[float] | None:
    """A goal's ``between``: ``[t0, t1]``, 0 <= t0 <= t1 (s), or ``None`` (the whole take)."""
    value = spec.get("between")
    if value is None:
        return None
    if (
        not isinstance(value, (list, tuple))
        or len(value) != 2
        or not all(_is_number(v) for v in value)
    ):
        raise GoalError("between", f"{value!r} is not [t0, t1]: two finite times (s)")
    t0, t1 = float(value[0]), float(value[1])
    if t0 < 0.0:
        raise GoalError("between", f"[{t0:g}, {t1:g}] starts before the take, at t0 < 0 s")
    if t0 > t1:
        raise GoalError("between", f"[{t0:g}, {t1:g}] is reversed: t0 must be <= t1 (s)")
    return [t0, t1]


def _region_distance(region: Any) -> Callable[[np.ndarray], np.ndarray]:
    """Distance (m) of points (..., 3) outside a region (0 inside).

    Raises
    ------
    GoalError
        A malformed region (its field named, e.g. ``region.box.min``).
    """
    usage = (
        '{"box": {"min": [x,y,z], "max": [x,y,z]}} or {"sphere": {"center": [x,y,z], '
        '"radius": r}} (m)'
    )
    if not isinstance(region, Mapping) or len(region) != 1:
        raise GoalError("region", f"must be {usage}")
    ((kind, spec),) = region.items()
    if kind not in ("box", "sphere"):
        raise GoalError("region", f"unknown region {kind!r}: use box or sphere, {usage}")
    keys = {"box": {"min", "max"}, "sphere": {"center", "radius"}}[kind]
    if not isinstance(spec, Mapping) or set(spec) != keys:
        raise GoalError(f"region.{kind}", f"must have exactly the fields {sorted(keys)}: {usage}")

    def triple(key: str) -> np.ndarray:
        value = spec[key]
        if (
            not isinstance(value, (list, tuple))
            or len(value) != 3
            or not all(_is_number(v) for v in value)
        ):
            raise GoalError(f"region.{kind}.{key}", f"{value!r} is not three finite numbers (m)")
        return np.asarray(value, dtype=np.float64)

    if kind == "box":
        low, high = triple("min"), triple("max")
        if np.any(high < low):
            raise GoalError("region.box.max", f"{high.tolist()} is below min {low.tolist()}")
        return lambda p: np.linalg.norm(np.maximum(np.maximum(low - p, p - high), 0.0), axis=-1)
    center = triple("center")
    radius = spec["radius"]
    if not _is_number(radius) or not radius > 0.0:
        raise GoalError("region.sphere.radius", f"{radius!r} must be a finite number > 0 (m)")
    return lambda p: np.maximum(np.linalg.norm(p - center, axis=-1) - float(radius), 0.0)


def _axis_angles(
    record: Record, index: int, axis: Sequence[float], up: Sequence[float] | None
) -> np.ndarray:
    """Angle (rad) between the body's ``axis`` (body frame) and ``up`` (world frame; ``None``:
    against gravity) at every frame, (F,)."""
    up_vector = -np.asarray(record.gravity, dtype=np.float64) if up is None else np.asarray(up)
    if np.linalg.norm(up_vector) == 0.0:
        raise ValueError("goal: up must be non-zero (it defaults to against gravity)")
    q = np.asarray(record.orientations[:, index], dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    u, w = q[:, :3], q[:, 3:]
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    turned = a + 2.0 * np.cross(u, np.cross(u, a) + w * a)
    cosine = turned @ (up_vector / np.linalg.norm(up_vector))
    return np.arccos(np.clip(cosine, -1.0, 1.0))


def _touch_frames(record: Record, a: int, b: int, frames: np.ndarray) -> list[int]:
    pair = (min(a, b), max(a, b))
    return [f for f in frames if pair in record.touching[f]]


def _contact_episodes(frames: Sequence[int]) -> int:
    """Separate contacts among sorted frame indices: runs of consecutive frames in contact
    (a bounce is one run; a body resting on another is one long run)."""
    return sum(1 for k, frame in enumerate(frames) if k == 0 or frame != frames[k - 1] + 1)


_ALLOWED = {
    "ends_inside": {"body", "region", "at"},
    "passes_through": {"body", "region", "between"},
    "stays_inside": {"body", "region", "between"},
    "rests_with_axis_up": {"body", "axis", "up", "tolerance_degrees", "rest_speed"},
    "tilted": {"body", "axis", "up", "min_degrees"},
    "touches": {"body", "other", "between", "times"},
    "never_touches": {"body", "other", "between"},
}


def goal_from_dict(spec: Mapping[str, Any]) -> Goal:
    """A goal from its JSON object (the table in this module's documentation). Its fields are
    checked here; the bodies it names and its times against a scene by :meth:`Goal.check`.

    Raises
    ------
    GoalError
        An unknown ``type`` or field, a missing one, or a field out of its range (negative
        tolerances, angles beyond 180 degrees, a reversed ``between``, a zero ``axis``, a
        ``touches`` of a body with itself, a malformed region): the field named.
    """
    if not isinstance(spec, Mapping):
        raise GoalError("type", f"{spec!r} is not a goal: a goal is an object with a 'type'")
    if "type" not in spec:
        raise GoalError("type", f"is required (one of {', '.join(_TYPES)})")
    kind = spec["type"]
    if kind not in _ALLOWED:
        raise GoalError("type", f"goal type {kind!r}: use one of {', '.join(_TYPES)}")
    unknown = set(spec) - _ALLOWED[kind] - {"type", "name", "weight"}
    if unknown:
        allowed = ", ".join(sorted(_ALLOWED[kind] | {"name", "weight"}))
        raise GoalError(
            sorted(unknown)[0], f"unknown fields {sorted(unknown)} for {kind}: use {allowed}"
        )
    body = _body_ref(spec, "body")
    if "name" in spec and not (isinstance(spec["name"], str) and spec["name"]):
        raise GoalError("name", f"{spec['name']!r} is not a non-empty string")
    name = str(spec.get("name", f"{kind}:{body}"))
    weight = spec.get("weight", 1.0)
    if not _is_number(weight) or not weight > 0.0:
        raise GoalError("weight", f"{weight!r} must be a finite number > 0")
    between = _window(spec)
    other: str | int | None = None
    if kind in ("touches", "never_touches"):
        other = _body_ref(spec, "other")
        if other == body:
            raise GoalError("other", f"{other!r} is the goal's own body: a body cannot touch itself")
    at = None
    if "at" in spec:
        at = _number(spec, "at", 0.0, "s")
    axis = _vector(spec, "axis", [0.0, 1.0, 0.0]) if "axis" in _ALLOWED[kind] else None
    up = _vector(spec, "up") if "up" in _ALLOWED[kind] else None

    def check(shot: Shot) -> None:
        index = shot.body("body", body)
        if other is not None and shot.body("other", other) == index:
            raise GoalError(
                "other", f"{other!r} is the goal's body {body!r}: a body cannot touch itself"
            )
        if at is not None:
            shot.time("at", at)
        if between is not None:
            shot.time("between", between[0])
            shot.time("between", between[1])
        if axis is not None and up is None and not np.any(shot.gravity):
            raise GoalError("up", "is required: the scene has no gravity to point against")

    def make(cost: Callable[[Record], float], needs_contacts: bool = False) -> Goal:
        return Goal(name, cost, float(weight), spec, needs_contacts=needs_contacts, check=check)

    if kind in ("ends_inside", "passes_through", "stays_inside"):
        if "region" not in spec:
            raise GoalError("region", "is required (a box or a sphere)")
        distance = _region_distance(spec["region"])

        def region_cost(record: Record) -> float:
            index = record.body(body)
            if kind == "ends_inside":
                frame = -1 if at is None else int(record.window([at, at])[0])
                return float(distance(record.positions[frame, index]))
            d = distance(record.positions[record.window(between), index])
            return float(d.min() if kind == "passes_through" else d.max())

        return make(region_cost)

    if kind == "rests_with_axis_up":
        tolerance = math.radians(_number(spec, "tolerance_degrees", 10.0, "degrees", 0.0, 180.0))
        rest = _number(spec, "rest_speed", 0.05, "m/s and rad/s")

        def rest_cost(record: Record) -> float:
            index = record.body(body)
            angle = float(_axis_angles(record, index, axis, up)[-1])
            speed = float(np.linalg.norm(record.linear_velocities[-1, index]))
            spin = float(np.linalg.norm(record.angular_velocities[-1, index]))
            return max(0.0, angle - tolerance) + max(0.0, speed - rest) + max(0.0, spin - rest)

        return make(rest_cost)

    if kind == "tilted":
        least = math.radians(_number(spec, "min_degrees", 45.0, "degrees", 0.0, 180.0))

        def tilt_cost(record: Record) -> float:
            # Half the final angle short of the least, half the largest angle reached short
            # of it: a body that rocked and stood again is nearer to falling than one that
            # never moved. Both halves are 0 when the final angle reaches the least (the
            # largest is at least the final), so the goal is met exactly as before.
            angles = _axis_angles(record, record.body(body), axis, up)
            final, largest = float(angles[-1]), float(angles.max())
            return 0.5 * max(0.0, least - final) + 0.5 * max(0.0, least - largest)

        return make(tilt_cost)

    times = spec.get("times")
    if times is not None and (isinstance(times, bool) or not isinstance(times, int) or times < 0):
        raise GoalError("times", f"'times' must be an integer >= 0, got {times!r}")

    def touch_cost(record: Record) -> float:
        a, b = record.body(body), record.body(other)
        frames = record.window(between)
        touching = _touch_frames(record, a, b, frames)
        if kind == "never_touches":
            return len(touching) * float(record.dt)
        miss = 0.0
        if not touching:
            gap = record.positions[frames, a] - record.positions[frames, b]
            miss = float(np.linalg.norm(gap, axis=-1).min())
        if times is None:
            return miss
        return float(abs(_contact_episodes(touching) - times)) + (miss if times > 0 else 0.0)

    return make(touch_cost, needs_contacts=True)


def goals_from_json(value: Any) -> list[Goal]:
    """Goals from a parsed goals file: a list of goal objects or ``{"goals": [...]}`` (with
    ``steps`` and ``variation`` beside it, read by the command line).

    Raises
    ------
    ValueError
        Not a list, empty, an unknown top-level key, two goals with one name, or a bad goal:
        ``goals[k].field: what is wrong``.
    """
    if isinstance(value, Mapping):
        unknown = sorted(set(value) - set(FILE_KEYS))
        if unknown:
            raise ValueError(f"unknown keys {unknown}: a goals file has {', '.join(FILE_KEYS)}")
        value = value.get("goals")
    if not isinstance(value, list) or not value:
        raise ValueError('goals: expected a non-empty list of goals (or {"goals": [...]})')
    goals = []
    for k, spec in enumerate(value):
        try:
            goals.append(goal_from_dict(spec))
        except GoalError as error:
            raise ValueError(f"goals[{k}].{error.field}: {error.message}") from None
    check_names(goals)
    return goals


def check_goals(goals: Sequence[Goal], shot: Shot) -> None:
    """Checks every goal against the scene and the takes' length before any take runs.

    Raises
    ------
    ValueError
        ``goals[k].field: what is wrong`` for the first goal naming a body the scene does not
        have, a body touching itself, or a time after the take's end.
    """
    for k, goal in enumerate(goals):
        try:
            goal.check(shot)
        except GoalError as error:
            raise ValueError(f"goals[{k}].{error.field}: {error.message}") from None


def check_names(goals: Sequence[Goal]) -> None:
    """Raises ValueError when two goals share a name (their cost columns would collide)."""
    seen = set()
    for goal in goals:
        if goal.name in seen:
            raise ValueError(f"two goals are named {goal.name!r}: give one a 'name'")
        seen.add(goal.name)


def code_identity(function: Callable[..., Any]) -> str:
    """What a custom goal's function computes, as 16 hex digits of SHA-256: its source when
    Python finds it (else its bytecode, constants and names, nested functions' too), its
    default arguments, the values its closure holds and the module globals it names that are
    plain data (numbers, strings, booleans, None and lists, tuples and dicts of them, by
    value; other objects by their type's name). The functions it calls are not followed: a
    change in a helper alone keeps the identity."""
    hasher = hashlib.sha256()
    code = getattr(function, "__code__", None)
    if code is None:  # a callable object: its class's __call__
        call = vars(type(function)).get("__call__")
        code = getattr(call, "__code__", None)
    try:
        hasher.update(inspect.getsource(function).encode())
    except (OSError, TypeError):
        if code is None:
            hasher.update(f"{type(function).__module__}.{type(function).__qualname__}".encode())
        else:
            _hash_code(hasher, code)
    defaults = getattr(function, "__defaults__", None) or ()
    keyword_defaults = getattr(function, "__kwdefaults__", None) or {}
    cells = []
    for cell in getattr(function, "__closure__", None) or ():
        try:
            cells.append(_plain(cell.cell_contents))
        except ValueError:  # an empty cell
            cells.append(None)
    names = {}
    module_globals = getattr(function, "__globals__", {})
    for name in code.co_names if code is not None else ():
        if name in module_globals and not callable(module_globals[name]):
            names[name] = _plain(module_globals[name])
    extra = [_plain(list(defaults)), _plain(dict(keyword_defaults)), cells, names]
    hasher.update(json.dumps(extra, sort_keys=True, default=str).encode())
    return hasher.hexdigest()[:16]


def _hash_code(hasher: Any, code: Any) -> None:
    hasher.update(code.co_code)
    hasher.update(repr(code.co_names).encode())
    for constant in code.co_consts:
        if inspect.iscode(constant):
            _hash_code(hasher, constant)
        else:
            hasher.update(repr(_plain(constant)).encode())


def _plain(value: Any) -> Any:
    """``value`` as JSON-like data when it is plain data, else its type's name (an object's
    repr may hold its address, which changes from run to run)."""
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, (list, tuple)):
        return [_plain(item) for item in value]
    if isinstance(value, dict):
        return {str(key): _plain(item) for key, item in value.items()}
    if isinstance(value, np.ndarray) and value.size <= 4096:
        return {"ndarray": value.tolist()}
    return f"<{type(value).__module__}.{type(value).__qualname__}>"
