//! The extension module `collide._collide`: the verified kernels of `crates/quadratic`
//! (through the same functions the `collide roots` and `collide contact-time` commands
//! call, so the answers are theirs bit for bit) and the embedded default configuration.
//! The Python package around it (`python/collide/__init__.py`) gives the public names,
//! their docstrings and the constant for "every x".
//!
//! Every refusal is a Python `ValueError` whose message names the argument and its value;
//! nothing here can panic on a caller's input (the kernels validate, and a vector of the
//! wrong length is refused before it reaches them).

use collide::engine::Outcome;
use collide::query::protocol::{DynBall, contact_time_dyn};
use collide::run::config::Config;
use collide::run::output::{AnyCheckpoint, load_any_checkpoint};
use collide::run::{Run, Sink, Status};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use quadratic::Roots;
use std::sync::atomic::{AtomicBool, Ordering};

pyo3::create_exception!(
    _collide,
    ConfigError,
    PyValueError,
    "A configuration, initial state or checkpoint that collide refuses: the message names the source, the field and the value, and what is allowed."
);

/// The real roots of `a·x² + b·x + c = 0`, ascending: `None` when every x is a root
/// (`a = b = c = 0`), else a list of zero, one or two floats.
#[pyfunction]
fn roots(a: f64, b: f64, c: f64) -> PyResult<Option<Vec<f64>>> {
    match quadratic::solve(a, b, c) {
        Ok(Roots::All) => Ok(None),
        Ok(found) => Ok(Some(found.as_vec())),
        Err(e) => Err(PyValueError::new_err(e.to_string())),
    }
}

/// The contact time of two disks (2 components) or spheres (3), radii growing at `g1`, `g2`:
/// `None` for never, `0.0` for now.
#[pyfunction]
#[pyo3(signature = (r1, v1, radius1, r2, v2, radius2, g1 = 0.0, g2 = 0.0))]
#[allow(clippy::too_many_arguments)]
fn contact_time(
    r1: Vec<f64>,
    v1: Vec<f64>,
    radius1: f64,
    r2: Vec<f64>,
    v2: Vec<f64>,
    radius2: f64,
    g1: f64,
    g2: f64,
) -> PyResult<Option<f64>> {
    let first = DynBall { position: r1, velocity: v1, radius: radius1 };
    let second = DynBall { position: r2, velocity: v2, radius: radius2 };
    contact_time_dyn(&first, &second, [g1, g2]).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// The embedded default configuration, as TOML text (`collide run --print-default`).
#[pyfunction]
fn default_config() -> &'static str {
    collide::run::config::DEFAULT_CONFIG
}

/// The edge-case reference (`quadratic::reference`), for the package's tests: one tuple per
/// case, `(kind, name, inputs, exact)`. `kind` is `"roots"` (inputs `[a, b, c]`, exact a list
/// of roots or `None` for every x) or `"contact"` (inputs `[r1, v1, R1, r2, v2, R2, g1, g2]`,
/// exact the time or `None` for never).
#[pyfunction]
fn _reference_cases(py: Python<'_>) -> PyResult<Vec<(String, String, Py<PyAny>, Option<Py<PyAny>>)>> {
    use quadratic::reference::{CONTACT_CASES, GROWING_CASES, ROOT_CASES};
    let mut cases = Vec::new();
    for case in ROOT_CASES {
        let exact = match case.exact {
            Roots::All => None,
            r => Some(r.as_vec().into_pyobject(py)?.into_any().unbind()),
        };
        let inputs = vec![case.a, case.b, case.c].into_pyobject(py)?.into_any().unbind();
        cases.push(("roots".to_string(), case.name.to_string(), inputs, exact));
    }
    let contacts = CONTACT_CASES
        .iter()
        .map(|c| (c.name, c.first, c.second, [0.0, 0.0], c.exact))
        .chain(GROWING_CASES.iter().map(|c| (c.name, c.first, c.second, c.rates, c.exact)));
    for (name, p, q, rates, exact) in contacts {
        let inputs = (p.position, p.velocity, p.radius, q.position, q.velocity, q.radius, rates[0], rates[1])
            .into_pyobject(py)?
            .into_any()
            .unbind();
        let exact = exact.time().map(|t| t.into_pyobject(py).map(|t| t.into_any().unbind())).transpose()?;
        cases.push(("contact".to_string(), name.to_string(), inputs, exact));
    }
    Ok(cases)
}

/// A run of either dimension.
enum AnyRun {
    Disks(Box<Run<2>>),
    Spheres(Box<Run<3>>),
}

/// Calls `$body` with `$run` bound to the run, whatever its dimension.
macro_rules! with_run {
    ($any:expr, $run:ident => $body:expr) => {
        match $any {
            AnyRun::Disks($run) => $body,
            AnyRun::Spheres($run) => $body,
        }
    };
}

/// Stops a run after `left` events: the package advances a run in slices, so that Python
/// can show progress and take Ctrl-C between them, with the state whole.
struct Slice<'a> {
    left: u64,
    stop: &'a AtomicBool,
}

