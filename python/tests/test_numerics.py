"""The numerics through Python: the edge-case reference to the bit, the command line's
answers to the bit on a few thousand adversarial cases, and every refusal.

The command line is ``target/release/collide`` of this checkout (``cargo build --release``),
or the binary named by the environment variable ``COLLIDE_BIN``.
"""

import json
import math
import os
import pathlib
import pickle
import random
import subprocess
import sys

import pytest

import collide

REPO = pathlib.Path(__file__).resolve().parents[2]


def cli():
    path = pathlib.Path(os.environ.get("COLLIDE_BIN", REPO / "target" / "release" / "collide"))
    assert path.exists(), f"{path} is missing: build it with `cargo build --release` (or set COLLIDE_BIN)"
    return str(path)


def bits(x):
    """A float's identity to the bit (``-0.0`` and ``0.0`` differ), or ``None``."""
    return None if x is None else x.hex()


def hexes(values):
    return [v.hex() for v in values]


# ---------------------------------------------------------------------------------------
# The edge-case reference

CASES = collide._collide._reference_cases()


def test_the_reference_is_all_there():
    # The cases of crates/quadratic/src/reference.rs: 16 quadratics, 15 rigid and 10
    # growing contacts (a case left out of the bindings fails here).
    kinds = [kind for kind, *_ in CASES]
    assert (kinds.count("roots"), kinds.count("contact")) == (16, 25)


@pytest.mark.parametrize("kind,name,inputs,exact", CASES, ids=[c[1] for c in CASES])
def test_every_reference_case_is_answered_exactly(kind, name, inputs, exact):
    if kind == "roots":
        got = collide.roots(*inputs)
        if exact is None:
            assert got is collide.EVERY_X
        else:
            assert hexes(got) == hexes(exact)
    else:
        r1, v1, radius1, r2, v2, radius2, g1, g2 = inputs
        got = collide.contact_time(r1, v1, radius1, r2, v2, radius2, g1=g1, g2=g2)
        assert bits(got) == bits(exact)


def test_the_docstring_examples():
    assert collide.roots(1, -3, 2) == [1.0, 2.0]
    assert collide.roots(1, 0, 1) == []
    assert collide.roots(0, 0, 0) is collide.EVERY_X
    assert collide.roots(0, 0, 1) == []  # no x: distinct from every x
    assert collide.roots(1, -1e8, 1) == [1e-08, 1e8 - 1e-8]
    assert collide.contact_time([0, 0], [1, 0], 0.5, [3, 0], [-1, 0], 0.5) == 1.0
    assert collide.contact_time([0, 0, 0], [0, 0, 0], 0.5, [3, 0, 0], [0, 0, 0], 0.5) is None
    # Growth alone closes a gap of 2 at G = 1: t = 2.
    assert collide.contact_time([0, 0], [0, 0], 0.5, [3, 0], [0, 0], 0.5, g1=0.5, g2=0.5) == 2.0
    # Touching and approaching: now.
    assert collide.contact_time([0, 0], [0, 0], 0.5, [1, 0], [-1, 0], 0.5) == 0.0


def test_numpy_arrays_are_vectors():
    np = pytest.importorskip("numpy")
    t = collide.contact_time(np.zeros(3), np.array([1.0, 0, 0]), 0.5, np.array([3.0, 0, 0]), np.zeros(3), 0.5)
    assert t == 2.0


# ---------------------------------------------------------------------------------------
# The same answers as the command line, bit for bit


def scale(rng):
    return math.ldexp(rng.uniform(0.5, 1.0), rng.randint(-60, 60)) * rng.choice((-1.0, 1.0))


def root_cases(rng, n):
    cases = []
    for k in range(n):
        family = k % 4
        if family == 0:  # anything, over a wide range of scales
            a, b, c = scale(rng), scale(rng), scale(rng)
        elif family == 1:  # near-double roots: b² ≈ 4ac
            a, x = scale(rng), scale(rng)
            b = -2.0 * a * x
            c = a * x * x * (1.0 + rng.choice((-1.0, 1.0)) * math.ldexp(1.0, -rng.randint(20, 60)))
        elif family == 2:  # cancellation: one root far smaller than the other
            a, b, c = 1.0, scale(rng) * 1e8, scale(rng)
        else:  # a zero coefficient, or extreme exponents
            a, b, c = (rng.choice((0.0, -0.0, scale(rng))) for _ in range(3))
            if rng.random() < 0.5:
                a, c = math.ldexp(a, rng.randint(-900, 900)), math.ldexp(c, rng.randint(-900, 900))
        cases.append([a, b, c])
    return cases


def contact_cases(rng, n):
    cases = []
    for k in range(n):
        d = 2 + k % 2
        radius1, radius2 = rng.uniform(0.3, 0.7), rng.uniform(0.3, 0.7)
        sigma = radius1 + radius2
        direction = [rng.gauss(0, 1) for _ in range(d)]
        norm = math.sqrt(sum(x * x for x in direction))
        # Gaps from ulps to a diameter, a few overlaps.
        gap = sigma * rng.choice((0.0, math.ldexp(1.0, -rng.randint(1, 52)), -math.ldexp(1.0, -rng.randint(40, 53))))
        r1 = [rng.uniform(-10, 10) for _ in range(d)]
        r2 = [x + (sigma + gap) * u / norm for x, u in zip(r1, direction)]
        v1 = [rng.gauss(0, 1) for _ in range(d)]
        v2 = [rng.gauss(0, 1) for _ in range(d)]
        g1, g2 = (0.0, 0.0) if k % 3 else (abs(rng.gauss(0, 0.5)), abs(rng.gauss(0, 0.5)))
        cases.append([r1, v1, radius1, r2, v2, radius2, g1, g2])
    return cases


