//! # mechsys-core
//!
//! The engine of mechsys: rigid multibody kinematics, dynamics and time integration, following the
//! notation of *Fundamentals of Mechanical System Dynamics* (equation numbers are quoted in the code).
//!
//! Data flows one way: a [`model::ModelDescription`] (from Python or a model file) is validated
//! into an immutable [`model::Model`]; a [`data::Data`] workspace sized from the model holds every
//! intermediate quantity; free functions ([`kinematics::forward_kinematics`], [`dynamics::crba`],
//! [`dynamics::rnea`], [`dynamics::aba`]) fill it; [`simulate::simulate`] runs the step loop and
//! records signals.
#![warn(missing_docs)]
// Index loops mirror the formulas in the numeric kernels, and `!(x > 0.0)` is how NaN is rejected
// together with the out-of-range values; both lints would make those places less clear.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

pub mod batch;
pub mod constraints;
pub mod contact;
pub mod data;
pub mod dynamics;
pub mod elastic;
pub mod error;
pub mod fixtures;
pub mod forces;
pub mod geometry;
pub mod integrator;
pub mod kinematics;
pub mod linear;
pub mod math;
pub mod model;
pub mod resources;
pub mod simulate;
pub mod solver;
pub mod spatial;

pub use error::{Error, Result};
