"""The contact sheet: one static HTML page of a search's takes, each with an animated preview
drawn by ``impulse render``, its goals' costs and its perturbation; sorted and filtered in the
page by a few lines of script, opened from disk with no server."""

from __future__ import annotations

import hashlib
import html
import json
import math
import os
import shutil
import subprocess
import sys
from typing import Any

import numpy as np

PREVIEWS_DIR = "previews"


def _cli() -> tuple[list[str], dict[str, str] | None]:
    """The ``impulse`` command, as the start of an argument list, and the environment to run it
    in (None: this process's): ``$IMPULSE_CLI``, else the package's own (``python -m
    impulse._cli`` in a process of its own, so that a crash in it cannot take the caller down,
    with the folder this package was imported from first on ``PYTHONPATH``: the child runs the
    same package even when the caller found it by ``sys.path`` alone), else ``impulse`` on
    ``PATH`` (an embedded interpreter without ``sys.executable``).

    Raises
    ------
    FileNotFoundError
        ``$IMPULSE_CLI`` names no command, or none is found.
    """
    named = os.environ.get("IMPULSE_CLI")
    if named:
        if not os.path.exists(named) and shutil.which(named) is None:
            raise FileNotFoundError(
                f"IMPULSE_CLI = {named!r} names no command: unset it to draw the previews with "
                "the package's own impulse command, or pass previews=False (--no-previews)"
            )
        return [named], None
    if sys.executable:
        import impulse

        package_parent = os.path.dirname(os.path.dirname(os.path.abspath(impulse.__file__)))
        environment = dict(os.environ)
        search_path = environment.get("PYTHONPATH")
        environment["PYTHONPATH"] = (
            package_parent if not search_path else package_parent + os.pathsep + search_path
        )
        return [sys.executable, "-m", "impulse._cli"], environment
    found = shutil.which("impulse")
    if found is None:
        raise FileNotFoundError(
            "the previews are drawn by the impulse command: this interpreter has no "
            "sys.executable to run the package's, and none is on PATH; set IMPULSE_CLI to its "
            "path, or pass previews=False (--no-previews)"
        )
    return [found], None


#: The preview cameras: ``goals`` frames the goal bodies where the goals are judged (the
#: default, :func:`goal_camera`), ``scene``
#: is ``impulse render``'s own view of the moving bodies at step 0.
CAMERAS = ("goals", "scene")
#: Room around what a ``goals`` preview frames: the framed box fits the image's field of view
#: divided by this.
MARGIN = 1.15
#: ``impulse render``'s default field of view (degrees, vertical) and three-quarter view
#: direction, which a ``goals`` camera keeps.
FOV_DEGREES = 40.0
#: The fields of view (degrees, vertical) a ``goals`` camera tries, widest first: a longer
#: lens, seen from farther, draws bodies apart in depth at more nearly one size (two dice
#: on a table), so it frames more goal bodies each :data:`GOAL_PIXELS` across.
FIELDS_OF_VIEW = (FOV_DEGREES, 30.0, 20.0, 15.0, 10.0)
VIEW_DIRECTION = (0.45, 0.5, 1.0)


def _extent(shape: Any) -> float:
    """The radius (m) of a sphere about a body's origin holding its shape (0 when unknown)."""
    if not isinstance(shape, dict):
        return 0.0
    kind = shape.get("type")
    border = float(shape.get("border_radius", 0.0) or 0.0)
    try:
        if kind == "sphere":
            return float(shape["radius"])
        if kind == "cuboid":
            return float(np.linalg.norm(shape["half_extents"])) + border
        if kind == "capsule":
            return float(shape["half_height"]) + float(shape["radius"])
        if kind in ("cylinder", "cone"):
            return math.hypot(float(shape["half_height"]), float(shape["radius"])) + border
        if kind == "convex_hull":
            return float(np.linalg.norm(shape["points"], axis=1).max()) + border
        if kind == "compound":
            return max(
                float(np.linalg.norm(part.get("position", [0.0, 0.0, 0.0])))
                + _extent(part.get("shape"))
                for part in shape["parts"]
            )
    except (KeyError, TypeError, ValueError):
        return 0.0
    return 0.0


