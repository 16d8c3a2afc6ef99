"""What a stage holds that the scene does not, by prim path, and how bodies map to prims."""

from __future__ import annotations

import dataclasses


@dataclasses.dataclass(frozen=True)
class Issue:
    """One thing of the stage the scene does not simulate as authored.

    ``kind`` is ``"dropped"`` (not simulated at all), ``"approximated"`` (simulated
    differently, the message says how) or ``"note"`` (simulated as authored, but worth
    knowing: an implicit choice the reader made).
    """

    path: str
    kind: str
    message: str

    def __str__(self) -> str:
        return f"{self.path}: {self.kind}: {self.message}"


@dataclasses.dataclass(frozen=True)
class BodyPrim:
    """How scene body ``index`` sits on its prim.

    The body's frame is the prim's world frame without its scale, times the offset
    (``offset_position`` in metres and ``offset_orientation`` ``[x, y, z, w]``, both in the
    prim's frame, y up): the reader moves a body's frame onto its one collider so that a
    capsule along z or a box off the prim's origin needs no compound. ``path`` is the prim
    whose transform the bake writes; ``moves`` is false for static bodies (never written).
    """

    index: int
    path: str
    offset_position: tuple[float, float, float]
    offset_orientation: tuple[float, float, float, float]
    moves: bool


@dataclasses.dataclass
class Report:
    """The reader's account of a stage: its units and axes, the bodies' prims, and every
    authored physics property it dropped or approximated, by prim path.

    ``up_axis`` is ``"Y"`` or ``"Z"``; ``meters_per_unit`` and ``kilograms_per_unit`` the
    stage's; ``time_codes_per_second`` and ``start_time_code`` the stage's time codes (the
    bake writes its samples on them).
    """

    up_axis: str = "Y"
    meters_per_unit: float = 1.0
    kilograms_per_unit: float = 1.0
    time_codes_per_second: float = 24.0
    start_time_code: float = 0.0
    end_time_code: float | None = None
    bodies: list[BodyPrim] = dataclasses.field(default_factory=list)
    joints: list[str] = dataclasses.field(default_factory=list)
    issues: list[Issue] = dataclasses.field(default_factory=list)

    def add(self, path: object, kind: str, message: str) -> None:
        """Records an issue of ``kind`` (``dropped``, ``approximated`` or ``note``)."""
        if kind not in ("dropped", "approximated", "note"):
            raise ValueError(f"unknown issue kind {kind!r}")
        self.issues.append(Issue(str(path), kind, message))

    def dropped(self) -> list[Issue]:
        """The issues of what is not simulated at all."""
        return [issue for issue in self.issues if issue.kind == "dropped"]

    def approximated(self) -> list[Issue]:
        """The issues of what is simulated differently from the stage."""
        return [issue for issue in self.issues if issue.kind == "approximated"]

    def for_path(self, path: str) -> list[Issue]:
        """The issues of one prim (and of its properties)."""
        return [issue for issue in self.issues if issue.path == path]

    def __str__(self) -> str:
        head = (
            f"{len(self.bodies)} bodies, {len(self.joints)} joints; up axis {self.up_axis}, "
            f"{self.meters_per_unit:g} m and {self.kilograms_per_unit:g} kg per unit"
        )
        return "\n".join([head, *(str(issue) for issue in self.issues)])
