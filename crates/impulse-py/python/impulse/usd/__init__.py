"""impulse.usd: UsdPhysics stages in, baked stages out.

Reads a stage's physics (OpenUSD's UsdPhysics schemas: ``PhysicsScene``, ``RigidBodyAPI``,
``CollisionAPI``, ``MassAPI``, ``MeshCollisionAPI``, ``MaterialAPI``, collision groups,
filtered pairs and the joints) into an impulse scene, simulates it, and writes the motion back
as a layer of time samples over the stage, on the same prim paths, in the stage's units and
axes. The reader is OpenUSD's own Python module ``pxr`` (PyPI ``usd-core``): the one reader of
``.usda``, ``.usdc`` and ``.usdz`` that composes references, payloads, sublayers and variants,
and that has UsdPhysics' schema classes and its parser with the schema's precedence rules.

    from impulse import usd
    scene, report = usd.stage_to_scene("shot.usda")   # a scene dict, and what did not map
    print(report)                                     # by prim path
    usd.bake("shot.usda", "shot_baked.usda")          # sublayers shot.usda: opening it plays
    usd.scene_to_stage("scenes/arch.json", "arch.usda")

From the shell: ``python -m impulse.usd run|export|import`` (docs/usd.md).
"""

from __future__ import annotations

try:
    import pxr  # noqa: F401
except ImportError as error:  # pragma: no cover - depends on the environment
    raise ImportError(
        "impulse.usd needs OpenUSD's Python module pxr: pip install usd-core"
    ) from error

from ._bake import bake
from ._read import load_descriptors, open_stage, stage_to_scene
from ._report import BodyPrim, Issue, Report
from ._write import scene_to_stage

__all__ = [
    "BodyPrim",
    "Issue",
    "Report",
    "bake",
    "load_descriptors",
    "open_stage",
    "scene_to_stage",
    "stage_to_scene",
]