impl<const D: usize> Sink<D> for Slice<'_> {
    type Error = std::convert::Infallible;
    #[inline]
    fn event(&mut self, _: &Run<D>, _: &Outcome<D>) -> Result<(), Self::Error> {
        self.left -= 1;
        if self.left == 0 {
            self.stop.store(true, Ordering::Relaxed);
        }
        Ok(())
    }
}

fn config_error(e: impl std::fmt::Display) -> PyErr {
    ConfigError::new_err(e.to_string())
}

/// f64s as their native bytes (numpy reads them with `frombuffer`).
fn bytes_of(py: Python<'_>, values: impl Iterator<Item = f64>) -> Py<PyBytes> {
    let raw: Vec<u8> = values.flat_map(f64::to_ne_bytes).collect();
    PyBytes::new(py, &raw).unbind()
}

/// The engine behind `collide.Simulation` (see python/collide/__init__.py).
#[pyclass(name = "_Simulation", module = "collide._collide")]
struct Simulation {
    run: AnyRun,
}

impl Simulation {
    fn start(config: Config, source: &str) -> PyResult<Self> {
        let run = match config.dimension {
            3 => AnyRun::Spheres(Box::new(Run::new(config).map_err(|e| config_error(format!("{source}: {e}")))?)),
            _ => AnyRun::Disks(Box::new(Run::new(config).map_err(|e| config_error(format!("{source}: {e}")))?)),
        };
        Ok(Simulation { run })
    }
}

#[pymethods]
impl Simulation {
    /// From TOML text; `source` names it in errors.
    #[staticmethod]
    fn from_toml(text: &str, source: &str) -> PyResult<Self> {
        Self::start(Config::parse(text, source).map_err(config_error)?, source)
    }

    /// From JSON text (a Python dict, dumped); `source` names it in errors.
    #[staticmethod]
    fn from_json(text: &str, source: &str) -> PyResult<Self> {
        // Where in the JSON text (line and column) means nothing to the dict's author.
        let config: Config = serde_json::from_str(text).map_err(|e| {
            let message = e.to_string();
            let message = message.rsplit_once(" at line ").map_or(message.as_str(), |(m, _)| m);
            config_error(format!("{source}: {message}"))
        })?;
        config.check().map_err(|e| config_error(format!("{source}: {e}")))?;
        Self::start(config, source)
    }

    /// From particles given as flat arrays (`positions`, `velocities`: N·D; `radii`,
    /// `masses`, `species`: N) and a configuration (JSON text) whose species, box and
    /// dimension they match.
    #[staticmethod]
    #[allow(clippy::too_many_arguments)]
    fn from_particles(
        config: &str,
        positions: Vec<f64>,
        velocities: Vec<f64>,
        radii: Vec<f64>,
        masses: Vec<f64>,
        species: Vec<u32>,
        source: &str,
    ) -> PyResult<Self> {
        let config: Config = serde_json::from_str(config).map_err(|e| config_error(format!("{source}: {e}")))?;
        config.check().map_err(|e| config_error(format!("{source}: {e}")))?;
        fn particles<const D: usize>(
            positions: &[f64],
            velocities: &[f64],
            radii: &[f64],
            masses: &[f64],
            species: &[u32],
        ) -> Vec<collide::engine::Particle<D>> {
            (0..radii.len())
                .map(|i| collide::engine::Particle {
                    position: nalgebra::SVector::from_column_slice(&positions[i * D..(i + 1) * D]),
                    velocity: nalgebra::SVector::from_column_slice(&velocities[i * D..(i + 1) * D]),
                    time: 0.0,
                    radius: radii[i],
                    mass: masses[i],
                    species: species[i],
                    events: 0,
                })
                .collect()
        }
        let n = radii.len();
        let d = config.dimension;
        if positions.len() != n * d || velocities.len() != n * d || masses.len() != n || species.len() != n {
            return Err(PyValueError::new_err(format!(
                "{source}: {n} radii need {} position and velocity components, {n} masses and species",
                n * d
            )));
        }
        let failed = |e: collide::run::RunError| config_error(format!("{source}: {e}"));
        let run = match d {
            3 => AnyRun::Spheres(Box::new(
                Run::from_particles(config, particles::<3>(&positions, &velocities, &radii, &masses, &species))
                    .map_err(failed)?,
            )),
            _ => AnyRun::Disks(Box::new(
                Run::from_particles(config, particles::<2>(&positions, &velocities, &radii, &masses, &species))
                    .map_err(failed)?,
            )),
        };
        Ok(Simulation { run })
    }

    /// From a checkpoint file.
    #[staticmethod]
    fn resume(path: std::path::PathBuf) -> PyResult<Self> {
        let source = path.display().to_string();
        let checkpoint = load_any_checkpoint(&path).map_err(|e| config_error(format!("{source}: {e}")))?;
        let run = match checkpoint {
            AnyCheckpoint::Disks(c) => {
                AnyRun::Disks(Box::new(Run::resume(c).map_err(|e| config_error(format!("{source}: {e}")))?))
            }
            AnyCheckpoint::Spheres(c) => {
                AnyRun::Spheres(Box::new(Run::resume(c).map_err(|e| config_error(format!("{source}: {e}")))?))
            }
        };
        Ok(Simulation { run })
    }

