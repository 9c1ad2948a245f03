//! PyO3 glue for `ballcage._native`: no physics here.
//!
//! Scenes are validated in Rust only; runs release the GIL; tables cross to
//! pyarrow zero-copy through the Arrow PyCapsule interface (pyo3-arrow).

use std::collections::HashMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::{Arc, Mutex};

use ballcage_core::drillpipe::sizing;
use ballcage_core::loader::{self, Document, Kind};
use ballcage_core::scene::{FieldUnits, IntegratorKind, whole_multiple as core_whole_multiple};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};
use pyo3_arrow::{PySchema, PyTable};

create_exception!(
    ballcage._native,
    Error,
    PyException,
    "Base class of every error ballcage raises: `except ballcage.Error` catches them all."
);

/// The subclasses of `Error`, each also a subclass of the built-in exception
/// that code written before them catches (`ValueError`, `RuntimeError`).
struct ErrorTypes {
    scene: Py<PyType>,
    simulation: Py<PyType>,
    input: Py<PyType>,
    internal: Py<PyType>,
}

static ERROR_TYPES: PyOnceLock<ErrorTypes> = PyOnceLock::new();

/// `type(name, (Error, *builtins), {...})`, in module `ballcage._native`.
fn error_subclass(
    py: Python<'_>,
    name: &str,
    builtins: &[Bound<'_, PyType>],
    doc: &str,
) -> PyResult<Py<PyType>> {
    let mut bases = vec![py.get_type::<Error>()];
    bases.extend(builtins.iter().cloned());
    let namespace = PyDict::new(py);
    namespace.set_item("__doc__", doc)?;
    namespace.set_item("__module__", "ballcage._native")?;
    let made = py
        .get_type::<PyType>()
        .call1((name, PyTuple::new(py, bases)?, namespace))?;
    Ok(made.cast_into::<PyType>()?.unbind())
}

fn error_types(py: Python<'_>) -> PyResult<&ErrorTypes> {
    ERROR_TYPES.get_or_try_init(py, || {
        let value = py.get_type::<PyValueError>();
        let runtime = py.get_type::<PyRuntimeError>();
        Ok(ErrorTypes {
            scene: error_subclass(
                py,
                "SceneError",
                std::slice::from_ref(&value),
                "A scene field is missing or invalid; `.path`, `.value` and `.reason` name it.",
            )?,
            simulation: error_subclass(
                py,
                "SimulationError",
                std::slice::from_ref(&runtime),
                "A run stopped because its state stopped being physical.",
            )?,
            input: error_subclass(
                py,
                "InputError",
                &[value, py.get_type::<PyTypeError>()],
                "An argument of a ballcage function is invalid (out of range, or of the wrong type); \
                 the message names it, its value and the reason.",
            )?,
            internal: error_subclass(
                py,
                "InternalError",
                &[runtime],
                "A bug in ballcage (a Rust panic, caught): the message says where; please report it.",
            )?,
        })
    })
}

/// An exception of one of the `ErrorTypes` with `message`.
fn raise(py: Python<'_>, pick: fn(&ErrorTypes) -> &Py<PyType>, message: String) -> PyErr {
    match error_types(py) {
        Ok(types) => PyErr::from_type(pick(types).bind(py).clone(), message),
        Err(e) => e,
    }
}

fn scene_err(py: Python<'_>, e: ballcage_core::SceneError) -> PyErr {
    // Every error found in one pass, "; "-separated; a document error (TOML syntax) names no field.
    let err = raise(py, |t| &t.scene, e.to_string());
    let value = err.value(py);
    // Attributes for programmatic access (the first error's, and all of them in `errors`);
    // setting them on a fresh exception cannot fail in practice.
    let _ = value.setattr("path", e.path.clone());
    let _ = value.setattr("value", e.value.clone());
    let _ = value.setattr("reason", e.reason.clone());
    let each: Vec<(String, String, String)> = e
        .each()
        .map(|x| (x.path.clone(), x.value.clone(), x.reason.clone()))
        .collect();
    let _ = value.setattr("errors", each);
    err
}

fn sim_err(py: Python<'_>, e: ballcage_core::SimulationError) -> PyErr {
    raise(py, |t| &t.simulation, e.to_string())
}

fn input_err(py: Python<'_>, message: String) -> PyErr {
    raise(py, |t| &t.input, message)
}

/// Where the last panic happened (`file:line`), recorded by the panic hook
/// `quiet_panic_hook` installs; a worker thread's panic is read on the
/// thread that catches it, hence a global, not a thread-local.
static LAST_PANIC_AT: Mutex<Option<String>> = Mutex::new(None);

/// Replaces the default panic hook, which prints a multi-line report to
/// stderr, by one that only records where the panic happened: `guard` puts
/// that into the one-line `InternalError`.
fn quiet_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        let at = info
            .location()
            .map(|l| format!("{}:{}", l.file(), l.line()));
        if let Ok(mut last) = LAST_PANIC_AT.lock() {
            *last = at;
        }
    }));
}

