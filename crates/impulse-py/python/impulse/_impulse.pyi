"""Type stubs of the native module ``impulse._impulse`` (re-exported by ``impulse``)."""

import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from ._trajectory import Trajectory

__version__: str

class SceneError(ValueError):
    """A scene that cannot be read or is invalid: the message names the file, line, body and
    field as ``impulse run`` prints it."""

class WorldError(ValueError):
    """A bad edit of a world or a bad argument to one."""

class StepError(RuntimeError):
    """A step failed (a blow-up names the step and the body). After ``World.simulate`` the
    frames recorded before the failure are the ``trajectory`` attribute."""

    trajectory: Trajectory

def scenes() -> list[str]:
    """The built-in scene names, as ``impulse scenes`` lists them."""

class Settings:
    """Solver settings: the scene format's ``solver`` object (same fields and units)."""

    def __init__(self) -> None: ...
    @staticmethod
    def preset(name: str) -> Settings:
        """``"fast"``, ``"default"``, ``"precise"`` or ``"reference"``; else ``WorldError``."""
    @staticmethod
    def from_dict(fields: Mapping[str, Any]) -> Settings: ...
    def to_dict(self) -> dict[str, Any]: ...
    def replace(self, **fields: Any) -> Settings: ...
    def __getattr__(self, name: str) -> Any: ...

class BodyHandle:
    """A body's name in a world (slot index and generation); hashable."""

    @property
    def index(self) -> int: ...
    @property
    def generation(self) -> int: ...

class Shape:
    """A collision shape in the body frame (m)."""

    @staticmethod
    def ball(radius: float) -> Shape: ...
    @staticmethod
    def cuboid(hx: float, hy: float, hz: float) -> Shape: ...
    @staticmethod
    def capsule(half_height: float, radius: float) -> Shape: ...
    @staticmethod
    def cylinder(half_height: float, radius: float) -> Shape: ...
    @staticmethod
    def cone(half_height: float, radius: float) -> Shape: ...
    @staticmethod
    def convex_hull(points: Sequence[Sequence[float]]) -> Shape: ...
    @staticmethod
    def halfspace(normal: Sequence[float]) -> Shape: ...
    @staticmethod
    def from_dict(shape: Mapping[str, Any]) -> Shape: ...
    def to_dict(self) -> dict[str, Any]: ...

class BodyBuilder:
    """A body to insert: ``BodyBuilder.dynamic(Shape.ball(0.5), translation=(0, 2, 0))``.

    Keywords: translation (m), rotation (x y z w), linear_velocity (m/s), angular_velocity
    (rad/s), friction, restitution, density (kg/m³), mass (kg), name, linear_damping,
    angular_damping (1/s), lock_rotation.
    """

    @staticmethod
    def dynamic(shape: Shape, **props: Any) -> BodyBuilder: ...
    @staticmethod
    def fixed(shape: Shape, **props: Any) -> BodyBuilder: ...
    @staticmethod
    def kinematic(shape: Shape, **props: Any) -> BodyBuilder: ...
    @staticmethod
    def particle(radius: float, **props: Any) -> BodyBuilder: ...

_Vec3 = Sequence[float]
_ArrayF32 = npt.NDArray[np.float32]

