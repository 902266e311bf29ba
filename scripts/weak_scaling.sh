#!/usr/bin/env bash
# Weak scaling on two ranks (issue #17), with the machine's own ceiling measured in the same
# rounds. Each round runs, one after the other, on the settled window of the 65,000-sphere bed:
#   alone  one process, one thread, on bench/spheres_65k.toml;
#   pair   two such processes started together, independent (no MPI): what this machine gives
#          two busy cores at that moment (it has given from 1.7x to 2.2x one run alone);
#   ranks  two MPI ranks, one thread each, on bench/spheres_130k.toml (the 65k bed twice: a
#          65k bed's worth per rank), with the ranks' own account of their window.
#
#   POLYDEM=target/release/polydem scripts/weak_scaling.sh [ROUNDS] [STEPS] [WINDOW_START]
#
# POLYDEM must be built with `cargo build --release --features mpi`. Prints, per round, the
# three rates (particle-steps/s over the window), ranks/alone (the issue's weak scaling),
# pair/alone (the machine's ceiling) and ranks/pair (what the decomposition keeps of it).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" = "-h" ] || [ "${1:-}" = "--help" ]; then
  sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'
  exit 0
fi
polydem=${POLYDEM:-target/release/polydem}
rounds=${1:-3} steps=${2:-10000} window=${3:-5000}
command -v mpirun >/dev/null || { echo "mpirun is missing: apt-get install -y openmpi-bin" >&2; exit 2; }
[ -x "$polydem" ] || { echo "$polydem is not built: cargo build --release --features mpi" >&2; exit 2; }
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
bench() { "$@" bench scene "$scene" --threads 1 --steps "$steps" --window-start "$window"; }
rate() { grep -o 'particle_steps_per_s=[0-9.e+]*' "$1" | cut -d= -f2; }
for round in $(seq "$rounds"); do
  scene=bench/spheres_65k.toml
  bench "$polydem" >"$logs/alone" 2>&1 </dev/null
  bench "$polydem" >"$logs/first" 2>&1 </dev/null &
  bench "$polydem" >"$logs/second" 2>&1 </dev/null &
  wait
  scene=bench/spheres_130k.toml
  bench mpirun --allow-run-as-root --bind-to none -np 2 "$polydem" >"$logs/ranks" 2>&1 </dev/null
  a=$(rate "$logs/alone") p1=$(rate "$logs/first") p2=$(rate "$logs/second") r=$(rate "$logs/ranks")
  python3 -c "
a, p, r = $a, $p1 + $p2, $r
print(f'round $round: alone {a/1e6:.2f} M, pair {$p1/1e6:.2f} + {$p2/1e6:.2f} M, ranks {r/1e6:.2f} M; '
      f'ranks/alone {r/a:.2f}, pair/alone {p/a:.2f}, ranks/pair {r/p:.3f}')"
  grep -e "in the window: own step" -e "in the window, candidate lists" "$logs/ranks" | sed 's/^/  /'
done
