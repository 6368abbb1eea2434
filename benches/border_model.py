"""How much of two cores a division of space keeps: a schedule model.

Two cores each own half the box and resolve their own events. An event near the border (a
fraction `f` of them) may change what the other side reads, so it starts only once the other
core has resolved every event before it in simulated time, and it costs `h` more for the
hand-over between the cores. Events arrive on each side as a Poisson stream of rate 1 in
simulated time and cost gamma-distributed work of mean 1 (coefficient of variation `cv`).

Two schedules:
* in order: a core resolves its events strictly in order of time, so a waiting border event
  holds up its core (a conservative division);
* overtaking: the events away from the border behind a waiting border event go first — an
  upper bound, as it takes every one of them to be independent of the border events before
  it (in an engine, those that are not would have to wait or be undone).

Printed: the efficiency, the work divided by twice the wall time of the busier core (1: both
cores busy throughout; 0.5: no gain over one core). A model, not a measurement: see
docs/benchmarks.md, "Against Smallenburg's EDMD, in 3D".

    python3 benches/border_model.py                  # the tables of docs/benchmarks.md
    python3 benches/border_model.py 0.31 0.2 [over]  # one fraction f and hand-over cost h
"""

import bisect
import random
import sys

INF = float("inf")


def efficiency(f, h, overtake=False, cv=0.5, n=50_000, seed=1):
    rng = random.Random(seed)
    k = 1.0 / cv**2
    # Each core's events as two streams in order of time, 0 away from the border and 1 at it:
    # their simulated times and their work.
    stimes = [[[], []], [[], []]]
    work = [[[], []], [[], []]]
    for a in range(2):
        t = 0.0
        for _ in range(n):
            t += rng.expovariate(1.0)
            s = int(rng.random() < f)
            stimes[a][s].append(t)
            work[a][s].append(rng.gammavariate(k, 1.0 / k))
    done = [[0, 0], [0, 0]]  # events resolved, per core and stream
    finished = [[[0.0] * len(stimes[a][s]) for s in (0, 1)] for a in range(2)]  # their wall times
    wall = [0.0, 0.0]  # each core's wall clock

    def passed(b, t):
        """The wall time by which core b had resolved all its events before t, or None."""
        w = 0.0
        for s in (0, 1):
            m = bisect.bisect_left(stimes[b][s], t)
            if done[b][s] < m:
                return None
            if m > 0:
                w = max(w, finished[b][s][m - 1])
        return w

    def next_time(a, s):
        d = done[a][s]
        return stimes[a][s][d] if d < len(stimes[a][s]) else INF

    def step(a):
        """Core a resolves one event if it can; whether it did."""
        away, at = next_time(a, 0), next_time(a, 1)
        if away == at == INF:
            return False
        ready = passed(1 - a, at) if at < INF else None
        if at < away and ready is not None and (ready <= wall[a] or not overtake or away == INF):
            s, start = 1, max(wall[a], ready)
        elif away < at or (overtake and away < INF):
            s, start = 0, wall[a]
        else:
            return False  # its next event waits for the other core
        wall[a] = start + work[a][s][done[a][s]] + (h if s else 0.0)
        finished[a][s][done[a][s]] = wall[a]
        done[a][s] += 1
        return True

    while sum(map(sum, done)) < 2 * n:
        a = 0 if wall[0] <= wall[1] else 1
        if not step(a):
            assert step(1 - a), "the schedule cannot deadlock: the earliest event can always go"
    return sum(sum(w) for core in work for w in core) / (2.0 * max(wall))


if __name__ == "__main__":
    if len(sys.argv) >= 3:
        print(f"{efficiency(float(sys.argv[1]), float(sys.argv[2]), len(sys.argv) > 3):.3f}")
    else:
        hs = (0.0, 0.1, 0.2, 0.3)
        for overtake in (False, True):
            print("overtaking" if overtake else "in order")
            print("f \\ h  " + "  ".join(f"{h:5.1f}" for h in hs))
            for f in (0.0, 0.05, 0.31, 0.63, 1.0):
                print(f"{f:5.2f}  " + "  ".join(f"{efficiency(f, h, overtake):5.3f}" for h in hs))
