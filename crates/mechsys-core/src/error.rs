//! The engine's error type.
//!
//! Every user-facing failure names the item it concerns (a body, a joint, a file key) so that the
//! message alone tells the user what to fix. Internal invariants are `debug_assert!`s instead.

use thiserror::Error;

/// Result alias used throughout the engine.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in the engine, grouped by what the user has to change.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum Error {
    /// The model description is inconsistent or non-physical.
    #[error("{0}")]
    Model(String),
    /// A model description could not be read (syntax, unknown key, wrong type); the path names the key.
    #[error("{path}: {message}")]
    Description {
        /// Key path such as `bodies[2].inertia`.
        path: String,
        /// What is wrong there.
        message: String,
    },
    /// Simulation settings or initial states are invalid.
    #[error("{0}")]
    Settings(String),
    /// A kinematic parametrization met its singularity.
    #[error("{0}")]
    Singular(String),
    /// The numerical solution failed (divergence, step size underflow, NaN state).
    #[error("{0}")]
    Solver(String),
    /// A Painlevé situation: with the sliding friction, the contact problem has no solution (the
    /// message names the contacts, the time, µ and the critical µ).
    #[error("{0}")]
    Painleve(String),
    /// A user-supplied callback failed.
    #[error("{0}")]
    Callback(String),
}

/// Returns `Err(Error::$kind(format!(...)))` from the enclosing function unless `cond` holds.
///
/// Used for checks of user input; the message must name the offending item.
#[macro_export]
macro_rules! ensure {
    ($cond:expr, $kind:ident, $($fmt:tt)+) => {
        if !($cond) {
            return Err($crate::error::Error::$kind(format!($($fmt)+)));
        }
    };
}
