//! Linearization about an equilibrium or a steady operating point into the form of eq. 2.204,
//! `M ÿ + (D + G) ẏ + (K + N) y = g(t)`, in minimal coordinates.
//!
//! The coordinates y are increments along a basis V of the directions the bilateral constraints
//! allow (`G V = 0`; V = I without constraints), in the tangent chart of the joints (quaternions
//! are perturbed by rotation vectors): `q = q* ⊕ V y`, `u = u* + V ẏ`. With the accelerations
//! `u̇(q, u, t)` of the constrained forward dynamics,
//!
//! ```text
//! M_r = Vᵀ M V,   C = −Vᵀ M ∂u̇/∂u V,   S = −Vᵀ M ∂u̇/∂q V,
//! D = (C + Cᵀ)/2, G = (C − Cᵀ)/2,   K = (S + Sᵀ)/2, N = (S − Sᵀ)/2,
//! ```
//!
//! because `Vᵀ M u̇ = Vᵀ (h + Gᵀλ) = Vᵀ h` on the constraint manifold: the reaction forces drop out
//! and their geometric stiffness stays in. The residual `Vᵀ M u̇*` says how far the point is from
//! an equilibrium (zero there; a steady operating point has `u̇* = 0` with `u* ≠ 0`).
//!
//! Two ways to the derivatives ([`Derivatives`]):
//!
//! - **Exact** (`ad`): the equations `r(q, u, u̇) = M(q) u̇ − h(q, u, t) − Gᵀλ = 0` hold at
//!   every (q, u) for the u̇, λ of the forward dynamics. Differentiating them with u̇*, λ* held and
//!   premultiplying by Vᵀ (`Vᵀ Gᵀ = 0` drops `∂λ`) gives, with the inverse dynamics
//!   `ID = M u̇ − h`,
//!
//!   ```text
//!   C = Vᵀ ∂ID/∂u V,   S = Vᵀ (∂ID/∂q − ∂(Gᵀλ*)/∂q) V,
//!   ```
//!
//!   the same matrices as above without differencing the forward dynamics. `∂ID/∂q` and
//!   `∂ID/∂u` are exact (forward-mode dual numbers through a generic RNEA, in the same chart); the
//!   geometric stiffness of the constraints `∂(Gᵀλ*)/∂q` is taken by five-point differences of
//!   `Gᵀλ*` at fixed λ* (`geometric`, ~1e-12 relative), and the method is then reported as
//!   [`DerivativeMethod::ExactWithDifferencedConstraints`].
//! - **Central differences** (`differences`) of the engine's own forward dynamics (step `1e-5`,
//!   error of order 1e-10 relative for smooth force laws; exact for linear ones). Needed for
//!   force elements the exact path cannot see into (Python callbacks).

mod ad;
mod differences;
mod geometric;
mod motion;

pub use differences::difference_step;
pub use motion::{state_space, Basis, StateSpace};

use nalgebra::{DMatrix, DVector};

use crate::data::Data;
use crate::error::{Error, Result};
use crate::forces::Callbacks;
use crate::model::Model;

/// How [`linearize_with`] takes the derivatives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Derivatives {
    /// Exact where the model allows (every force element covered), else central differences.
    #[default]
    Auto,
    /// Exact; a model with an element the exact path does not cover is an `Error::Settings`
    /// naming it.
    Exact,
    /// Central differences of the forward dynamics.
    CentralDifferences,
}

impl Derivatives {
    /// The names [`Derivatives::from_name`] accepts, in the order of the variants.
    pub const NAMES: [&'static str; 3] = ["auto", "exact", "fd"];

    /// From `"auto"`, `"exact"` or `"fd"` (None for anything else).
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "auto" => Some(Derivatives::Auto),
            "exact" => Some(Derivatives::Exact),
            "fd" => Some(Derivatives::CentralDifferences),
            _ => None,
        }
    }
}

