"""How much of two cores a conservative division of space keeps: a schedule model.

Two cores each own half the box and resolve their own events in order of simulated time.
An event near the border (a fraction `f` of them) may change what the other side reads, so
it starts only once the other core has resolved every event before it (its clock has passed
the event's time) and costs `h` more for the hand-over between the cores. Events arrive on
each side as a Poisson stream of rate 1 in simulated time and cost gamma-distributed work of
mean 1 (coefficient of variation `cv`). Printed: the efficiency, the work divided by twice
the wall time the busier core needs (1 = both cores busy throughout; 0.5 = no gain over one
core). A model, not a measurement: see docs/benchmarks.md, "Against Smallenburg's EDMD, in 3D".

    python3 benches/border_model.py            # the table of docs/benchmarks.md
    python3 benches/border_model.py 0.31 0.2   # one fraction f and hand-over cost h
"""

import bisect
import random
import sys


def efficiency(f, h, cv=0.5, n=50_000, seed=1):
    rng = random.Random(seed)
    k = 1.0 / cv**2
    times, border, cost = [], [], []
    for _ in range(2):
        t, ts, bs, cs = 0.0, [], [], []
        for _ in range(n):
            t += rng.expovariate(1.0)
            ts.append(t)
            bs.append(rng.random() < f)
            cs.append(rng.gammavariate(k, 1.0 / k))
        times.append(ts)
        border.append(bs)
        cost.append(cs)
    done = [0, 0]  # events resolved on each side
    wall = [0.0, 0.0]  # each core's wall clock
    finished = [[0.0] * n, [0.0] * n]  # the wall time each event was resolved
    while done[0] < n or done[1] < n:
        progressed = False
        for a in (0, 1):
            b = 1 - a
            while done[a] < n:
                i = done[a]
                start, work = wall[a], cost[a][i]
                if border[a][i]:
                    # The other side's first event at or after this one's time: once every
                    # event before it is resolved, its clock has passed this time.
                    m = bisect.bisect_left(times[b], times[a][i])
                    if done[b] < m:
                        break  # it is not there yet: let it run
                    start = max(start, finished[b][m - 1] if m > 0 else 0.0)
                    work += h
                wall[a] = start + work
                finished[a][i] = wall[a]
                done[a] += 1
                progressed = True
        assert progressed, "the schedule cannot deadlock: the earliest event can always go"
    return (sum(cost[0]) + sum(cost[1])) / (2.0 * max(wall))


if __name__ == "__main__":
    if len(sys.argv) == 3:
        print(f"{efficiency(float(sys.argv[1]), float(sys.argv[2])):.3f}")
    else:
        print("f \\ h  " + "  ".join(f"{h:5.1f}" for h in (0.0, 0.1, 0.2, 0.3)))
        for f in (0.0, 0.05, 0.31, 0.63, 1.0):
            print(f"{f:5.2f}  " + "  ".join(f"{efficiency(f, h):5.3f}" for h in (0.0, 0.1, 0.2, 0.3)))
