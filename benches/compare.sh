#!/usr/bin/env bash
# Compare two builds of collide on this noisy, shared machine: alternate them, one run at a
# time on one core, and report the median and maximum collisions per second of each.
#
#   bash benches/compare.sh BIN_A BIN_B [ROUNDS=8] [N=10000] [TIMED=1000000] [WARMUP=20] [ETA=0.65]
#
# BIN_A and BIN_B are collide binaries (copy target/release/collide aside before rebuilding).
# A single pair of runs proves nothing under about 30 % here; eight rounds resolve about 5 %.
set -euo pipefail
if [ $# -lt 2 ]; then
  sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'
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
ra=() rb=()
for _ in $(seq 1 "$rounds"); do
  ra+=("$(rate "$a")")
  rb+=("$(rate "$b")")
done
summary() {
  printf '%s\n' "${@:2}" | sort -g | awk -v name="$1" '{ v[NR] = $1 / 1e6 }
    END { m = (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2;
          printf "%-40s median %.3f  max %.3f  (10^6 collisions/s, %d runs)\n", name, m, v[NR], NR }'
}
echo "N = $n, eta = $eta, $timed timed collisions after $warmup per particle"
summary "$a" "${ra[@]}"
summary "$b" "${rb[@]}"