/// Which derivatives a [`Linearization`] was built from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DerivativeMethod {
    /// Exact (dual numbers) throughout.
    Exact,
    /// Exact for the tree and its force elements; the geometric stiffness of the bilateral
    /// constraints by five-point differences (module `geometric`).
    ExactWithDifferencedConstraints,
    /// Central differences of the forward dynamics.
    CentralDifferences,
}

impl DerivativeMethod {
    /// Short name: `"exact"`, `"exact+fd-constraints"` or `"fd"`.
    pub fn as_str(self) -> &'static str {
        match self {
            DerivativeMethod::Exact => "exact",
            DerivativeMethod::ExactWithDifferencedConstraints => "exact+fd-constraints",
            DerivativeMethod::CentralDifferences => "fd",
        }
    }
}

/// The linear model at one point (row-major `n × n` matrices, `n` = degrees of freedom).
#[derive(Debug, Clone, PartialEq)]
pub struct Linearization {
    /// Degrees of freedom (columns of V).
    pub n: usize,
    /// Mass matrix, symmetric.
    pub m: Vec<f64>,
    /// Damping matrix, symmetric.
    pub d: Vec<f64>,
    /// Gyroscopic matrix, skew-symmetric.
    pub g: Vec<f64>,
    /// Stiffness matrix, symmetric.
    pub k: Vec<f64>,
    /// Circulatory (non-conservative) matrix, skew-symmetric.
    pub n_mat: Vec<f64>,
    /// Basis V of the minimal coordinates in the generalized velocities (`nu × n`, row-major).
    pub v: Vec<f64>,
    /// `Vᵀ M u̇*`: the generalized force out of balance at the point (n).
    pub residual: Vec<f64>,
    /// How the derivatives were taken.
    pub method: DerivativeMethod,
}

/// Linearizes `model` at (t, q, u), exactly where the model allows ([`Derivatives::Auto`]).
pub fn linearize(model: &Model, t: f64, q: &[f64], u: &[f64], cb: &dyn Callbacks) -> Result<Linearization> {
    linearize_with(model, t, q, u, cb, Derivatives::Auto)
}

/// Linearizes `model` at (t, q, u) with the derivatives taken as `how` says.
pub fn linearize_with(
    model: &Model,
    t: f64,
    q: &[f64],
    u: &[f64],
    cb: &dyn Callbacks,
    how: Derivatives,
) -> Result<Linearization> {
    let (nu, nc) = (model.nu, model.nc);
    let exact = check_point(model, q, u, how, "linearize")?;
    let (mut data, mut ws) = (Data::new(model), crate::dynamics::Workspace::new(model));
    // the basis of the allowed directions
    let v = if nc > 0 {
        crate::dynamics::prepare(model, &mut data, &mut ws, t, q, u, cb)?;
        crate::constraints::positions(model, &mut data, t, q, cb)?;
        null_space(&data.g, nu)
    } else {
        DMatrix::identity(nu, nu)
    };
    let n = v.ncols();
    crate::ensure!(n > 0, Model, "linearize: the constraints leave no degree of freedom");
    crate::dynamics::crba::mass_matrix(model, &mut data, t, q);
    let mass = data.mass_matrix.clone();
    if let Some(i) = (0..nu).find(|&i| !(mass[(i, i)] > 0.0)) {
        return Err(Error::Model(format!(
            "linearize: the mass matrix is singular (diagonal entry {i} is {})",
            mass[(i, i)]
        )));
    }
    // the point: accelerations u̇* and multipliers λ*
    crate::dynamics::forward_dynamics(model, &mut data, &mut ws, t, q, u, None, cb)?;
    let (a0, lambda) = (data.udot.clone(), data.lambda.clone());
    // Vᵀ X; without constraints V = I and the O(nu³) products are skipped
    let identity = nc == 0;
    let vt = v.transpose();
    let project = |a: DMatrix<f64>| if identity { a } else { &vt * a };
    let vt_m = project(mass);
    let (c, s, method) = if exact {
        let (mut dq, du) = ad::inverse_dynamics_derivatives(model, t, q, u, &a0, &v, cb)?;
        let method = if nc > 0 {
            dq -= geometric::constraint_load_derivative(model, t, q, &lambda, &v, cb)?;
            DerivativeMethod::ExactWithDifferencedConstraints
        } else {
            DerivativeMethod::Exact
        };
        (project(du), project(dq), method)
    } else {
        let (dq, du) = differences::acceleration_derivatives(model, &mut data, &mut ws, t, q, u, &v, cb)?;
        (-(&vt_m * du), -(&vt_m * dq), DerivativeMethod::CentralDifferences)
    };
    let m_r = if identity { vt_m.clone() } else { &vt_m * &v };
    let residual = &vt_m * DVector::from_vec(a0);
    let row_major = |a: &DMatrix<f64>| -> Vec<f64> {
        (0..a.nrows()).flat_map(|r| (0..a.ncols()).map(move |c| a[(r, c)])).collect()
    };
    let sym = |a: &DMatrix<f64>| (a + a.transpose()) * 0.5;
    let skew = |a: &DMatrix<f64>| (a - a.transpose()) * 0.5;
    let lin = Linearization {
        n,
        m: row_major(&sym(&m_r)),
        d: row_major(&sym(&c)),
        g: row_major(&skew(&c)),
        k: row_major(&sym(&s)),
        n_mat: row_major(&skew(&s)),
        v: row_major(&v),
        residual: residual.iter().copied().collect(),
        method,
    };
    if let Some(x) = lin.m.iter().chain(&lin.d).chain(&lin.k).chain(&lin.g).chain(&lin.n_mat).find(|x| !x.is_finite()) {
        return Err(Error::Solver(format!("linearize: a matrix entry is not finite ({x})")));
    }
    Ok(lin)
}

