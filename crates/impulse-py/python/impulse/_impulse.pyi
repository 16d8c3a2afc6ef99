"""Type stubs of the native module ``impulse._impulse`` (re-exported by ``impulse``)."""

import math
import os
from collections.abc import Mapping, Sequence
from typing import Any, Literal, TypeAlias, final

import numpy as np
import numpy.typing as npt

from ._diagnostics import Diagnostics
from ._trajectory import Trajectory

# The native classes are `@final`: pyo3 classes cannot be subclassed (mypy's stubtest checks
# these stubs against the module).

__version__: str

__all__ = [
    "SceneError",
    "WorldError",
    "StepError",
    "Settings",
    "World",
    "BodyHandle",
    "Shape",
    "BodyBuilder",
    "JointHandle",
    "JointBuilder",
    "scenes",
    "set_decomposition_cache_dir",
    "_cli_main",
    "__version__",
]

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

def set_decomposition_cache_dir(directory: str | os.PathLike[str] | None) -> None:
    """Keep moving meshes' convex decompositions in ``directory`` across processes (None: memory only)."""

def _cli_main(argv: list[str], *, signals: bool = False) -> int:
    """Run the ``impulse`` command on ``argv`` (program name first) without the GIL; its exit
    status (101: a panic, caught). ``signals=True`` hands Ctrl-C, SIGTERM and SIGHUP to the
    command for the rest of the process (the console script ``impulse._cli``)."""

