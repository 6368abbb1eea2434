#!/usr/bin/env bash
# What a collision costs in instructions, cache misses and mispredicted branches, counted
# rather than timed: collide's spheres (and, with --peer, Smallenburg's EDMD beside them)
# under valgrind's cachegrind.
#
#   benches/count.sh [N ...] [--length L] [--peer EDMD_DIR] [--valgrind PATH]
#
# Counts do not drift with a shared machine's load, so they read a change of a per cent
# that timing cannot; they do not say what a count costs in time (a miss waited for, or
# not) — the rates in docs/benchmarks.md do that. What is counted:
#
# * valgrind simulates no AVX-512, so collide is built for `x86-64-v3` (AVX2 and FMA; the
#   same results bit for bit, fewer lanes per instruction) into target/x86-64-v3, and the
#   peer — with --peer, built by `benches/peer.sh --build-only --march x86-64-v3` outside
#   the repository — for the same;
# * N spheres at η = 0.45 (4k³, the peer's FCC start; default 10976), from the time the
#   peer's comparison starts timing (t = 10, or 5 above 20 000 spheres: 142 or 71
#   collisions a sphere, `benches/peer.sh`): collide equilibrates natively from its FCC
#   start and writes a checkpoint after one more collision (`collide run
#   --interrupt-after 1`), then cachegrind runs `collide run --resume` for L and for 2L
#   collisions (default L = 200 000); the peer runs from that time for about L and 2L;
# * each figure is the difference of the two runs over the collisions between them, so
#   that start-up and warm-up cancel. Caches as this machine's level 1 (data) and level 2
#   (the last level simulated), from /sys, else 48 KiB 12-way and 2 MiB 16-way; the branch
#   model is cachegrind's, simpler than a core's predictor (its mispredictions are an
#   upper bound's kind of figure, for comparing two builds or codes, not cycles).
#
# Needs valgrind 3.20 or later (3.19 stops at an instruction of the `x86-64-v3` build);
# `--valgrind PATH` names one outside PATH (a release unpacked elsewhere needs
# VALGRIND_LIB set to its libexec/valgrind). The native build target/release/collide
# writes the checkpoints: run `cargo build --release --locked` first.
set -euo pipefail

usage() {
  echo "usage: benches/count.sh [N ...] [--length L] [--peer EDMD_DIR] [--valgrind PATH]" >&2
  echo "  N: 4k³ spheres (default 10976); L: collisions between the two runs (default 200000);" >&2
  echo "  EDMD_DIR: a checkout of github.com/FSmallenburg/EDMD, counted beside collide;" >&2
  echo "  PATH: valgrind 3.20 or later (default: valgrind)" >&2
  exit 2
}

root=$(cd "$(dirname "$0")/.." && pwd)
. "$root/benches/spheres.sh"
valgrind=valgrind
length=200000
edmd=
sizes=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --length)
      [[ ${2:-} =~ ^[1-9][0-9]*$ ]] || { echo "count.sh: --length takes a positive count, not '${2:-}'" >&2; exit 2; }
      length=$2; shift 2 ;;
    --peer)
      [[ -f ${2:-}/Single/mdSingle.c ]] ||
        { echo "count.sh: --peer: '${2:-}' has no Single/mdSingle.c (a checkout of FSmallenburg/EDMD?)" >&2; exit 2; }
      edmd=$2; shift 2 ;;
    --valgrind)
      [[ -x ${2:-} ]] || { echo "count.sh: --valgrind: '${2:-}' is not an executable" >&2; exit 2; }
      valgrind=$2; shift 2 ;;
    -h | --help) usage ;;
    *)
      fcc_count count.sh "$1" || { echo "count.sh: '$1' is not a sphere count or an option" >&2; usage; }
      sizes+=("$1"); shift ;;
  esac