def ask(command, requests):
    text = "".join(json.dumps(r) + "\n" for r in requests)
    done = subprocess.run([cli(), command, "--jsonl", "--hex"], input=text, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    answers = [json.loads(line) for line in done.stdout.splitlines()]
    assert len(answers) == len(requests), done.stderr
    return {a["id"]: a for a in answers}


def number(text):
    return float(text) if text in ("inf", "-inf") else float.fromhex(text)


def test_roots_agree_with_the_command_line():
    rng = random.Random(2026)
    cases = root_cases(rng, 3000) + [inputs for kind, _, inputs, _ in CASES if kind == "roots"]
    answers = ask("roots", [{"id": k, "a": a.hex(), "b": b.hex(), "c": c.hex()} for k, (a, b, c) in enumerate(cases)])
    for k, (a, b, c) in enumerate(cases):
        got = collide.roots(a, b, c)
        expected = answers[k]
        if expected.get("all"):
            assert got is collide.EVERY_X, (a, b, c)
        else:
            assert hexes(got) == hexes([number(x) for x in expected["roots"]]), (a.hex(), b.hex(), c.hex())


def test_contact_times_agree_with_the_command_line():
    rng = random.Random(2027)
    cases = contact_cases(rng, 3000) + [inputs for kind, _, inputs, _ in CASES if kind == "contact"]
    requests = []
    for k, (r1, v1, radius1, r2, v2, radius2, g1, g2) in enumerate(cases):
        requests.append({
            "id": k, "r1": hexes(r1), "v1": hexes(v1), "R1": radius1.hex(),
            "r2": hexes(r2), "v2": hexes(v2), "R2": radius2.hex(), "g1": g1.hex(), "g2": g2.hex(),
        })
    answers = ask("contact-time", requests)
    kinds = {"never": 0, "now": 0, "later": 0}
    for k, (r1, v1, radius1, r2, v2, radius2, g1, g2) in enumerate(cases):
        got = collide.contact_time(r1, v1, radius1, r2, v2, radius2, g1=g1, g2=g2)
        t = answers[k]["t"]
        assert bits(got) == bits(None if t is None else number(t)), requests[k]
        kinds["never" if got is None else "now" if got == 0 else "later"] += 1
    # The families reach every class.
    assert min(kinds.values()) >= 100, kinds


# ---------------------------------------------------------------------------------------
# Refusals


@pytest.mark.parametrize("a,b,c,named", [
    (math.nan, 1.0, 1.0, "a = NaN"),
    (1.0, math.inf, 1.0, "b = inf"),
    (1.0, 1.0, -math.inf, "c = -inf"),
])
def test_non_finite_coefficients_are_refused(a, b, c, named):
    with pytest.raises(ValueError, match=named):
        collide.roots(a, b, c)


@pytest.mark.parametrize("args,kwargs,message", [
    (([0, 0], [1, 0, 0], 0.5, [3, 0], [-1, 0], 0.5), {}, "v1 has 3 components but r1 has 2"),
    (([0, 0, 0, 0], [1, 0, 0, 0], 0.5, [3, 0, 0, 0], [-1, 0, 0, 0], 0.5), {}, "2 .disks. or 3 .spheres."),
    (([0], [1], 0.5, [3], [-1], 0.5), {}, "2 .disks. or 3 .spheres."),
    (([0, 0], [1, 0], -0.5, [3, 0], [-1, 0], 0.5), {}, "R1 = -0.5 is negative"),
    (([0, 0], [1, 0], 0.5, [3, 0], [-1, 0], 0.5), {"g2": -1.0}, "g2 = -1 is negative"),
    (([0, math.nan], [1, 0], 0.5, [3, 0], [-1, 0], 0.5), {}, "NaN"),
    (([0, 0], [1, 0], 0.5, [3, 0], [-math.inf, 0], 0.5), {}, "inf"),
])
def test_bad_contact_queries_are_refused(args, kwargs, message):
    with pytest.raises(ValueError, match=message):
        collide.contact_time(*args, **kwargs)


def test_a_vector_must_be_numbers():
    with pytest.raises((TypeError, ValueError)):
        collide.contact_time("ab", [1, 0], 0.5, [3, 0], [-1, 0], 0.5)


# ---------------------------------------------------------------------------------------
# The rest


def test_every_x_pickles_to_itself():
    assert pickle.loads(pickle.dumps(collide.EVERY_X)) is collide.EVERY_X
    assert repr(collide.EVERY_X) == "collide.EVERY_X"
    assert collide.EVERY_X != []


def test_the_default_configuration_is_the_command_lines():
    printed = subprocess.run([cli(), "run", "--print-default"], capture_output=True, text=True, check=True).stdout
    assert collide.default_config().strip() == printed.strip()
    if sys.version_info >= (3, 11):
        import tomllib

        config = tomllib.loads(collide.default_config())
        assert config["species"][0]["count"] == 1000


def test_the_version_is_the_crates():
    cargo = (REPO / "python" / "Cargo.toml").read_text()
    assert f'version = "{collide.__version__}"' in cargo