/// Runs `f`, turning a Rust panic into an `InternalError` naming `what`,
/// the panic's message and where it happened, so a bug never aborts or
/// escapes as a `BaseException`.
fn guard<T>(what: &str, f: impl FnOnce() -> T) -> Result<T, String> {
    catch_unwind(AssertUnwindSafe(f)).map_err(|payload| {
        let message = payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "no message".to_owned());
        let at = LAST_PANIC_AT
            .lock()
            .ok()
            .and_then(|mut last| last.take())
            .map(|at| format!(" at {at}"))
            .unwrap_or_default();
        format!(
            "internal error in {what}: {message}{at} (a bug in ballcage; please report it with the scene)"
        )
    })
}

fn internal_err(py: Python<'_>, message: String) -> PyErr {
    raise(py, |t| &t.internal, message)
}

/// An `InputError` for a key `Scene.<method>` cannot answer for.
fn unknown_key(py: Python<'_>, method: &str, key: &str, e: ballcage_core::SceneError) -> PyErr {
    input_err(py, format!("Scene.{method}({key:?}): {e}"))
}

/// A validated, assembled scene document of any kind.
#[pyclass(module = "ballcage._native", frozen)]
struct Scene {
    inner: Document,
}

impl Scene {
    /// The drill-pipe document and its layout, or a `SceneError` on `kind`
    /// naming `what` needs one.
    fn drill_pipe(
        &self,
        py: Python<'_>,
        what: &str,
    ) -> PyResult<(
        &ballcage_core::drillpipe::DrillPipeSpec,
        &ballcage_core::drillpipe::Layout,
    )> {
        self.inner.drill_pipe_parts().ok_or_else(|| {
            scene_err(
                py,
                ballcage_core::SceneError::new(
                    "kind",
                    self.inner.kind().name(),
                    format!("{what} needs a drill-pipe scene (kind = \"drill-pipe\")"),
                ),
            )
        })
    }
}

#[pymethods]
impl Scene {
    /// Parses and validates TOML text, after applying `key=value` overrides.
    #[staticmethod]
    #[pyo3(signature = (text, overrides = Vec::new()))]
    fn from_toml(py: Python<'_>, text: &str, overrides: Vec<String>) -> PyResult<Self> {
        guard("Scene.from_toml", || {
            Document::from_toml_str(text, &overrides)
        })
        .map_err(|m| internal_err(py, m))?
        .map(|inner| Self { inner })
        .map_err(|e| scene_err(py, e))
    }

    /// Validates a dict with the structure of a TOML scene.
    #[staticmethod]
    #[pyo3(signature = (obj, overrides = Vec::new()))]
    fn from_dict(
        py: Python<'_>,
        obj: &Bound<'_, PyDict>,
        overrides: Vec<String>,
    ) -> PyResult<Self> {
        let table: toml::Table = pythonize::depythonize(obj.as_any()).map_err(|e| {
            scene_err(
                py,
                ballcage_core::SceneError::new("", "", format!("not a scene table: {e}")),
            )
        })?;
        guard("Scene.from_dict", || {
            Document::from_table(table, &overrides)
        })
        .map_err(|m| internal_err(py, m))?
        .map(|inner| Self { inner })
        .map_err(|e| scene_err(py, e))
    }

