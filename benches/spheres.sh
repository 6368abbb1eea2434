# The sphere comparison's shared terms, sourced by benches/peer.sh and benches/count.sh, so
# that both count and time the same stretch of the same runs.
#
# The peer starts from an FCC lattice of 4k³ spheres at η = 0.45, which collide at
# Γ ≈ 28.45 per sphere per unit time: N spheres make about N·Γ/2 collisions a unit time.
GAMMA=28.45

# Exits (status 2) with the reason unless $2 is a sphere count the peer can start from; $1
# names the script for the message.
fcc_count() { # SCRIPT N
  [[ $2 =~ ^[0-9]+$ ]] || return 1
  local k
  k=$(python3 -c "n=$2; k=round((n/4)**(1/3)); print(k if n>0 and 4*k**3==n else 0)")
  [[ $k -gt 0 ]] || { echo "$1: N = $2 is not 4k³ (the peer's FCC start): try 4000, 10976, 32000 or 97556" >&2; exit 2; }
}

# The time from which N spheres are timed and counted: t = 10 up to 20 000 spheres, t = 5
# above (larger systems melt sooner in collisions a sphere).
start_time() { # N
  if [[ $1 -le 20000 ]]; then echo 10; else echo 5; fi
}

# Collisions a sphere up to `start_time` (142 from t = 10, 71 from t = 5): collide's warm-up.
start_per_sphere() { # N
  python3 -c "print(round($(start_time "$1") * $GAMMA / 2))"
}

# The time at which about $2 collisions of N spheres have followed `start_time`, rounded to
# $3 decimals if given.
end_time() { # N COLLISIONS [DIGITS]
  python3 -c "t = $(start_time "$1") + $2 / ($1 * $GAMMA / 2); print(t if '${3:-}' == '' else round(t, int('${3:-0}')))"
}
