"""impulse: simultaneous contact resolution for computer animation, from Python.

Rigid bodies and particles in piles, stacks and pyramids, whose contact impulses are found
together as one linear complementarity problem (LCP) per time step. SI units, y up.

    import impulse
    world = impulse.World.from_scene("pyramid20")       # a built-in, a .json file or a dict
    start = world.positions.copy()                      # (N, 3) float32, metres
    world.step(60)                                      # releases the GIL
    print(world.quality(start), world.diagnostics["natural_map_residual"])
    trajectory = world.simulate(120, every=4)           # (F, N, 3) and (F, N, 4) arrays
    trajectory.save("pyramid.npz")

See docs/python.md in the repository for the API, the arrays' lifetime rule, pickling and
errors.
"""

import os as _os

from ._impulse import (
    BodyBuilder,
    BodyHandle,
    JointBuilder,
    JointHandle,
    SceneError,
    Settings,
    Shape,
    StepError,
    World,
    WorldError,
    __version__,
    scenes,
    set_decomposition_cache_dir,
)
from ._diagnostics import Diagnostics
from ._trajectory import Trajectory, load_trajectory

# `impulse.sweep` is the function; the module's other names: `from impulse.sweep import ...`.
from .sweep import sweep

#: The environment variable naming a decomposition cache directory for every process that
#: imports impulse, as :func:`set_decomposition_cache_dir` does for one: a sweep's or a takes
#: search's workers are new processes, which inherit the environment.
DECOMPOSITION_CACHE_VARIABLE = "IMPULSE_DECOMPOSITION_CACHE"

if _os.environ.get(DECOMPOSITION_CACHE_VARIABLE):
    set_decomposition_cache_dir(_os.environ[DECOMPOSITION_CACHE_VARIABLE])

__all__ = [
    "BodyBuilder",
    "BodyHandle",
    "Diagnostics",
    "JointBuilder",
    "JointHandle",
    "SceneError",
    "Settings",
    "Shape",
    "StepError",
    "Trajectory",
    "World",
    "WorldError",
    "__version__",
    "load_trajectory",
    "scenes",
    "set_decomposition_cache_dir",
    "sweep",
]


def _world_from_snapshot(data: bytes) -> World:
    """Unpickles a world: the inverse of ``World.__reduce__`` (snapshot bytes)."""
    return World.from_snapshot(data)


def _body_builder(constructor: str, shape: Shape | float, properties: dict) -> BodyBuilder:
    """Unpickles a body builder: the inverse of ``BodyBuilder.__reduce__`` (the call that made
    it: ``BodyBuilder.dynamic(shape, **properties)`` and the like)."""
    return getattr(BodyBuilder, constructor)(shape, **properties)