class World:
    """A simulation world. State arrays are read-only float32 views of the engine's storage
    (see docs/python.md for their lifetime rule); assigning an array sets every body."""

    def __init__(
        self,
        gravity: _Vec3 = (0.0, -9.81, 0.0),
        dt: float = 1.0 / 60.0,
        settings: Settings | str | None = None,
    ) -> None: ...
    @staticmethod
    def from_scene(
        scene: str | os.PathLike[str] | Mapping[str, Any],
        *,
        overrides: Mapping[str, Any] | Sequence[str] | None = None,
        seed: int = 0,
        jitter: Mapping[str, float] | None = None,
        settings: Settings | str | None = None,
    ) -> World: ...
    @staticmethod
    def from_snapshot(data: bytes) -> World: ...
    def snapshot(self) -> bytes: ...
    def step(self, n: int = 1) -> None: ...
    def simulate(self, steps: int, every: int = 1) -> Trajectory: ...
    @property
    def positions(self) -> _ArrayF32:
        """(N, 3) float32, metres (read-only view)."""
    @positions.setter
    def positions(self, value: npt.ArrayLike) -> None: ...
    @property
    def orientations(self) -> _ArrayF32:
        """(N, 4) float32, quaternions x y z w (read-only view)."""
    @orientations.setter
    def orientations(self, value: npt.ArrayLike) -> None: ...
    @property
    def linear_velocities(self) -> _ArrayF32:
        """(N, 3) float32, m/s (read-only view)."""
    @linear_velocities.setter
    def linear_velocities(self, value: npt.ArrayLike) -> None: ...
    @property
    def angular_velocities(self) -> _ArrayF32:
        """(N, 3) float32, rad/s, world frame (read-only view)."""
    @angular_velocities.setter
    def angular_velocities(self, value: npt.ArrayLike) -> None: ...
    @property
    def names(self) -> list[str]: ...
    @property
    def kinds(self) -> list[str]: ...
    @property
    def masses(self) -> npt.NDArray[np.float32]: ...
    @property
    def diagnostics(self) -> dict[str, Any]: ...
    @property
    def profile(self) -> dict[str, float]: ...
    def quality(self, initial_positions: npt.ArrayLike | None = None) -> dict[str, Any]: ...
    @property
    def step_count(self) -> int: ...
    @property
    def time(self) -> float: ...
    @property
    def dt(self) -> float: ...
    @dt.setter
    def dt(self, value: float) -> None: ...
    @property
    def gravity(self) -> list[float]: ...
    @gravity.setter
    def gravity(self, value: _Vec3) -> None: ...
    @property
    def settings(self) -> Settings: ...
    @settings.setter
    def settings(self, value: Settings | str) -> None: ...
    @property
    def parallel(self) -> bool: ...
    @parallel.setter
    def parallel(self, value: bool) -> None: ...
    @property
    def body_count(self) -> int: ...
    def __len__(self) -> int: ...
    def insert(self, builder: BodyBuilder) -> BodyHandle: ...
    def remove(self, handle: BodyHandle) -> str | None: ...
    def handle_of(self, index: int) -> BodyHandle: ...
    def index_of(self, handle: BodyHandle) -> int: ...
    def apply_force(self, handle: BodyHandle, force: _Vec3, point: _Vec3 | None = None) -> None: ...
    def apply_torque(self, handle: BodyHandle, torque: _Vec3) -> None: ...
    def apply_impulse(
        self, handle: BodyHandle, impulse: _Vec3, point: _Vec3 | None = None
    ) -> None: ...
    def apply_torque_impulse(self, handle: BodyHandle, impulse: _Vec3) -> None: ...
    def cast_ray(
        self,
        origin: _Vec3,
        direction: _Vec3,
        max_distance: float = ...,
        solid: bool = True,
    ) -> dict[str, Any] | None:
        """First hit: ``body``, ``index``, ``distance``, ``point`` (m), ``normal``; or None."""
    def cast_shape(
        self,
        shape: Shape,
        translation: _Vec3,
        velocity: _Vec3,
        max_time: float,
        rotation: Sequence[float] = (0.0, 0.0, 0.0, 1.0),
    ) -> dict[str, Any] | None:
        """First touch: ``body``, ``index``, ``time`` (s), ``witness_shape``, ``witness_body``,
        ``normal``; or None."""
    def contact_pairs(self) -> list[dict[str, Any]]:
        """Pairs after the last step with their points as arrays (see docs/python.md)."""
    def contact_events(self) -> list[dict[str, Any]]:
        """The last step's ``started`` / ``stopped`` events."""
    def contact_lcp(self) -> dict[str, Any]:
        """The last step's contact LCP: ``A`` (SciPy CSR array, or COO arrays without SciPy),
        ``b``, ``lo``, ``hi``, ``friction_index``, ``mu``, ``engine_solution``,
        ``contact_of_row``."""
    def __copy__(self) -> World: ...
    def __deepcopy__(self, memo: Any) -> World: ...
