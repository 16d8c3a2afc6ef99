#!/usr/bin/env python3
"""Instructions per step of the functions whose names match a pattern, by kind of instruction.

    python3 scripts/instruction-anatomy.py [--steps N] [--function REGEX] -- IMPULSE ARGS...
    python3 scripts/instruction-anatomy.py --self-test

Runs IMPULSE ARGS under callgrind twice, with `--steps N` and `--steps 2N` appended, and
prints what the extra N steps executed per step inside the machine code of every function
whose demangled name matches REGEX (default: the lanes' sweep kernels), instruction by
instruction, summed by mnemonic and by kind (multiply, add or subtract, select or sign mask,
gather and scatter moves, ...). The difference of the two runs leaves out the scene's set-up
and the first N steps. IMPULSE is an `impulse` binary (a path, or a name on PATH) built with
symbols (the release profile keeps them); ARGS a `run` or `resume` command without `--steps`.

Example (pyramid20 at 3 substeps, the sweep kernels):

    python3 scripts/instruction-anatomy.py --steps 60 -- target/release/impulse run pyramid20 \\
        --no-sleep --threads 1 --substeps 3 --soft-hertz 36 --quiet

Needs valgrind, nm and objdump (binutils). valgrind 3.19 does not decode every x86-64-v3
instruction a build may contain (it stops with SIGILL); `IMPULSE_INSTRUCTION_SET=baseline` in
the environment then runs the baseline kernels, which it decodes. Those are compiled into their
callers, so match the callers: `--function '^impulse::solver::lanes::(schedule|solve)'`.
Functions are attributed by address, so code inlined into a matching function counts as its
own; a matching function's calls to others do not count.
"""

from __future__ import annotations

import argparse
import collections
import os
import re
import shutil
import subprocess
import sys
import tempfile

DEFAULT_FUNCTION = r"lanes::schedule::.*::sweep::with_"

# Kinds of instruction, by mnemonic (VEX and legacy SSE spellings), first match wins.
KINDS = [
    ("multiply", r"^v?mul[sp][sd]$"),
    ("add or subtract", r"^v?(add|sub)[sp][sd]$"),
    ("fused multiply-add", r"^vf(n)?m(add|sub)"),
    ("divide or square root", r"^v?(div|sqrt|rcp|rsqrt)[sp][sd]$"),
    ("min or max", r"^v?(min|max)[sp][sd]$"),
    ("compare", r"^v?cmp"),
    ("select or sign mask", r"^v?(and|andn|or|xor)p[sd]$|^vblendv|^vpternlog"),
    ("lane insert, extract or shuffle", r"^v?(insert|extract|shuf|unpck|perm|movlh|movhl|broadcast|blend)"),
    ("vector move, load or store", r"^v?mov(a|u)p[sd]$|^v?movs[sd]$|^v?movq$|^v?movd$|^v?movsh|^v?movaps"),
    ("prefetch", r"^prefetch"),
    ("branch", r"^j"),
    ("integer and addressing", r"^(mov|lea|add|sub|inc|dec|cmp|test|imul|shl|shr|sar|and|or|xor|cmov|set|movz|movs|neg|not)"),
]


def run_callgrind(command: list[str], steps: int, out: str) -> None:
    subprocess.run(
        ["valgrind", "--tool=callgrind", "--dump-instr=yes", f"--callgrind-out-file={out}"]
        + command
        + ["--steps", str(steps)],
        check=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )


def function_ranges(binary: str, pattern: str) -> list[tuple[int, int, str]]:
    """(start, end, name) of every function symbol of `binary` whose name matches."""
    out = subprocess.run(["nm", "-S", "-C", binary], check=True, capture_output=True, text=True)
    ranges = []
    for line in out.stdout.splitlines():
        parts = line.split(None, 3)
        if len(parts) == 4 and parts[2] in "tTwW" and re.search(pattern, parts[3]):
            start, size = int(parts[0], 16), int(parts[1], 16)
            ranges.append((start, start + size, parts[3]))
    return sorted(ranges)


def costs_by_address(path: str) -> collections.Counter:
    """Instructions executed per address (the first event of a `--dump-instr=yes` file),
    leaving out the lines that give a call's inclusive cost."""
    cost: collections.Counter = collections.Counter()
    address = 0
    after_calls = False
    position = re.compile(r"^(0x[0-9a-f]+|[+-]\d+|\*)$")
    with open(path) as lines:
        for line in lines:
            if line.startswith("calls="):
                after_calls = True
                continue
            # A cost line: "instr-position line-position count" (positions absolute, relative
            # as +n / -n, or * for the same as the line before).
            fields = line.split()
            if len(fields) != 3 or not position.match(fields[0]) or not fields[2].isdigit():
                continue
            where = fields[0]
            if where.startswith("0x"):
                address = int(where, 16)
            elif where[0] in "+-":
                address += int(where)
            if after_calls:
                after_calls = False
                continue
            cost[address] += int(fields[2])
    return cost