#: The goals that read a body's pose at one time (``at``, default the end).
_AT_ONE_TIME = ("ends_inside", "rests_with_axis_up", "tilted")
#: The contact goals, read over a window (``between``, default the whole take) with no place
#: of their own: a ``goals`` camera frames their bodies' paths only when no goal gives a place.
_CONTACTS = ("touches", "never_touches")
#: A goal body's judged place farther than this many times the median distance of them all
#: from their median (a bowling pin knocked into the pit) is left out of a ``goals`` frame.
OUTLIER = 3.0
#: A ``goals`` frame's narrower side is at least this many times the largest goal body's
#: extent (half of it from the centre), so that a lone body is seen with what is around it.
CONTEXT = 3.0
#: The least width and height (pixels) of each goal body a ``goals`` preview frames: the
#: 20 pixels a viewer needs to judge a body, and one for the rasteriser's rounding.
GOAL_PIXELS = 21.0


def goal_views(specs: Any) -> list[tuple[Any, str, Any, Any]]:
    """Where the search's JSON goals are judged, as ``(body, how, when, region)``: ``how`` is
    ``"at"`` (the body at ``when`` s, None: the end; ``ends_inside``, ``rests_with_axis_up``,
    ``tilted``), ``"closest"`` (the body where it comes closest to ``region`` in the window
    ``when``, [t0, t1] s or None for the whole take; ``passes_through``) or ``"path"`` (the
    body over the window ``when``; ``stays_inside``, and ``body`` and ``other`` of ``touches``
    and ``never_touches``). ``region`` is the goal's region (a ``box`` or ``sphere`` mapping)
    or None."""
    views: list[tuple[Any, str, Any, Any]] = []
    for spec in specs or []:
        if not isinstance(spec, dict) or "type" not in spec:
            continue
        kind = spec["type"]
        region = spec.get("region")
        if kind in _AT_ONE_TIME:
            views.append((spec.get("body"), "at", spec.get("at"), region))
        elif kind == "passes_through":
            views.append((spec.get("body"), "closest", spec.get("between"), region))
        elif kind == "stays_inside":
            views.append((spec.get("body"), "path", spec.get("between"), region))
        elif kind in _CONTACTS:
            for field in ("body", "other"):
                if field in spec:
                    views.append((spec[field], "path", spec.get("between"), None))
    return views


def region_box(region: Any) -> tuple[np.ndarray, np.ndarray] | None:
    """The box (low, high; m) holding a goal's region, None when it is not one."""
    if not isinstance(region, dict):
        return None
    try:
        if "box" in region:
            return (
                np.asarray(region["box"]["min"], dtype=float),
                np.asarray(region["box"]["max"], dtype=float),
            )
        if "sphere" in region:
            centre = np.asarray(region["sphere"]["center"], dtype=float)
            radius = float(region["sphere"]["radius"])
            return centre - radius, centre + radius
    except (KeyError, TypeError, ValueError):
        return None
    return None


def region_arguments(views: list[tuple[Any, ...]]) -> list[str]:
    """``impulse render``'s ``--region`` flags outlining the goals' regions (:func:`goal_views`),
    each once."""
    arguments: list[str] = []
    for view in views:
        region = view[3] if len(view) > 3 else None
        flag: str | None = None
        try:
            if isinstance(region, dict) and "box" in region:
                low, high = region["box"]["min"], region["box"]["max"]
                flag = "box:" + ",".join(f"{float(v):.9g}" for v in [*low, *high])
            elif isinstance(region, dict) and "sphere" in region:
                sphere = region["sphere"]
                values = [*sphere["center"], sphere["radius"]]
                flag = "sphere:" + ",".join(f"{float(v):.9g}" for v in values)
        except (KeyError, TypeError, ValueError):
            flag = None
        if flag is not None and flag not in arguments[1::2]:
            arguments += ["--region", flag]
    return arguments


