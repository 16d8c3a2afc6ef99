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


#: The preview cameras: ``goals`` frames the goal bodies' paths (the default), ``scene``
#: is ``impulse render``'s own view of the moving bodies at step 0.
CAMERAS = ("goals", "scene")
#: Room around the goal bodies' paths in a ``goals`` preview: the framed sphere's radius is
#: this times the paths' bounding sphere's.
MARGIN = 1.15
#: ``impulse render``'s default field of view (degrees, vertical) and three-quarter view
#: direction, which a ``goals`` camera keeps.
FOV_DEGREES = 40.0
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


#: The goals that read a body's pose at one time (``at``, default the end); the others read it
#: over a window (``between``, default the whole take).
_AT_ONE_TIME = ("ends_inside", "rests_with_axis_up", "tilted")


def goal_views(specs: Any) -> list[tuple[Any, str, Any]]:
    """What the search's JSON goals look at: ``(body, "at", seconds or None)`` for a goal read
    at one time (None: the end) and ``(body, "between", [t0, t1] or None)`` for one read over
    a window (None: the whole take), for ``body`` and ``other``."""
    views: list[tuple[Any, str, Any]] = []
    for spec in specs or []:
        if not isinstance(spec, dict) or "type" not in spec:
            continue
        if spec["type"] in _AT_ONE_TIME:
            when: tuple[str, Any] = ("at", spec.get("at"))
        else:
            when = ("between", spec.get("between"))
        for field in ("body", "other"):
            if field in spec:
                views.append((spec[field], *when))
    return views


def goal_camera(
    scene: dict[str, Any],
    steps: int,
    views: list[tuple[Any, str, Any]],
    size: tuple[int, int],
    preset: str | None = None,
) -> tuple[list[float], list[float]] | None:
    """The camera (eye, target; m) of a ``goals`` preview: ``impulse render``'s three-quarter
    view and field of view, aimed at the centre of the box that holds the moving bodies the
    goals look at (:func:`goal_views`) when they look (at the end for a body that must rest,
    over its window for one that must pass through or touch), each grown by its shape's
    extent, and far enough that the box's bounding sphere, times :data:`MARGIN`, fits the
    ``size`` (W, H) image. Static bodies (the ground a ball must touch) are left out. ``None``
    when the goals look at no moving body (custom goals only, say)."""
    from impulse.takes._search import simulate_take

    shapes = scene.get("bodies", [])
    moving = [
        view
        for view in views
        if not isinstance(view[0], int) or view[0] >= len(shapes) or view[0] < 0
        or shapes[view[0]].get("kind", "static") != "static"
    ]
    if not moving:
        return None
    record, _, _ = simulate_take(scene, steps, [], preset)
    low = np.full(3, np.inf)
    high = np.full(3, -np.inf)
    for body, kind, when in moving:
        index = record.body(body)
        if index < len(shapes) and shapes[index].get("kind", "static") == "static":
            continue
        if kind == "at":
            frames = [len(record.times) - 1] if when is None else record.window([when, when])[:1]
        else:
            frames = record.window(when)
        path = record.positions[frames, index]
        extent = _extent(shapes[index].get("shape")) if index < len(shapes) else 0.0
        low = np.minimum(low, path.min(axis=0) - extent)
        high = np.maximum(high, path.max(axis=0) + extent)
    if not np.all(np.isfinite(low)):
        return None
    centre = 0.5 * (low + high)
    radius = max(MARGIN * 0.5 * float(np.linalg.norm(high - low)), 1e-3)
    width, height = size
    half_y = 0.5 * math.radians(FOV_DEGREES)
    half_x = math.atan(math.tan(half_y) * width / height)
    direction = np.asarray(VIEW_DIRECTION) / np.linalg.norm(VIEW_DIRECTION)
    eye = centre + direction * (radius / math.sin(min(half_x, half_y)))
    return [float(v) for v in eye], [float(v) for v in centre]


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
        eye, target = framed
    else:
        eye_text, _, target_text = camera.partition(":")
        eye = [float(v) for v in eye_text.split(",")]
        target = [float(v) for v in target_text.split(",")]
    return [
        "--camera-eye",
        ",".join(f"{v:.9g}" for v in eye),
        "--camera-target",
        ",".join(f"{v:.9g}" for v in target),
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
        Draw previews with ``impulse render`` (``False``: the page without pictures).
    camera : str
        ``"goals"`` (frame the bodies the goals name on their whole paths, :func:`goal_camera`;
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
        key = camera if camera != "goals" else f"goals {MARGIN} {FOV_DEGREES} {VIEW_DIRECTION}"
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
