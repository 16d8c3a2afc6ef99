#!/usr/bin/env bash
# Checks `impulse run --out` animation exports with the real tools:
# - the Khronos glTF-Validator (npm `gltf-validator`) on every .glb and .gltf: no errors;
# - OpenUSD (PyPI `usd-core`) on every .usda: its validators, units, axes, time codes, one
#   Xform per body and every translate/orient sample against the CSV of the same run;
# - Blender (PyPI `bpy`) importing every .glb and .gltf headless: one mesh object per body and its
#   world transform at every written step against the CSV. IMPULSE_CHECK_BLENDER=0 skips it.
#
# Installs what it needs into a scratch directory kept between runs
# (IMPULSE_EXPORT_CHECK_DIR, default $TMPDIR/impulse-export-check). Uses the impulse binary
# at IMPULSE_BIN if set, else builds the release binary.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)
checks="$repo/scripts/export-checks"
scratch=${IMPULSE_EXPORT_CHECK_DIR:-${TMPDIR:-/tmp}/impulse-export-check}
blender=${IMPULSE_CHECK_BLENDER:-1}
mkdir -p "$scratch/node" "$scratch/out"

if [[ -z "${IMPULSE_BIN:-}" ]]; then
  cargo build --release --locked -p impulse-cli --quiet
  IMPULSE_BIN="${CARGO_TARGET_DIR:-$repo/target}/release/impulse"
fi

echo "-- tools"
if [[ ! -d "$scratch/node/node_modules/gltf-validator" ]]; then
  npm install --prefix "$scratch/node" --silent --no-audit --no-fund gltf-validator
fi
if [[ ! -x "$scratch/venv/bin/python" ]]; then
  python3 -m venv "$scratch/venv"
fi
python="$scratch/venv/bin/python"
packages=(usd-core)
if [[ "$blender" != 0 ]]; then
  packages+=(bpy)
fi
"$python" -m pip install --quiet --disable-pip-version-check "${packages[@]}"
echo "gltf-validator $(node -p "require('$scratch/node/node_modules/gltf-validator/package.json').version"), $("$python" -m pip list --disable-pip-version-check 2>/dev/null | grep -E '^(usd-core|bpy) ' | tr -s ' ' | paste -sd, -)"

# scene (built-in name or file), steps, every (60 is no multiple of 7: the last frame is
# written on its own); every standard scene family, a scene of every shape, and the mesh,
# height-field, compound and rounded shapes
runs=(
  "pyramid20 60 7"
  "pyramid3d10 20 10"
  "stack30 30 10"
  "massratio 30 10"
  "balls1k 20 10"
  "scenes/shapes.json 120 10"
  "scenes/example-three-spheres.json 60 1"
  "scenes/mesh_terrain.json 120 10"
  "scenes/compound.json 60 10"
)
glbs=()
failed=0
for run in "${runs[@]}"; do
  read -r scene steps every <<<"$run"
  name=$(basename "$scene" .json)
  out="$scratch/out/$name"
  echo "-- $name: $steps steps, every $every"
  "$IMPULSE_BIN" export "$scene" --out "$out.json"
  for ext in csv glb gltf usda; do
    "$IMPULSE_BIN" run "$scene" --steps "$steps" --every "$every" --threads 1 --quiet \
      --out "$out.$ext" >/dev/null
  done
  glbs+=("$out.glb" "$out.gltf")
  "$python" "$checks/check-usd.py" "$out.usda" "$out.csv" "$out.json" || failed=1
  if [[ "$blender" != 0 ]]; then
    # Blender logs every imported node; keep its verdict and any problem.
    for ext in glb gltf; do
      "$python" "$checks/check-blender.py" "$out.$ext" "$out.csv" "$out.json" 2>&1 \
        | grep -v '| INFO:' || failed=1
    done
  fi
done
echo "-- glTF-Validator"
NODE_PATH="$scratch/node/node_modules" node "$checks/validate-gltf.js" "${glbs[@]}" || failed=1
if [[ "$blender" == 0 ]]; then
  echo "Blender import skipped (IMPULSE_CHECK_BLENDER=0)"
fi
if [[ "$failed" != 0 ]]; then
  echo "export checks failed"
  exit 1
fi
echo "export checks passed"
