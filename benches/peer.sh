#!/usr/bin/env bash
# Spheres against Smallenburg's EDMD, side by side: alternating whole processes of the peer
# and of collide, each timed from inside over its steady state, collisions per second.
#
#   benches/peer.sh EDMD_DIR [N ...] [--rounds R] [--collide PATH] [--threads 2]
#
# EDMD_DIR is a checkout of https://github.com/FSmallenburg/EDMD (F. Smallenburg, Eur.
# Phys. J. E 45, 22 (2022)). Nothing of it enters this repository: its `Single` variant is
# copied to a temporary directory, given a command line and a timer there, and built with
# its own Makefile's flags (`-Ofast -funroll-loops -march=native`).
#
# What is compared (docs/benchmarks.md, "Against Smallenburg's EDMD, in 3D"):
# * the peer: N spheres from its FCC start at η = 0.45, thermostat off; timed from t = 10
#   (N ≤ 20 000) or t = 5 (larger N, which melts sooner in collisions per sphere) for about
#   T collisions (the end time from the collision rate at η = 0.45, Γ ≈ 28.45 per sphere per
#   unit time: T/(NΓ/2));
# * collide: `collide bench-point --dimension 3 --n N --eta 0.45 --warmup W --timed T`, the
#   same N from its own lattice, timed from the same time as the peer: W collisions a sphere
#   of warm-up, the peer's start time times Γ/2 (142 from t = 10, 71 from t = 5), then T
#   timed collisions. Both codes are timed over the same stretch of their trajectories: the
#   clock enters the cost of an event time (early in a run a bracket's ends round to two
#   absolute times more often, and the exact time is pinned), and the melting of the start
#   is over by then.
# T is 3·10⁶ below 50 000 spheres and 2·10⁶ from there on. Each round runs both, the order
# flipped from round to round, pinned to one core where `taskset` exists. The figures to
# read are the ratios within a round: shared machines drift by a fifth within minutes.
#
# With `--threads 2` each round also runs collide in two threads (`bench-point --threads 2`:
# the box in two slabs, a thread each, in the order of time — the same events; pinned to
# cores 0 and 1), timed to the end time T collisions take, and the table gains its rate and
# its ratio to the peer's in the same round. The peer runs in one thread: that column
# compares two cores with one.
#
# N must be 4k³ (the peer's FCC start): 2048, 4000, 10976, 32000, 97556, 256000, ...
#
# `--build-only DIR` builds the edited peer into DIR/md (run as `md N WARM END`) and stops;
# `--march ARCH` builds it for ARCH instead of the Makefile's `native` (`benches/count.sh`
# counts it on `x86-64-v3`, which valgrind simulates).
set -euo pipefail

usage() {
  echo "usage: benches/peer.sh EDMD_DIR [N ...] [--rounds R] [--collide PATH] [--threads 2]" >&2
  echo "  EDMD_DIR: a checkout of github.com/FSmallenburg/EDMD; N: 4k³ spheres (default 10976 97556);" >&2
  echo "  R: rounds per size (default 4); PATH: the collide binary (default target/release/collide);" >&2
  echo "  --threads 2: collide in two threads as well (the peer runs in one)" >&2
  echo "  --build-only DIR: build the edited peer into DIR/md and stop; --march ARCH: build it for ARCH" >&2
  exit 2
}

[[ $# -ge 1 ]] || usage
case "$1" in -h | --help) usage ;; esac
edmd=$1
shift
[[ -f "$edmd/Single/mdSingle.c" && -f "$edmd/Single/Makefile" ]] ||
  { echo "peer.sh: $edmd: no Single/mdSingle.c and Single/Makefile (a checkout of FSmallenburg/EDMD?)" >&2; exit 2; }
root=$(cd "$(dirname "$0")/.." && pwd)
. "$root/benches/spheres.sh"
collide="$root/target/release/collide"
rounds=4
threads=1
sizes=()
build_only=
march=
while [[ $# -gt 0 ]]; do
  case "$1" in
    --rounds)
      [[ ${2:-} =~ ^[1-9][0-9]*$ ]] || { echo "peer.sh: --rounds takes a positive count, not '${2:-}'" >&2; exit 2; }
      rounds=$2; shift 2 ;;
    --collide)
      [[ -x ${2:-} ]] || { echo "peer.sh: --collide: '${2:-}' is not an executable" >&2; exit 2; }
      collide=$2; shift 2 ;;
    --threads)
      [[ ${2:-} == 2 ]] || { echo "peer.sh: --threads takes 2 (collide in two threads as well), not '${2:-}'" >&2; exit 2; }
      threads=2; shift 2 ;;
    --build-only)
      [[ -d ${2:-} ]] || { echo "peer.sh: --build-only: '${2:-}' is not a directory" >&2; exit 2; }
      build_only=$2; shift 2 ;;
    --march)
      [[ ${2:-} =~ ^[A-Za-z0-9_.-]+$ ]] || { echo "peer.sh: --march takes a gcc -march value, not '${2:-}'" >&2; exit 2; }
      march=$2; shift 2 ;;
    -h | --help) usage ;;
    *)
      fcc_count peer.sh "$1" || { echo "peer.sh: '$1' is not a sphere count or an option" >&2; usage; }
      sizes+=("$1"); shift ;;
  esac
