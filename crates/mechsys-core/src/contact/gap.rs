//! User gap functions: a unilateral contact given directly by its normal distance `g_N(q, t)`
//! and, optionally, tangential coordinates `g_T,k(q, t)` whose rates are the sliding velocities
//! (the relative kinematics of section 2.2.7 written by the user instead of found from contours).
//!
//! With `q̇ = u` for the coordinates the functions read (joints without quaternions), the
//! contact's rows and rheonomic terms follow from the functions alone (eqs. 2.110–2.115 in
//! generalized coordinates):
//!
//! - `ġ = Wᵀ u + w̃` with `W = ∂g/∂q` and `w̃ = ∂g/∂t`;
//! - `g̈ = Wᵀ u̇ + w̄` with `w̄ = uᵀ (∂²g/∂q²) u + 2 (∂²g/∂q∂t) u + ∂²g/∂t²`, the second
//!   derivative of `g(q + u τ, t + τ)` at τ = 0.
//!
//! A closed-form function ([`Expr`]) is evaluated on dual numbers: one second-order pass along
//! `(u, 1)` gives `g`, `ġ` and `w̄`, one first-order pass per coordinate read gives `W`. A Python
//! function goes through [`Callbacks::gap_function`], which returns the same numbers.
//!
//! The contact has no geometry of its own: its frame is the fixed `n = e_z`, `t1 = e_x`,
//! `t2 = e_y` at the world origin, so that a direction `d = c_N n + c_1 t1 + c_2 t2` the
//! contact solvers ask a row for is `c_N W_N + c_1 W_T1 + c_2 W_T2`.

use num_dual::{Dual2_64, Dual64};

use super::kinematics::ContactKinematics;
use super::narrow::ContactPoint;
use crate::error::{Error, Result};
use crate::forces::Callbacks;
use crate::math::expr::Expr;
use crate::math::Vec3;

/// One scalar function of (q, t): a closed-form expression or a Python callable.
#[derive(Debug, Clone, PartialEq)]
pub enum GapTerm {
    /// Parsed expression; its variable slots index [`GapFunction::coordinates`].
    Expr(Expr),
    /// Callback id ([`Callbacks::gap_function`]).
    Callback(usize),
}

/// A validated gap function: the normal distance, then 0–2 tangential coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct GapFunction {
    /// `g_N`, then `g_T1`, `g_T2` (as many as given).
    pub terms: Vec<GapTerm>,
    /// The coordinates the expressions read, by slot: `(iq, iu)` (`q̇[iq] = u[iu]`).
    pub coordinates: Vec<(usize, usize)>,
    /// Largest expression stack.
    stack: usize,
}

/// Scratch of the gap-function evaluations (in [`crate::data::Data`]): dual variables, the
/// expression stacks and, per gap contact, its rows `W_N, W_T1, W_T2` (3 × nu) at the last
/// evaluated state.
#[derive(Debug, Clone, Default)]
pub struct GapWork {
    /// Rows of every gap contact: contact slot k at `[3 k nu, 3 (k + 1) nu)`.
    pub rows: Vec<f64>,
    vars2: Vec<Dual2_64>,
    vars1: Vec<Dual64>,
    stack2: Vec<Dual2_64>,
    stack1: Vec<Dual64>,
    grad: Vec<f64>,
}

impl GapWork {
    /// Scratch for `n_gap` gap contacts of a model with `nq`, `nu` coordinates.
    pub fn new(n_gap: usize, nq: usize, nu: usize, functions: &[&GapFunction]) -> GapWork {
        let vars = functions.iter().map(|f| f.coordinates.len()).max().unwrap_or(0);
        let stack = functions.iter().map(|f| f.stack).max().unwrap_or(0);
        GapWork {
            rows: vec![0.0; 3 * n_gap * nu],
            vars2: Vec::with_capacity(vars),
            vars1: Vec::with_capacity(vars),
            stack2: Vec::with_capacity(stack),
            stack1: Vec::with_capacity(stack),
            grad: vec![0.0; if functions.iter().any(|f| f.has_callback()) { nq } else { 0 }],
        }
    }
}

impl GapFunction {
    /// From its terms (normal first) and the coordinates their expressions read.
    pub fn new(terms: Vec<GapTerm>, coordinates: Vec<(usize, usize)>) -> GapFunction {
        let stack = terms.iter().map(|t| if let GapTerm::Expr(e) = t { e.stack_len() } else { 0 }).max().unwrap_or(0);
        GapFunction { terms, coordinates, stack }
    }

