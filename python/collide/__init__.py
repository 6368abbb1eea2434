"""collide: event-driven hard disks and spheres on verified collision numerics.

The numerics are the Rust crate ``quadratic``'s, called through the same functions as the
``collide roots`` and ``collide contact-time`` commands, so the answers here are theirs bit
for bit. Python floats are IEEE-754 doubles, so every input is taken exactly as given.

* :func:`roots` -- the real roots of ``a*x**2 + b*x + c = 0``, each correctly rounded;
* :func:`contact_time` -- when two disks or spheres in uniform motion (radii optionally
  growing) first touch;
* :func:`default_config` -- the embedded default configuration of ``collide run``;
* :class:`Simulation` -- a run of ``collide run`` held in Python: from a configuration or a
  checkpoint, run with the GIL released, its state as numpy arrays, its summary as a dict.

A refused input raises :class:`ValueError` naming the argument and its value.
"""

from __future__ import annotations

import math
import os
import sys
from typing import Final, List, Optional, Sequence, Union

from . import _collide

__all__ = [
    "EVERY_X", "EveryX", "roots", "contact_time", "default_config",
    "Simulation", "ConfigError", "__version__",
]

__version__: Final[str] = _collide.__version__


class EveryX:
    """The answer of :func:`roots` when every x is a root (``a = b = c = 0``, the equation
    ``0 = 0``): not a list, so that it cannot be mistaken for "no root" (``[]``).
    There is one instance, :data:`EVERY_X`."""

    _instance: Optional["EveryX"] = None

    def __new__(cls) -> "EveryX":
        if cls._instance is None:
            cls._instance = super().__new__(cls)
        return cls._instance

    def __repr__(self) -> str:
        return "collide.EVERY_X"

    def __reduce__(self) -> str:
        return "EVERY_X"


#: Every x solves ``0 = 0``: what :func:`roots` returns for ``roots(0, 0, 0)``.
EVERY_X: Final[EveryX] = EveryX()


def roots(a: float, b: float, c: float) -> Union[List[float], EveryX]:
    """The real roots of ``a*x**2 + b*x + c = 0``, ascending.

    Returns a list: ``[]`` when there is no real root (discriminant ``b**2 - 4*a*c < 0``,
    or ``c = 0`` with ``c != 0``), one element for a linear equation (``a = 0 != b``:
    ``x = -c/b``) or an exact double root (``b**2 = 4*a*c`` exactly), two for two distinct
    roots ``x1 <= x2`` (distinct exact roots may round to the same float). Every root is
    the exact root of the equation with these coefficients, correctly rounded -- no
    cancellation (``roots(1, -1e8, 1)`` gives ``1e-08`` exactly), no spurious overflow
    or underflow of ``b**2`` or ``4*a*c``. Returns :data:`EVERY_X` when ``a = b = c = 0``.

    Raises :class:`ValueError` for a NaN or infinite coefficient.

    >>> roots(1, -3, 2)
    [1.0, 2.0]
    >>> roots(1, 0, 1)
    []
    >>> roots(0, 0, 0)
    collide.EVERY_X
    """
    found = _collide.roots(float(a), float(b), float(c))
    return EVERY_X if found is None else found


def contact_time(
    r1: Sequence[float],
    v1: Sequence[float],
    R1: float,
    r2: Sequence[float],
    v2: Sequence[float],
    R2: float,
    g1: float = 0.0,
    g2: float = 0.0,
) -> Optional[float]:
    """When two disks (2 components) or spheres (3) first touch, or ``None`` for never.

    The balls are at ``r1``, ``r2`` with velocities ``v1``, ``v2`` and radii ``R1 + g1*t``,
    ``R2 + g2*t`` (``g1 = g2 = 0``: rigid). With ``dr = r2 - r1``, ``dv = v2 - v1``,
    ``sigma = R1 + R2`` and ``G = g1 + g2`` the gap is
    ``f(t) = |dr + dv*t|**2 - (sigma + G*t)**2 = A*t**2 + B*t + C`` with
    ``A = |dv|**2 - G**2``, ``B = 2*(dr.dv - sigma*G)``, ``C = |dr|**2 - sigma**2``, and the
    answer is

    * touching or overlapping (``C <= 0``): ``0.0`` (now) when approaching (``B < 0``),
      else ``None``;
    * apart (``C > 0``): the smallest ``t > 0`` with ``f(t) = 0``; ``None`` when there is
      none, and for an exact tangency (a double root).

    Classification is exact for the exact values of the inputs, and the time is within
    one ulp of the exact one (rigid balls: correctly rounded). Any array-like of floats
    works for the vectors (lists, tuples, numpy arrays); all four must have the same
    length, 2 or 3.

    Raises :class:`ValueError` for vectors of other or unequal lengths, a NaN or infinite
    number, a negative radius or a negative growth rate.

    >>> contact_time([0, 0], [1, 0], 0.5, [3, 0], [-1, 0], 0.5)
    1.0
    >>> contact_time([0, 0, 0], [0, 0, 0], 0.5, [3, 0, 0], [0, 0, 0], 0.5) is None
    True
    """
    vector = lambda x: [float(c) for c in x]  # noqa: E731
    return _collide.contact_time(
        vector(r1), vector(v1), float(R1), vector(r2), vector(v2), float(R2), float(g1), float(g2)
    )


