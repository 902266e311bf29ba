#!/usr/bin/env bash
# Side-by-side benchmark of polydem against LIGGGHTS 3.8 (spheres) and Yade (polyhedra), part 7
# of issue #18. On a fresh Debian machine with the Rust toolchain and Python:
#
#   scripts/bench_peers.sh
#
# installs what is missing (liggghts, yade, openmpi-bin from Debian), builds polydem, then runs
# each scene alternately peer, polydem, peer, polydem, ... and prints a Markdown table: per run
# the particle-steps per second of the settled window, the contacts per particle at the end
# (2 × touching body pairs / bodies, counted the same way in each code) and the wall contacts,
# and on polydem's rows the ratio to the peer's run just before it (and to polydem on 1 thread).
# Both codes start from the same bodies: `polydem bench initial` writes them, the peer reads them.
#
# Scenes (bench/*.toml; the peers' inputs are in bench/peers/):
#   spheres_10k, spheres_65k   LIGGGHTS (bench/peers/liggghts/spheres.in): 10,000 steps of 20 us,
#                              window steps 5,000-10,000
#   spheres_10k_rolling        the same with rolling resistance (EPSD2 in both codes; LIGGGHTS
#                              takes the scene's rolling_friction as `-var rolling`)
#   spheres_10k_mesh           the 10k bed in the same box given as one triangle mesh (STL);
#                              LIGGGHTS gets polydem's triangles (mesh/surface, wall/gran mesh)
#   cubes_1k                   Yade (bench/peers/yade/cubes.py): the bed settled by polydem
#                              (10,000 steps of 50 us, untimed) handed over at rest to both
#                              codes, then 300 steps, window steps 100-300 (Yade: ~2 min)
#
# Environment:
#   ROUNDS=2                          alternations per scene and thread count
#   SCENES="spheres_10k cubes_1k"     which scenes (spheres_65k takes about an hour a round)
#   THREADS="1 2"                     threads (polydem, Yade) or MPI ranks (LIGGGHTS)
#   POLYDEM_RANKS=1                   polydem too as MPI ranks of one thread each (issue #17):
#                                     built with `--features mpi`, N > 1 under mpirun, so both
#                                     codes' scaling over ranks shows side by side
#   SPHERE_STEPS=10000 SPHERE_WINDOW=5000   steps, and the step the timed window starts at
#   CUBE_STEPS=300 CUBE_WINDOW=100          (smaller values for a quick check)
#   CUBE_SETTLE=10000                 polydem's untimed settling before the cubes' hand-over
#   OUT=output/bench_peers            where logs, bodies files and results.md go
#   NO_INSTALL=1                      do not install anything
set -euo pipefail
cd "$(dirname "$0")/.."

ROUNDS=${ROUNDS:-2}
SCENES=${SCENES:-spheres_10k cubes_1k}
THREADS=${THREADS:-1 2}
SPHERE_STEPS=${SPHERE_STEPS:-10000}
SPHERE_WINDOW=${SPHERE_WINDOW:-5000}
CUBE_STEPS=${CUBE_STEPS:-300}
CUBE_WINDOW=${CUBE_WINDOW:-100}
CUBE_SETTLE=${CUBE_SETTLE:-10000}
OUT=${OUT:-output/bench_peers}
LIGGGHTS=${LIGGGHTS:-liggghts}
YADE=${YADE:-yade}

# --- Install what is missing -----------------------------------------------------------------
missing=()
command -v "$LIGGGHTS" >/dev/null || missing+=(liggghts)
command -v "$YADE" >/dev/null || missing+=(yade)
command -v mpirun >/dev/null || missing+=(openmpi-bin)
if [ -n "${POLYDEM_RANKS:-}" ]; then
  # rsmpi's build reads the MPI headers with bindgen (as in .ci/mpi)
  command -v mpicc >/dev/null || missing+=(libopenmpi-dev libclang-dev)
