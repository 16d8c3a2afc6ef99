#!/usr/bin/env bash
# One table of solver configurations × scenes, from `impulse run --summary-json`.
# Usage: scripts/solver-table.sh [SCENE...]   (writes Markdown to standard output)
# Quality figures (sink, overlap, energy, residual) are deterministic; ms/step depends on load.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q -p impulse-cli
bin=target/release/impulse
scenes=("$@")
if [ ${#scenes[@]} -eq 0 ]; then
  scenes=(pyramid20 stack30 massratio vertical_stack15 mass_ratio_pyramid100 mass_ratio_pyramid300 plate card_house arch overlap_pyramid)
fi
configs=(
  "basic: PGS, 1 solve/step, velocity bias|--preset reference --substeps 1 --relax 0 --method pgs --iterations 20 --repair bias"
  "PGS, 4 substeps, bias + relax|--preset reference --method pgs --repair bias"
  "NNCG, 4 substeps, bias + relax|--preset reference --method nncg --repair bias"
  "PGS, 4 substeps, split impulse|--preset reference --method pgs"
  "NNCG, 4 substeps, split impulse|--preset reference --method nncg"
  "APGD, 4 substeps, split impulse|--preset reference --method apgd"
  "reference: auto (NNCG → exact or more NNCG), split impulse|--preset reference"
  "fast: soft step, 8 substeps|--preset fast"
  "default: soft step, 20 substeps|"
  "precise: soft step, 48 substeps|--preset precise"
)
tmp=$(mktemp -d)
echo "| scene | solver | top sink (mm) | largest overlap (mm) | kinetic energy at 10 s (J) | largest speed (m/s) | largest LCP residual | island solves | ms/step |"
echo "|---|---|---:|---:|---:|---:|---:|---|---:|"
for scene in "${scenes[@]}"; do
  for config in "${configs[@]}"; do
    name=${config%%|*}
    flags=${config#*|}
    # shellcheck disable=SC2086
    if ! "$bin" run "$scene" --quiet --no-sleep $flags --summary-json "$tmp/s.json" >/dev/null 2>"$tmp/err"; then
      status="stopped"
    else
      status=""
    fi
    python3 - "$tmp/s.json" "$scene" "$name" "$status" <<'PY'
import json, sys
path, scene, name, status = sys.argv[1:]
s = json.load(open(path))
note = "" if s["status"] == "completed" else " (" + s["status"] + ")"
solves = ", ".join(f"{k} {v}" for k, v in s["island_solves"].items()
                   if v and k not in ("escalations", "exact_failures"))
if s["island_solves"]["exact_failures"]:
    solves += f" ({s['island_solves']['exact_failures']} exact failed)"
print(f"| {scene} | {name}{note} | {s['top_sink_m']*1e3:.2f} | {s['max_overlap_m']*1e3:.2f} | "
      f"{s['kinetic_energy_j']:.3g} | {s['max_speed_m_s']:.2f} | {s['max_natural_map_residual']:.2e} | {solves} | {s['ms_per_step']:.3f} |")
PY
  done
done
rm -rf "$tmp"