    /// The resolved scene as TOML, every default written out; with `units`,
    /// each number's unit as a comment at the end of its line.
    #[pyo3(signature = (*, units = false))]
    fn to_toml(&self, units: bool) -> String {
        if units {
            self.inner.to_toml_with_units()
        } else {
            self.inner.to_toml()
        }
    }

    /// A digest (hex) of everything a run of the scene computes from: two
    /// scenes with the same digest record bitwise the same tables, so a
    /// sweep runs them once (`Document::engine_digest`).
    fn engine_digest(&self) -> String {
        self.inner.engine_digest()
    }

    /// Scene name.
    #[getter]
    fn name(&self) -> String {
        self.inner.scene().name.clone()
    }

    /// Simulated duration [s].
    #[getter]
    fn duration(&self) -> f64 {
        self.inner.scene().simulation.duration
    }

    /// Integrator step [s].
    #[getter]
    fn dt(&self) -> f64 {
        self.inner.scene().simulation.dt
    }

    /// Output interval [s].
    #[getter]
    fn output_interval(&self) -> f64 {
        self.inner.scene().simulation.output_interval
    }

    /// Integrator name.
    #[getter]
    fn integrator(&self) -> &'static str {
        self.inner.scene().simulation.integrator.name()
    }

    /// Names of the tables this scene records.
    #[getter]
    fn table_names(&self) -> Vec<&'static str> {
        self.inner.table_names()
    }

    /// The scene kind: "generic" or "drill-pipe".
    #[getter]
    fn kind(&self) -> &'static str {
        self.inner.kind().name()
    }

    /// Names of the bodies the integrator moves (motion `dynamic`, `spin`
    /// or `spin-slide`: `BodySpec::is_integrated`), in body order; for a drill pipe,
    /// those of its expansion.
    #[getter]
    fn integrated_bodies(&self) -> Vec<String> {
        let bodies = &self.inner.scene().bodies;
        bodies
            .iter()
            .filter(|b| b.is_integrated())
            .map(|b| b.name.clone())
            .collect()
    }

    /// The unit of the field at a dotted key, as `scene show` prints it.
    fn unit(&self, py: Python<'_>, key: &str) -> PyResult<String> {
        let field = self.inner.field(key);
        Ok(field.map_err(|e| unknown_key(py, "unit", key, e))?.unit)
    }

    /// One line on what the field at a dotted key is.
    fn meaning(&self, py: Python<'_>, key: &str) -> PyResult<&'static str> {
        let field = self.inner.field(key);
        Ok(field
            .map_err(|e| unknown_key(py, "meaning", key, e))?
            .meaning)
    }

    /// The factor that turns a value of the contact-law field at `key`,
    /// written in `units` ("SI" or "N-mm-s"), into the law's own units.
    fn scale_from(&self, py: Python<'_>, key: &str, units: &str) -> PyResult<f64> {
        let from: FieldUnits = toml::Value::String(units.to_string())
            .try_into()
            .map_err(|_| {
                input_err(
                    py,
                    format!("units = {units:?}: must be \"SI\" or \"N-mm-s\""),
                )
            })?;
        self.inner
            .scale_from(key, from)
            .map_err(|e| unknown_key(py, "scale_from", key, e))
    }

    /// The resolved value at a dotted key of the scene document.
    fn value<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyAny>> {
        let v = self.inner.value(key).map_err(|e| scene_err(py, e))?;
        pythonize::pythonize(py, &v)
            .map_err(|e| internal_err(py, format!("scene value `{key}`: {e}")))
    }

    /// The tightest guide-tube curvature radius [m] the drill pipe allows.
    fn tightest_radius(&self, py: Python<'_>) -> PyResult<f64> {
        Ok(self.drill_pipe(py, "tightest_radius")?.0.tightest_radius())
    }

    /// The hinges' articulation limit [deg], the bend at which a hinge
    /// binds; `None` when nothing limits the bend.
    fn articulation_limit_deg(&self, py: Python<'_>) -> PyResult<Option<f64>> {
        let spec = self.drill_pipe(py, "articulation_limit_deg")?.0;
        Ok(spec.articulation_limit().map(f64::to_degrees))
    }

    /// The chain as placed at t = 0: `hinges` (centres 0…n [m]), `axes`
    /// (unit body axes) and `masses` [kg] of the bodies as built (upper
    /// connector, links 1…n, lower connector), world frame.
    fn placed_chain<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (spec, layout) = self.drill_pipe(py, "placed_chain")?;
        let (hinges, axes) = spec.placed_chain();
        let rows = |v: Vec<ballcage_core::math::Vec3>| -> Vec<Vec<f64>> {
            v.iter().map(|p| vec![p.x, p.y, p.z]).collect()
        };
        let bodies = &self.inner.scene().bodies;
        let masses: Vec<Option<f64>> = layout.chain.iter().map(|&i| bodies[i].mass).collect();
        let out = PyDict::new(py);
        out.set_item("hinges", rows(hinges))?;
        out.set_item("axes", rows(axes))?;
        out.set_item("masses", masses)?;
        Ok(out)
    }

    /// `count` points along the drill pipe's extended tube centreline.
    fn centreline<'py>(&self, py: Python<'py>, count: usize) -> PyResult<Bound<'py, PyDict>> {
        let layout = self.drill_pipe(py, "centreline")?.1;
        if count < 2 {
            return Err(input_err(
                py,
                format!("count = {count}: must be at least 2 points"),
            ));
        }
        // the path the load built once, the one the chain was placed on
        let path = &layout.centreline;
        let (mut point, mut tangent, mut outward, mut s) = (vec![], vec![], vec![], vec![]);
        for i in 0..count {
            let arc = path.length() * i as f64 / (count - 1) as f64;
            let c = path.point_at(arc);
            let o = layout.lateral.cross(&c.tangent);
            point.push(vec![c.point.x, c.point.y, c.point.z]);
            tangent.push(vec![c.tangent.x, c.tangent.y, c.tangent.z]);
            outward.push(vec![o.x, o.y, o.z]);
            s.push(arc);
        }
        let out = PyDict::new(py);
        out.set_item("point", point)?;
        out.set_item("tangent", tangent)?;
        out.set_item("outward", outward)?;
        out.set_item("s", s)?;
        Ok(out)
    }

    fn __repr__(&self) -> String {
        let s = self.inner.scene();
        format!(
            "Scene(kind={:?}, name={:?}, bodies={}, contacts={}, duration={} s, dt={} s)",
            self.inner.kind().name(),
            s.name,
            s.bodies.len(),
            s.contacts.len(),
            s.simulation.duration,
            s.simulation.dt
        )
    }
}