def default_config() -> str:
    """The embedded default configuration of ``collide run`` as TOML text (1000 disks at
    packing fraction 0.5): a starting point for a configuration of your own."""
    return _collide.default_config()


# ---------------------------------------------------------------------------------------
# Simulations

ConfigError = _collide.ConfigError
ConfigError.__doc__ = (
    "A configuration, initial state or checkpoint that collide refuses (a ValueError): the "
    "message names the source, the field and its value, and what is allowed."
)


class Simulation:
    """A run of ``collide run`` held in Python: hard disks (``dimension = 2``) or spheres
    (``dimension = 3``) as a configuration describes them (docs/configuration.md), run by
    the same engine and loop as the command line -- the same configuration and seed give
    the same trajectory, bit for bit, and the same ``summary()`` as summary.json.

    A run has phases: the compression (with ``[compress]``), the equilibration, and the
    production, which alone is measured. :meth:`run` goes through them.

    >>> sim = Simulation.from_config(default_config())
    >>> sim.run(collisions=10_000)
    'complete'
    >>> sim.positions.shape
    (1000, 2)
    """

    def __init__(
        self,
        positions,
        velocities,
        radii,
        masses,
        box,
        boundary: Union[str, Sequence[str]] = "periodic",
        seed: int = 1,
        config: Optional[dict] = None,
    ) -> None:
        """From particles as arrays: ``positions`` and ``velocities`` of shape (N, D) with
        D = 2 (disks) or 3 (spheres), ``radii`` and ``masses`` of shape (N,), the box's edge
        lengths ``box`` (D,), its ``boundary`` ("periodic", "wall", or one per axis).

        Particles of equal radius and mass form one species (numbered in the order they
        first appear). The velocities are taken as they are (kT is what they make it);
        positions must lie in the box, with no overlap.

        ``config`` (a dict in the configuration's layout) supplies the rest: ``seed``,
        ``[equilibration]``, ``[run]``, ``[observe]``, ``init.kT`` (for a compression's
        thermostat), ``[compress]``; its box, species and dimension are those of the arrays.
        Without a ``[run]`` the simulation has no plan of its own, and :meth:`run` wants a
        length. A simulation built so from the state of another (same seed and lengths)
        runs the same trajectory, bit for bit.

        Raises :class:`ConfigError` naming the argument for arrays of the wrong shape, non-
        finite numbers, a particle outside the box or overlapping another.
        """
        import numpy as np

        def array(name, value, shape):
            try:
                a = np.asarray(value, dtype=np.float64)
            except (TypeError, ValueError) as e:
                raise ConfigError(f"{name}: not an array of numbers ({e})") from None
            if a.ndim != len(shape) or any(want is not None and got != want for got, want in zip(a.shape, shape)):
                wanted = "(" + ", ".join("N" if w is None else str(w) for w in shape) + ("," if len(shape) == 1 else "") + ")"
                raise ConfigError(f"{name} has shape {a.shape}: expected {wanted}")
            if not np.all(np.isfinite(a)):
                k = int(np.flatnonzero(~np.isfinite(a.ravel()))[0])
                at = tuple(int(i) for i in np.unravel_index(k, a.shape))
                raise ConfigError(f"{name}: element {at} = {float(a.ravel()[k])!r} is not finite")
            return a

        p = np.asarray(positions)
        if p.ndim != 2 or p.shape[1] not in (2, 3):
            raise ConfigError(f"positions has shape {p.shape}: expected (N, 2) for disks or (N, 3) for spheres")
        n, d = p.shape
        p = array("positions", positions, (n, d))
        v = array("velocities", velocities, (n, d))
        r = array("radii", radii, (n,))
        m = array("masses", masses, (n,))
        b = array("box", box, (d,))
        kinds, species = {}, []
        for radius, mass in zip(r.tolist(), m.tolist()):
            species.append(kinds.setdefault((radius, mass), len(kinds)))
        settings = dict(config or {})
        for key in ("dimension", "box", "species"):
            if key in settings:
                raise ConfigError(f"config.{key}: comes from the arrays; leave it out")
        init = dict(settings.get("init", {}))
        init.pop("placement", None)
        settings.update(
            dimension=d,
            seed=settings.get("seed", seed),
            box={"size": b.tolist(), "boundary": boundary},
            species=[{"count": species.count(k), "radius": radius, "mass": mass} for (radius, mass), k in kinds.items()],
            init=init,
        )
        self._planned = "run" in settings
        settings.setdefault("run", {"collisions": 1})
        bad = _first_non_finite(settings, "config")
        if bad is not None:
            raise ConfigError(f"{bad[0]} = {bad[1]!r}: must be a finite number")
        import json

        self._engine = _collide._Simulation.from_particles(
            json.dumps(settings), p.ravel().tolist(), v.ravel().tolist(), r.tolist(), m.tolist(), species, "the arrays"
        )

    @classmethod
    def _wrap(cls, engine) -> "Simulation":
        sim = cls.__new__(cls)
        sim._engine = engine
        sim._planned = True
        return sim

    @classmethod
    def from_config(cls, config: Union[str, dict], source: Optional[str] = None) -> "Simulation":
        """From a configuration: TOML text (what a ``.toml`` file holds, e.g.
        :func:`default_config`) or a dict of the same layout (``{"seed": 1, "box":
        {"packing_fraction": 0.5}, "species": [{"count": 100, "radius": 0.5, "mass": 1.0}],
        ...}``). The initial state is built at once; nothing runs yet.

        Raises :class:`ConfigError` naming the field and the value for anything the
        command line would refuse.
        """
        import json

        if isinstance(config, str):
            return cls._wrap(_collide._Simulation.from_toml(config, source or "the configuration text"))
        if isinstance(config, dict):
            name = source or "the configuration dict"
            bad = _first_non_finite(config, "")
            if bad is not None:
                raise ConfigError(f"{name}: {bad[0]} = {bad[1]!r}: must be a finite number")
            try:
                text = json.dumps(config, allow_nan=False)
            except (TypeError, ValueError) as e:
                raise ConfigError(f"{name}: {e}") from None
            return cls._wrap(_collide._Simulation.from_json(text, source or "the configuration dict"))
        raise TypeError(f"a configuration is TOML text or a dict, not {type(config).__name__}")

    @classmethod
    def resume(cls, path: Union[str, "os.PathLike[str]"]) -> "Simulation":
        """From a checkpoint written by :meth:`save_checkpoint` or by ``collide run``:
        the run continues exactly as it would have (its configuration is in the
        checkpoint). Raises :class:`ConfigError` for a file that is not a valid
        checkpoint."""
        return cls._wrap(_collide._Simulation.resume(os.fspath(path)))

    def run(
        self,
        collisions: Optional[int] = None,
        time: Optional[float] = None,
        progress: bool = False,
        slice_events: int = 200_000,
    ) -> str:
        """Runs, and says how it ended.

        With neither ``collisions`` nor ``time``: the plan of the configuration, to the end
        of its production. With either or both: first whatever compression and
        equilibration remain, then ``collisions`` more production pair collisions or
        ``time`` more units of time, whichever comes first (``collide run``'s ``[run]``
        lengths, counted from now).

        Returns ``"complete"``, or how the run stopped early with its state whole:
        ``"stalled"`` (the clock stuck), ``"jammed"`` (a compression jammed before its
        target), ``"too-many-samples"``.

        The engine runs with the GIL released, ``slice_events`` events at a time; between
        slices ``progress=True`` updates a progress bar (tqdm's, in a notebook or a
        terminal, where tqdm is installed; else a line on stderr), and Ctrl-C
        (KeyboardInterrupt) stops the run there -- the simulation is left whole, at an
        event, and ``run`` can be called again to continue.
        """
        if collisions is None and time is None and not self._planned:
            raise ValueError(
                "this simulation was built from arrays without a [run] length: "
                "run(collisions=...) or run(time=...), or pass config={'run': {...}}"
            )
        if collisions is not None or time is not None:
            if collisions is not None and (isinstance(collisions, bool) or int(collisions) != collisions or collisions < 1):
                raise ValueError(f"collisions = {collisions!r}: a whole number ≥ 1")
            if time is not None and not (float(time) > 0 and math.isfinite(float(time))):
                raise ValueError(f"time = {time!r}: a finite number > 0")
            self._engine.extend_production(
                None if collisions is None else int(collisions), None if time is None else float(time)
            )
        bar = _Progress(self._engine) if progress else None
        try:
            while True:
                status = self._engine.advance(int(slice_events))
                if bar is not None:
                    bar.update()
                if status != "paused":
                    return status
        finally:
            if bar is not None:
                bar.close()

    @property
    def dimension(self) -> int:
        """2 (disks) or 3 (spheres)."""
        return self._engine.dimension

    @property
    def time(self) -> float:
        """The simulation clock (units: σ√(m/kT) for the reference σ, m, kT)."""
        return self._engine.time

    @property
    def collisions(self) -> int:
        """Production pair collisions so far (0 before the production)."""
        return self._engine.collisions

    @property
    def phase(self) -> str:
        """``"compression"``, ``"equilibration"`` or ``"production"``."""
        return self._engine.phase

    def _array(self, raw: bytes, columns: int):
        import numpy as np

        values = np.frombuffer(raw, dtype=np.float64).copy()
        return values.reshape(-1, columns) if columns > 1 else values

    @property
    def positions(self):
        """Positions now, shape (N, D), wrapped into the box along periodic axes (a new
        numpy array: changing it changes nothing in the simulation)."""
        return self._array(self._engine.positions(), self.dimension)

    @property
    def velocities(self):
        """Velocities, shape (N, D) (a new numpy array)."""
        return self._array(self._engine.velocities(), self.dimension)

    @property
    def radii(self):
        """Radii now, shape (N,) (growing during a compression)."""
        return self._array(self._engine.radii(), 1)

    @property
    def masses(self):
        """Masses, shape (N,)."""
        return self._array(self._engine.masses(), 1)

    @property
    def box(self):
        """The box's edge lengths, shape (D,)."""
        return self._array(self._engine.box_lengths(), 1)

    def summary(self) -> dict:
        """What ``collide run``'s summary.json holds for the run so far, as a dict (its
        fields: docs/outputs.md): the pressure and compressibility with their errors,
        kT, the energy drift, the largest overlap, the counts, the status."""
        import json

        return json.loads(self._engine.summary())

    def samples(self) -> dict:
        """The production's time series (timeseries.csv's columns) as numpy arrays, one
        row per sampling interval: ``t`` (its end), ``kinetic_energy``, ``kt``,
        ``collisions`` (since the production began), ``pressure_virial`` (over the
        interval), and ``pressure_walls`` of shape (S, D, 2): the pressure on the lower and
        upper wall of each axis, NaN along periodic axes."""
        import json

        import numpy as np

        rows = json.loads(self._engine.samples())
        keys = ("t", "kinetic_energy", "kt", "collisions", "pressure_virial")
        out = {k: np.array([row[k] for row in rows], dtype=np.int64 if k == "collisions" else np.float64) for k in keys}
        walls = np.full((len(rows), self.dimension, 2), np.nan)
        for i, row in enumerate(rows):
            for axis, pair in enumerate(row["pressure_walls"]):
                if pair is not None:
                    walls[i, axis] = pair
        out["pressure_walls"] = walls
        return out

    def save_checkpoint(self, path: Union[str, "os.PathLike[str]"]) -> None:
        """Writes the run's checkpoint (``collide run``'s format: ``collide run --resume``
        and :meth:`resume` continue it bit for bit), to a temporary file first, then
        renamed, so that an existing file is never half-overwritten."""
        self._engine.save_checkpoint(os.fspath(path))

    def __reduce__(self):
        raise TypeError(
            "a collide.Simulation cannot be pickled: save_checkpoint(path) writes its whole state, "
            "and Simulation.resume(path) continues it bit for bit"
        )

    def __repr__(self) -> str:
        return (
            f"<collide.Simulation: {self._engine.n} {'disks' if self.dimension == 2 else 'spheres'}, "
            f"{self.phase}, t = {self.time:.6g}, {self.collisions} production collisions>"
        )


