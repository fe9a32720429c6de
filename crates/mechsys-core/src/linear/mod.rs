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
//! and their geometric stiffness stays in. The derivatives are taken by central differences of
//! the engine's own forward dynamics (step `1e-5`, error of order 1e-10 relative for smooth
//! force laws; exact for linear ones). The residual `Vᵀ M u̇*` says how far the point is from an
//! equilibrium (zero there; a steady operating point has `u̇* = 0` with `u* ≠ 0`).

use nalgebra::DMatrix;

use crate::data::Data;
use crate::error::{Error, Result};
use crate::forces::Callbacks;
use crate::model::Model;

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
}

/// Relative step of the central differences.
const STEP: f64 = 1e-5;

/// Linearizes `model` at (t, q, u).
pub fn linearize(model: &Model, t: f64, q: &[f64], u: &[f64], cb: &dyn Callbacks) -> Result<Linearization> {
    let (nq, nu, nc) = (model.nq, model.nu, model.nc);
    crate::ensure!(q.len() == nq, Settings, "linearize: q has {} entries, the model {nq}", q.len());
    crate::ensure!(u.len() == nu, Settings, "linearize: u has {} entries, the model {nu}", u.len());
    model.check_q(q, "q")?;
    if let Some(i) = u.iter().position(|v| !v.is_finite()) {
        return Err(Error::Settings(format!("linearize: u[{i}] is not finite ({})", u[i])));
    }
    let mut data = Data::new(model);
    // the basis of the allowed directions
    let v = if nc > 0 {
        crate::dynamics::prepare(model, &mut data, t, q, u, cb)?;
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
        return Err(Error::Model(format!("linearize: the mass matrix is singular (diagonal entry {i} is {})", mass[(i, i)])));
    }
    let accel = |data: &mut Data, q: &[f64], u: &[f64]| -> Result<Vec<f64>> {
        crate::dynamics::forward_dynamics(model, data, t, q, u, None, cb)?;
        Ok(data.udot.clone())
    };
    let a0 = accel(&mut data, q, u)?;
    let (mut qp, mut up, mut dir) = (vec![0.0; nq], u.to_vec(), vec![0.0; nu]);
    let mut dq = DMatrix::zeros(nu, n);
    let mut du = DMatrix::zeros(nu, n);
    for j in 0..n {
        for i in 0..nu {
            dir[i] = v[(i, j)];
        }
        // positions: q* ⊕ ±h V_j
        let mut col = [vec![0.0; nu], vec![0.0; nu]];
        for (s, sign) in [1.0, -1.0].iter().enumerate() {
            model.integrate(q, &dir, sign * STEP, &mut qp);
            model.normalize(&mut qp);
            col[s] = accel(&mut data, &qp, u)?;
        }
        for i in 0..nu {
            dq[(i, j)] = (col[0][i] - col[1][i]) / (2.0 * STEP);
        }
        let hu = STEP * u.iter().fold(1.0f64, |a, x| a.max(x.abs()));
        for (s, sign) in [1.0, -1.0].iter().enumerate() {
            for i in 0..nu {
                up[i] = u[i] + sign * hu * dir[i];
            }
            col[s] = accel(&mut data, q, &up)?;
        }
        for i in 0..nu {
            du[(i, j)] = (col[0][i] - col[1][i]) / (2.0 * hu);
        }
    }
    let vt_m = v.transpose() * &mass;
    let m_r = &vt_m * &v;
    let c = -(&vt_m * du);
    let s = -(&vt_m * dq);
    let residual = &vt_m * nalgebra::DVector::from_vec(a0);
    let row_major = |a: &DMatrix<f64>| -> Vec<f64> { (0..a.nrows()).flat_map(|r| (0..a.ncols()).map(move |c| a[(r, c)])).collect() };
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
    };
    if let Some(x) = lin.m.iter().chain(&lin.d).chain(&lin.k).chain(&lin.g).chain(&lin.n_mat).find(|x| !x.is_finite()) {
        return Err(Error::Solver(format!("linearize: a matrix entry is not finite ({x})")));
    }
    Ok(lin)
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
