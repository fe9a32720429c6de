//! The contact matrices of a state, for users: the rows `W = [w_N, w_T1, w_T2]` of every contact
//! point, the Delassus matrix `Wᵀ M̃⁻¹ W` under the bilateral constraints (the matrix of the
//! transition and impact problems, section 2.5), the velocity-product terms `w̄` and the free
//! relative accelerations, computed by the same machinery as the event-driven scheme.

use super::Phase;
use crate::error::Result;

/// The contact matrices at one state (all explicit contact points, open or not).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactMatrices {
    /// Number of contact points.
    pub points: usize,
    /// Gaps `g_N` (points), m.
    pub gap: Vec<f64>,
    /// Relative velocities `(ġ_N, ġ_T1, ġ_T2)` (points × 3), m/s.
    pub velocity: Vec<f64>,
    /// Rows `w_N, w_T1, w_T2` per point, each `nu` long (3 points × nu), row-major.
    pub w: Vec<f64>,
    /// Delassus matrix `Wᵀ M̃⁻¹ W` (3 points × 3 points), row-major: relative acceleration per
    /// unit force, with the bilateral constraints' reactions included.
    pub delassus: Vec<f64>,
    /// Velocity-product accelerations `w̄` per point (n, t1, t2) (points × 3), m/s².
    pub wbar: Vec<f64>,
    /// Relative accelerations of the free motion (no contact forces) per point (points × 3).
    pub free_acceleration: Vec<f64>,
}

impl Phase<'_> {
    /// The contact matrices at (t, q, u).
    pub fn contact_matrices(&mut self, t: f64, q: &[f64], u: &[f64]) -> Result<ContactMatrices> {
        let (model, nu, np) = (self.model, self.model.nu, self.model.n_contact_points);
        self.free_motion(t, q, u)?;
        let m = 3 * np;
        let mut w = vec![0.0; m * nu];
        let mut x = vec![0.0; m * nu];
        let mut row = nalgebra::DMatrix::zeros(1, nu);
        for pt in 0..np {
            let kp = self.kin[pt].point;
            for (k, dir) in [kp.n, kp.t1, kp.t2].iter().enumerate() {
                Self::put_row(model, &self.data, &self.kin, pt, dir, &mut row, 0);
                let a = 3 * pt + k;
                for i in 0..nu {
                    w[a * nu + i] = row[(0, i)];
                    x[a * nu + i] = row[(0, i)];
                }
                Self::inverse_mass(
                    &mut self.data,
                    &mut self.dynamics.saddle,
                    model.nc,
                    &mut x[a * nu..(a + 1) * nu],
                    None,
                );
            }
        }
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
        let mut delassus = vec![0.0; m * m];
        for a in 0..m {
            for b in 0..m {
                delassus[a * m + b] = dot(&w[a * nu..(a + 1) * nu], &x[b * nu..(b + 1) * nu]);
            }
        }
        let (mut gap, mut velocity, mut wbar, mut free) = (vec![0.0; np], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        for pt in 0..np {
            let k = &self.kin[pt];
            gap[pt] = k.point.g_n;
            velocity[3 * pt..3 * pt + 3].copy_from_slice(&[k.gd_n, k.gd_t[0], k.gd_t[1]]);
            wbar[3 * pt..3 * pt + 3].copy_from_slice(&[k.wbar_n, k.wbar_t[0], k.wbar_t[1]]);
            for r in 0..3 {
                let a = 3 * pt + r;
                free[a] = dot(&w[a * nu..(a + 1) * nu], &self.a_free) + wbar[a];
            }
        }
        Ok(ContactMatrices { points: np, gap, velocity, w, delassus, wbar, free_acceleration: free })
    }
}