def _outline(shape: Any) -> list[tuple[np.ndarray, float]] | None:
    """A shape as points (n, 3; m, the body's frame) each grown by a radius (m): the shape is
    the convex hull of those balls (a ring of 32 points stands for a circle). None when the
    shape is not one a preview frames by its size (a mesh, a half-space)."""
    if not isinstance(shape, dict):
        return None
    kind = shape.get("type")
    border = float(shape.get("border_radius", 0.0) or 0.0)
    try:
        if kind == "sphere":
            return [(np.zeros((1, 3)), float(shape["radius"]))]
        if kind == "cuboid":
            half = np.asarray(shape["half_extents"], dtype=float)
            corners = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
            return [(corners * half, border)]
        if kind == "capsule":
            height = float(shape["half_height"])
            return [(np.array([[0.0, -height, 0.0], [0.0, height, 0.0]]), float(shape["radius"]))]
        if kind in ("cylinder", "cone"):
            height, radius = float(shape["half_height"]), float(shape["radius"])
            angles = np.linspace(0.0, 2.0 * math.pi, 32, endpoint=False)
            ring = np.stack([radius * np.cos(angles), np.zeros(32), radius * np.sin(angles)], 1)
            top = ring + [0.0, height, 0.0] if kind == "cylinder" else [[0.0, height, 0.0]]
            return [(np.vstack([ring - [0.0, height, 0.0], top]), border)]
        if kind == "convex_hull":
            return [(np.asarray(shape["points"], dtype=float).reshape(-1, 3), border)]
        if kind == "compound":
            outline = []
            for part in shape["parts"]:
                inner = _outline(part.get("shape"))
                if inner is None:
                    return None
                turn = _rotation(part.get("orientation", [0.0, 0.0, 0.0, 1.0]))
                offset = np.asarray(part.get("position", [0.0, 0.0, 0.0]), dtype=float)
                outline += [(points @ turn.T + offset, radius) for points, radius in inner]
            return outline
    except (KeyError, TypeError, ValueError):
        return None
    return None


