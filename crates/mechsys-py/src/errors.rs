//! Engine errors → Python exceptions. The exception tree itself is defined in Python
//! (`mechsys/errors.py`, so that `ModelError` can also be a `ValueError`); this file maps each
//! engine error variant to its class.

use mechsys_core::Error;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

/// Wrapper so that `?` turns engine errors into the right Python exception.
pub struct PyMechsysError(pub Error);

impl From<Error> for PyMechsysError {
    fn from(e: Error) -> Self {
        PyMechsysError(e)
    }
}

fn raise(class: &str, msg: String) -> PyErr {
    Python::with_gil(|py| {
        let made = py.import("mechsys.errors").and_then(|m| m.getattr(class)).and_then(|c| c.call1((msg.clone(),)));
        match made {
            Ok(exc) => PyErr::from_value(exc),
            Err(_) => PyRuntimeError::new_err(msg),
        }
    })
}

impl From<PyMechsysError> for PyErr {
    fn from(e: PyMechsysError) -> PyErr {
        let msg = e.0.to_string();
        if matches!(e.0, Error::Callback(_)) && msg.contains(crate::simulate::INTERRUPTED) {
            return pyo3::exceptions::PyKeyboardInterrupt::new_err("interrupted inside a Python callback");
        }
        let class = match e.0 {
            Error::Model(_) | Error::Description { .. } => "ModelError",
            Error::Settings(_) => "SettingsError",
            Error::Solver(_) => "SolverError",
            Error::Painleve(_) => "PainleveError",
            Error::Singular(_) => "SingularityError",
            Error::Callback(_) => "CallbackError",
        };
        raise(class, msg)
    }
}

/// A settings error raised by the bindings' own argument checks.
pub fn settings(msg: impl Into<String>) -> PyErr {
    let msg = msg.into();
    let e = raise("SettingsError", msg.clone());
    if Python::with_gil(|py| e.is_instance_of::<PyValueError>(py)) {
        e
    } else {
        PyValueError::new_err(msg)
    }
}
