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
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

#: Cost at or below which a goal counts as met.
MET = 1e-9

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
    """One goal: a name, a weight and ``cost(record) -> float`` (>= 0; 0 when met)."""

    def __init__(
        self,
        name: str,
        cost: Callable[[Record], float],
        weight: float = 1.0,
        spec: Mapping[str, Any] | None = None,
        needs_contacts: bool = False,
    ):
        if not math.isfinite(weight) or weight <= 0.0:
            raise ValueError(f"goal {name!r}: weight must be finite and > 0, got {weight}")
        self.name = name
        self.weight = float(weight)
        self.spec = None if spec is None else dict(spec)
        self.needs_contacts = needs_contacts
        self._cost = cost

    def cost(self, record: Record) -> float:
        """The goal's cost for a take (>= 0, 0 when met)."""
        value = float(self._cost(record))
        if not value >= 0.0:  # NaN as well
            raise ValueError(f"goal {self.name!r}: cost must be >= 0, got {value}")
        return value

    def __repr__(self) -> str:
        return f"Goal({self.name!r})"


def custom(function: Callable[[Record], float], name: str, weight: float = 1.0) -> Goal:
    """A goal from a Python callable ``function(record) -> cost`` (a :class:`Record`; cost >= 0,
    0 when met). For the local pool it must be picklable (a module-level function; with
    ``cloudpickle`` installed also a lambda or closure)."""
    return Goal(name, function, weight, needs_contacts=True)


def _region_distance(region: Mapping[str, Any]) -> Callable[[np.ndarray], np.ndarray]:
    """Distance (m) of points (..., 3) outside a region (0 inside)."""
    if not isinstance(region, Mapping) or len(region) != 1:
        raise ValueError(
            'goal: region must be {"box": {"min": [x,y,z], "max": [x,y,z]}} or '
            '{"sphere": {"center": [x,y,z], "radius": r}}'
        )
    ((kind, spec),) = region.items()
    if kind == "box":
        low = np.asarray(spec["min"], dtype=np.float64)
        high = np.asarray(spec["max"], dtype=np.float64)
        if low.shape != (3,) or high.shape != (3,) or np.any(high < low):
            raise ValueError("goal: a box region needs min <= max, three values each")
        return lambda p: np.linalg.norm(np.maximum(np.maximum(low - p, p - high), 0.0), axis=-1)
    if kind == "sphere":
        center = np.asarray(spec["center"], dtype=np.float64)
        radius = float(spec["radius"])
        if center.shape != (3,) or not radius > 0.0:
            raise ValueError("goal: a sphere region needs a center of three values and radius > 0")
        return lambda p: np.maximum(np.linalg.norm(p - center, axis=-1) - radius, 0.0)
    raise ValueError(f"goal: unknown region {kind!r}: use box or sphere")