def _first_non_finite(value, path):
    """The path (``box.size[1]``) and value of the first NaN or infinity in a configuration
    dict, or ``None``."""
    if isinstance(value, float) and not math.isfinite(value):
        return path, value
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, (list, tuple)) else ()
    for key, item in items:
        where = f"{path}[{key}]" if isinstance(key, int) else f"{path}.{key}" if path else str(key)
        found = _first_non_finite(item, where)
        if found is not None:
            return found
    return None


class _Progress:
    """A progress bar over the phases of a run: tqdm's where it is installed, else a line."""

    def __init__(self, engine) -> None:
        self._engine = engine
        self._phase = None
        self._bar = None
        try:
            from tqdm.auto import tqdm
        except ImportError:
            tqdm = None
        self._tqdm = tqdm

    def update(self) -> None:
        phase = self._engine.phase
        if phase != self._phase:
            self.close()
            self._phase = phase
            if self._tqdm is not None:
                self._bar = self._tqdm(total=1000 if phase == "production" else None, desc=phase, unit="")
        done = self._engine.progress if phase == "production" else None
        if self._bar is not None:
            if done is not None:
                self._bar.n = int(1000 * done)
            else:
                self._bar.n = self._engine.pair_collisions
            self._bar.refresh()
        else:
            text = f"{done:.0%}" if done is not None else f"{self._engine.pair_collisions} collisions"
            sys.stderr.write(f"\rcollide: {phase}: {text}   ")
            sys.stderr.flush()

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        elif self._phase is not None:
            sys.stderr.write("\n")
            self._phase = None
