//! Equations of motion of the tree, `M(q) u̇ = h(q, u, t) + τ` (Newton–Euler, section 2.3,
//! projected with the Jacobians of section 2.2.5):
//! - [`crba`]: the mass matrix by the composite-rigid-body algorithm;
//! - [`rnea`]: inverse dynamics and `h` by the recursive Newton–Euler algorithm;
//! - [`aba`]: forward dynamics in O(n) by the articulated-body algorithm;
//! - [`energy`]: kinetic and potential energy, linear momentum and moment of momentum.
//!
//! `h` contains every force the model itself produces (gravity, gyroscopic and Coriolis terms,
//! force elements, joint springs and dampers); `τ` is an extra actuation input.

pub mod aba;
pub mod constrained;
pub mod crba;
pub mod energy;
pub mod reactions;
pub mod rnea;
pub mod sparse;

pub use aba::aba;
pub use crba::crba;
pub use reactions::joint_reactions;
pub use rnea::{inverse_dynamics, nonlinear_effects, rnea};

#[cfg(test)]
mod tests;

use crate::data::Data;
use crate::error::Result;
use crate::forces::{self, Callbacks, Powers};
use crate::kinematics;
use crate::model::Model;

/// The stages before the solve: kinematics of (q, u), time-dependent inertias, force elements.
/// Returns the power balance of the force elements.
pub fn prepare(model: &Model, data: &mut Data, t: f64, q: &[f64], u: &[f64], cb: &dyn Callbacks) -> Result<Powers> {
    kinematics::forward_pass(model, data, t, q, u);
    forces::evaluate(model, data, t, q, u, cb)
}

/// One full forward evaluation: kinematics → forces → ABA; leaves `data.udot` and returns the power balance of the force elements.
pub fn forward_dynamics(
    model: &Model,
    data: &mut Data,
    t: f64,
    q: &[f64],
    u: &[f64],
    tau: Option<&[f64]>,
    cb: &dyn Callbacks,
) -> Result<Powers> {
    if model.nc > 0 {
        return constrained::forward_dynamics(model, data, t, q, u, tau, cb);
    }
    let p = prepare(model, data, t, q, u, cb)?;
    aba::aba_prepared(model, data, tau);
    Ok(p)
}
