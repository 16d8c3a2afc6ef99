#!/usr/bin/env python3
"""Medians of several `impulse-bench` runs: each run takes the engines by turns, and the runs
follow one another, so a machine whose speed drifts between runs moves each run's ratios alike
and the median of the runs keeps little of it.

    python3 scripts/bench-medians.py --runs 3 -- pour500 pour2000 scenes/mugs98.json --impulse-fast
    python3 scripts/bench-medians.py --runs 3 -- balls4096 pyramid100 --steps 200
    python3 scripts/bench-medians.py --runs 3 -- pour500 pour2000 --no-rapier --also-threads 2
    python3 scripts/bench-medians.py --self-test

Everything after `--` goes to `impulse-bench` as it is (`--bench` names the binary; by
default `impulse-bench` on the PATH, else `target/release/impulse-bench`). Prints one
Markdown table per table the runs printed: for every row, the median over the runs of its
ms/step (each run's median step), of each ratio column ("time impulse/PEER", a thread
speed-up) and of the end overlap, with each run's value after the median. Every run must
print the same rows (the same scenes, engines and options). `--self-test` checks the table
reading and the medians on tables written here, without running the benchmark.
"""

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

#: Columns whose values are medianed over the runs, with each run's value listed.
MEASURED = ("ms/step", "time impulse/", "speed-up", "end overlap")


def bench_binary(named: str | None) -> str:
    if named:
        return named
    found = shutil.which("impulse-bench")
    if found:
        return found
    local = os.path.join("target", "release", "impulse-bench")
    if os.path.exists(local):
        return local
    sys.exit("no impulse-bench: build it (`cargo build --release -p impulse-bench --features rapier`) or pass --bench")


def tables(markdown: str) -> list[tuple[list[str], list[list[str]]]]:
    """Every Markdown table of `markdown` as (header cells, rows of cells)."""
    found, lines = [], markdown.splitlines()
    k = 0
    while k < len(lines):
        if lines[k].startswith("|") and k + 1 < len(lines) and lines[k + 1].startswith("|---"):
            header = cells(lines[k])
            rows = []
            k += 2
            while k < len(lines) and lines[k].startswith("|"):
                rows.append(cells(lines[k]))
                k += 1
            found.append((header, rows))
        else:
            k += 1
    return found


def cells(line: str) -> list[str]:
    # A settings cell escapes its pipes as `\|`.
    parts = line.strip().strip("|").replace("\\|", "\x00").split("|")
    return [part.strip().replace("\x00", "\\|") for part in parts]


def is_measured(column: str) -> bool:
    return any(column.startswith(prefix) for prefix in MEASURED)


def number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def merged(runs: list[tuple[list[str], list[list[str]]]]) -> str:
    header, first_rows = runs[0]
    for other_header, other_rows in runs[1:]:
        keys = [row[:2] for row in other_rows]
        if other_header != header or keys != [row[:2] for row in first_rows]:
            sys.exit("the runs printed different rows; run the same scenes and options each time")
    kept = [k for k, column in enumerate(header) if k < 2 or is_measured(column)]
    out = ["| " + " | ".join(header[k] for k in kept) + " |", "|" + "|".join("---" for _ in kept) + "|"]
    for r, row in enumerate(first_rows):
        line = []
        for k in kept:
            if k < 2:
                line.append(row[k])
                continue
            values = [number(run_rows[r][k]) for _, run_rows in runs]
            present = [v for v in values if v is not None]
            if not present:
                line.append("")
                continue
            each = ", ".join(run_rows[r][k] for _, run_rows in runs if number(run_rows[r][k]) is not None)
            line.append(f"**{statistics.median(present):.3g}** ({each})")
        out.append("| " + " | ".join(line) + " |")
    return "\n".join(out)


#: The header of `impulse-bench --markdown`'s table with a Rapier row, for `--self-test`.
SELF_TEST_HEADER = (
    "| scene | engine | bodies | steps | ms/step (median) | steps/s | time impulse/rapier | top sink (mm) | "
    "largest overlap (mm) | end overlap (mm) | largest drift (mm) | settings |\n"
    "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n"
)


def self_test_run(impulse_ms: str, ratio: str, rapier_ms: str) -> str:
    """One run's table as `impulse-bench --markdown` writes it (an escaped pipe in a setting)."""
    return (
        SELF_TEST_HEADER
        + f"| pour500 | impulse | 505 | 300 | {impulse_ms} | 333 | {ratio} | 1.0 | 12.1 | 3.26 | 2.0 | PGS, a \\| b |\n"
        + f"| pour500 | rapier | 505 | 300 | {rapier_ms} | 1000 |  | 1.0 | 192.7 | 12.06 | 2.0 | TGS |\n"
    )


def self_test() -> None:
    """Medians of three hand-written runs: each column's own median, an empty ratio cell kept
    empty, an escaped pipe read as part of its cell, and runs with different rows refused."""
    cells_of_runs = [("3.00", "3.00", "1.00"), ("4.00", "2.00", "2.00"), ("3.50", "3.50", "1.00")]
    runs = [tables(self_test_run(*run))[0] for run in cells_of_runs]
    assert runs[0][1][0][-1] == "PGS, a \\| b", runs[0][1][0][-1]
    table = merged(runs).splitlines()
    assert table[0] == "| scene | engine | ms/step (median) | time impulse/rapier | end overlap (mm) |", table[0]
    impulse = "| pour500 | impulse | **3.5** (3.00, 4.00, 3.50) | **3** (3.00, 2.00, 3.50) | **3.26** (3.26, 3.26, 3.26) |"
    assert table[2] == impulse, table[2]
    assert table[3] == "| pour500 | rapier | **1** (1.00, 2.00, 1.00) |  | **12.1** (12.06, 12.06, 12.06) |", table[3]
    other = (runs[0][0], runs[0][1][:1])
    try:
        merged([runs[0], other])
    except SystemExit:
        pass
    else:
        raise AssertionError("runs with different rows were merged")
    print("bench-medians self-test: ok")


def main() -> None:
    if sys.argv[1:] == ["--self-test"]:
        self_test()
        return
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="runs of impulse-bench (default 3)")
    parser.add_argument("--bench", help="the impulse-bench binary")
    parser.add_argument("bench_args", nargs=argparse.REMAINDER, help="-- then impulse-bench's arguments")
    args = parser.parse_args()
    bench_args = args.bench_args[1:] if args.bench_args[:1] == ["--"] else args.bench_args
    if args.runs < 1:
        sys.exit("--runs must be at least 1")
    if "--markdown" in bench_args:
        sys.exit("--markdown is this script's own: leave it out")
    binary = bench_binary(args.bench)
    per_run = []
    with tempfile.TemporaryDirectory() as scratch:
        for run in range(args.runs):
            path = os.path.join(scratch, f"run{run}.md")
            print(f"run {run + 1} of {args.runs}: {binary} {' '.join(bench_args)}", file=sys.stderr)
            done = subprocess.run([binary, *bench_args, "--markdown", path], stdout=subprocess.DEVNULL)
            if done.returncode != 0:
                sys.exit(f"impulse-bench failed (exit {done.returncode}) in run {run + 1}")
            with open(path, encoding="utf-8") as report:
                per_run.append(tables(report.read()))
    counts = {len(found) for found in per_run}
    if len(counts) != 1:
        sys.exit("the runs printed different tables")
    print(f"Medians of {args.runs} runs of `impulse-bench {' '.join(bench_args)}` (each run's value in brackets):\n")
    for t in range(counts.pop()):
        print(merged([found[t] for found in per_run]))
        print()


if __name__ == "__main__":
    main()
