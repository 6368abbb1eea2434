#!/usr/bin/env bash
# Compare two builds of collide on this noisy, shared machine: alternate them, one run at a
# time on one core, and report the median and maximum collisions per second of each, and
# the median (with the extremes) of the per-round ratios B/A.
#
#   bash benches/compare.sh BIN_A BIN_B [ROUNDS=8] [N=10000] [TIMED=1000000] [WARMUP=20] [ETA=0.65]
#
# BIN_A and BIN_B are collide binaries (copy target/release/collide aside before rebuilding).
# A single pair of runs proves nothing under about 30 % here; eight rounds resolve about 5 %.
# The order alternates (A first in odd rounds, B first in even ones), and each round's ratio
# compares two runs a second apart, so that the hour's drift cancels from the ratios.
set -euo pipefail
if [ $# -lt 2 ]; then
  sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
a=$1 b=$2 rounds=${3:-8} n=${4:-10000} timed=${5:-1000000} warmup=${6:-20} eta=${7:-0.65}
for bin in "$a" "$b"; do
  [ -x "$bin" ] || { echo "compare.sh: $bin is not an executable collide binary" >&2; exit 2; }
done
pin=()
command -v taskset > /dev/null && pin=(taskset -c 0)
rate() {
  "${pin[@]}" "$1" bench-point --n "$n" --eta "$eta" --warmup "$warmup" --timed "$timed" \
    | sed -n 's/.*"collisions_per_second":\([0-9.e+]*\).*/\1/p'
}
ra=() rb=() ratios=()
for round in $(seq 1 "$rounds"); do
  if [ $((round % 2)) -eq 1 ]; then
    x=$(rate "$a") y=$(rate "$b")
  else
    y=$(rate "$b") x=$(rate "$a")
  fi
  ra+=("$x") rb+=("$y")
  ratios+=("$(awk -v x="$x" -v y="$y" 'BEGIN { printf "%.6f", y / x }')")
done
median() { # name, scale, values...
  local name=$1 scale=$2
  shift 2
  printf '%s\n' "$@" | sort -g | awk -v name="$name" -v scale="$scale" '{ v[NR] = $1 / scale }
    END { m = (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2;
          printf "%-40s median %.3f  min %.3f  max %.3f  (%d runs)\n", name, m, v[1], v[NR], NR }'
}
echo "N = $n, eta = $eta, $timed timed collisions after $warmup per particle (10^6 collisions/s)"
median "$a" 1e6 "${ra[@]}"
median "$b" 1e6 "${rb[@]}"
median "ratio B/A, round by round" 1 "${ratios[@]}"