done
[[ ${#sizes[@]} -gt 0 ]] || sizes=(10976)

version=$("$valgrind" --version 2>/dev/null) ||
  { echo "count.sh: no valgrind at '$valgrind' (give --valgrind PATH, version 3.20 or later)" >&2; exit 2; }
python3 -c "import sys; v = sys.argv[1].removeprefix('valgrind-').split('.'); sys.exit(0 if (int(v[0]), int(v[1])) >= (3, 20) else 1)" "$version" ||
  { echo "count.sh: $version cannot run the x86-64-v3 build (it stops at a register-form vmovq): 3.20 or later is needed" >&2; exit 2; }
native="$root/target/release/collide"
[[ -x $native ]] || { echo "count.sh: $native not built: run cargo build --release --locked first" >&2; exit 2; }

echo "count.sh: building collide for x86-64-v3 into target/x86-64-v3 ..." >&2
(cd "$root" && RUSTFLAGS="-C target-cpu=x86-64-v3" CARGO_TARGET_DIR="$root/target/x86-64-v3" \
  cargo build --release --locked --quiet --bin collide)
counted="$root/target/x86-64-v3/release/collide"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [[ -n $edmd ]]; then
  bash "$root/benches/peer.sh" "$edmd" --build-only "$work" --march x86-64-v3
fi

# Cache geometry `size,ways,line` of /sys's cache index $1 of cpu0, else $2.
geometry() {
  local d=/sys/devices/system/cpu/cpu0/cache/index$1
  python3 - "$d" "$2" <<'PY'
import sys
d, fallback = sys.argv[1], sys.argv[2]
try:
    read = lambda f: open(f"{d}/{f}").read().strip()
    size = read("size")
    size = int(size[:-1]) * {"K": 1 << 10, "M": 1 << 20}[size[-1]] if size[-1] in "KM" else int(size)
    ways, line = int(read("ways_of_associativity")), int(read("coherency_line_size"))
    sets = size // (ways * line)
    # cachegrind simulates a power-of-two count of sets only.
    print(f"{size},{ways},{line}" if sets > 0 and sets & (sets - 1) == 0 else fallback)
except (OSError, ValueError, KeyError, IndexError):
    print(fallback)
PY
}
d1=$(geometry 0 49152,12,64)
ll=$(geometry 2 2097152,16,64)
cg=("$valgrind" --tool=cachegrind --cache-sim=yes --branch-sim=yes --D1="$d1" --LL="$ll")
pin=()
command -v taskset >/dev/null && pin=(taskset -c 0)

# The totals of a cachegrind output file, as "name=value" words.
totals() {
  python3 - "$1" <<'PY'
import sys
events = summary = None
for line in open(sys.argv[1]):
    if line.startswith("events:"):
        events = line.split()[1:]
    elif line.startswith("summary:"):
        summary = [int(x) for x in line.split()[1:]]
print(" ".join(f"{e}={v}" for e, v in zip(events, summary)))
PY
}

# A table row from two runs' totals and the collisions between them.
row() { # NAME N TOTALS_A TOTALS_B COLLISIONS
  python3 - "$@" <<'PY'
import sys
name, n, a, b, c = sys.argv[1:6]
parse = lambda s: {k: int(v) for k, v in (w.split("=") for w in s.split())}
a, b, c = parse(a), parse(b), int(c)
d = lambda *keys: sum(b[k] - a[k] for k in keys) / c
print(f"| {name} | {n} | {c} | {d('Ir'):.0f} | {d('Dr'):.0f} + {d('Dw'):.0f} | {d('D1mr'):.1f} | {d('DLmr'):.1f} "
      f"| {d('Bc'):.0f} | {d('Bcm', 'Bim'):.1f} |")
PY
}

echo "| code | N | collisions apart | instructions | data reads + writes | level-1 read misses | last-level read misses | conditional branches | mispredicted |"
echo "|---|---|---|---|---|---|---|---|---|"
for n in "${sizes[@]}"; do
  warm=$(start_time "$n")
  per_sphere=$(start_per_sphere "$n")
  runs=()
  # A checkpoint for each run, the same state with a different run length (a resumed run
  # keeps its configuration's length): both runs then start and end the same way.
  for len in "$length" $((2 * length)); do
    cat > "$work/c$len.toml" <<EOF
dimension = 3
seed = 1
[box]
packing_fraction = 0.45
boundary = ["periodic", "periodic", "periodic"]
[[species]]
count = $n
radius = 0.5
mass = 1.0
[init]
placement = "fcc"
[equilibration]
collisions = $((per_sphere * n))
[run]
collisions = $((len + 1))
EOF
    "${pin[@]}" "$native" run "$work/c$len.toml" --out "$work/ck$len" --force --quiet --interrupt-after 1 2>/dev/null || true
    [[ -f $work/ck$len/checkpoint.json ]] || { echo "count.sh: no checkpoint for N = $n" >&2; exit 1; }
    echo "count.sh: collide, N = $n, $len collisions under cachegrind ..." >&2
    "${pin[@]}" "${cg[@]}" --cachegrind-out-file="$work/cg$len" "$counted" run --resume "$work/ck$len/checkpoint.json" \
      --out "$work/r$len" --force --quiet >/dev/null 2>"$work/log$len" ||
      { echo "count.sh: cachegrind failed; its log:" >&2; tail -n 20 "$work/log$len" >&2; exit 1; }
    runs+=("$(totals "$work/cg$len")")
  done
  row collide "$n" "${runs[0]}" "${runs[1]}" "$length"
  if [[ -n $edmd ]]; then
    peer=() done=()
    for len in "$length" $((2 * length)); do
      end=$(end_time "$n" "$len")
      echo "count.sh: the peer, N = $n, about $len collisions under cachegrind ..." >&2
      (cd "$work" && "${pin[@]}" "${cg[@]}" --cachegrind-out-file="$work/cgp$len" ./md "$n" "$warm" "$end" >/dev/null 2>"$work/logp$len") ||
        { echo "count.sh: cachegrind failed on the peer; its log:" >&2; tail -n 20 "$work/logp$len" >&2; exit 1; }
      peer+=("$(totals "$work/cgp$len")")
      done+=("$(sed -n 's/^timed \([0-9]*\) collisions.*/\1/p' "$work/logp$len")")
    done
    row peer "$n" "${peer[0]}" "${peer[1]}" $((done[1] - done[0]))
  fi
done