    /// The production ends `collisions` pair collisions and/or `time` from now.
    fn extend_production(&mut self, collisions: Option<u64>, time: Option<f64>) -> PyResult<()> {
        with_run!(&mut self.run, run => run.extend_production(collisions, time))
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// Advances at most `events` events (the GIL released) toward the end of the plan:
    /// `"complete"` at its end, `"paused"` after `events` events, or how it stopped
    /// (`"stalled"`, `"too-many-samples"`, `"jammed"`).
    fn advance(&mut self, py: Python<'_>, events: u64) -> PyResult<&'static str> {
        if events == 0 {
            return Err(PyValueError::new_err("events = 0: advance by at least one event"));
        }
        let run = &mut self.run;
        let status = py.detach(|| {
            let stop = AtomicBool::new(false);
            let mut slice = Slice { left: events, stop: &stop };
            let status = with_run!(run, run => run.advance(&stop, &mut slice));
            match status {
                Ok(Status::Interrupted) => "paused",
                Ok(Status::Complete) => "complete",
                Ok(Status::Stalled) => "stalled",
                Ok(Status::TooManySamples) => "too-many-samples",
                Ok(Status::Jammed) => "jammed",
                Err(never) => match never {},
            }
        });
        Ok(status)
    }

    /// 2 or 3.
    #[getter]
    fn dimension(&self) -> usize {
        match self.run {
            AnyRun::Disks(_) => 2,
            AnyRun::Spheres(_) => 3,
        }
    }

    /// The particle count.
    #[getter]
    fn n(&self) -> usize {
        with_run!(&self.run, run => run.sim.particles().len())
    }

    /// The simulation clock.
    #[getter]
    fn time(&self) -> f64 {
        with_run!(&self.run, run => run.sim.time())
    }

    /// Production pair collisions so far.
    #[getter]
    fn collisions(&self) -> u64 {
        with_run!(&self.run, run => run.collisions())
    }

    /// All pair collisions so far, every phase.
    #[getter]
    fn pair_collisions(&self) -> u64 {
        with_run!(&self.run, run => run.sim.counts().pair)
    }

    /// `"compression"`, `"equilibration"` or `"production"`.
    #[getter]
    fn phase(&self) -> &'static str {
        with_run!(&self.run, run => run.phase().name())
    }

    /// The fraction of the production done.
    #[getter]
    fn progress(&self) -> f64 {
        with_run!(&self.run, run => run.progress())
    }

    /// Positions now, wrapped into the box along periodic axes: N·D f64s.
    fn positions(&self, py: Python<'_>) -> Py<PyBytes> {
        with_run!(&self.run, run => bytes_of(py, run.sim.wrapped_positions().iter().flat_map(|r| r.iter().copied().collect::<Vec<_>>())))
    }

    /// Velocities: N·D f64s.
    fn velocities(&self, py: Python<'_>) -> Py<PyBytes> {
        with_run!(&self.run, run => bytes_of(py, run.sim.particles().iter().flat_map(|p| p.velocity.iter().copied().collect::<Vec<_>>())))
    }

    /// Radii now (growing during a compression): N f64s.
    fn radii(&self, py: Python<'_>) -> Py<PyBytes> {
        with_run!(&self.run, run => bytes_of(py, (0..run.sim.particles().len()).map(|i| run.sim.radius(i))))
    }

    /// Masses: N f64s.
    fn masses(&self, py: Python<'_>) -> Py<PyBytes> {
        with_run!(&self.run, run => bytes_of(py, run.sim.particles().iter().map(|p| p.mass)))
    }

    /// The box's edge lengths: D f64s.
    fn box_lengths(&self, py: Python<'_>) -> Py<PyBytes> {
        with_run!(&self.run, run => bytes_of(py, run.sim.sim_box().lengths.iter().copied()))
    }

    /// What summary.json holds, as JSON text.
    fn summary(&self) -> PyResult<String> {
        with_run!(&self.run, run => serde_json::to_string(&run.summary()))
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// The production's samples (time series), as JSON text.
    fn samples(&self) -> PyResult<String> {
        with_run!(&self.run, run => serde_json::to_string(&run.thermo.samples))
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// Writes the checkpoint to `path` (a temporary file in its directory, then renamed).
    fn save_checkpoint(&self, path: std::path::PathBuf) -> PyResult<()> {
        let text = with_run!(&self.run, run => run.checkpoint(0).to_json());
        collide::run::rundir::write_atomic(&path, text.as_bytes()).map_err(|e| PyOSError::new_err(e.to_string()))
    }
}

#[pymodule]
fn _collide(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Simulation>()?;
    m.add("ConfigError", m.py().get_type::<ConfigError>())?;
    m.add_function(wrap_pyfunction!(roots, m)?)?;
    m.add_function(wrap_pyfunction!(contact_time, m)?)?;
    m.add_function(wrap_pyfunction!(default_config, m)?)?;
    m.add_function(wrap_pyfunction!(_reference_cases, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
