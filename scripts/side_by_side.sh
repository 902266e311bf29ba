#!/usr/bin/env bash
# Two polydem binaries on the same scene at the same time, one per core, ROUNDS times: the way to
# compare two builds on a shared machine, whose bursts of foreign load hit both runs of a pair
# alike (alternated runs of one binary vary by ±30 % here; pairs side by side by a few %).
#
#   scripts/side_by_side.sh OLD_BINARY NEW_BINARY SCENE [ROUNDS] [STEPS] [WINDOW_START]
#   scripts/side_by_side.sh old-build/polydem target/release/polydem bench/spheres_65k.toml 2
#
# Prints, per round, both window rates (particle-steps/s) and new/old. Each run has one thread.
set -euo pipefail
if [ $# -lt 3 ]; then
  sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
old=$1 new=$2 scene=$3 rounds=${4:-2} steps=${5:-6000} window=${6:-5000}
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
rate() { grep -o 'particle_steps_per_s=[0-9.e+]*' "$1" | cut -d= -f2; }
for round in $(seq "$rounds"); do
  "$old" bench scene "$scene" --threads 1 --steps "$steps" --window-start "$window" >"$logs/old" 2>&1 &
  "$new" bench scene "$scene" --threads 1 --steps "$steps" --window-start "$window" >"$logs/new" 2>&1 &
  wait
  o=$(rate "$logs/old") n=$(rate "$logs/new")
  python3 -c "print(f'round $round: old {$o/1e6:.2f} M, new {$n/1e6:.2f} M, new/old {$n/$o:.3f}')"
done
