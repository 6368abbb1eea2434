"""Simulations from Python: the command line's results to the bit, slices and checkpoints
that change nothing, Ctrl-C that leaves the state whole, and every refusal."""

import json
import math
import pathlib
import pickle
import signal
import subprocess
import threading
import _thread

import pytest

import collide

from test_numerics import cli

np = pytest.importorskip("numpy")

SMALL = """
seed = 3
[box]
packing_fraction = 0.45
boundary = "periodic"
[[species]]
count = 200
radius = 0.5
mass = 1.0
[init]
placement = "triangular"
velocities = "maxwell"
kT = 1.0
[equilibration]
collisions = 5000
[run]
collisions = 40000
sample_interval = 1.0
blocks = 10
"""

# Fields that depend on the wall clock, not on the trajectory.
CLOCK = ("wall_time_s", "collisions_per_second")


def physics(summary):
    return {k: v for k, v in summary.items() if k not in CLOCK}


def cli_summary(config_text, tmp_path, name):
    path = tmp_path / f"{name}.toml"
    path.write_text(config_text)
    out = tmp_path / name
    subprocess.run([cli(), "run", str(path), "--out", str(out), "--quiet"], check=True, capture_output=True)
    return json.loads((out / "summary.json").read_text())


def test_the_default_run_is_the_command_lines_to_the_bit(tmp_path):
    sim = collide.Simulation.from_config(collide.default_config())
    assert sim.run() == "complete"
    expected = cli_summary(collide.default_config(), tmp_path, "default")
    got = sim.summary()
    # Every number, as its exact float: json gives back the shortest repr, which is exact.
    assert physics(got) == physics({k: v for k, v in expected.items() if k in got})
    assert got["pressure_virial"] == expected["pressure_virial"]
    assert sim.collisions == 1_000_000


def test_spheres_from_a_dict_equal_the_same_toml(tmp_path):
    config = {
        "dimension": 3, "seed": 5,
        "box": {"packing_fraction": 0.3, "boundary": "periodic"},
        "species": [{"count": 108, "radius": 0.5, "mass": 1.0}],
        "init": {"placement": "fcc", "velocities": "maxwell", "kT": 1.0},
        "equilibration": {"collisions": 2000},
        "run": {"collisions": 20000},
    }
    a = collide.Simulation.from_config(config)
    toml = SMALL.replace("seed = 3", "dimension = 3\nseed = 5").replace("0.45", "0.3").replace("200", "108")
    toml = toml.replace("triangular", "fcc").replace("5000", "2000").replace("40000", "20000")
    toml = toml.replace("sample_interval = 1.0\nblocks = 10\n", "")
    b = collide.Simulation.from_config(toml)
    assert a.run() == b.run() == "complete"
    assert a.dimension == 3 and a.positions.shape == (108, 3)
    assert physics(a.summary()) == physics(b.summary())
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.velocities, b.velocities)


def test_slices_and_lengths_change_nothing():
    whole = collide.Simulation.from_config(SMALL)
    whole.run(slice_events=10**9)
    sliced = collide.Simulation.from_config(SMALL)
    sliced.run(slice_events=997)
    assert physics(sliced.summary()) == physics(whole.summary())
    # The same production in two calls of 15 000 and 25 000 collisions.
    parts = collide.Simulation.from_config(SMALL)
    assert parts.run(collisions=15000) == "complete" and parts.collisions == 15000
    assert parts.run(collisions=25000) == "complete" and parts.collisions == 40000
    assert np.array_equal(parts.positions, whole.positions)
    assert parts.time == whole.time
    s = parts.samples()
    assert len(s["t"]) == whole.summary()["samples"] and np.all(np.diff(s["t"]) > 0)


