//! Equations of motion of the tree, `M(q) u̇ = h(q, u, t) + τ` (Newton–Euler, section 2.3,
//! projected with the Jacobians of section 2.2.5):
//! - [`crba`]: the mass matrix by the composite-rigid-body algorithm;
//! - [`rnea`]: inverse dynamics and `h` by the recursive Newton–Euler algorithm;
//! - [`aba`]: forward dynamics in O(n) by the articulated-body algorithm;
//! - [`energy`]: kinetic and potential energy, linear momentum and moment of momentum.
//!
//! `h` contains every force the model itself produces (gravity, gyroscopic and Coriolis terms,
//! force elements, joint springs and dampers); `τ` is an extra actuation input.
//!
//! The algorithms take the model, the [`Data`] (the quantities every stage reads and writes) and
//! the stage's own [`Workspace`] (the factorization of the constrained solve and the force stage's
//! scratch), both allocated once per model:
//!
//! ```
//! use mechsys_core::{data::Data, dynamics, fixtures, forces::NoCallbacks};
//! let model = fixtures::chain(3, "revolute");
//! let (mut data, mut ws) = (Data::new(&model), dynamics::Workspace::new(&model));
//! let (q, u) = (model.q0(), model.u0());
//! dynamics::aba(&model, &mut data, &mut ws, 0.0, &q, &u, None, &NoCallbacks).unwrap();
//! assert_eq!(data.udot.len(), model.nu);
//! ```

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

/// The dynamics stage's own working memory, kept next to the [`Data`]: the plan and factors of
/// the sparse constrained solve ([`sparse::Saddle`]; the time-stepping schemes reuse its tree
/// factor of M) and the force stage's scratch ([`forces::Workspace`]). Its form is the stage's
/// business; the quantities other stages read stay in [`Data`]. [`Workspace::new`] sizes it once
/// per model; the evaluations then do not allocate.
#[derive(Debug, Clone, Default)]
pub struct Workspace {
    /// The saddle-point factorization of `M u̇ = h + τ + Gᵀλ`, `G u̇ = γ`.
    pub saddle: sparse::Saddle,
    /// The force stage's scratch (the Jenkins chains' slider problems).
    pub forces: forces::Workspace,
}

impl Workspace {
    /// Allocates the workspace for `model`.
    pub fn new(model: &Model) -> Self {
        Workspace { saddle: sparse::Saddle::new(model), forces: forces::Workspace::new(model) }
    }
}

/// The stages before the solve: kinematics of (q, u), time-dependent inertias, force elements.
/// Returns the power balance of the force elements.
pub fn prepare(
    model: &Model,
    data: &mut Data,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
    u: &[f64],
    cb: &dyn Callbacks,
) -> Result<Powers> {
    kinematics::forward_pass(model, data, t, q, u);
    forces_at(model, data, ws, t, q, u, cb)
}

/// [`prepare`] at the positions of the last one (the same `t` and `q`) with new velocities `u`:
/// the placements, subspaces and inertias stand, the velocities and the forces are redone.
pub fn prepare_rates(
    model: &Model,
    data: &mut Data,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
    u: &[f64],
    cb: &dyn Callbacks,
) -> Result<Powers> {
    kinematics::velocities(model, data, q, u);
    forces_at(model, data, ws, t, q, u, cb)
}

/// The force elements (and the elastic bodies' material damping) at the kinematics in `data`.
fn forces_at(
    model: &Model,
    data: &mut Data,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
    u: &[f64],
    cb: &dyn Callbacks,
) -> Result<Powers> {
    let mut p = forces::evaluate(model, data, &mut ws.forces, t, q, u, cb)?;
    for e in &model.elastic {
        // the elastic bodies' material damping q̇ᵀ D q̇
        let qd = &u[e.iu..e.iu + e.ne];
        for k in 0..e.ne {
            for l in 0..e.ne {
                p.dissipated += qd[k] * e.d[(k, l)] * qd[l];
            }
        }
    }
    Ok(p)
}

/// One full forward evaluation: kinematics → forces → ABA; leaves `data.udot` and returns the power balance of the force elements.
#[allow(clippy::too_many_arguments)]
pub fn forward_dynamics(
    model: &Model,
    data: &mut Data,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
    u: &[f64],
    tau: Option<&[f64]>,
    cb: &dyn Callbacks,
) -> Result<Powers> {
    if model.nc > 0 || !model.elastic.is_empty() {
        // elastic coordinates couple with their body's reference motion through C: the
        // tree-sparse factorization of M takes them (the articulated-body recursion does not)
        return constrained::forward_dynamics(model, data, ws, t, q, u, tau, cb);
    }
    let p = prepare(model, data, ws, t, q, u, cb)?;
    aba::aba_prepared(model, data, tau);
    Ok(p)
}
