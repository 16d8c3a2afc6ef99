"""The contact sheet: one static HTML page of a search's takes, each with an animated preview
drawn by ``impulse render``, its goals' costs and its perturbation; sorted and filtered in the
page by a few lines of script, opened from disk with no server."""

from __future__ import annotations

import html
import json
import os
import shutil
import subprocess
from typing import Any

PREVIEWS_DIR = "previews"


def _cli() -> str:
    """The ``impulse`` command: ``$IMPULSE_CLI``, else on ``PATH``.

    Raises
    ------
    FileNotFoundError
        Neither names a command.
    """
    found = os.environ.get("IMPULSE_CLI") or shutil.which("impulse")
    if not found or not os.path.exists(found) and shutil.which(found) is None:
        raise FileNotFoundError(
            "the previews are drawn by the impulse command: install it (cargo install --path "
            "crates/impulse-cli), or set IMPULSE_CLI to its path, or pass previews=False "
            "(--no-previews)"
        )
    return found


def sheet(
    out: str | os.PathLike,
    html_path: str | os.PathLike | None = None,
    count: int = 24,
    every: int = 4,
    size: str = "192x144",
    previews: bool = True,
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

    Raises
    ------
    FileNotFoundError
        ``out`` is not a search, or previews are asked for and the ``impulse`` command is not
        found.
    RuntimeError
        ``impulse render`` failed for a take (its message included).
    """
    from impulse.takes._search import load

    takes = load(out)
    chosen = [take for take in takes.best(count) if take.status == "completed"]
    root = takes.root
    page = os.path.abspath(os.fspath(html_path)) if html_path else os.path.join(root, "sheet.html")
    steps = int(takes.manifest["steps"])
    images: dict[str, str] = {}
    if previews and chosen:
        command = _cli()
        folder = os.path.join(root, PREVIEWS_DIR)
        os.makedirs(folder, exist_ok=True)
        for take in chosen:
            gif = os.path.join(folder, f"{take.take_id}.gif")
            if not os.path.exists(gif):
                scene = os.path.join(folder, f"{take.take_id}.json")
                take.write_scene(scene)
                preset = takes.manifest.get("preset")
                arguments = [command, "render", scene, "--gif", gif, "--steps", str(steps)]
                arguments += ["--every", str(every), "--size", size, "--quiet"]
                if preset:
                    arguments += ["--preset", preset]
                done = subprocess.run(arguments, capture_output=True, text=True, check=False)
                if done.returncode != 0:
                    raise RuntimeError(
                        f"impulse render of take {take.take_id} failed: {done.stderr.strip()}"
                    )
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