/// A running simulation.
#[pyclass(module = "ballcage._native")]
struct Simulation {
    inner: Option<ballcage_core::Simulation>,
    /// Feature `test-panic`: `advance` panics, for the test that a panic reaches Python as `InternalError`.
    #[cfg(feature = "test-panic")]
    panic_in_advance: bool,
}

/// The scene name that makes `advance` panic when built with feature `test-panic`.
#[cfg(feature = "test-panic")]
const TEST_PANIC_SCENE: &str = "ballcage-test-panic";

impl Simulation {
    fn get(&self, py: Python<'_>) -> PyResult<&ballcage_core::Simulation> {
        self.inner.as_ref().ok_or_else(|| {
            input_err(
                py,
                "the simulation was finished (or dropped after an internal error); its tables were handed over"
                    .to_owned(),
            )
        })
    }
}

#[pymethods]
impl Simulation {
    #[new]
    fn new(py: Python<'_>, scene: &Scene) -> PyResult<Self> {
        let inner =
            guard("Simulation()", || scene.inner.simulation()).map_err(|m| internal_err(py, m))?;
        Ok(Self {
            inner: Some(inner),
            #[cfg(feature = "test-panic")]
            panic_in_advance: scene.inner.scene().name == TEST_PANIC_SCENE,
        })
    }

    /// Simulated time reached [s].
    #[getter]
    fn time(&self, py: Python<'_>) -> PyResult<f64> {
        Ok(self.get(py)?.time())
    }

    /// Scene duration [s].
    #[getter]
    fn duration(&self, py: Python<'_>) -> PyResult<f64> {
        Ok(self.get(py)?.model().duration())
    }

    /// Integrator steps taken.
    #[getter]
    fn steps(&self, py: Python<'_>) -> PyResult<u64> {
        Ok(self.get(py)?.steps())
    }