done
[[ ${#sizes[@]} -gt 0 ]] || sizes=(10976 97556)
[[ -n $build_only || -x $collide ]] ||
  { echo "peer.sh: $collide not built: run cargo build --release --locked first" >&2; exit 2; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp -r "$edmd/Single" "$work/Single"
# The edits, made to the copy only: η = 0.45 from the FCC start, no thermostat, the sphere
# count and the warm-up and end times from the command line, and a timer between the two
# that prints the timed collisions per second on stderr.
python3 - "$work/Single/mdSingle.c" <<'PY'
import re, sys
path = sys.argv[1]
s = open(path).read()
def sub(pattern, repl):
    global s
    # A function, so that the replacement's backslashes reach the C source as written.
    s, n = re.subn(pattern, lambda m: repl(m) if callable(repl) else repl, s, count=1)
    if n != 1:
        sys.exit(f"peer.sh: the peer's source has changed: no match for {pattern!r} in mdSingle.c")
sub(r"int initialconfig = \d+;", "int initialconfig = 1;")
sub(r"double packfrac = [0-9.]+;", "double packfrac = 0.45;")
sub(r"const int usethermostat = \d+;", "const int usethermostat = 0;")
sub(r"int main\(\)\s*\{\s*init\(\);",
    "#include <time.h>\n"
    "static double peer_wall(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }\n"
    "int main(int argc, char** argv)\n{\n"
    "    if (argc != 4) { fprintf(stderr, \"usage: md N WARM END\\n\"); return 2; }\n"
    "    N = atoi(argv[1]); double peer_warm = atof(argv[2]); maxtime = atof(argv[3]);\n"
    "    init();\n"
    "    while (simtime <= peer_warm) step();\n"
    "    unsigned int peer_c0 = colcounter; double peer_w0 = peer_wall();")
sub(r"(while \(simtime <= maxtime\)\s*\{\s*step\(\);\s*\})",
    lambda m: m.group(1) + "\n    double peer_w1 = peer_wall();\n"
    "    fprintf(stderr, \"timed %u collisions in %.4f s: %.6f M/s\\n\", colcounter - peer_c0, peer_w1 - peer_w0,"
    " (colcounter - peer_c0) / (peer_w1 - peer_w0) / 1e6);")
open(path, "w").write(s)
PY
if [[ -n $march ]]; then
  # The Makefile's flags with the target changed.
  flags=$(sed -n 's/^CFLAGS *= *//p' "$work/Single/Makefile" | sed "s/-march=[^ ]*/-march=$march/")
  make -s -C "$work/Single" CFLAGS="$flags" >/dev/null
else
  make -s -C "$work/Single" >/dev/null
fi
if [[ -n $build_only ]]; then
  cp "$work/Single/md" "$build_only/md"
  exit 0
fi
pin=() pin2=()
command -v taskset >/dev/null && pin=(taskset -c 0) pin2=(taskset -c 0,1)

peer_rate() { # N WARM END
  (cd "$work" && "${pin[@]}" ./Single/md "$1" "$2" "$3" 2>&1 >/dev/null) | sed -n 's/.*: \([0-9.]*\) M\/s$/\1/p'
}
collide_rate() { # N W T [THREADS]
  local threads=${4:-1} cores=("${pin[@]}")
  [[ $threads == 2 ]] && cores=("${pin2[@]}")
  "${cores[@]}" "$collide" bench-point --dimension 3 --n "$1" --eta 0.45 --warmup "$2" --timed "$3" --threads "$threads" |
    python3 -c 'import json, sys; print(json.loads(sys.stdin.read().strip().splitlines()[-1])["collisions_per_second"] / 1e6)'
}

if [[ $threads == 2 ]]; then
  echo "| N | rounds | peer, 10⁶/s: median (range) | collide, 10⁶/s | collide / peer, round by round: median (range) | collide in two threads, 10⁶/s | two threads / peer |"
  echo "|---|---|---|---|---|---|---|"
else
  echo "| N | rounds | peer, 10⁶/s: median (range) | collide, 10⁶/s | collide / peer, round by round: median (range) |"
  echo "|---|---|---|---|---|"
fi
for n in "${sizes[@]}"; do
  if [[ $n -lt 50000 ]]; then timed=3000000; else timed=2000000; fi
  warm=$(start_time "$n")
  end=$(end_time "$n" "$timed" 3)
  per_sphere=$(start_per_sphere "$n")
  peers=() ours=() twos=()
  for ((r = 0; r < rounds; r++)); do
    c2=
    if ((r % 2 == 0)); then
      p=$(peer_rate "$n" "$warm" "$end"); c=$(collide_rate "$n" "$per_sphere" "$timed")
      [[ $threads == 2 ]] && c2=$(collide_rate "$n" "$per_sphere" "$timed" 2)
    else
      [[ $threads == 2 ]] && c2=$(collide_rate "$n" "$per_sphere" "$timed" 2)
      c=$(collide_rate "$n" "$per_sphere" "$timed"); p=$(peer_rate "$n" "$warm" "$end")
    fi
    [[ -n $p && -n $c && ( $threads == 1 || -n $c2 ) ]] || { echo "peer.sh: a run at N = $n gave no rate" >&2; exit 1; }
    echo "  N = $n, round $((r + 1)): peer $p, collide $c${c2:+, collide in two threads $c2}" >&2
    peers+=("$p") ours+=("$c") twos+=("${c2:-0}")
  done
  python3 - "$n" "$threads" "${peers[*]}" "${ours[*]}" "${twos[*]}" <<'PY'
import statistics, sys
n, threads = sys.argv[1], sys.argv[2]
peer, ours, twos = ([float(x) for x in a.split()] for a in sys.argv[3:6])
f = lambda xs, d, bold="": f"{bold}{statistics.median(xs):.{d}f}{bold} ({min(xs):.{d}f}–{max(xs):.{d}f})"
row = f"| {n} | {len(peer)} | {f(peer, 3)} | {f(ours, 3)} | {f([c / p for p, c in zip(peer, ours)], 2, '**')} |"
if threads == "2":
    row += f" {f(twos, 3)} | {f([c / p for p, c in zip(peer, twos)], 2, '**')} |"
print(row)
PY
done
