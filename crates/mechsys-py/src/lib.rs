//! `mechsys._core`: thin PyO3 bindings of the engine. Type conversion and error mapping only;
//! the GIL is released while a simulation runs.

mod bearing;
mod compliant;
mod dynamics;
mod errors;
mod geometry;
mod kinematics;
mod math;
mod model;
mod simulate;

use pyo3::prelude::*;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    model::register(m)?;
    dynamics::register(m)?;
    bearing::register(m)?;
    compliant::register(m)?;
    geometry::register(m)?;
    kinematics::register(m)?;
    math::register(m)?;
    simulate::register(m)?;
    Ok(())
}
