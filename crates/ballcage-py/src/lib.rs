//! PyO3 glue for `ballcage._native`: no physics here.
//!
//! Scenes are validated in Rust only; runs release the GIL; tables cross to
//! pyarrow zero-copy through the Arrow PyCapsule interface (pyo3-arrow).

use std::collections::HashMap;
use std::sync::Arc;

use ballcage_core::drillpipe::sizing;
use ballcage_core::loader::{self, Document, Kind};
use ballcage_core::scene::{IntegratorKind, whole_multiple as core_whole_multiple};
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use pyo3_arrow::{PySchema, PyTable};

create_exception!(
    _native,
    SceneError,
    PyValueError,
    "A scene field is missing or invalid; `.path` names it."
);
create_exception!(
    _native,
    SimulationError,
    PyRuntimeError,
    "A run stopped because its state stopped being physical."
);

fn scene_err(py: Python<'_>, e: ballcage_core::SceneError) -> PyErr {
    // An error of the document as a whole (a TOML syntax error) names no field.
    let message = if e.path.is_empty() {
        e.reason.clone()
    } else {
        e.to_string()
    };
    let err = SceneError::new_err(message);
    let value = err.value(py);
    // Attributes for programmatic access; setting them on a fresh exception cannot fail in practice.
    let _ = value.setattr("path", e.path.clone());
    let _ = value.setattr("value", e.value.clone());
    let _ = value.setattr("reason", e.reason.clone());
    err
}

fn sim_err(e: ballcage_core::SimulationError) -> PyErr {
    SimulationError::new_err(e.to_string())
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
        Document::from_toml_str(text, &overrides)
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
        Document::from_table(table, &overrides)
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

    /// The resolved value at a dotted key of the scene document.
    fn value<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyAny>> {
        let v = self.inner.value(key).map_err(|e| scene_err(py, e))?;
        pythonize::pythonize(py, &v)
            .map_err(|e| PyRuntimeError::new_err(format!("scene value `{key}`: {e}")))
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
        let (spec, layout) = self.drill_pipe(py, "centreline")?;
        if count < 2 {
            return Err(PyValueError::new_err(format!(
                "count = {count}: must be at least 2 points"
            )));
        }
        let path = spec.extended_centreline();
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
}

impl Simulation {
    fn get(&self) -> PyResult<&ballcage_core::Simulation> {
        self.inner.as_ref().ok_or_else(|| {
            PyRuntimeError::new_err("the simulation was finished; its tables were handed over")
        })
    }
}

#[pymethods]
impl Simulation {
    #[new]
    fn new(scene: &Scene) -> Self {
        Self {
            inner: Some(scene.inner.simulation()),
        }
    }

    /// Simulated time reached [s].
    #[getter]
    fn time(&self) -> PyResult<f64> {
        Ok(self.get()?.time())
    }

    /// Scene duration [s].
    #[getter]
    fn duration(&self) -> PyResult<f64> {
        Ok(self.get()?.model().duration())
    }

    /// Integrator steps taken.
    #[getter]
    fn steps(&self) -> PyResult<u64> {
        Ok(self.get()?.steps())
    }

    /// Runs until `t_end` [s] (clamped to the duration), without the GIL.
    fn advance(&mut self, py: Python<'_>, t_end: f64) -> PyResult<()> {
        if !t_end.is_finite() {
            return Err(PyValueError::new_err(format!(
                "t_end = {t_end}: must be a finite time in seconds"
            )));
        }
        let sim = self
            .inner
            .as_mut()
            .ok_or_else(|| PyRuntimeError::new_err("the simulation was finished"))?;
        py.detach(|| sim.advance_to(t_end)).map_err(sim_err)
    }

    /// Ends the run: one `pyarrow.Table` per recorded table, by name.
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let sim = self
            .inner
            .take()
            .ok_or_else(|| PyRuntimeError::new_err("finish() was already called"))?;
        let batches = ballcage_core::output::record_batches(sim.finish())
            .map_err(|e| PyRuntimeError::new_err(format!("building Arrow tables failed: {e}")))?;
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

/// The Arrow schema of an output table of any scene kind.
#[pyfunction]
fn table_schema<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    let def = loader::table(name).ok_or_else(|| {
        let names: Vec<&str> = loader::tables().iter().map(|t| t.name).collect();
        PyValueError::new_err(format!(
            "table `{name}`: unknown (tables are {})",
            names.join(", ")
        ))
    })?;
    let schema = ballcage_core::output::schema(def, HashMap::new());
    PySchema::new(Arc::new(schema)).into_pyarrow(py)
}

/// Per integrator: whether it is implicit, its order and a description.
#[pyfunction]
fn integrator_facts(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let out = PyDict::new(py);
    for k in IntegratorKind::ALL {
        let facts = PyDict::new(py);
        facts.set_item("implicit", k.is_implicit())?;
        facts.set_item("order", k.order())?;
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
fn longest_link(curvature_radius: f64, tube_diameter: f64, link_radius: f64) -> f64 {
    sizing::longest_link(curvature_radius, tube_diameter, link_radius)
}

/// Eq. (9) solved for R: the tightest centreline radius [m] a link fits.
#[pyfunction]
fn tightest_radius_for_link(length: f64, tube_diameter: f64, link_radius: f64) -> f64 {
    sizing::tightest_radius_for_link(length, tube_diameter, link_radius)
}

/// Eq. (9) solved for r: the largest link radius [m] for a length, or `None`.
#[pyfunction]
fn largest_link_radius(length: f64, curvature_radius: f64, tube_diameter: f64) -> Option<f64> {
    sizing::largest_link_radius(length, curvature_radius, tube_diameter)
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
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add_class::<Scene>()?;
    m.add_class::<Simulation>()?;
    m.add_function(wrap_pyfunction!(table_schema, m)?)?;
    m.add_function(wrap_pyfunction!(default_scene_toml, m)?)?;
    m.add_function(wrap_pyfunction!(integrator_facts, m)?)?;
    m.add_function(wrap_pyfunction!(whole_multiple, m)?)?;
    m.add_function(wrap_pyfunction!(longest_link, m)?)?;
    m.add_function(wrap_pyfunction!(tightest_radius_for_link, m)?)?;
    m.add_function(wrap_pyfunction!(largest_link_radius, m)?)?;
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