@final
class Settings:
    """Solver settings: the scene format's ``solver`` object (same fields and units)."""

    def __new__(cls) -> Settings: ...
    @staticmethod
    def preset(name: str) -> Settings:
        """``"fast"``, ``"default"``, ``"precise"`` or ``"reference"``; else ``WorldError``."""
    @staticmethod
    def from_dict(fields: Mapping[str, Any]) -> Settings: ...
    def to_dict(self) -> dict[str, Any]: ...
    def replace(self, **fields: Any) -> Settings: ...
    @property
    def method(self) -> Literal["pgs", "nncg", "apgd", "auto"]:
        """The method: ``"pgs"``, ``"nncg"``, ``"apgd"`` or ``"auto"`` (the escalation policy)."""
    @property
    def substeps(self) -> int:
        """Substeps per step (≥ 1); contacts are found once per step."""
    @property
    def iterations(self) -> int:
        """Solver iterations per substep, at most (≥ 1)."""
    @property
    def relax_iterations(self) -> int:
        """Relax iterations per substep, without the repair bias (≥ 0)."""
    @property
    def impact_sweeps(self) -> int:
        """Sweeps an impact may add to a substep's solves, at most (≥ 0; default 32).

        A face landing at restitution 0 then stops dead. 0 takes none (but in islands with
        joints): cheaper, and such a face rises again at 7-9 % of its impact speed.
        """
    @property
    def tolerance(self) -> float:
        """Early exit (m/s): no row's velocity changed by more than this in an iteration; 0 disables."""
    @property
    def escalation_tolerance(self) -> float:
        """``auto``: an island still changing a row's velocity by more than this (m/s) escalates."""
    @property
    def escalation_iterations(self) -> int:
        """``auto``: NNCG iterations an unconverged island gets beyond the budget."""
    @property
    def mass_ratio_threshold(self) -> float:
        """``auto``: islands whose heaviest/lightest moving mass ratio exceeds this go to the exact path."""
    @property
    def exact_max_contacts(self) -> int:
        """``auto``: islands with at most this many contact points may be solved exactly; 0 = never."""
    @property
    def heavy_on_light_mass_ratio(self) -> float:
        """Mass ratio above which a heavy-on-light island is stepped as one exact LCP; 0 = never."""
    @property
    def restitution_threshold(self) -> float:
        """Restitution applies only to contacts approaching faster than this (m/s)."""
    @property
    def repair(self) -> dict[str, Any]:
        """How overlap is repaired: ``{"type": "soft" | "bias" | "split_impulse", ...}`` (docs/scene-format.md)."""
    @property
    def overlap_slop(self) -> float:
        """Overlap tolerated without repair (m)."""
    @property
    def max_repair_speed(self) -> float:
        """Cap on the repair speed (m/s)."""
    @property
    def warm_start(self) -> float:
        """Fraction of last step's impulses used as the starting guess, in [0, 1]."""
    @property
    def prediction_distance(self) -> float:
        """Base speculative margin (m): contacts are generated up to this separation at steps of
        1/60 s or longer, and up to this times dt·60 at shorter steps."""
    @property
    def split_overlap(self) -> float:
        """Overlap (m) beyond which a step that left moving bodies crossed is taken again in halves; 0 is off."""
    @property
    def collision_steps(self) -> int:
        """At most how many collision steps (contacts found again) a step takes for fast pairs (4; 1 is off).

        A pair with a body thinner than 5 mm (a card) may take eight times as many.
        """
    @property
    def recycle_distance(self) -> float:
        """How far (m) a pair of flat shapes may move before its contacts are found again (0.001; 0.02 in `fast`; 0: every step)."""
    @property
    def sleep(self) -> bool:
        """Whether islands that stay quiet sleep."""
    @property
    def sleep_linear_speed(self) -> float:
        """A body slower than this (m/s) …"""
    @property
    def sleep_angular_speed(self) -> float:
        """… and spinning slower than this (rad/s) counts as quiet."""
    @property
    def time_to_sleep(self) -> float:
        """An island sleeps when all its bodies have been quiet this long (s)."""
    @property
    def friction(self) -> bool:
        """Whether Coulomb friction rows are applied."""
    @property
    def friction_in_main_solve(self) -> bool:
        """Whether the friction rows are swept in the main (repairing) solve too."""
    @property
    def direct_joint_solve(self) -> bool:
        """Whether an island's locked joint rows are solved together (sparse Cholesky)."""
    @property
    def parallel_island_contacts(self) -> int:
        """Islands with at least this many contact points are swept colour by colour over the threads; 0 = never."""
    @property
    def simd_island_contacts(self) -> int:
        """Islands with at least this many contact points are solved in SIMD lanes; 0 = never."""
    @property
    def fused_multiply_add(self) -> bool:
        """Whether the SIMD lanes' sweeps use fused multiply-adds (one rounding) where the CPU has them."""
    @property
    def gyroscopic(self) -> bool:
        """Whether the gyroscopic term ω × Iω of rigid bodies is integrated."""
    @property
    def continuous(self) -> bool:
        """Whether continuous collision (motion clamping against static and kinematic bodies) is on."""
    @property
    def impact(self) -> Literal["simultaneous", "propagation"]:
        """How simultaneous impacts are resolved: ``"simultaneous"`` or ``"propagation"``."""
    @property
    def friction_combine(self) -> Literal["geometric_mean", "average", "min", "max", "multiply"]:
        """How a contact's friction is made from its two bodies'."""
    @property
    def restitution_combine(self) -> Literal["geometric_mean", "average", "min", "max", "multiply"]:
        """How a contact's restitution is made from its two bodies'."""
    @property
    def max_distance(self) -> float:
        """World bound (m): a moving body farther than this from the origin leaves the world."""
    @property
    def max_linear_speed(self) -> float:
        """Largest speed of a body's centre of mass (m/s) before a blow-up."""
    @property
    def max_angular_speed(self) -> float:
        """Largest angular speed of a body (rad/s) before a blow-up."""

@final
class BodyHandle:
    """A body's name in a world (slot index and generation); hashable, picklable."""

    def __new__(cls, index: int, generation: int) -> BodyHandle: ...
    @property
    def index(self) -> int: ...
    @property
    def generation(self) -> int: ...

