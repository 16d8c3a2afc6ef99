"""The runs of a sweep: the grid's product with the seeds, and each run's key."""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from impulse.sweep._constants import KEY_VERSION


class Run:
    """One run of a sweep: its overrides (path → value, the grid's order), seed and key."""

    __slots__ = ("overrides", "seed", "key")

    def __init__(self, overrides: dict[str, Any], seed: int, key: str):
        self.overrides = overrides
        self.seed = seed
        self.key = key

    def __repr__(self) -> str:
        return f"Run(overrides={self.overrides!r}, seed={self.seed}, key={self.key[:12]!r}...)"


def _seed_list(seeds: int | Iterable[int]) -> list[int]:
    """``seeds`` as a list: an int N means seeds 0 … N−1; an iterable is taken as it is."""
    if isinstance(seeds, bool):
        raise TypeError("seeds must be an int (a count) or an iterable of ints, not a bool")
    if isinstance(seeds, int):
        if seeds < 1:
            raise ValueError(f"seeds = {seeds}: a sweep needs at least one seed")
        return list(range(seeds))
    out = []
    for seed in seeds:
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0 or seed >= 2**64:
            raise ValueError(f"seed {seed!r} is not an integer in 0 ≤ seed < 2^64")
        out.append(int(seed))
    if not out:
        raise ValueError("seeds is empty: a sweep needs at least one seed")
    return out


def _check_grid(grid: Mapping[str, Sequence[Any]] | None) -> dict[str, list[Any]]:
    if grid is None:
        return {}
    if not isinstance(grid, Mapping):
        raise TypeError("grid must be a mapping of override path -> list of values")
    out = {}
    for path, values in grid.items():
        if not isinstance(path, str) or not path:
            raise ValueError(
                f"grid key {path!r} is not an override path (like 'materials.default.friction')"
            )
        if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
            raise ValueError(f"grid[{path!r}] must be a list of values, got {values!r}")
        values = list(values)
        if not values:
            raise ValueError(f"grid[{path!r}] is empty: the sweep would have no run")
        for value in values:
            try:
                _canonical_json(value)
            except (TypeError, ValueError) as error:
                raise ValueError(f"grid[{path!r}] value {value!r} is not JSON: {error}") from None
        out[path] = values
    return out


def expand(
    grid: Mapping[str, Sequence[Any]] | None, seeds: int | Iterable[int] = 1
) -> list[tuple[dict[str, Any], int]]:
    """The runs of a sweep as ``(overrides, seed)`` pairs: the product of the grid's values (in
    the grid's key order, the last key varying fastest) and the seeds (fastest of all).

    ``grid``: override path → list of values (JSON values: numbers, strings, lists, objects);
    ``None`` or ``{}`` is the scene as it is. ``seeds``: an int N (seeds 0 … N−1) or an iterable
    of ints. Raises ``ValueError`` for an empty value list, a non-JSON value or a bad seed.
    """
    grid = _check_grid(grid)
    seed_list = _seed_list(seeds)
    paths = list(grid)
    return [
        (dict(zip(paths, values, strict=True)), seed)
        for values in itertools.product(*(grid[p] for p in paths))
        for seed in seed_list
    ]


def _canonical_json(value: Any) -> str:
    """JSON with sorted keys and no spaces; numbers as Python prints them (``0.5`` and ``0.50``
    are one value; ``1`` and ``1.0`` are not, as a scene file tells them apart)."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"), allow_nan=False)


def _impulse_version() -> str:
    try:
        import impulse

        version = getattr(impulse, "__version__", None)
        if version:
            return str(version)
    except ImportError:
        pass
    try:
        from importlib.metadata import version

        return version("impulse-contact")
    except Exception:
        return "unknown"


def _normalise_scene(scene: Any) -> tuple[Any, str]:
    """The scene as workers receive it (an absolute path for a file, the name of a built-in, or
    the dict) and a description for the manifest."""
    if isinstance(scene, Mapping):
        return dict(scene), "<dict>"
    if isinstance(scene, os.PathLike) or (isinstance(scene, str) and os.path.exists(scene)):
        path = os.path.abspath(os.fspath(scene))
        if not os.path.isfile(path):
            raise ValueError(f"scene {path}: not a file")
        return path, path
    if isinstance(scene, str):
        return scene, scene
    raise TypeError(
        f"scene must be a file path, a built-in scene name or a dict, not {type(scene).__name__}"
    )


def scene_digest(scene: Any) -> str:
    """SHA-256 (hex) of a scene's content: a file's bytes, a dict's canonical JSON, or for a
    built-in scene its name and the package version (built-in scenes are part of the package).
    Files the scene refers to (meshes) are not hashed."""
    scene, _ = _normalise_scene(scene)
    digest = hashlib.sha256()
    if isinstance(scene, dict):
        digest.update(b"dict\0" + _canonical_json(scene).encode())
    elif os.path.isfile(scene):
        digest.update(b"file\0")
        with open(scene, "rb") as file:
            for block in iter(lambda: file.read(1 << 20), b""):
                digest.update(block)
    else:
        digest.update(f"builtin\0{scene}\0{_impulse_version()}".encode())
    return digest.hexdigest()


def _normalise_jitter(jitter: Mapping[str, float] | None) -> dict[str, float] | None:
    if jitter is None:
        return None
    if not isinstance(jitter, Mapping):
        raise TypeError(
            "jitter must be a mapping with keys 'position' (m), 'angle' (degrees), 'velocity' (m/s)"
        )
    unknown = set(jitter) - {"position", "angle", "velocity"}
    if unknown:
        raise ValueError(
            f"jitter has unknown keys {sorted(unknown)}: use 'position', 'angle', 'velocity'"
        )
    out = {}
    for name in ("position", "angle", "velocity"):
        value = float(jitter.get(name, 0.0))
        if not math.isfinite(value) or value < 0.0:
            raise ValueError(f"jitter[{name!r}] = {value}: must be finite and ≥ 0")
        out[name] = value
    return out if any(out.values()) else None  # zero jitter is no jitter


def run_key(
    digest: str,
    overrides: Mapping[str, Any],
    seed: int,
    steps: int,
    preset: str | None = None,
    jitter: Mapping[str, float] | None = None,
) -> str:
    """The key of one run (SHA-256, hex): a hash of the scene's content (``digest``, from
    :func:`scene_digest`), the overrides (as a set: their order does not matter), the seed, the
    step count and the settings (preset, jitter). Equal keys mean equal simulated results."""
    record = {
        "key_version": KEY_VERSION,
        "scene": digest,
        "overrides": sorted([path, _canonical_json(value)] for path, value in overrides.items()),
        "seed": int(seed),
        "steps": int(steps),
        "preset": preset,
        "jitter": _normalise_jitter(jitter),
    }
    return hashlib.sha256(_canonical_json(record).encode()).hexdigest()