def _rotation(quaternion: Any) -> np.ndarray:
    """The rotation matrix of a quaternion ``[x, y, z, w]`` (normalised here)."""
    x, y, z, w = np.asarray(quaternion, dtype=float) / np.linalg.norm(quaternion)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _view_axes() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The image's right and up directions and the direction back toward the eye (unit
    vectors, world frame) of a ``goals`` camera (:data:`VIEW_DIRECTION`)."""
    back = np.asarray(VIEW_DIRECTION, dtype=float)
    back /= np.linalg.norm(back)
    right = np.cross([0.0, 1.0, 0.0], back)
    right /= np.linalg.norm(right)
    return right, np.cross(back, right), back


def _drawn_widths(shape: Any, orientations: np.ndarray) -> np.ndarray | None:
    """A body's widths (m) across the image and up it under a ``goals`` camera (seen along
    :data:`VIEW_DIRECTION`, without perspective), the least over its ``orientations`` (n, 4;
    ``[x, y, z, w]``): the sides of the box its picture fills, times the distance's scale.
    None when the shape has no outline (:func:`_outline`)."""
    outline = _outline(shape)
    if outline is None:
        return None
    right, up, _ = _view_axes()
    axes = np.stack([right, up])
    least = np.full(2, math.inf)
    for quaternion in orientations:
        turn = _rotation(quaternion)
        low, high = np.full(2, math.inf), np.full(2, -math.inf)
        for points, radius in outline:
            along = points @ turn.T @ axes.T  # (n, 2): each point across and up the image
            low = np.minimum(low, along.min(axis=0) - radius)
            high = np.maximum(high, along.max(axis=0) + radius)
        least = np.minimum(least, high - low)
    return least


def _judged_boxes(
    record: Any, shapes: list[Any], views: list[tuple[Any, ...]]
) -> tuple[list[tuple[Any, ...]], list[tuple[np.ndarray, np.ndarray]]]:
    """What a ``goals`` camera frames: the boxes of the moving goal bodies where their goals
    are judged, in the goals' order, each as ``(low, high, extent, widths, body, points)``:
    the box (m), the body's extent (m), its drawn widths (:func:`_drawn_widths`, m, or None),
    its index and points (n, 3; m) the picture must hold (the body's outline at one place,
    else the box's corners). A body is taken at its time, or where it comes closest to its region, less those
    far from the rest (:func:`_without_outliers`); or, when no goal judges a body at a place,
    over its window. And the boxes of the goals' regions. Static bodies are left out (the
    ground a ball must touch is everywhere)."""

    def moving(index: int) -> bool:
        return index < len(shapes) and shapes[index].get("kind", "static") != "static"

    placed: list[tuple[Any, ...]] = []
    paths: list[tuple[Any, ...]] = []
    regions: list[tuple[np.ndarray, np.ndarray]] = []
    last = len(record.times) - 1
    for view in views:
        body, how, when = view[:3]
        region = region_box(view[3]) if len(view) > 3 else None
        if region is not None:
            regions.append(region)
        if body is None:
            continue
        index = record.body(body)
        if not moving(index):
            continue
        extent = _extent(shapes[index].get("shape"))
        if how == "at":
            frames = np.array([last]) if when is None else record.window([when, when])[:1]
        elif how == "closest" and region is not None:
            frames = record.window(when)
            centres = record.positions[frames, index]
            gap = np.maximum(np.maximum(region[0] - centres, 0.0), centres - region[1])
            frames = frames[[int(np.argmin(np.linalg.norm(gap, axis=1)))]]
        else:
            frames = record.window(when)
        path = record.positions[frames, index]
        shape = shapes[index].get("shape")
        widths = _drawn_widths(shape, record.orientations[frames, index])
        low, high = path.min(axis=0) - extent, path.max(axis=0) + extent
        points = _corners(low, high)
        outline = _outline(shape)
        if len(frames) == 1 and outline is not None:  # the body itself, not its extent's box
            turn = _rotation(record.orientations[frames[0], index])
            grow = np.vstack([np.eye(3), -np.eye(3)])
            points = np.vstack(
                [(p @ turn.T + path[0])[:, None, :] + r * grow for p, r in outline]
            ).reshape(-1, 3)
        box = (low, high, extent, widths, index, points)
        (paths if how == "path" else placed).append(box)
    return (_without_outliers(placed) or paths), regions


def _without_outliers(boxes: list[tuple[Any, ...]]) -> list[tuple[Any, ...]]:
    """``boxes`` less those whose centre is more than :data:`OUTLIER` times the median distance
    of the centres from their median (and farther than the largest box is wide)."""
    if len(boxes) < 3:
        return boxes
    centres = np.array([0.5 * (box[0] + box[1]) for box in boxes])
    distances = np.linalg.norm(centres - np.median(centres, axis=0), axis=1)
    largest = max(float(np.linalg.norm(box[1] - box[0])) for box in boxes)
    limit = max(OUTLIER * float(np.median(distances)), largest)
    return [box for box, distance in zip(boxes, distances, strict=True) if distance <= limit]


def _corners(low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """The 8 corners (8, 3) of the box from ``low`` to ``high``."""
    return np.array(np.meshgrid(*zip(low, high, strict=True))).reshape(3, -1).T


def _framed(
    corners: np.ndarray,
    size: tuple[int, int],
    margin: float = MARGIN,
    fov: float = FOV_DEGREES,
) -> tuple[np.ndarray, float]:
    """The target (m) and the least distance (m) from it along :data:`VIEW_DIRECTION` at which
    every point of ``corners`` (n, 3; m) is inside the ``size`` (W, H) image shrunk by
    ``margin``, seen with a vertical field of view of ``fov`` degrees. The target is the
    middle of the points across and up the image and in depth, so bodies apart (two dice on
    a table) are framed by their own outlines, not the corners of one box holding them all."""
    right, up, back = _view_axes()
    axes = np.stack([right, up, back])
    along = corners @ axes.T
    centre = 0.5 * (along.min(axis=0) + along.max(axis=0)) @ axes
    tan_y, tan_x = _half_tangents(size, fov)
    distance = 1e-3
    for corner in corners:
        offset = corner - centre
        # A corner at depth d beyond the target (along the view) is in the image when its
        # sideways offsets are within (distance + d) times the half field's tangents.
        depth = -float(offset @ back)
        for side, tangent in ((float(offset @ right), tan_x), (float(offset @ up), tan_y)):
            distance = max(distance, margin * abs(side) / tangent - depth)
    return centre, distance


def _half_tangents(size: tuple[int, int], fov: float = FOV_DEGREES) -> tuple[float, float]:
    """The tangents of half the vertical and horizontal fields of view of a ``size`` image
    whose vertical field of view is ``fov`` degrees."""
    width, height = size
    tan_y = math.tan(0.5 * math.radians(fov))
    return tan_y, tan_y * width / height


def _pixels_per_metre_at_unit_distance(size: tuple[int, int], fov: float) -> float:
    """Pixels a metre across covers at 1 m from the eye (at D m: this over D)."""
    tan_y, tan_x = _half_tangents(size, fov)
    return min(size) / (2.0 * min(tan_x, tan_y))


def _least_pixels(
    boxes: list[tuple[Any, ...]],
    centre: np.ndarray,
    distance: float,
    size: tuple[int, int],
    fov: float,
) -> float:
    """The smallest side (pixels) of the drawn box of any body of ``boxes`` (those with
    widths) seen from ``distance`` m back from ``centre`` with a vertical field of view of
    ``fov`` degrees; infinite when none has widths."""
    scale = _pixels_per_metre_at_unit_distance(size, fov)
    back = _view_axes()[2]
    least = math.inf
    for box in boxes:
        if box[3] is None:
            continue
        depth = distance - float((0.5 * (box[0] + box[1]) - centre) @ back)
        least = min(least, float(min(box[3])) * scale / max(depth, 1e-9))
    return least


def _frame(
    boxes: list[tuple[Any, ...]], size: tuple[int, int], fov: float
) -> tuple[np.ndarray, float]:
    """The target and distance (m) framing ``boxes`` with a vertical field of view of ``fov``
    degrees: as far as keeps them inside the image shrunk by :data:`MARGIN` and a
    :data:`CONTEXT` frame around the largest, unless that draws a body smaller than
    :data:`GOAL_PIXELS`: then nearer, down to the distance that keeps them inside the image
    itself."""
    points = np.vstack([box[5] for box in boxes])
    centre, fitted = _framed(points, size, fov=fov)
    _, bare = _framed(points, size, margin=1.0, fov=fov)
    tan_y, tan_x = _half_tangents(size, fov)
    context = CONTEXT * max(box[2] for box in boxes) / min(tan_x, tan_y)
    preferred = max(fitted, context)
    # The distance at which the smallest body is GOAL_PIXELS: the least of each body's.
    scale = _pixels_per_metre_at_unit_distance(size, fov)
    back = _view_axes()[2]
    needed = math.inf
    for box in boxes:
        if box[3] is not None:
            nearer = float((0.5 * (box[0] + box[1]) - centre) @ back)
            needed = min(needed, float(min(box[3])) * scale / GOAL_PIXELS + nearer)
    return centre, max(bare, min(preferred, needed))


def goal_frame(
    scene: dict[str, Any],
    steps: int,
    views: list[tuple[Any, ...]],
    size: tuple[int, int],
    preset: str | None = None,
) -> tuple[list[float], list[float], float, list[int]] | None:
    """The camera of a ``goals`` preview (eye, target; m; vertical field of view, degrees)
    and the goal bodies it frames (indices): ``impulse render``'s three-quarter view, aimed
    at the goal bodies where their goals are judged (:func:`goal_views`): a body that must
    end somewhere, rest or tilt where it is at the end (or ``at``), a body that must pass
    through a region where it comes closest to it; the paths of the bodies of contact goals
    (``touches``, ``never_touches``) only when no goal judges a body at a place. A place far
    from all the others (:data:`OUTLIER`; a pin knocked into the pit) is left out, and so are
    static bodies (the ground a ball must touch).

    Each framed body's picture is at least :data:`GOAL_PIXELS` wide and high (its outline
    seen along the view, :func:`_drawn_widths`): the bodies are taken in the goals' order, a
    body only when the frame holding it and those before still draws each of them that large
    (the first goal's body always), so ten pins scattered over 2 m show the first goals'
    pins, each large enough to judge. Each of :data:`FIELDS_OF_VIEW` is tried and the first
    framing the most bodies kept (``impulse render``'s 40° when it frames them all). The
    camera is as close as keeps the framed bodies inside the image shrunk by :data:`MARGIN`,
    and no closer than a frame :data:`CONTEXT` times the largest one's extent across (room
    around a lone body), unless a body would then be drawn smaller than :data:`GOAL_PIXELS`
    (:func:`_frame`). The goals' regions are framed too when every framed body still is
    that large. ``None`` when the goals look at no moving body (custom goals only, say)."""
    from impulse.takes._search import simulate_take

    shapes = scene.get("bodies", [])
    if not views:
        return None
    record, _, _ = simulate_take(scene, steps, [], preset)
    boxes, regions = _judged_boxes(record, shapes, views)
    if not boxes:
        return None
    chosen: tuple[int, float, list[tuple[Any, ...]]] | None = None
    for fov in FIELDS_OF_VIEW:
        kept: list[tuple[Any, ...]] = []
        for box in boxes:
            if any(box[4] == other[4] for other in kept):
                kept.append(box)  # the same body judged again: framed as it is
                continue
            trial = kept + [box]
            centre, distance = _frame(trial, size, fov)
            if not kept or _least_pixels(trial, centre, distance, size, fov) >= GOAL_PIXELS:
                kept = trial
        count = len({box[4] for box in kept})
        if chosen is None or count > chosen[0]:
            chosen = (count, fov, kept)
    _, fov, kept = chosen
    centre, distance = _frame(kept, size, fov)
    if regions:
        points = np.vstack([box[5] for box in kept] + [_corners(*region) for region in regions])
        with_regions, farther = _framed(points, size, fov=fov)
        farther = max(farther, distance)
        if _least_pixels(kept, with_regions, farther, size, fov) >= GOAL_PIXELS:
            centre, distance = with_regions, farther
    if not (np.all(np.isfinite(centre)) and math.isfinite(distance)):
        return None
    eye = centre + _view_axes()[2] * distance
    framed = sorted({int(box[4]) for box in kept})
    return [float(v) for v in eye], [float(v) for v in centre], fov, framed


def goal_camera(
    scene: dict[str, Any],
    steps: int,
    views: list[tuple[Any, ...]],
    size: tuple[int, int],
    preset: str | None = None,
) -> tuple[list[float], list[float], float] | None:
    """The camera (eye, target; m; vertical field of view, degrees) of a ``goals`` preview
    (:func:`goal_frame`), None when the goals look at no moving body."""
    framed = goal_frame(scene, steps, views, size, preset)
    return None if framed is None else (framed[0], framed[1], framed[2])


def _size(text: str) -> tuple[int, int]:
    try:
        width, height = (int(part) for part in text.lower().split("x"))
    except ValueError:
        raise ValueError(f"size {text!r}: expected WxH pixels, e.g. 192x144") from None
    if width < 1 or height < 1:
        raise ValueError(f"size {text!r}: width and height must be >= 1")
    return width, height


def _camera_arguments(
    camera: str, take: Any, takes: Any, size: tuple[int, int]
) -> list[str]:
    """``impulse render``'s camera flags for one take's preview."""
    if camera == "scene":
        return []
    if camera == "goals":
        framed = goal_camera(
            take.scene(),
            int(takes.manifest["steps"]),
            goal_views(takes.manifest.get("goals")),
            size,
            takes.manifest.get("preset"),
        )
        if framed is None:
            return []
        eye, target, fov = framed
    else:
        eye_text, _, target_text = camera.partition(":")
        eye = [float(v) for v in eye_text.split(",")]
        target = [float(v) for v in target_text.split(",")]
        fov = FOV_DEGREES
    return [
        "--camera-eye",
        ",".join(f"{v:.9g}" for v in eye),
        "--camera-target",
        ",".join(f"{v:.9g}" for v in target),
        "--fov",
        f"{fov:.9g}",
    ]


def _check_camera(camera: str) -> None:
    if camera in CAMERAS:
        return
    eye, separator, target = camera.partition(":")
    try:
        values = [float(v) for v in eye.split(",")] + [float(v) for v in target.split(",")]
    except ValueError:
        values = []
    if not separator or len(values) != 6 or not all(math.isfinite(v) for v in values):
        raise ValueError(
            f"camera {camera!r}: use goals, scene, or EX,EY,EZ:TX,TY,TZ (the eye and the "
            "target, m)"
        )


def _preview_name(take_id: str, camera: str, size: str, every: int) -> str:
    """A preview's file name: the take and what draws it (the camera, size and frame
    interval), so a sheet drawn another way draws its previews again."""
    key = hashlib.sha256(f"{camera}|{size}|{every}".encode()).hexdigest()[:8]
    return f"{take_id}-{key}.gif"


def sheet(
    out: str | os.PathLike,
    html_path: str | os.PathLike | None = None,
    count: int = 24,
    every: int = 4,
    size: str = "192x144",
    previews: bool = True,
    camera: str = "goals",
) -> str:
    """Writes the contact sheet of the search in ``out`` and returns its path.

    Parameters
    ----------
    out : str | os.PathLike
        A search directory (:func:`impulse.takes.search`'s ``out``).
    html_path : str | os.PathLike, optional
        Where to write the page (default ``out/sheet.html``); previews go to
        ``out/previews/<take_id>.gif`` and are reused when present.
    count : int
        How many takes, best first (:meth:`Takes.best`).
    every : int
        Draw every ``every``-th step in a preview.
    size : str
        Preview size, ``WxH`` pixels.
    previews : bool
        Draw previews with ``impulse render`` (``False``: the page without pictures). The goals'
        regions are outlined in magenta (``impulse render --region``) with any camera.
    camera : str
        ``"goals"`` (frame the goal bodies where their goals are judged, :func:`goal_camera`;
        ``impulse render``'s own view when only custom goals name none), ``"scene"``
        (``impulse render``'s view of the moving bodies at step 0) or ``"EX,EY,EZ:TX,TY,TZ"``
        (eye and target, m). A preview is kept under a name that holds the camera, ``size`` and
        ``every``, so a sheet drawn another way draws its own.

    Raises
    ------
    FileNotFoundError
        ``out`` is not a search, or previews are asked for and the ``impulse`` command is not
        found.
    ValueError
        A bad ``camera``, ``size``, ``count`` or ``every``.
    RuntimeError
        ``impulse render`` failed for a take (its message included).
    """
    from impulse.takes._search import load

    _check_camera(camera)
    pixels = _size(size)
    for name, value in (("count", count), ("every", every)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ValueError(f"{name} = {value!r}: must be an integer >= 1")
    takes = load(out)
    chosen = [take for take in takes.best(count) if take.status == "completed"]
    root = takes.root
    page = os.path.abspath(os.fspath(html_path)) if html_path else os.path.join(root, "sheet.html")
    steps = int(takes.manifest["steps"])
    images: dict[str, str] = {}
    if previews and chosen:
        command, environment = _cli()
        folder = os.path.join(root, PREVIEWS_DIR)
        os.makedirs(folder, exist_ok=True)
        framing = f"{MARGIN} {FIELDS_OF_VIEW} {VIEW_DIRECTION} {OUTLIER} {CONTEXT} {GOAL_PIXELS}"
        # The regions are outlined whatever the camera: part of every key.
        key = (camera if camera != "goals" else f"goals {framing}") + " regions"
        regions = region_arguments(goal_views(takes.manifest.get("goals")))
        for take in chosen:
            gif = os.path.join(folder, _preview_name(take.take_id, key, size, every))
            if not os.path.exists(gif):
                scene = os.path.join(folder, f"{take.take_id}.json")
                take.write_scene(scene)
                preset = takes.manifest.get("preset")
                partial = gif[: -len(".gif")] + ".partial.gif"  # renamed when whole
                arguments = [*command, "render", scene, "--gif", partial, "--steps", str(steps)]
                arguments += ["--every", str(every), "--size", size, "--quiet"]
                arguments += _camera_arguments(camera, take, takes, pixels)
                arguments += regions
                if preset:
                    arguments += ["--preset", preset]
                done = subprocess.run(
                    arguments, capture_output=True, text=True, check=False, env=environment
                )
                if done.returncode != 0:
                    raise RuntimeError(
                        f"impulse render of take {take.take_id} failed: {done.stderr.strip()}"
                    )
                os.replace(partial, gif)
            images[take.take_id] = os.path.relpath(gif, os.path.dirname(page)).replace(os.sep, "/")
    with open(page, "w", encoding="utf-8") as file:
        file.write(_page(takes, chosen, images))
    return page


def _number(value: Any) -> str:
    return "—" if value is None else f"{value:.4g}"


def _page(takes: Any, chosen: list[Any], images: dict[str, str]) -> str:
    names = takes.goal_names
    met = sum(1 for take in takes.values() if take.met)
    cards = []
    for rank, take in enumerate(chosen):
        goal_rows = "".join(
            f"<tr><td>{html.escape(name)}</td><td>{_number(take.costs[name])}</td></tr>"
            for name in names
        )
        image = (
            f'<img src="{html.escape(images[take.take_id])}" alt="take {take.take_id}">'
            if take.take_id in images
            else '<div class="noimage">no preview</div>'
        )
        cost = "" if take.cost is None else f"{take.cost:.17g}"
        cards.append(
            f'<figure class="take{" met" if take.met else ""}" data-take-id="{take.take_id}" '
            f'data-rank="{rank}" data-cost="{cost}" data-perturbation="{take.perturbation:.17g}" '
            f'data-met="{int(take.met)}">{image}<figcaption>'
            f'<code class="id">{take.take_id}</code> '
            f'<button type="button" class="copy" data-copy="{take.take_id}">copy id</button>'
            f"<div>{'every goal met' if take.met else 'not met'} · cost {_number(take.cost)}"
            f" · perturbation {take.perturbation:.3g}</div>"
            f'<table class="goals">{goal_rows}</table></figcaption></figure>'
        )
    summary = (
        f"{len(takes)} takes, {met} meet every goal; showing the best {len(chosen)}. "
        f"Goals: {', '.join(html.escape(n) for n in names)}."
    )
    manifest = html.escape(
        json.dumps({"steps": takes.manifest["steps"], "seed": takes.manifest["seed"]})
    )
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>impulse takes</title>
<style>
body {{ font: 14px system-ui, sans-serif; margin: 1em; }}
#takes {{ display: flex; flex-wrap: wrap; gap: 12px; }}
figure.take {{ margin: 0; padding: 6px; border: 2px solid #ccc; border-radius: 6px; width: 200px; }}
figure.take.met {{ border-color: #2a2; }}
figure.take img, .noimage {{ width: 192px; display: block; background: #eee; min-height: 40px; }}
table.goals {{ font-size: 12px; border-collapse: collapse; }}
table.goals td {{ padding: 0 6px 0 0; }}
.hidden {{ display: none; }}
</style></head>
<body data-search="{manifest}">
<h1>Takes</h1>
<p id="summary">{summary}</p>
<p><label>Sort by <select id="sort">
<option value="cost">cost</option><option value="perturbation">perturbation</option>
<option value="rank">rank</option></select></label>
<label><input type="checkbox" id="only-met"> only takes that meet every goal</label></p>
<div id="takes">
{chr(10).join(cards)}
</div>
<script>
const box = document.getElementById("takes");
function key(card, field) {{
  const v = card.dataset[field];
  return v === "" ? Infinity : Number(v);
}}
function order() {{
  const field = document.getElementById("sort").value;
  const cards = Array.from(box.children);
  cards.sort((a, b) => key(a, field) - key(b, field) || key(a, "rank") - key(b, "rank"));
  cards.forEach(card => box.appendChild(card));
  const onlyMet = document.getElementById("only-met").checked;
  cards.forEach(card => card.classList.toggle("hidden", onlyMet && card.dataset.met !== "1"));
}}
document.getElementById("sort").addEventListener("change", order);
document.getElementById("only-met").addEventListener("change", order);
box.addEventListener("click", event => {{
  const id = event.target.dataset && event.target.dataset.copy;
  if (id && navigator.clipboard) navigator.clipboard.writeText(id);
}});
order();
</script>
</body></html>
"""