def _axis_angles(record: Record, index: int, spec: Mapping[str, Any]) -> np.ndarray:
    """Angle (rad) between the body's ``axis`` and ``up`` at every frame, (F,)."""
    axis = np.asarray(spec.get("axis", [0.0, 1.0, 0.0]), dtype=np.float64)
    if "up" in spec:
        up = np.asarray(spec["up"], dtype=np.float64)
    else:
        up = -np.asarray(record.gravity, dtype=np.float64)
    if np.linalg.norm(axis) == 0.0 or np.linalg.norm(up) == 0.0:
        raise ValueError("goal: axis and up must be non-zero (up defaults to against gravity)")
    q = np.asarray(record.orientations[:, index], dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    u, w = q[:, :3], q[:, 3:]
    a = axis / np.linalg.norm(axis)
    turned = a + 2.0 * np.cross(u, np.cross(u, a) + w * a)
    cosine = turned @ (up / np.linalg.norm(up))
    return np.arccos(np.clip(cosine, -1.0, 1.0))


def _touch_frames(record: Record, a: int, b: int, frames: np.ndarray) -> list[int]:
    pair = (min(a, b), max(a, b))
    return [f for f in frames if pair in record.touching[f]]


def _contact_episodes(frames: Sequence[int]) -> int:
    """Separate contacts among sorted frame indices: runs of consecutive frames in contact
    (a bounce is one run; a body resting on another is one long run)."""
    return sum(1 for k, frame in enumerate(frames) if k == 0 or frame != frames[k - 1] + 1)


def goal_from_dict(spec: Mapping[str, Any]) -> Goal:
    """A goal from its JSON object (the table in this module's documentation).

    Raises
    ------
    ValueError
        An unknown ``type`` or field, or a malformed region.
    """
    if not isinstance(spec, Mapping) or "type" not in spec:
        raise ValueError(f"goal {spec!r}: a goal is an object with a 'type' (one of {_TYPES})")
    kind = spec["type"]
    allowed = {
        "ends_inside": {"body", "region", "at"},
        "passes_through": {"body", "region", "between"},
        "stays_inside": {"body", "region", "between"},
        "rests_with_axis_up": {"body", "axis", "up", "tolerance_degrees", "rest_speed"},
        "tilted": {"body", "axis", "up", "min_degrees"},
        "touches": {"body", "other", "between", "times"},
        "never_touches": {"body", "other", "between"},
    }
    if kind not in allowed:
        raise ValueError(f"goal type {kind!r}: use one of {', '.join(_TYPES)}")
    unknown = set(spec) - allowed[kind] - {"type", "name", "weight"}
    if unknown:
        raise ValueError(f"goal {kind}: unknown fields {sorted(unknown)}")
    if "body" not in spec:
        raise ValueError(f"goal {kind}: 'body' is required")
    body = spec["body"]
    name = str(spec.get("name", f"{kind}:{body}"))
    weight = float(spec.get("weight", 1.0))
    between = spec.get("between")

    if kind in ("ends_inside", "passes_through", "stays_inside"):
        if "region" not in spec:
            raise ValueError(f"goal {kind}: 'region' is required")
        distance = _region_distance(spec["region"])

        def region_cost(record: Record) -> float:
            index = record.body(body)
            if kind == "ends_inside":
                at = spec.get("at")
                frame = -1 if at is None else int(record.window([at, at])[0])
                return float(distance(record.positions[frame, index]))
            d = distance(record.positions[record.window(between), index])
            return float(d.min() if kind == "passes_through" else d.max())

        return Goal(name, region_cost, weight, spec)

    if kind == "rests_with_axis_up":
        tolerance = math.radians(float(spec.get("tolerance_degrees", 10.0)))
        rest = float(spec.get("rest_speed", 0.05))

        def rest_cost(record: Record) -> float:
            index = record.body(body)
            angle = float(_axis_angles(record, index, spec)[-1])
            speed = float(np.linalg.norm(record.linear_velocities[-1, index]))
            spin = float(np.linalg.norm(record.angular_velocities[-1, index]))
            return max(0.0, angle - tolerance) + max(0.0, speed - rest) + max(0.0, spin - rest)

        return Goal(name, rest_cost, weight, spec)

    if kind == "tilted":
        least = math.radians(float(spec.get("min_degrees", 45.0)))

        def tilt_cost(record: Record) -> float:
            # Half the final angle short of the least, half the largest angle reached short
            # of it: a body that rocked and stood again is nearer to falling than one that
            # never moved. Both halves are 0 when the final angle reaches the least (the
            # largest is at least the final), so the goal is met exactly as before.
            angles = _axis_angles(record, record.body(body), spec)
            final, largest = float(angles[-1]), float(angles.max())
            return 0.5 * max(0.0, least - final) + 0.5 * max(0.0, least - largest)

        return Goal(name, tilt_cost, weight, spec)

    if "other" not in spec:
        raise ValueError(f"goal {kind}: 'other' is required")
    other = spec["other"]
    times = spec.get("times")
    if times is not None and (isinstance(times, bool) or not isinstance(times, int) or times < 0):
        raise ValueError(f"goal {kind}: 'times' must be an integer >= 0, got {times!r}")

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

    return Goal(name, touch_cost, weight, spec, needs_contacts=True)


def goals_from_json(value: Any) -> list[Goal]:
    """Goals from a parsed goals file: a list of goal objects or ``{"goals": [...]}``.

    Raises
    ------
    ValueError
        Not a list, empty, two goals with one name, or a bad goal (its position named).
    """
    if isinstance(value, Mapping) and "goals" in value:
        value = value["goals"]
    if not isinstance(value, list) or not value:
        raise ValueError('goals: expected a non-empty list of goals (or {"goals": [...]})')
    goals = []
    for k, spec in enumerate(value):
        try:
            goals.append(goal_from_dict(spec))
        except (ValueError, TypeError, KeyError) as error:
            raise ValueError(f"goals[{k}]: {error}") from None
    check_names(goals)
    return goals


def check_names(goals: Sequence[Goal]) -> None:
    """Raises ValueError when two goals share a name (their cost columns would collide)."""
    seen = set()
    for goal in goals:
        if goal.name in seen:
            raise ValueError(f"two goals are named {goal.name!r}: give one a 'name'")
        seen.add(goal.name)