def test_a_checkpoint_continues_to_the_same_bits(tmp_path):
    whole = collide.Simulation.from_config(SMALL)
    whole.run()
    first = collide.Simulation.from_config(SMALL)
    first.run(collisions=12345)
    path = tmp_path / "ck.json"
    first.save_checkpoint(path)
    assert not list(tmp_path.glob(".*tmp")), "the temporary file is renamed"
    resumed = collide.Simulation.resume(path)
    assert resumed.collisions == 12345 and resumed.time == first.time
    resumed.run(collisions=40000 - 12345)
    assert np.array_equal(resumed.positions, whole.positions)
    assert physics(resumed.summary())["pressure_virial"] == whole.summary()["pressure_virial"]
    # The command line continues it too, to the same end.
    out = tmp_path / "cli"
    first.run(collisions=40000 - 12345)  # the plan's length, as in the checkpoint
    done = subprocess.run([cli(), "run", "--resume", str(path), "--out", str(out), "--quiet"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_ctrl_c_stops_between_slices_with_the_state_whole():
    sim = collide.Simulation.from_config(SMALL)
    # Ctrl-C becomes KeyboardInterrupt only under Python's own handler, which a process
    # started with SIGINT ignored (a background job of a shell without job control) lacks:
    # there interrupt_main does nothing. The test installs it for its length.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        timer = threading.Timer(0.2, _thread.interrupt_main)
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            sim.run(collisions=10**9, slice_events=50)  # far longer than the timer
        timer.join()
    finally:
        signal.signal(signal.SIGINT, previous)
    stopped = sim.collisions
    # Equilibrated within milliseconds, then stopped in production, far short of its length.
    assert 0 < stopped < 10**9
    # Continued, the run is the one never interrupted: a fresh run to the same count.
    sim.run(collisions=1000)
    whole = collide.Simulation.from_config(SMALL)
    whole.run(collisions=stopped + 1000)
    assert sim.collisions == whole.collisions
    assert sim.time == whole.time
    assert np.array_equal(sim.positions, whole.positions) and np.array_equal(sim.velocities, whole.velocities)


def test_the_gil_is_released_while_the_engine_runs():
    sim = collide.Simulation.from_config(collide.default_config())
    worker = threading.Thread(target=lambda: sim.run(slice_events=10**9))
    spins = 0
    worker.start()
    while worker.is_alive():
        spins += 1
    worker.join()
    # Holding the GIL for the whole run (one slice) would leave this thread a handful of
    # turns at most; released, it spins freely while the engine runs.
    assert spins > 1000, spins
    assert sim.collisions == 1_000_000


@pytest.mark.parametrize("edit,named", [
    (("radius = 0.5", "radius = -1.0"), r"species\[0\]\.radius = -1"),
    (("packing_fraction = 0.45", "packing_fraction = 0.95"), "packing_fraction"),
    (("blocks = 10", "blocks = 10\nbogus = 1"), "bogus"),
    (("count = 200", "count = \"many\""), "line 7, column 9: invalid type: string"),
])
def test_bad_configurations_raise_config_error(edit, named):
    with pytest.raises(collide.ConfigError, match=named) as caught:
        collide.Simulation.from_config(SMALL.replace(*edit))
    assert isinstance(caught.value, ValueError)
    assert "the configuration text" in str(caught.value)


def test_bad_dicts_and_types():
    with pytest.raises(collide.ConfigError, match=r"box\.size\[1\] = inf: must be a finite number"):
        collide.Simulation.from_config({"box": {"size": [10.0, math.inf]}})
    with pytest.raises(collide.ConfigError, match="^the configuration dict: missing field `boundary`$"):
        collide.Simulation.from_config({"box": {"packing_fraction": 0.5}})
    with pytest.raises(collide.ConfigError, match="Object of type set"):
        collide.Simulation.from_config({"box": {1, 2}})
    with pytest.raises(TypeError, match="TOML text or a dict"):
        collide.Simulation.from_config(42)


def test_bad_run_lengths_and_checkpoints(tmp_path):
    sim = collide.Simulation.from_config(SMALL)
    for bad in (0, -5, 2.5, True):
        with pytest.raises(ValueError, match="collisions"):
            sim.run(collisions=bad)
    for bad in (0.0, -1.0, math.inf, math.nan):
        with pytest.raises(ValueError, match="time"):
            sim.run(time=bad)
    with pytest.raises(collide.ConfigError, match="missing.json"):
        collide.Simulation.resume(tmp_path / "missing.json")
    broken = tmp_path / "broken.json"
    broken.write_text('{"not": "a checkpoint"}')
    with pytest.raises(collide.ConfigError, match="broken.json"):
        collide.Simulation.resume(broken)


def test_a_simulation_refuses_pickling_and_says_what_to_do():
    sim = collide.Simulation.from_config(SMALL)
    with pytest.raises(TypeError, match="save_checkpoint"):
        pickle.dumps(sim)


def test_arrays_are_copies_with_their_shapes():
    sim = collide.Simulation.from_config(SMALL)
    p = sim.positions
    assert p.shape == (200, 2) and sim.radii.shape == (200,) and sim.masses.shape == (200,)
    assert np.all((p >= 0) & (p < sim.box))
    p[:] = 0
    assert not np.array_equal(sim.positions, p)


def state_of(sim):
    return dict(positions=sim.positions, velocities=sim.velocities, radii=sim.radii, masses=sim.masses, box=sim.box)


@pytest.mark.parametrize("dimension", [2, 3])
def test_arrays_give_the_configurations_run_to_the_bit(dimension):
    text = SMALL if dimension == 2 else SMALL.replace("seed = 3", "dimension = 3\nseed = 3").replace(
        "triangular", "fcc").replace("count = 200", "count = 256").replace("0.45", "0.3")
    # A mixture: a second species of other radius and mass.
    text += "[[species]]\ncount = 20\nradius = 0.3\nmass = 0.5\n"
    text = text.replace("[init]", "[init]").replace('placement = "triangular"', 'placement = "random"').replace(
        'placement = "fcc"', 'placement = "random"')
    made = collide.Simulation.from_config(text)
    lengths = {"equilibration": {"collisions": 5000}, "run": {"collisions": 40000, "sample_interval": 1.0, "blocks": 10}}
    given = collide.Simulation(**state_of(made), seed=3, config=lengths)
    assert given.dimension == dimension
    assert made.run() == given.run() == "complete"
    a, b = made.summary(), given.summary()
    for key in ("pressure_virial", "pressure_virial_error", "compressibility", "kT", "sim_time", "events", "max_overlap"):
        assert a[key] == b[key], key
    assert np.array_equal(made.positions, given.positions) and np.array_equal(made.velocities, given.velocities)


def test_arrays_without_a_plan_want_a_length():
    made = collide.Simulation.from_config(SMALL)
    sim = collide.Simulation(**state_of(made))
    with pytest.raises(ValueError, match="without a \\[run\\] length"):
        sim.run()
    assert sim.run(collisions=1000) == "complete" and sim.collisions == 1000


def test_bad_arrays_are_refused_naming_the_argument():
    made = collide.Simulation.from_config(SMALL)
    good = state_of(made)
    cases = [
        (dict(positions=good["positions"][:, :1]), r"positions has shape \(200, 1\)"),
        (dict(velocities=good["velocities"][:10]), r"velocities has shape \(10, 2\): expected \(200, 2\)"),
        (dict(radii=np.append(good["radii"], 0.5)), r"radii has shape \(201,\): expected \(200,\)"),
        (dict(masses=np.where(np.arange(200) == 7, np.nan, good["masses"])), r"masses: element \(7,\) = nan is not finite"),
        (dict(box=[10.0, 10.0, 10.0]), r"box has shape \(3,\): expected \(2,\)"),
        (dict(radii=["a"] * 200), "radii: not an array of numbers"),
    ]
    for change, message in cases:
        with pytest.raises(collide.ConfigError, match=message):
            collide.Simulation(**{**good, **change})
    overlapping = good["positions"].copy()
    overlapping[1] = overlapping[0] + [0.1, 0.0]
    with pytest.raises(collide.ConfigError, match="overlap"):
        collide.Simulation(**{**good, "positions": overlapping})
    with pytest.raises(collide.ConfigError, match="config.species: comes from the arrays"):
        collide.Simulation(**good, config={"species": []})
    with pytest.raises(collide.ConfigError, match="boundary"):
        collide.Simulation(**good, boundary="sticky")


def test_samples_are_the_command_lines_time_series(tmp_path):
    walled = SMALL.replace('boundary = "periodic"', 'boundary = ["wall", "periodic"]').replace("0.45", "0.3")
    walled = walled.replace('placement = "triangular"', 'placement = "square"')
    sim = collide.Simulation.from_config(walled)
    sim.run()
    cli_summary(walled, tmp_path, "walled")
    series = np.genfromtxt(tmp_path / "walled" / "timeseries.csv", delimiter=",", names=True)
    got = sim.samples()
    assert len(got["t"]) == len(series) > 10
    for name in ("t", "kinetic_energy", "pressure_virial"):
        assert np.array_equal(got[name], series[name]), name
    assert np.array_equal(got["pressure_walls"][:, 0, 0], series["pressure_wall_x_lower"])
    assert np.array_equal(got["pressure_walls"][:, 0, 1], series["pressure_wall_x_upper"])
    assert np.all(np.isnan(got["pressure_walls"][:, 1]))


def test_observables_run_in_the_package_as_in_the_command_line(tmp_path):
    observe = "[observe.rdf]\nr_max = 3.0\nbins = 300\n[observe.msd]\n[observe.vacf]\n[observe.sk]\n[observe.bond_order]\n\n"
    text = collide.default_config().replace("[run]", observe + "[run]")
    sim = collide.Simulation.from_config(text)
    assert sim.run() == "complete"
    everything = sim.summary()["observables"]
    assert sorted(everything) == ["bond_order", "msd", "rdf", "sk", "vacf"]
    assert everything == cli_summary(text, tmp_path, "rdf")["observables"]
    got = everything["rdf"]
    (contact,) = got["contact"]
    assert contact["species"] == [0, 0] and contact["sigma"] == 1.0
    # The pressure route of the same run, within the 3σ-equivalent of both errors.
    s = sim.summary()
    eta = s["packing_fraction"]
    g_pressure = (s["compressibility"] - 1) / (2 * eta)
    error = (contact["error"] ** 2 + (s["compressibility_error"] / (2 * eta)) ** 2) ** 0.5
    assert abs(contact["g"] - g_pressure) < 3.45 * error
