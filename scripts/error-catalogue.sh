#!/usr/bin/env bash
# Prints docs/errors.md's catalogue: each bad input below, run through `impulse run` (or
# `impulse resume`), with the exit status and the first line the command prints on standard
# error.
# Usage: scripts/error-catalogue.sh [path/to/impulse]  (default: target/release/impulse)
set -uo pipefail
bin=${1:-target/release/impulse}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
body='{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5}, "position": [0, 2, 0]}'
ground='{"kind": "static", "shape": {"type": "half_space", "normal": [0, 1, 0]}}'
scene() { printf '{"name": "case", "bodies": [%s, %s]}' "$ground" "$1"; }
case_file() { printf '%s' "$2" > "$dir/$1.json"; echo "$dir/$1.json"; }
row() {
  local what=$1; shift
  local err status
  err=$("$bin" "$@" 2>&1 >/dev/null | grep -v '^$' | head -1)
  "$bin" "$@" >/dev/null 2>&1; status=$?
  err=${err//"$dir/"/}
  printf '| %s | %s | `` %s `` |\n' "$what" "$status" "${err//|/\\|}"
}
echo "| input | exit | message (first line) |"
echo "|---|---:|---|"
row "malformed JSON" run "$(case_file malformed '{"name": "x", "bodies": [')" --steps 1 --quiet
row "unknown field" run "$(case_file unknown "$(scene '{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5}, "colour": "red"}')")" --steps 1 --quiet
row "wrong type" run "$(case_file wrongtype "$(scene '{"kind": "dynamic", "shape": {"type": "sphere", "radius": "big"}}')")" --steps 1 --quiet
row "unknown shape type" run "$(case_file shape "$(scene '{"kind": "dynamic", "shape": {"type": "torus", "radius": 1}}')")" --steps 1 --quiet
row "NaN is not JSON" run "$(case_file nan "$(scene '{"kind": "dynamic", "shape": {"type": "sphere", "radius": NaN}}')")" --steps 1 --quiet
row "negative radius" run "$(case_file radius "$(scene '{"kind": "dynamic", "shape": {"type": "sphere", "radius": -1}}')")" --steps 1 --quiet
row "a box with two zero half extents" run "$(case_file extent "$(scene '{"kind": "dynamic", "shape": {"type": "cuboid", "half_extents": [0.5, 0, 0]}}')")" --steps 1 --quiet
row "a shape larger than 1,000 km" run "$(case_file huge "$(scene '{"kind": "dynamic", "shape": {"type": "cuboid", "half_extents": [2e6, 0.5, 0.5]}}')")" --steps 1 --quiet
row "negative mass" run "$(case_file mass "$(scene '{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5}, "mass": -2}')")" --steps 1 --quiet
row "friction below zero" run "$(case_file friction "$(scene '{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5}, "material": {"friction": -0.1}}')")" --steps 1 --quiet
row "restitution above one" run "$(case_file restitution "$(scene '{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5}, "material": {"restitution": 1.5}}')")" --steps 1 --quiet
row "degenerate hull" run "$(case_file hull "$(scene '{"kind": "dynamic", "shape": {"type": "convex_hull", "points": [[0,0,0],[1,1,1],[2,2,2],[3,3,3]]}}')")" --steps 1 --quiet
row "flat trimesh on a moving body" run "$(case_file dynmesh "$(scene '{"kind": "dynamic", "shape": {"type": "trimesh", "vertices": [[0,0,0],[1,0,0],[0,0,1]], "indices": [[0,2,1]]}}')")" --steps 1 --quiet
row "missing mesh file" run "$(case_file nomesh "$(scene '{"kind": "static", "shape": {"type": "trimesh", "file": "terrain.obj"}}')")" --steps 1 --quiet
printf 'v 0 0 0\nv 1 0 x\nf 1 2 3\n' > "$dir/corrupt.obj"
row "corrupt mesh file" run "$(case_file badmesh "$(scene '{"kind": "static", "shape": {"type": "trimesh", "file": "corrupt.obj"}}')")" --steps 1 --quiet
printf 'v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n' > "$dir/line.obj"
row "degenerate mesh triangle" run "$(case_file flatmesh "$(scene '{"kind": "static", "shape": {"type": "trimesh", "file": "line.obj"}}')")" --steps 1 --quiet
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n' > "$dir/lines.obj"
row "an OBJ of only lines" run "$(case_file linesobj "$(scene '{"kind": "dynamic", "shape": {"type": "trimesh", "file": "lines.obj"}}')")" --steps 1 --quiet
ln -s /dev/zero "$dir/zero.obj"
row "a mesh file linked to /dev/zero" run "$(case_file zeroobj "$(scene '{"kind": "dynamic", "shape": {"type": "trimesh", "file": "zero.obj"}}')")" --steps 1 --quiet
cube='"vertices": [[0,0,0],[1,0,0],[0,1,0],[1,1,0],[0,0,1],[1,0,1],[0,1,1],[1,1,1]], "indices": [[0,2,3],[0,3,1],[4,5,7],[4,7,6],[0,1,5],[0,5,4],[2,6,7],[2,7,3],[0,4,6],[0,6,2],[1,3,7],[1,7,5]]'
row "decomposition max_parts 2147483649" run "$(case_file maxparts "$(scene "{\"kind\": \"dynamic\", \"shape\": {\"type\": \"trimesh\", $cube, \"decomposition\": {\"max_parts\": 2147483649}}}")")" --steps 1 --quiet
row "decomposition resolution 512 on a cube" run "$(case_file resolution "$(scene "{\"kind\": \"dynamic\", \"shape\": {\"type\": \"trimesh\", $cube, \"decomposition\": {\"resolution\": 512}}}")")" --steps 1 --quiet
row "a roughness draw of three numbers" run "$(case_file draws "$(scene '{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5}, "roughness_draws": [[1, 2, 3]]}')")" --steps 1 --quiet
row "an open mesh on a moving body (a warning)" run "$(case_file openmesh "$(scene "{\"kind\": \"dynamic\", \"position\": [0, 2, 0], \"shape\": {\"type\": \"trimesh\", \"vertices\": [[0,0,0],[1,0,0],[0,1,0],[1,1,0],[0,0,1],[1,0,1],[0,1,1],[1,1,1]], \"indices\": [[0,2,3],[0,3,1],[4,5,7],[4,7,6],[0,1,5],[0,5,4],[2,6,7],[2,7,3],[0,4,6],[0,6,2]]}}")")" --steps 1 --quiet
row "half-space on a moving body" run "$(case_file halfspace "$(scene '{"kind": "dynamic", "shape": {"type": "half_space", "normal": [0, 1, 0]}}')")" --steps 1 --quiet
row "keyframes out of order" run "$(case_file keyframes "$(scene '{"kind": "kinematic", "shape": {"type": "cuboid", "half_extents": [1, 0.1, 1]}, "keyframes": [{"t": 2, "position": [0, 1, 0]}, {"t": 1, "position": [0, 2, 0]}]}')")" --steps 1 --quiet
row "keyframes on a dynamic body" run "$(case_file keyed "$(scene '{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5}, "keyframes": [{"t": 1, "position": [0, 1, 0]}]}')")" --steps 1 --quiet
row "unknown locked axis" run "$(case_file axis "$(scene '{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5}, "locked_axes": {"rotation": ["w"]}}')")" --steps 1 --quiet
row "locked axes on a static body" run "$(case_file lockedstatic "$(scene '{"kind": "static", "shape": {"type": "sphere", "radius": 0.5}, "locked_axes": {"translation": ["x"]}}')")" --steps 1 --quiet
row "dt = 0 in the scene" run "$(case_file dt '{"name": "x", "dt": 0, "bodies": []}')" --steps 1 --quiet
row "--dt -0.01" run stack3 --dt -0.01 --steps 1 --quiet
row "--every 0" run stack3 --every 0 --steps 1 --quiet
row "unknown preset" run stack3 --preset q2 --steps 1 --quiet
row "unknown scene" run no_such_scene --steps 1 --quiet
row "missing file" run "$dir/missing.json" --steps 1 --quiet
row "binary file" run /bin/true --steps 1 --quiet
row "truncated file" run "$(case_file truncated '{"name": "x", "bodies": [{"kind": "dynamic", "sha')" --steps 1 --quiet
row "unknown --out extension" run stack3 --steps 1 --quiet --out "$dir/x.txt"
"$bin" run stack3 --steps 5 --quiet --checkpoint-dir "$dir/checkpoints" >/dev/null 2>&1
good="$dir/checkpoints/step-000005.snapshot"
head -c 100 "$good" > "$dir/cut.snapshot"
cp "$good" "$dir/damaged.snapshot"
python3 -c 'import sys; b = bytearray(open(sys.argv[1], "rb").read()); b[-1] ^= 1; open(sys.argv[1], "wb").write(b)' "$dir/damaged.snapshot"
cp "$good" "$dir/newer.snapshot"; printf '\x09' | dd of="$dir/newer.snapshot" bs=1 seek=16 conv=notrunc status=none
row "resume: truncated snapshot" resume "$dir/cut.snapshot" --quiet
row "resume: damaged snapshot" resume "$dir/damaged.snapshot" --quiet
row "resume: not a snapshot" resume "$(case_file scene_not_snapshot '{"name": "x", "bodies": []}')" --quiet
row "resume: another format version" resume "$dir/newer.snapshot" --quiet
row "resume: missing snapshot" resume "$dir/missing.snapshot" --quiet
row "resume: animation output" resume "$good" --steps 1 --quiet --out "$dir/x.glb"
row "--checkpoint-every without --checkpoint-dir" run stack3 --steps 1 --quiet --checkpoint-every 10
row "empty scene (a warning)" run "$(case_file empty '{"name": "empty", "bodies": []}')" --steps 1 --quiet
row "bodies created overlapping (a warning)" run "$(case_file overlap "$(scene "$body, {\"kind\": \"dynamic\", \"shape\": {\"type\": \"sphere\", \"radius\": 0.5}, \"position\": [0, 2.2, 0]}")")" --steps 1 --quiet
row "--threads above 4 per logical CPU" run stack3 --steps 1 --quiet --threads 1000000
row "substeps beyond the maximum" run "$(case_file substeps '{"name": "x", "solver": {"substeps": 4294967295}, "bodies": []}')" --steps 1 --quiet
row "--steps 0" run stack3 --steps 0 --quiet
row "steps: 0 in the scene" run "$(case_file zero '{"name": "zero", "steps": 0, "bodies": []}')" --quiet
row "not a regular file" run /dev/zero --quiet
truncate -s 268435457 "$dir/big.json"
row "scene file over 256 MiB" run "$dir/big.json" --quiet
row "two outputs to one file" run stack3 --steps 1 --quiet --out "$dir/a.csv" --stats "$dir/a.csv"
row "an output over the scene file" run "$(case_file own '{"name": "own", "bodies": []}')" --steps 1 --quiet --summary-json "$dir/own.json"
ln -s /dev/full "$dir/full.csv"
row "a full disk (write error)" run stack3 --steps 1 --quiet --out "$dir/full.csv"
row "resume: snapshot at the run's end" resume "$good" --quiet
python3 -c 'import json, sys; n = 50000; json.dump({"n": n, "a": {"csr": {"indptr": list(range(n + 1)), "indices": list(range(n)), "values": [1.0] * n}}, "b": [1.0] * n}, open(sys.argv[1], "w"))' "$dir/identity.json"
row "lcp solve: Lemke above its size limit" lcp solve "$dir/identity.json" --solver lemke
