#!/usr/bin/env bash
# Runs examples/screw_conveyor.toml at several speeds and prints, per speed, the measured mass
# flow rate next to the volumetric estimate (swept volume × fill × speed). The table in
# docs/screw-conveyor.md comes from this script.
#   scripts/screw_conveyor_sweep.sh [RPM ...]        (default: 120 180 240)
# THREADS=n sets the worker threads of each run (default: the scene's), e.g. to run two sweeps
# side by side on two cores; TABLE_ONLY=1 only tabulates runs already in the output folder.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -n "${TABLE_ONLY:-}" ] || cargo build --release --quiet
speeds=("$@")
[ ${#speeds[@]} -eq 0 ] && speeds=(120 180 240)
out=${OUT:-output/screw_conveyor_sweep}
mkdir -p "$out"
# Geometry and material of the example (keep in step with examples/screw_conveyor.toml).
shaft=0.012; flight=0.04; pitch=0.06; density=2600
box_length=0.06; box_side=0.084       # the packing_region round the conveying section
from=1.7                              # averages over [from, end]: once the outflow is steady
echo "| rpm | measured flow [kg/s] | fill (solid fraction of the swept annulus) | volumetric estimate [kg/s] | measured / estimate | drive torque [N m] | drive power [W] |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
for rpm in "${speeds[@]}"; do
  scene="$out/screw_conveyor_$rpm.toml"
  sed "s/rpm = 120.0/rpm = $rpm/" examples/screw_conveyor.toml > "$scene"
  if [ -z "${TABLE_ONLY:-}" ]; then
    ./target/release/polydem run "$scene" --out "$out/run_$rpm" ${THREADS:+--threads "$THREADS"} \
      > "$out/run_$rpm.log" 2>&1
  fi
  # The screw is wall 0; the bodies' torque on it about the axis (tx, the axis being −x) is
  # what the drive must overcome.
  awk -F, -v from="$from" -v rpm="$rpm" -v shaft="$shaft" -v flight="$flight" -v pitch="$pitch" \
      -v density="$density" -v box_length="$box_length" -v box_side="$box_side" '
    FNR == 1 {
      file++
      for (i = 1; i <= NF; i++) {
        if (file == 2 && $i == "packing_fraction") pf = i
        if (file == 3 && $i == "wall0_tx") tx = i
      }
      next
    }
    file == 1 && $1 >= from { if (!t0) { t0 = prev_t; m0 = prev_m } t1 = $1; m1 = $2 }
    file == 1 { prev_t = $1; prev_m = $2 }
    file == 2 && $1 >= from { sum += $pf; n++ }
    file == 3 && $1 >= from { torque += $tx; nt++ }
    END {
      pi = 3.141592653589793
      flow = (m1 - m0) / (t1 - t0)
      annulus = pi * (flight * flight - shaft * shaft)
      fill = (sum / n) * box_side * box_side * box_length / (annulus * box_length)
      estimate = density * fill * annulus * pitch * rpm / 60
      torque /= nt
      printf "| %s | %.4f | %.3f | %.4f | %.2f | %.4f | %.3f |\n", rpm, flow, fill, estimate, \
        flow / estimate, torque, torque * 2 * pi * rpm / 60
    }' "$out/run_$rpm/flow.csv" "$out/run_$rpm/energy.csv" "$out/run_$rpm/wall_forces.csv"
done
