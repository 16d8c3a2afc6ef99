"""The parameter space of a take: per-body offsets of the initial state, applied to the scene.

A take is a point θ of this space. θ is unit-free: component k moves its field by
``θ[k] × scale`` of that field, so θ = 0 is the scene as authored and a standard normal draw of
θ is a perturbation of the size the scales state. Per varied body, in this order:

====================  ======  ==========================================================
components            unit    field changed
====================  ======  ==========================================================
0-2 (x, y, z)         m       ``position`` += θ × ``position``
3-5 (rotation vector) degree  ``orientation`` turned by the rotation vector θ × ``angle``
                              (world frame, about the body's origin)
6-8 (x, y, z)         m/s     ``linear_velocity`` += θ × ``velocity``
9-11 (x, y, z)        rad/s   ``angular_velocity`` += θ × ``angular_velocity``
12 … 12+2K-1 (a, b)   none    ``roughness_draws`` = the K pairs [a, b] of θ as they are
====================  ======  ==========================================================

A field whose scale is 0 is not varied and its components are left out of θ (so the draws
follow directly after the last varied field). The varied values are rounded to float32 (the
engine's precision) before they are written, so the varied scene read from a file gives the
same bits as the one simulated in the search.

With ``roughness_draws=K`` each varied body's first K new rough contacts take their tilts from
θ instead of the seed: pair k (a, b), standard-normal coordinates with no scale, gives the
contact's normal a tilt with cap 1 − exp(−(a² + b²)/2) and azimuth atan2(b, a) (the body field
``roughness_draws``, docs/scene-format.md). A standard normal (a, b) gives the seeded draws'
distribution and the map is continuous, so the search refines rough bounces as it refines the
initial state. Only contacts with a rough body (a material ``roughness``) draw at all.

With ``seeds=True`` a take also has its own scene ``seed``: the seed of the engine's seeded
draws, which tilt each new contact's normal on rough surfaces (materials with ``roughness``,
degrees) and move each impact's restitution by up to ± ``impact_perturbation`` (materials with
one, in [0, 1]; the rebound never exceeds the approach speed). It is an integer, not part of θ:
the search draws a fresh one, or reuses one of the best takes' seeds.

Small perturbations of the initial state are the plausible variations of Barzel, Hughes & Wood,
"Plausible motion simulation for computer graphics animation" (Eurographics CAS 1996).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

#: The fields a variation may change, with their unit, in θ's order per body.
FIELDS = ("position", "angle", "velocity", "angular_velocity")
UNITS = {"position": "m", "angle": "degrees", "velocity": "m/s", "angular_velocity": "rad/s"}
#: The most roughness draws a body may have (the engine's bound on ``roughness_draws``).
MAX_ROUGHNESS_DRAWS = 256
_MOVING = ("dynamic", "particle")


class Variation:
    """Which bodies a take may vary and by how much (the scales of θ).

    Parameters
    ----------
    bodies : sequence of str | int, optional
        Body names (the scene's ``name``) or indices; default every dynamic body.
    position : float
        Scale of the position offsets (m); 0 leaves positions as authored.
    angle : float
        Scale of the rotation offsets (degrees).
    velocity : float
        Scale of the linear velocity offsets (m/s).
    angular_velocity : float
        Scale of the angular velocity offsets (rad/s).
    seeds : bool
        Give each take its own scene ``seed`` (the draws of rough surfaces and perturbed
        impacts; materials need a ``roughness`` or an ``impact_perturbation`` for it to
        matter).
    roughness_draws : int
        K ≥ 0: each varied body's first K rough contacts take their draws from θ (2K
        components per body, after its other ones); 0 (the default) leaves them to the seed.

    Raises
    ------
    ValueError
        A scale negative or not finite, ``roughness_draws`` not an integer in [0, 256], nothing
        varied, or an unknown key in :meth:`from_dict`.
    """

    def __init__(
        self,
        bodies: Sequence[str | int] | None = None,
        position: float = 0.0,
        angle: float = 0.0,
        velocity: float = 0.0,
        angular_velocity: float = 0.0,
        seeds: bool = False,
        roughness_draws: int = 0,
    ):
        self.bodies = None if bodies is None else list(bodies)
        self.seeds = bool(seeds)
        if (
            isinstance(roughness_draws, bool)
            or not isinstance(roughness_draws, (int, np.integer))
            or not 0 <= roughness_draws <= MAX_ROUGHNESS_DRAWS
        ):
            raise ValueError(
                f"variation roughness_draws = {roughness_draws!r}: must be an integer in "
                f"[0, {MAX_ROUGHNESS_DRAWS}] (pairs per varied body)"
            )
        self.roughness_draws = int(roughness_draws)
        self.scales = {
            "position": float(position),
            "angle": float(angle),
            "velocity": float(velocity),
            "angular_velocity": float(angular_velocity),
        }
        for name, value in self.scales.items():
            if not math.isfinite(value) or value < 0.0:
                raise ValueError(
                    f"variation {name} = {value} {UNITS[name]}: must be finite and >= 0"
                )
        if not any(self.scales.values()) and not self.seeds and not self.roughness_draws:
            raise ValueError(
                "a variation with every scale 0 varies nothing: give position (m), angle "
                "(degrees), velocity (m/s), angular_velocity (rad/s), seeds or roughness_draws"
            )

    @staticmethod
    def from_dict(spec: Mapping[str, Any]) -> Variation:
        """From ``{"bodies": [...], "position": m, "angle": degrees, "velocity": m/s,
        "angular_velocity": rad/s, "seeds": bool, "roughness_draws": K}`` (every key optional
        but one that varies something)."""
        unknown = set(spec) - {"bodies", "seeds", "roughness_draws", *FIELDS}
        if unknown:
            raise ValueError(
                f"variation has unknown keys {sorted(unknown)}: use bodies, seeds, "
                f"roughness_draws, {', '.join(FIELDS)}"
            )
        return Variation(**dict(spec))

    def to_dict(self) -> dict[str, Any]:
        """The spec :meth:`from_dict` reads."""
        out: dict[str, Any] = {"bodies": self.bodies}
        out.update(self.scales)
        if self.seeds:
            out["seeds"] = True
        if self.roughness_draws:
            out["roughness_draws"] = self.roughness_draws
        return out

    def fields(self) -> list[str]:
        """The varied fields (scale > 0), in θ's order."""
        return [name for name in FIELDS if self.scales[name] > 0.0]

    def body_indices(self, scene: Mapping[str, Any]) -> list[int]:
        """The indices of the varied bodies in ``scene["bodies"]``.

        Raises
        ------
        ValueError
            A name or index not in the scene, or a named body that is not dynamic.
        """
        bodies = scene.get("bodies", [])
        if self.bodies is None:
            found = [i for i, body in enumerate(bodies) if body.get("kind") in _MOVING]
            if not found:
                raise ValueError("the scene has no dynamic body to vary")
            return found
        names = {body.get("name"): i for i, body in enumerate(bodies) if body.get("name")}
        indices = []
        for body in self.bodies:
            if isinstance(body, str):
                if body not in names:
                    raise ValueError(f"variation: no body named {body!r} in the scene")
                index = names[body]
            else:
                index = int(body)
                if not 0 <= index < len(bodies):
                    raise ValueError(f"variation: body index {index} is not in the scene")
            if bodies[index].get("kind") not in _MOVING:
                raise ValueError(
                    f"variation: body {body!r} is {bodies[index].get('kind', 'static')}, "
                    "only dynamic bodies are varied"
                )
            indices.append(index)
        return indices

    def per_body(self) -> int:
        """θ's components per varied body: 3 per varied field, then 2 per roughness draw."""
        return 3 * len(self.fields()) + 2 * self.roughness_draws

    def dimension(self, scene: Mapping[str, Any]) -> int:
        """Length of θ for ``scene``: :meth:`per_body` per varied body."""
        return self.per_body() * len(self.body_indices(scene))

    def apply(
        self,
        scene: Mapping[str, Any],
        theta: Sequence[float],
        seed: int | None = None,
        steps: int | None = None,
        dt: float | None = None,
    ) -> dict[str, Any]:
        """A copy of ``scene`` (a dict as in a scene file) with θ's offsets applied (and its
        roughness draws written as the varied bodies' ``roughness_draws``) and the changed
        values rounded to float32; with ``seed``, also the scene's ``seed``; with ``steps`` and
        ``dt`` (s), the scene's ``steps`` and ``dt``, so ``impulse run``, ``render`` and the
        exports of the written scene run the take's length.

        Raises
        ------
        ValueError
            θ of the wrong length or not finite.
        """
        theta = np.asarray(theta, dtype=np.float64)
        indices = self.body_indices(scene)
        fields = self.fields()
        if theta.shape != (self.per_body() * len(indices),):
            raise ValueError(
                f"theta has shape {theta.shape}, the variation needs "
                f"({self.per_body() * len(indices)},)"
            )
        if not np.all(np.isfinite(theta)):
            raise ValueError("theta must be finite")
        out = copy.deepcopy(dict(scene))
        if seed is not None:
            out["seed"] = int(seed)
        if steps is not None:
            out["steps"] = int(steps)
        if dt is not None:
            out["dt"] = float(np.float32(dt))  # the engine's dt is float32: exact both ways
        k = 0
        for index in indices:
            body = out["bodies"][index]
            for name in fields:
                offset = theta[k : k + 3] * self.scales[name]
                k += 3
                if name == "angle":
                    body["orientation"] = _turned(
                        body.get("orientation", [0.0, 0.0, 0.0, 1.0]), np.radians(offset)
                    )
                else:
                    key = {"velocity": "linear_velocity"}.get(name, name)
                    value = np.asarray(body.get(key, [0.0, 0.0, 0.0]), dtype=np.float64)
                    body[key] = _float32_list(value + offset)
            if self.roughness_draws:
                draws = theta[k : k + 2 * self.roughness_draws]
                k += 2 * self.roughness_draws
                body["roughness_draws"] = [_float32_list(pair) for pair in draws.reshape(-1, 2)]
        return out

    @staticmethod
    def perturbation(theta: Sequence[float]) -> float:
        """The size of a take's perturbation: the root mean square of θ (unit-free: 1 is a
        perturbation of the scales' size on every component, 0 the scene as authored). Smaller
        is more plausible."""
        theta = np.asarray(theta, dtype=np.float64)
        return float(np.sqrt(np.mean(theta * theta))) if theta.size else 0.0


def _float32_list(values: Any) -> list[float]:
    return [float(np.float32(v)) for v in values]


def _turned(orientation: Sequence[float], rotation: np.ndarray) -> list[float]:
    """``orientation`` ([x, y, z, w]) turned by the world-frame rotation vector ``rotation``
    (rad): q' = r·q, normalised."""
    angle = float(np.linalg.norm(rotation))
    if angle == 0.0:
        r = np.array([0.0, 0.0, 0.0, 1.0])
    else:
        axis = rotation / angle
        r = np.concatenate([axis * math.sin(0.5 * angle), [math.cos(0.5 * angle)]])
    q = np.asarray(orientation, dtype=np.float64)
    q = q / np.linalg.norm(q)
    ax, ay, az, aw = r
    bx, by, bz, bw = q
    product = np.array(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ]
    )
    return _float32_list(product / np.linalg.norm(product))