    /// Runs until `t_end` [s] (clamped to the duration), without the GIL.
    ///
    /// A panic inside (a bug) raises `InternalError` and drops the
    /// simulation, whose state can no longer be trusted.
    fn advance(&mut self, py: Python<'_>, t_end: f64) -> PyResult<()> {
        if !t_end.is_finite() {
            return Err(input_err(
                py,
                format!("t_end = {t_end}: must be a finite time in seconds"),
            ));
        }
        #[cfg(feature = "test-panic")]
        let inject = self.panic_in_advance;
        let sim = self.inner.as_mut().ok_or_else(|| {
            input_err(
                py,
                "the simulation was finished (or dropped after an internal error)".to_owned(),
            )
        })?;
        let outcome = py.detach(|| {
            guard("Simulation.advance", || {
                #[cfg(feature = "test-panic")]
                assert!(
                    !inject,
                    "injected panic (feature test-panic, scene `{TEST_PANIC_SCENE}`)"
                );
                sim.advance_to(t_end)
            })
        });
        match outcome {
            Ok(result) => result.map_err(|e| sim_err(py, e)),
            Err(message) => {
                self.inner = None;
                Err(internal_err(
                    py,
                    format!("{message}; the simulation was dropped"),
                ))
            }
        }
    }

    /// Ends the run: one `pyarrow.Table` per recorded table, by name.
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let sim = self
            .inner
            .take()
            .ok_or_else(|| input_err(py, "finish() was already called".to_owned()))?;
        let batches = guard("Simulation.finish", || {
            ballcage_core::output::record_batches(sim.finish())
        })
        .map_err(|m| internal_err(py, m))?
        .map_err(|e| internal_err(py, format!("building Arrow tables failed: {e}")))?;
        let out = PyDict::new(py);
        for (def, batch) in batches {
            let schema = batch.schema();
            let table = PyTable::try_new(vec![batch], schema)?;
            out.set_item(def.name, table.into_pyarrow(py)?)?;
        }
        Ok(out)
    }
}

/// The embedded default scene (the paper's drill pipe) as TOML.
#[pyfunction]
fn default_scene_toml() -> String {
    loader::default_document().to_toml()
}

/// The registry of unstated parameters (PROPOSAL values): one dict per
/// entry, `ballcage.proposals()`'s rows; `kind` keeps one scene kind's.
#[pyfunction]
#[pyo3(signature = (kind = None))]
fn proposals<'py>(py: Python<'py>, kind: Option<&str>) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let kind = kind
        .map(|name| {
            Kind::named(name).ok_or_else(|| {
                let kinds: Vec<String> = Kind::ALL
                    .iter()
                    .map(|k| format!("{:?}", k.name()))
                    .collect();
                input_err(
                    py,
                    format!(
                        "kind = {name:?}: unknown scene kind (kinds: {})",
                        kinds.join(", ")
                    ),
                )
            })
        })
        .transpose()?;
    let entries = guard("proposals", || loader::proposals(kind))
        .map_err(|m| internal_err(py, m))?
        .map_err(|e| internal_err(py, format!("the registry of PROPOSAL values: {e} (a bug)")))?;
    entries
        .into_iter()
        .map(|e| {
            let row = PyDict::new(py);
            row.set_item("key", e.key)?;
            row.set_item("scene_kind", e.kind.name())?;
            row.set_item("default", e.default)?;
            row.set_item("low", e.proposal.low)?;
            row.set_item("high", e.proposal.high)?;
            row.set_item("unit", e.unit)?;
            row.set_item("source", e.proposal.source.name())?;
            row.set_item("reference", e.proposal.reference)?;
            row.set_item("meaning", e.meaning)?;
            row.set_item("range_reason", e.proposal.range_reason)?;
            Ok(row)
        })
        .collect()
}

/// The Arrow schema of an output table of any scene kind.
#[pyfunction]
fn table_schema<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    let def = loader::table(name).ok_or_else(|| {
        let names: Vec<&str> = loader::tables().iter().map(|t| t.name).collect();
        input_err(
            py,
            format!("table `{name}`: unknown (tables are {})", names.join(", ")),
        )
    })?;
    let schema = ballcage_core::output::schema(def, HashMap::new());
    PySchema::new(Arc::new(schema)).into_pyarrow(py)
}