@final
class JointHandle:
    """A joint's name in a world (slot index and generation); hashable, ordered, picklable."""

    def __new__(cls, index: int, generation: int) -> JointHandle: ...
    @property
    def index(self) -> int: ...
    @property
    def generation(self) -> int: ...
    def __lt__(self, other: JointHandle, /) -> bool: ...
    def __le__(self, other: JointHandle, /) -> bool: ...
    def __gt__(self, other: JointHandle, /) -> bool: ...
    def __ge__(self, other: JointHandle, /) -> bool: ...

@final
class JointBuilder:
    """A joint between body A and body B to ``World.insert_joint``; every method returns a new
    builder. Degrees of freedom are B's frame relative to A's: ``"linear_x"`` … ``"angular_z"``
    (m, rad, along and about A's frame axes); the joint axis is the frames' x axis. Values are
    checked at insertion (``WorldError`` naming the field)."""

    @staticmethod
    def fixed(body_a: BodyHandle, body_b: BodyHandle) -> JointBuilder: ...
    @staticmethod
    def spherical(body_a: BodyHandle, body_b: BodyHandle) -> JointBuilder: ...
    @staticmethod
    def revolute(body_a: BodyHandle, body_b: BodyHandle) -> JointBuilder: ...
    @staticmethod
    def prismatic(body_a: BodyHandle, body_b: BodyHandle) -> JointBuilder: ...
    @staticmethod
    def distance(
        body_a: BodyHandle, body_b: BodyHandle, min: float, max: float
    ) -> JointBuilder: ...
    @staticmethod
    def generic(body_a: BodyHandle, body_b: BodyHandle) -> JointBuilder: ...
    @staticmethod
    def new(kind: str, body_a: BodyHandle, body_b: BodyHandle) -> JointBuilder: ...
    @property
    def kind(self) -> str: ...
    def local_anchors(self, anchor_a: _Vec3, anchor_b: _Vec3) -> JointBuilder: ...
    def world_anchor(self, anchor: _Vec3) -> JointBuilder: ...
    def world_anchors(self, anchor_a: _Vec3, anchor_b: _Vec3) -> JointBuilder: ...
    def world_axis(self, axis: _Vec3) -> JointBuilder: ...
    def local_axes(self, axis_a: _Vec3, axis_b: _Vec3) -> JointBuilder: ...
    def local_frames(
        self, rotation_a: Sequence[float], rotation_b: Sequence[float]
    ) -> JointBuilder: ...
    def dof(
        self, dof: str, mode: str, lower: float | None = None, upper: float | None = None
    ) -> JointBuilder:
        """``mode``: ``"locked"``, ``"free"`` or ``"limited"`` (with ``lower`` ≤ ``upper``)."""
    def dof_spring(
        self, dof: str, hertz: float, damping_ratio: float, rest: float
    ) -> JointBuilder: ...
    def dof_motor_velocity(self, dof: str, speed: float, max_force: float) -> JointBuilder: ...
    def limits(self, lower: float, upper: float) -> JointBuilder: ...
    def spring(self, hertz: float, damping_ratio: float, rest: float) -> JointBuilder: ...
    def motor_velocity(self, speed: float, max_force: float) -> JointBuilder: ...
    def motor_position(
        self, target: float, hertz: float, damping_ratio: float, max_force: float
    ) -> JointBuilder: ...
    def stiffness(
        self, hertz: float | None = None, damping_ratio: float | None = None
    ) -> JointBuilder: ...
    def collide_connected(self, collide: bool) -> JointBuilder: ...
    def breakable(self, force: float, torque: float = math.inf, window: float = 0.0) -> JointBuilder:
        """Strength ``force`` (N) and ``torque`` (N·m, default inf), measured over ``window``
        seconds (0: one substep)."""
    def name(self, name: str) -> JointBuilder: ...

@final
class Shape:
    """A collision shape in the body frame (m); compares with ``==``, picklable."""

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
    def trimesh(
        vertices: Sequence[Sequence[float]],
        indices: Sequence[Sequence[int]],
        decomposition: Mapping[str, Any] | None = None,
    ) -> Shape:
        """A triangle mesh; decomposed into convex parts on a moving body."""
    def convex_parts(self) -> list[tuple[npt.NDArray[np.float32], npt.NDArray[np.uint32]]]:
        """The convex parts (vertices (K, 3), triangles (F, 3)) of a moving body of this mesh."""
    @staticmethod
    def from_dict(shape: Mapping[str, Any]) -> Shape: ...
    def to_dict(self) -> dict[str, Any]: ...