/// Checks the point's sizes and values; returns whether the derivatives are to be exact.
fn check_point(model: &Model, q: &[f64], u: &[f64], how: Derivatives, what: &str) -> Result<bool> {
    let (nq, nu) = (model.nq, model.nu);
    crate::ensure!(q.len() == nq, Settings, "{what}: q has {} entries, the model {nq}", q.len());
    crate::ensure!(u.len() == nu, Settings, "{what}: u has {} entries, the model {nu}", u.len());
    model.check_q(q, "q")?;
    if let Some(i) = u.iter().position(|v| !v.is_finite()) {
        return Err(Error::Settings(format!("{what}: u[{i}] is not finite ({})", u[i])));
    }
    Ok(match how {
        Derivatives::CentralDifferences => false,
        Derivatives::Auto => ad::unsupported(model).is_none(),
        Derivatives::Exact => {
            if let Some(name) = ad::unsupported(model) {
                return Err(Error::Settings(format!(
                    "{what}: exact derivatives do not cover '{name}' (a callback force or an elastic body); \
                     use method \"auto\" or \"fd\" (central differences)"
                )));
            }
            true
        }
    })
}

/// An orthonormal basis of the null space of the `nc × nu` matrix `g` (columns), by SVD; rows
/// that depend on others (redundant constraints) do not remove directions.
fn null_space(g: &DMatrix<f64>, nu: usize) -> DMatrix<f64> {
    // the null space of G is that of Gᵀ G (nu × nu, symmetric): its eigenvectors of eigenvalue 0
    let gtg = g.transpose() * g;
    let eig = gtg.symmetric_eigen();
    let top = eig.eigenvalues.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let tol = 1e-10 * top.max(f64::MIN_POSITIVE);
    let cols: Vec<usize> = (0..nu).filter(|&i| eig.eigenvalues[i].abs() <= tol).collect();
    let mut v = DMatrix::zeros(nu, cols.len());
    for (k, &i) in cols.iter().enumerate() {
        v.set_column(k, &eig.eigenvectors.column(i));
    }
    v
}

#[cfg(test)]
mod tests;