/// Per integrator (every one, the adaptive pairs included): whether it is
/// implicit, its order, the stages it solves by Newton iterations and a
/// description.
#[pyfunction]
fn integrator_facts(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let out = PyDict::new(py);
    for k in IntegratorKind::EVERY {
        let facts = PyDict::new(py);
        facts.set_item("implicit", k.is_implicit())?;
        facts.set_item("order", k.order())?;
        facts.set_item("newton_stages", k.newton_stages())?;
        facts.set_item("description", k.description())?;
        out.set_item(k.name(), facts)?;
    }
    Ok(out)
}

/// `interval / step` when it is a whole number ≥ 1 (the engine's tolerance).
#[pyfunction]
fn whole_multiple(interval: f64, step: f64) -> Option<u64> {
    core_whole_multiple(interval, step)
}

/// Eq. (9): the longest rigid link [m] that fits the bent tube.
#[pyfunction]
fn longest_link(curvature_radius: f64, tube_inner_diameter: f64, link_outer_diameter: f64) -> f64 {
    sizing::longest_link(curvature_radius, tube_inner_diameter, link_outer_diameter)
}

/// Eq. (9) solved for R: the tightest centreline radius [m] a link fits.
#[pyfunction]
fn tightest_radius_for_link(
    link_length: f64,
    tube_inner_diameter: f64,
    link_outer_diameter: f64,
) -> f64 {
    sizing::tightest_radius_for_link(link_length, tube_inner_diameter, link_outer_diameter)
}

/// Eq. (9) solved for d: the largest link outer diameter [m] for a length, or `None`.
#[pyfunction]
fn largest_link_diameter(
    link_length: f64,
    curvature_radius: f64,
    tube_inner_diameter: f64,
) -> Option<f64> {
    sizing::largest_link_diameter(link_length, curvature_radius, tube_inner_diameter)
}

/// The tightest radius [m] at which hinges of pitch `pitch` bend `bend_limit` [rad].
#[pyfunction]
fn tightest_radius_for_bend(pitch: f64, bend_limit: f64) -> f64 {
    sizing::tightest_radius_for_bend(pitch, bend_limit)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", ballcage_core::VERSION)?;
    m.add(
        "BUILD_PROFILE",
        if cfg!(debug_assertions) {
            "debug"
        } else {
            "release"
        },
    )?;
    quiet_panic_hook();
    let types = error_types(py)?;
    m.add("Error", py.get_type::<Error>())?;
    m.add("SceneError", types.scene.bind(py))?;
    m.add("SimulationError", types.simulation.bind(py))?;
    m.add("InputError", types.input.bind(py))?;
    m.add("InternalError", types.internal.bind(py))?;
    m.add_class::<Scene>()?;
    m.add_class::<Simulation>()?;
    m.add_function(wrap_pyfunction!(table_schema, m)?)?;
    m.add_function(wrap_pyfunction!(default_scene_toml, m)?)?;
    m.add_function(wrap_pyfunction!(proposals, m)?)?;
    m.add_function(wrap_pyfunction!(integrator_facts, m)?)?;
    m.add_function(wrap_pyfunction!(whole_multiple, m)?)?;
    m.add_function(wrap_pyfunction!(longest_link, m)?)?;
    m.add_function(wrap_pyfunction!(tightest_radius_for_link, m)?)?;
    m.add_function(wrap_pyfunction!(largest_link_diameter, m)?)?;
    m.add_function(wrap_pyfunction!(tightest_radius_for_bend, m)?)?;
    m.add(
        "TABLE_NAMES",
        loader::tables().iter().map(|t| t.name).collect::<Vec<_>>(),
    )?;
    m.add(
        "SCENE_KINDS",
        Kind::ALL.iter().map(|k| k.name()).collect::<Vec<_>>(),
    )?;
    m.add(
        "INTEGRATORS",
        IntegratorKind::ALL
            .iter()
            .map(|k| k.name())
            .collect::<Vec<_>>(),
    )?;
    Ok(())
}