def mnemonics(binary: str, ranges: list[tuple[int, int, str]]) -> dict[int, str]:
    """The mnemonic at each instruction address inside `ranges`."""
    found: dict[int, str] = {}
    instruction = re.compile(r"^\s+([0-9a-f]+):\s+(\S+)")
    for start, end, _ in ranges:
        out = subprocess.run(
            ["objdump", "-d", "--no-show-raw-insn", f"--start-address={start:#x}",
             f"--stop-address={end:#x}", binary],
            check=True, capture_output=True, text=True,
        )
        for line in out.stdout.splitlines():
            match = instruction.match(line)
            if match:
                found[int(match.group(1), 16)] = match.group(2)
    return found


def kind_of(mnemonic: str) -> str:
    for kind, pattern in KINDS:
        if re.search(pattern, mnemonic):
            return kind
    return "other"


SELF_TEST_PROFILE = """\
positions: instr line
events: Ir
fn=(1) kernel
0x1000 10 5
+4 * 5
+2 11 7
calls=3 0x2000 20
+3 * 900
+5 * 2
fn=(2) other
0x1000 12 1
-4 * 3
"""


def self_test() -> int:
    """Checks the profile parser (absolute, relative and repeated positions; a call's inclusive
    cost left out) and the kinds of a few mnemonics."""
    with tempfile.TemporaryDirectory() as scratch:
        path = os.path.join(scratch, "profile.out")
        with open(path, "w") as out:
            out.write(SELF_TEST_PROFILE)
        cost = costs_by_address(path)
    expected = {0x1000: 6, 0x1004: 5, 0x1006: 7, 0x100E: 2, 0x0FFC: 3}
    assert dict(cost) == expected, dict(cost)
    kinds = {
        "vmulps": "multiply",
        "vsubps": "add or subtract",
        "vfmadd231ps": "fused multiply-add",
        "vandnps": "select or sign mask",
        "vinsertps": "lane insert, extract or shuffle",
        "vmovaps": "vector move, load or store",
        "prefetcht0": "prefetch",
        "jne": "branch",
        "lea": "integer and addressing",
    }
    for mnemonic, kind in kinds.items():
        assert kind_of(mnemonic) == kind, (mnemonic, kind_of(mnemonic))
    print("instruction-anatomy self-test: ok")
    return 0


def main() -> int:
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=60, help="N: runs of N and 2N steps")
    parser.add_argument("--function", default=DEFAULT_FUNCTION, help="regex on demangled names")
    parser.add_argument("--top", type=int, default=12, help="mnemonics listed")
    parser.add_argument("command", nargs=argparse.REMAINDER, help="-- IMPULSE ARGS...")
    args = parser.parse_args()
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("give the impulse command after --")
    binary = command[0] if os.path.sep in command[0] else shutil.which(command[0])
    if not binary:
        parser.error(f"{command[0]!r} is not on PATH")
    ranges = function_ranges(binary, args.function)
    if not ranges:
        print(f"no function matches {args.function!r} in {binary}", file=sys.stderr)
        return 1
    with tempfile.TemporaryDirectory() as scratch:
        short, long = os.path.join(scratch, "short.out"), os.path.join(scratch, "long.out")
        try:
            run_callgrind(command, args.steps, short)
            run_callgrind(command, 2 * args.steps, long)
        except subprocess.CalledProcessError as error:
            print(f"callgrind failed: {error}", file=sys.stderr)
            if error.returncode == -4:
                print("valgrind could not decode an instruction of the wider kernels; "
                      "IMPULSE_INSTRUCTION_SET=baseline runs the baseline ones", file=sys.stderr)
            return 1
        before, after = costs_by_address(short), costs_by_address(long)
    names = mnemonics(binary, ranges)
    by_mnemonic: collections.Counter = collections.Counter()
    for address, mnemonic in names.items():
        by_mnemonic[mnemonic] += after.get(address, 0) - before.get(address, 0)
    total = sum(by_mnemonic.values()) / args.steps
    if total <= 0:
        print(f"the functions matching {args.function!r} ran no instructions in the extra steps"
              " (the baseline kernels are inlined into their callers: with"
              " IMPULSE_INSTRUCTION_SET=baseline, match those, e.g."
              " --function '^impulse::solver::lanes::(schedule|solve)')", file=sys.stderr)
        return 1
    by_kind: collections.Counter = collections.Counter()
    for mnemonic, count in by_mnemonic.items():
        by_kind[kind_of(mnemonic)] += count
    print(f"{len(ranges)} functions matching {args.function!r}: "
          f"{total / 1e6:.3f} M instructions a step")
    print(f"{'kind':34} {'M/step':>8} {'share':>6}")
    for kind, count in by_kind.most_common():
        per_step = count / args.steps
        print(f"{kind:34} {per_step / 1e6:8.3f} {per_step / total:6.1%}")
    print(f"\n{'mnemonic':34} {'M/step':>8}")
    for mnemonic, count in by_mnemonic.most_common(args.top):
        print(f"{mnemonic:34} {count / args.steps / 1e6:8.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
