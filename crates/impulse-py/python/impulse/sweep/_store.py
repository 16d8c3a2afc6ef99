"""The sweep's table and files on any pyarrow filesystem: part files, merging, the manifest."""

from __future__ import annotations

import json
import os
import platform
import uuid
from collections.abc import Mapping, Sequence
from typing import Any

from impulse.sweep._constants import (
    _RUN_COLUMNS,
    _TAIL_COLUMNS,
    OBSERVE_PREFIX,
    PARTS_DIR,
    RESULTS_FILE,
)
from impulse.sweep._runs import _canonical_json, _impulse_version


def _filesystem(out: str) -> tuple[Any, str]:
    """pyarrow filesystem and root path of ``out`` (a local path or a URI)."""
    import pyarrow.fs

    out = os.fspath(out)
    if "://" in out:
        filesystem, path = pyarrow.fs.FileSystem.from_uri(out)
        return filesystem, path.rstrip("/")
    return pyarrow.fs.LocalFileSystem(), os.path.abspath(out).replace(os.sep, "/")


def _exists(filesystem: Any, path: str) -> bool:
    import pyarrow.fs

    return filesystem.get_file_info(path).type != pyarrow.fs.FileType.NotFound


def _table(rows: list[dict[str, Any]], override_types: Mapping[str, Any]) -> Any:
    """Rows (dicts) as an Arrow table: fixed columns with fixed types, override columns with
    the grid's types, ``observe`` columns with inferred types (all-null columns stay null-typed
    and are promoted when tables are concatenated)."""
    import pyarrow as pa

    names = ["run_key", *override_types]
    names += [name for name, _ in _RUN_COLUMNS]
    names += sorted({k for row in rows for k in row if k.startswith(OBSERVE_PREFIX)})
    names += [name for name, _ in _TAIL_COLUMNS]
    fixed = {
        "run_key": pa.string(),
        **{n: _arrow_type(t) for n, t in (*_RUN_COLUMNS, *_TAIL_COLUMNS)},
    }
    columns = {}
    for name in names:
        values = [row.get(name) for row in rows]
        if name in override_types:
            kind, arrow_type = override_types[name]
            if kind == "json":
                values = [None if v is None else _canonical_json(v) for v in values]
            columns[name] = pa.array(values, type=arrow_type)
        else:
            columns[name] = pa.array(values, type=fixed.get(name))
    return pa.table(columns)


def _arrow_type(alias: str) -> Any:
    """The Arrow type of a column alias: pyarrow's aliases, and ``list<float32>``."""
    import pyarrow as pa

    if alias == "list<float32>":
        return pa.list_(pa.float32())
    return pa.type_for_alias(alias)


def _override_types(grid: Mapping[str, list[Any]]) -> dict[str, tuple[str, Any]]:
    """Arrow type of each override column: inferred from the grid's values, or JSON text where
    the values have no common Arrow type (a number and a list)."""
    import pyarrow as pa

    types = {}
    for path, values in grid.items():
        try:
            types[path] = ("value", pa.array(values).type)
        except (pa.ArrowInvalid, pa.ArrowTypeError, TypeError):
            types[path] = ("json", pa.string())
    return types


def _read_table(filesystem: Any, path: str) -> Any:
    import pyarrow.parquet as pq

    return pq.read_table(path, filesystem=filesystem)


def _concat(tables: list[Any]) -> Any:
    import pyarrow as pa

    tables = [t for t in tables if t is not None]
    if not tables:
        return None
    if len(tables) == 1:
        return tables[0]
    return pa.concat_tables(tables, promote_options="permissive")


def _reorder_columns(table: Any, overrides_first: Sequence[str]) -> Any:
    """Columns in the order run_key, overrides, run columns, observe columns, tail columns."""
    run = [name for name, _ in _RUN_COLUMNS]
    tail = [name for name, _ in _TAIL_COLUMNS]
    names = table.column_names
    overrides = [n for n in overrides_first if n in names]
    overrides += [
        n
        for n in names
        if n not in overrides
        and n not in run
        and n not in tail
        and n != "run_key"
        and not n.startswith(OBSERVE_PREFIX)
    ]
    observed = sorted(n for n in names if n.startswith(OBSERVE_PREFIX))
    order = [
        "run_key",
        *overrides,
        *[n for n in run if n in names],
        *observed,
        *[n for n in tail if n in names],
    ]
    return table.select(order)


def read_results(out: str) -> Any:
    """The results table of the sweep in ``out`` (a directory or URI): ``results.parquet`` with
    the rows of any runs an interrupted sweep finished but had not merged yet. ``None`` if there
    are none. Each run appears once."""
    filesystem, root = _filesystem(out)
    return _read_all(filesystem, root)


def _part_paths(filesystem: Any, root: str) -> list[str]:
    import pyarrow.fs

    directory = f"{root}/{PARTS_DIR}"
    if not _exists(filesystem, directory):
        return []
    infos = filesystem.get_file_info(pyarrow.fs.FileSelector(directory))
    return sorted(
        i.path for i in infos if i.type == pyarrow.fs.FileType.File and i.path.endswith(".parquet")
    )


def _read_all(filesystem: Any, root: str) -> Any:
    import pyarrow as pa

    tables = []
    results = f"{root}/{RESULTS_FILE}"
    if _exists(filesystem, results):
        tables.append(_read_table(filesystem, results))
    tables += [_read_table(filesystem, p) for p in _part_paths(filesystem, root)]
    table = _concat(tables)
    if table is None:
        return None
    # Each run once, its newest row: a part merged into the results just before a crash appears
    # twice, and a failed run retried has its new row in a later part.
    keys = table.column("run_key").to_pylist()
    newest = {k: i for i, k in enumerate(keys)}
    if len(newest) < len(keys):
        table = table.take(pa.array(sorted(newest.values()), type=pa.int64()))
    return table


def _write_parquet(filesystem: Any, path: str, table: Any) -> None:
    """Writes ``table`` to ``path``, whole or not at all (a temporary file moved in place)."""
    import pyarrow.parquet as pq

    temporary = f"{path}.{uuid.uuid4().hex}.tmp"
    pq.write_table(table, temporary, filesystem=filesystem)
    filesystem.move(temporary, path)


def _write_json(filesystem: Any, path: str, value: Any) -> None:
    text = json.dumps(value, indent=2, sort_keys=False, default=str) + "\n"
    temporary = f"{path}.{uuid.uuid4().hex}.tmp"
    with filesystem.open_output_stream(temporary) as stream:
        stream.write(text.encode())
    filesystem.move(temporary, path)


def _versions(backend: str) -> dict[str, str]:
    versions = {"impulse": _impulse_version(), "python": platform.python_version()}
    for module in ("numpy", "pyarrow", "ray") if backend == "ray" else ("numpy", "pyarrow"):
        try:
            versions[module] = __import__(module).__version__
        except Exception:
            pass
    return versions