    /// Number of tangential coordinates (0–2).
    pub fn tangents(&self) -> usize {
        self.terms.len() - 1
    }

    /// Whether a term is a Python callable.
    pub fn has_callback(&self) -> bool {
        self.terms.iter().any(|t| matches!(t, GapTerm::Callback(_)))
    }

    /// The contact's kinematics at (q, u, t) into `out`, and with `with_rows` its rows into
    /// `work.rows` (3 × nu, zero rows for missing tangents) and `w̃`; without, only `g`, `ġ`
    /// and `w̄` (the acceleration stage of a held gap, whose rows the position stage left at the
    /// same q). No allocation once `work` has its capacity.
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate(
        &self,
        t: f64,
        q: &[f64],
        u: &[f64],
        cb: &dyn Callbacks,
        work: &mut GapWork,
        slot: usize,
        with_rows: bool,
        out: &mut ContactKinematics,
    ) -> Result<()> {
        let nu = u.len();
        let GapWork { rows, vars2, vars1, stack2, stack1, grad } = work;
        let rows = &mut rows[3 * slot * nu..3 * (slot + 1) * nu];
        if with_rows {
            rows.fill(0.0);
        }
        let mut value = [[0.0; 3]; 3]; // per term: g, ġ, w̄
        let mut w_tilde = [0.0; 3];
        for (k, term) in self.terms.iter().enumerate() {
            let row = &mut rows[k * nu..(k + 1) * nu];
            match term {
                GapTerm::Expr(e) => {
                    // along the motion: g, ġ and the velocity-product part of g̈
                    vars2.clear();
                    vars2.extend(self.coordinates.iter().map(|&(iq, iu)| Dual2_64::new(q[iq], u[iu], 0.0)));
                    let r = e.eval(vars2, Dual2_64::new(t, 1.0, 0.0), stack2);
                    value[k] = [r.re, r.v1, r.v2];
                    if !with_rows {
                        continue;
                    }
                    // the rows, one coordinate at a time
                    vars1.clear();
                    vars1.extend(self.coordinates.iter().map(|&(iq, _)| Dual64::from(q[iq])));
                    let mut wu = 0.0;
                    for (s, &(_, iu)) in self.coordinates.iter().enumerate() {
                        vars1[s].eps = 1.0;
                        let d = e.eval(vars1, Dual64::from(t), stack1).eps;
                        vars1[s].eps = 0.0;
                        row[iu] += d;
                        wu += d * u[iu];
                    }
                    w_tilde[k] = if e.uses_time() { r.v1 - wu } else { 0.0 };
                }
                GapTerm::Callback(id) => {
                    // q̇ = u everywhere in a model whose gap callbacks validated: rows are ∂g/∂q
                    value[k] = cb.gap_function(*id, t, q, u, grad)?;
                    if !with_rows {
                        continue;
                    }
                    let mut wu = 0.0;
                    for (i, r) in row.iter_mut().enumerate() {
                        *r = grad[i];
                        wu += grad[i] * u[i];
                    }
                    w_tilde[k] = value[k][1] - wu;
                }
            }
        }
        if let Some(k) = (0..self.terms.len()).find(|&k| !value[k].iter().all(|v| v.is_finite())) {
            let what = ["gap", "tangents[0]", "tangents[1]"][k];
            return Err(Error::Callback(format!(
                "{what} is not finite at t = {t} s (value {}, rate {}, velocity-product term {})",
                value[k][0], value[k][1], value[k][2]
            )));
        }
        if let Some(i) = rows.iter().position(|v| !v.is_finite()) {
            let what = ["gap", "tangents[0]", "tangents[1]"][i / nu];
            return Err(Error::Callback(format!(
                "the derivative of {what} with respect to velocity {} is not finite at t = {t} s",
                i % nu
            )));
        }
        *out = ContactKinematics {
            point: ContactPoint {
                g_n: value[0][0],
                n: Vec3::z(),
                p1: Vec3::zeros(),
                p2: Vec3::zeros(),
                t1: Vec3::x(),
                t2: Vec3::y(),
            },
            gd_n: value[0][1],
            gd_t: [value[1][1], value[2][1]],
            wbar_n: value[0][2],
            wbar_t: [value[1][2], value[2][2]],
            omega_rel: [0.0; 3],
            w_tilde,
        };
        Ok(())
    }
}