fi
if [ ${#missing[@]} -gt 0 ]; then
  if [ -n "${NO_INSTALL:-}" ]; then
    echo "missing: ${missing[*]} (NO_INSTALL is set)" >&2
    exit 1
  fi
  sudo=()
  [ "$(id -u)" -eq 0 ] || sudo=(sudo)
  echo "installing ${missing[*]} ..." >&2
  "${sudo[@]}" apt-get update -q >&2
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -q "${missing[@]}" >&2
fi

features=()
[ -n "${POLYDEM_RANKS:-}" ] && features=(--features mpi)
cargo build --release --quiet "${features[@]}"
POLYDEM=./target/release/polydem
mkdir -p "$OUT"
LIGGGHTS_IN=bench/peers/liggghts/spheres.in
YADE_SCRIPT=bench/peers/yade/cubes.py

# --- One run of each code; each prints "seconds particle_steps_per_s contacts_per_particle
# wall_contacts" --------------------------------------------------------------------------------

# field NAME LINE: the value of NAME=... in a key=value line.
field() { tr ' ' '\n' <<<"$2" | sed -n "s/^$1=//p"; }

run_polydem() { # scene threads steps window_start log settle_steps
  local line launch=("$POLYDEM") threads=$2
  if [ -n "${POLYDEM_RANKS:-}" ]; then
    threads=1
    [ "$2" -gt 1 ] && launch=(mpirun --allow-run-as-root --bind-to none -n "$2" "$POLYDEM")
  fi
  "${launch[@]}" bench scene "bench/$1.toml" --threads "$threads" --steps "$3" --window-start "$4" \
    --settle-steps "$6" >"$5" 2>"$5.err" </dev/null || { cat "$5.err" >&2; return 1; }
  line=$(grep '^polydem ' "$5")
  awk -v t="$(field seconds "$line")" -v pss="$(field particle_steps_per_s "$line")" \
    -v cpp="$(field contacts_per_particle "$line")" -v wall="$(field wall_contacts "$line")" \
    -v rss="$(field rss_bytes_per_body "$line")" \
    'BEGIN { printf "%.2f %.3e %.3f %d %s\n", t, pss, cpp, wall, (rss == "" ? "-" : rss) }'
}

run_liggghts() { # data ranks steps window_start log rolling_friction
  local launch=("$LIGGGHTS") loop line
  [ "$2" -gt 1 ] && launch=(mpirun --allow-run-as-root --bind-to none -n "$2" "$LIGGGHTS")
  # `-screen none` would make LIGGGHTS 3.8 crash reading a mesh (it prints to the screen it has
  # not got): the screen goes to /dev/null instead.
  "${launch[@]}" -in "$LIGGGHTS_IN" -var data "$1" -var settle "$4" -var window "$(($3 - $4))" \
    -var rolling "$6" -log "$5" -screen /dev/null </dev/null || { tail -20 "$5" >&2; return 1; }
  # The second "Loop time of T on P procs for S steps with N atoms" is the window's.
  loop=$(grep '^Loop time of' "$5" | sed -n 2p)
  line=$(grep '^LIGGGHTS_RESULT' "$5")
  awk -v l="$loop" -v cpp="$(field contacts_per_particle "$line")" \
    -v wall="$(field wall_contacts "$line")" 'BEGIN {
      split(l, w, " "); t = w[4]; s = w[9]; n = w[12]
      printf "%.2f %.3e %.3f %d -\n", t, n * s / t, cpp, wall
    }'
}

run_yade() { # bodies threads steps window_start log
  local line
  "$YADE" -n -x -j "$2" -f 2 "$YADE_SCRIPT" "$1" "$3" "$4" >"$5" 2>"$5.err" </dev/null ||
    { tail -20 "$5.err" >&2; return 1; }
  line=$(grep '^YADE_RESULT' "$5")
  awk -v t="$(field seconds "$line")" -v pss="$(field particle_steps_per_s "$line")" \
    -v cpp="$(field contacts_per_particle "$line")" -v wall="$(field wall_contacts "$line")" \
    'BEGIN { printf "%.2f %.3e %.3f %d -\n", t, pss, cpp, wall }'
}

# --- The table ---------------------------------------------------------------------------------
results="$OUT/results.md"
{
  echo "| round | scene | code | threads / ranks | window | window s | particle-steps/s | contacts per particle | wall contacts | polydem RSS bytes/body | polydem / peer | polydem / polydem 1 thread |"
  echo "| ---: | --- | --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
} | tee "$results"

declare -A polydem_one # scene,round -> polydem particle-steps/s on 1 thread
for scene in $SCENES; do
  case "$scene" in
    spheres_*) peer=LIGGGHTS steps=$SPHERE_STEPS window=$SPHERE_WINDOW settle=0 ;;
    cubes_*) peer=Yade steps=$CUBE_STEPS window=$CUBE_WINDOW settle=$CUBE_SETTLE ;;
    *) echo "unknown scene '$scene': spheres_10k, spheres_65k, spheres_10k_rolling, spheres_10k_mesh or cubes_1k" >&2; exit 1 ;;
  esac
  [ -f "bench/$scene.toml" ] || { echo "no bench/$scene.toml" >&2; exit 1; }
  # The scene's rolling friction, for the peer's input (0 where it has none).
  rolling=$(sed -n 's/^rolling_friction *= *\([0-9.eE+-]*\).*/\1/p' "bench/$scene.toml" | head -1)
  rolling=${rolling:-0}
  bodies="$OUT/$scene.bodies"
  echo "$scene: writing the bodies for $peer (settling $settle steps) ..." >&2
  "$POLYDEM" bench initial "bench/$scene.toml" --settle-steps "$settle" --out "$bodies" >&2
  input=$bodies
  if [ "$peer" = LIGGGHTS ]; then
    input="$OUT/$scene.data"
    python3 bench/peers/liggghts/bodies_to_data.py "$bodies" "$input"
  fi
  for round in $(seq 1 "$ROUNDS"); do
    for t in $THREADS; do
      log="$OUT/${scene}_${peer}_${t}_r$round.log"
      echo "round $round: $scene, $peer on $t ..." >&2
      if [ "$peer" = LIGGGHTS ]; then
        res=$(run_liggghts "$input" "$t" "$steps" "$window" "$log" "$rolling")
      else
        res=$(run_yade "$input" "$t" "$steps" "$window" "$log")
      fi
      read -r p_sec p_pss p_cpp p_wall _ <<<"$res"
      echo "| $round | $scene | $peer | $t | $window..$steps | $p_sec | $p_pss | $p_cpp | $p_wall | | | |" |
        tee -a "$results"

      log="$OUT/${scene}_polydem_${t}_r$round.log"
      echo "round $round: $scene, polydem on $t ..." >&2
      res=$(run_polydem "$scene" "$t" "$steps" "$window" "$log" "$settle")
      read -r sec pss cpp wall rss <<<"$res"
      [ "$t" -eq 1 ] && polydem_one[$scene,$round]=$pss
      ratio=$(awk -v a="$pss" -v b="$p_pss" 'BEGIN { printf "%.2f", a / b }')
      scaling=""
      if [ -n "${polydem_one[$scene,$round]:-}" ]; then
        scaling=$(awk -v a="$pss" -v b="${polydem_one[$scene,$round]}" 'BEGIN { printf "%.2f", a / b }')
      fi
      echo "| $round | $scene | polydem | $t | $window..$steps | $sec | $pss | $cpp | $wall | $rss | $ratio | $scaling |" |
        tee -a "$results"
    done
  done
done
echo "table: $results; logs: $OUT" >&2