@final
class BodyBuilder:
    """A body to insert: ``BodyBuilder.dynamic(Shape.ball(0.5), translation=(0, 2, 0))``.

    Keywords: translation (m), rotation (x y z w), linear_velocity (m/s), angular_velocity
    (rad/s), friction, restitution, roughness (degrees), impact_perturbation (0-1), density
    (kg/m³), mass (kg), name, linear_damping, angular_damping (1/s), lock_rotation,
    roughness_draws (pairs (a, b), standard-normal). Picklable; the repr is the call that made it.
    """

    @staticmethod
    def dynamic(shape: Shape, **props: Any) -> BodyBuilder: ...
    @staticmethod
    def fixed(shape: Shape, **props: Any) -> BodyBuilder: ...
    @staticmethod
    def kinematic(shape: Shape, **props: Any) -> BodyBuilder: ...
    @staticmethod
    def particle(radius: float, **props: Any) -> BodyBuilder: ...

_Vec3: TypeAlias = Sequence[float]
_ArrayF32: TypeAlias = npt.NDArray[np.float32]

@final
class World:
    """A simulation world. State arrays are read-only float32 views of the engine's storage
    (see docs/python.md for their lifetime rule); assigning an array sets every body. Calls
    from several threads on one world take turns; ``state()`` copies one moment's arrays."""

    def __new__(
        cls,
        gravity: _Vec3 = (0.0, -9.81, 0.0),
        dt: float = 0.016666666666666666,
        settings: Settings | str | None = None,
    ) -> World: ...
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
    def step(self, n: int = 1) -> None:
        """``n`` ≥ 0 steps without the GIL (else ``WorldError``, a ``ValueError``)."""
    def simulate(self, steps: int, every: int = 1) -> Trajectory: ...
    def state(self) -> dict[str, Any]:
        """Copies of one moment: ``step_count``, ``time``, ``positions``, ``orientations``,
        ``linear_velocities``, ``angular_velocities``."""
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
    def diagnostics(self) -> Diagnostics: ...
    @property
    def profile(self) -> dict[str, float | dict[str, float]]: ...
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
    def seed(self) -> int:
        """Seed of the rough surfaces' draws (the scene's ``seed``)."""
    @seed.setter
    def seed(self, value: int) -> None: ...
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
    def profile_solve_phases(self) -> bool: ...
    @profile_solve_phases.setter
    def profile_solve_phases(self, value: bool) -> None: ...
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
        max_distance: float = 3.4028234663852886e38,
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
        ``contact_of_row`` (−1 for a joint row), ``joint_of_row`` (−1 for a contact row)."""
    def insert_joint(self, builder: JointBuilder) -> JointHandle: ...
    def remove_joint(self, handle: JointHandle) -> str | None: ...
    def joint(self, handle: JointHandle) -> dict[str, Any]:
        """``handle``, ``kind``, ``name``, ``body_a``, ``body_b``, ``broken``, ``force`` (3,) N
        and ``torque`` (3,) N·m on B (world frame), ``collide_connected``,
        ``break_thresholds``, ``break_window`` (s), ``coordinates`` (6,)."""
    def joints(self) -> list[dict[str, Any]]: ...
    @property
    def joint_count(self) -> int: ...
    def joint_coordinates(self, handle: JointHandle) -> npt.NDArray[np.float32]:
        """(6,): m along A's frame axes x, y, z, then rad about them."""
    def joint_events(self) -> list[dict[str, Any]]:
        """The last step's ``{"type": "broken", "joint", "name", "force", "torque"}``."""
    def __copy__(self) -> World: ...
    def __deepcopy__(self, memo: Any) -> World: ...
