//! User surfaces `r(s1, s2)` (section 2.2.7.2): a bicubic spline patch through a grid of points,
//! natural or periodic in either direction, with its normal, fundamental forms and principal
//! curvatures, and the foot-point search of a point on it.
//!
//! **Interpolation.** The tensor-product cubic spline through the grid `P_ij` at the knots
//! `(s1_i, s2_j)` (uniform in each direction) is C² in both parameters. It is built from its
//! values and the derivatives `r_1`, `r_2`, `r_12` at the knots, each the derivative of a 1-D
//! spline ([`Spline1`]) along a grid line (`r_12` from the splines of `r_1` along `s2`); on each
//! cell these 16 vectors fix a bicubic Hermite patch, stored as power-basis coefficients. A
//! periodic direction requires its last grid line to repeat the first; a natural one has zero
//! second derivative across its end lines.
//!
//! **Geometry.** `E, F, G = r_i·r_j` (eq. 2.117), `ν = r_1 × r_2 / |r_1 × r_2|` (eq. 2.118, the
//! solid lies below `ν`), `L, M, N = ν·r_ij` (eq. 2.119); the principal curvatures are minus the
//! eigenvalues of the shape operator `I⁻¹ II` (convex > 0 with the outward `ν`), and `∂ν/∂s_i`
//! follows the Weingarten equations (eq. 2.125).
//!
//! **Foot point.** The nearest point of the patch to `y` minimizes `½|y - r(s)|²`. Each cell's
//! Bézier control net (the power basis converted) bounds it by a ball, blocks of 4 × 4 cells by
//! a ball around theirs; in the nearest block the cell whose ball has the nearest far side is
//! sampled first (5 × 5), then every cell (of every block) whose ball is nearer than the best
//! sample so far (the others cannot hold the minimum). Newton (Hessian `I - h II`,
//! `h = (y - r)·ν`; the metric `I` where that is not positive definite) refines the nearest
//! sample, kept inside the parameter range of a natural direction and wrapped in a periodic one. On a natural patch's edge the
//! foot point may be a boundary point; the contact then takes the edge's tangent plane.

use crate::ensure;
use crate::error::Result;
use crate::geometry::spline::{wrap, Spline1};
use crate::math::Vec3;

/// `r, r_1, r_2, r_11, r_12, r_22` at a parameter point.
pub type Jet = [Vec3; 6];

/// Cubic Hermite → power basis: `[p0, m0, p1, m1] ↦ [c0, c1, c2, c3]` (rows: coefficients).
const HERMITE: [[f64; 4]; 4] =
    [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [-3.0, -2.0, 3.0, -1.0], [2.0, 1.0, -2.0, 1.0]];
/// Power → Bernstein (Bézier control points) for a cubic on [0, 1]: rows are control points.
const BEZIER: [[f64; 4]; 4] =
    [[1.0, 0.0, 0.0, 0.0], [1.0, 1.0 / 3.0, 0.0, 0.0], [1.0, 2.0 / 3.0, 1.0 / 3.0, 0.0], [1.0, 1.0, 1.0, 1.0]];

/// A bicubic spline patch in a body frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Patch {
    /// Cells along s1, s2.
    cells: [usize; 2],
    /// First knot and knot spacing per direction.
    lo: [f64; 2],
    h: [f64; 2],
    periodic: [bool; 2],
    /// Per cell (index `i * cells[1] + j`), `c[p][q]` multiplies `τ1^p τ2^q`, `τ = (s - s_i) / h`.
    coef: Vec<[[Vec3; 4]; 4]>,
    /// Per cell a ball holding it (centre, radius).
    balls: Vec<(Vec3, f64)>,
    /// Blocks of up to `BLOCK × BLOCK` cells with a ball holding theirs (the search's first level).
    blocks: Vec<Block>,
}

/// Cells per side of a block of the search's bounding hierarchy.
const BLOCK: usize = 4;

/// A block of cells `i.0..i.1` × `j.0..j.1` and a ball holding their balls.
#[derive(Debug, Clone, PartialEq)]
struct Block {
    i: (usize, usize),
    j: (usize, usize),
    ball: (Vec3, f64),
}

impl Patch {
    /// The patch through `points[i][j]` (`n1 × n2`, at least 2 × 2; 4 along a periodic direction
    /// with the last line repeating the first) at `s_k = range_k.0 + i (range_k.1 - range_k.0) /
    /// (n_k - 1)`. `what` names the contact and contour in errors.
    pub fn new(
        points: &[Vec<Vec3>],
        range1: (f64, f64),
        range2: (f64, f64),
        periodic: [bool; 2],
        what: &str,
    ) -> Result<Self> {
        let n1 = points.len();
        let n2 = points.first().map_or(0, |r| r.len());
        for (k, (n, p)) in [(n1, periodic[0]), (n2, periodic[1])].iter().enumerate() {
            let min = if *p { 4 } else { 2 };
            ensure!(*n >= min, Model, "{what}: patch grid needs at least {min} points along s{}, got {n}", k + 1);
        }
        for (i, row) in points.iter().enumerate() {
            ensure!(
                row.len() == n2,
                Model,
                "{what}: patch grid must be rectangular: row {i} has {} points, row 0 has {n2}",
                row.len()
            );
            for (j, p) in row.iter().enumerate() {
                ensure!(
                    p.iter().all(|v| v.is_finite()),
                    Model,
                    "{what}: patch point [{i}][{j}] must be finite, got {:?}",
                    p.as_slice()
                );
            }
        }
        for (k, r) in [range1, range2].iter().enumerate() {
            ensure!(
                r.0.is_finite() && r.1.is_finite() && r.1 > r.0,
                Model,
                "{what}: patch parameter range s{} must be finite and increasing, got ({}, {})",
                k + 1,
                r.0,
                r.1
            );
        }
        let scale = points.iter().flatten().map(|p| p.norm()).fold(1e-300, f64::max);
        let ends = |a: &Vec3, b: &Vec3| (a - b).norm() <= 1e-9 * scale;
        if periodic[0] {
            for j in 0..n2 {
                ensure!(
                    ends(&points[0][j], &points[n1 - 1][j]),
                    Model,
                    "{what}: patch is periodic in s1 but its last row does not repeat the first (point [{}][{j}] differs by {:.3e})",
                    n1 - 1,
                    (points[0][j] - points[n1 - 1][j]).norm()
                );
            }
        }
        if periodic[1] {
            for (i, row) in points.iter().enumerate() {
                ensure!(
                    ends(&row[0], &row[n2 - 1]),
                    Model,
                    "{what}: patch is periodic in s2 but its last column does not repeat the first (point [{i}][{}] differs by {:.3e})",
                    n2 - 1,
                    (row[0] - row[n2 - 1]).norm()
                );
            }
        }
        let h = [(range1.1 - range1.0) / (n1 - 1) as f64, (range2.1 - range2.0) / (n2 - 1) as f64];
        let knots = |n: usize, lo: f64, h: f64| (0..n).map(|i| lo + h * i as f64).collect::<Vec<_>>();
        let (t1, t2) = (knots(n1, range1.0, h[0]), knots(n2, range2.0, h[1]));
        // derivative at the knots of the spline through `ys` (one coordinate)
        let slopes = |t: &[f64], ys: &[f64], per: bool| -> Result<Vec<f64>> {
            let s = if per { Spline1::periodic(t, ys, what)? } else { Spline1::natural(t, ys, what)? };
            Ok(t.iter().map(|&x| s.eval(x)[1]).collect())
        };
        let mut d1 = vec![vec![Vec3::zeros(); n2]; n1];
        let mut d2 = vec![vec![Vec3::zeros(); n2]; n1];
        let mut d12 = vec![vec![Vec3::zeros(); n2]; n1];
        for c in 0..3 {
            for j in 0..n2 {
                let ys: Vec<f64> = (0..n1).map(|i| points[i][j][c]).collect();
                for (i, v) in slopes(&t1, &ys, periodic[0])?.into_iter().enumerate() {
                    d1[i][j][c] = v;
                }
            }
            for i in 0..n1 {
                let ys: Vec<f64> = (0..n2).map(|j| points[i][j][c]).collect();
                for (j, v) in slopes(&t2, &ys, periodic[1])?.into_iter().enumerate() {
                    d2[i][j][c] = v;
                }
                let ys: Vec<f64> = (0..n2).map(|j| d1[i][j][c]).collect();
                for (j, v) in slopes(&t2, &ys, periodic[1])?.into_iter().enumerate() {
                    d12[i][j][c] = v;
                }
            }
        }
        let cells = [n1 - 1, n2 - 1];
        let mut coef = Vec::with_capacity(cells[0] * cells[1]);
        let mut balls = Vec::with_capacity(cells[0] * cells[1]);
        for i in 0..cells[0] {
            for j in 0..cells[1] {
                // Hermite data: a = [value, ∂τ1] at i, i+1; b likewise along τ2
                let at = |a: usize, b: usize| -> Vec3 {
                    let (ii, jj) = (i + a / 2, j + b / 2);
                    match (a % 2, b % 2) {
                        (0, 0) => points[ii][jj],
                        (1, 0) => d1[ii][jj] * h[0],
                        (0, 1) => d2[ii][jj] * h[1],
                        _ => d12[ii][jj] * (h[0] * h[1]),
                    }
                };
                let mut c = [[Vec3::zeros(); 4]; 4];
                for (p, cp) in c.iter_mut().enumerate() {
                    for (q, cpq) in cp.iter_mut().enumerate() {
                        for a in 0..4 {
                            for b in 0..4 {
                                *cpq += at(a, b) * (HERMITE[p][a] * HERMITE[q][b]);
                            }
                        }
                    }
                }
                // Bézier control net: the cell lies in its convex hull
                let mut net = [[Vec3::zeros(); 4]; 4];
                for (u, nu) in net.iter_mut().enumerate() {
                    for (v, nuv) in nu.iter_mut().enumerate() {
                        for (p, cp) in c.iter().enumerate() {
                            for (q, cpq) in cp.iter().enumerate() {
                                *nuv += cpq * (BEZIER[u][p] * BEZIER[v][q]);
                            }
                        }
                    }
                }
                let center = net.iter().flatten().sum::<Vec3>() / 16.0;
                let radius = net.iter().flatten().map(|p| (p - center).norm()).fold(0.0, f64::max);
                coef.push(c);
                balls.push((center, radius));
            }
        }
        let patch = Patch { cells, lo: [range1.0, range2.0], h, periodic, coef, balls, blocks: Vec::new() };
        // the normal r_1 × r_2 must exist everywhere: check the knots and the cell middles
        for i in 0..2 * cells[0] + 1 {
            for j in 0..2 * cells[1] + 1 {
                let s = [range1.0 + 0.5 * h[0] * i as f64, range2.0 + 0.5 * h[1] * j as f64];
                let jet = patch.eval(s);
                let area = jet[1].cross(&jet[2]).norm();
                ensure!(
                    area > 1e-9 * jet[1].norm().max(1e-300) * jet[2].norm().max(1e-300) && area.is_finite(),
                    Model,
                    "{what}: patch has no normal at (s1, s2) = ({:.4}, {:.4}) (r_1 × r_2 = 0: repeated or collinear grid                      points, a pole)",
                    s[0],
                    s[1]
                );
            }
        }
        let Patch { coef, balls, .. } = patch;
        let mut blocks = Vec::new();
        for bi in (0..cells[0]).step_by(BLOCK) {
            for bj in (0..cells[1]).step_by(BLOCK) {
                let (i, j) = ((bi, (bi + BLOCK).min(cells[0])), (bj, (bj + BLOCK).min(cells[1])));
                let ks: Vec<usize> = (i.0..i.1).flat_map(|a| (j.0..j.1).map(move |b| a * cells[1] + b)).collect();
                let center = ks.iter().map(|&k| balls[k].0).sum::<Vec3>() / ks.len() as f64;
                let radius = ks.iter().map(|&k| (balls[k].0 - center).norm() + balls[k].1).fold(0.0, f64::max);
                blocks.push(Block { i, j, ball: (center, radius) });
            }
        }
        Ok(Patch { cells, lo: [range1.0, range2.0], h, periodic, coef, balls, blocks })
    }

    /// Parameter range per direction.
    pub fn range(&self) -> [(f64, f64); 2] {
        [0, 1].map(|k| (self.lo[k], self.lo[k] + self.h[k] * self.cells[k] as f64))
    }

    /// Whether each direction is periodic.
    pub fn periodic(&self) -> [bool; 2] {
        self.periodic
    }

    /// A parameter brought into the range: wrapped when periodic, clamped otherwise.
    #[inline]
    pub fn clamp(&self, s: [f64; 2]) -> [f64; 2] {
        let r = self.range();
        [0, 1].map(|k| if self.periodic[k] { wrap(s[k], r[k].0, r[k].1) } else { s[k].clamp(r[k].0, r[k].1) })
    }

    /// `r, r_1, r_2, r_11, r_12, r_22` at `s` (brought into the range first). No allocation.
    pub fn eval(&self, s: [f64; 2]) -> Jet {
        let s = self.clamp(s);
        let mut idx = [0usize; 2];
        let mut tau = [0.0; 2];
        for k in 0..2 {
            let x = (s[k] - self.lo[k]) / self.h[k];
            let i = (x.floor().max(0.0) as usize).min(self.cells[k] - 1);
            idx[k] = i;
            tau[k] = x - i as f64;
        }
        let c = &self.coef[idx[0] * self.cells[1] + idx[1]];
        // powers and their first two derivatives in τ
        let pw = |t: f64| -> [[f64; 4]; 3] {
            [[1.0, t, t * t, t * t * t], [0.0, 1.0, 2.0 * t, 3.0 * t * t], [0.0, 0.0, 2.0, 6.0 * t]]
        };
        let (a, b) = (pw(tau[0]), pw(tau[1]));
        let mut out = [Vec3::zeros(); 6];
        // (d/dτ1 order, d/dτ2 order) for each output
        const ORDERS: [(usize, usize); 6] = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)];
        for (o, &(da, db)) in out.iter_mut().zip(ORDERS.iter()) {
            for (p, cp) in c.iter().enumerate() {
                for (q, cpq) in cp.iter().enumerate() {
                    let w = a[da][p] * b[db][q];
                    if w != 0.0 {
                        *o += cpq * w;
                    }
                }
            }
            *o /= self.h[0].powi(da as i32) * self.h[1].powi(db as i32);
        }
        out
    }

    /// Unit normal `ν` (eq. 2.118) of a jet.
    #[inline]
    pub fn normal(j: &Jet) -> Vec3 {
        j[1].cross(&j[2]).normalize()
    }

    /// Principal curvatures (convex > 0, the larger first) of a jet: minus the eigenvalues of
    /// `I⁻¹ II` (eqs. 2.117, 2.119).
    pub fn curvatures(j: &Jet) -> [f64; 2] {
        let nu = Self::normal(j);
        let (e, f, g) = (j[1].dot(&j[1]), j[1].dot(&j[2]), j[2].dot(&j[2]));
        let (l, m, n) = (nu.dot(&j[3]), nu.dot(&j[4]), nu.dot(&j[5]));
        let det = e * g - f * f;
        // mean and Gaussian curvature of the shape operator -I⁻¹ II
        let hm = -(e * n - 2.0 * f * m + g * l) / (2.0 * det);
        let k = (l * n - m * m) / det;
        let d = (hm * hm - k).max(0.0).sqrt();
        [hm + d, hm - d]
    }

    /// The parameters of the point of the patch nearest to `y` (see the module docs). No
    /// allocation.
    pub fn foot(&self, y: &Vec3) -> [f64; 2] {
        // the nearest block, and in it the cell with the nearest far side, first: its samples
        // bound the distance tightly
        let lower = |(c, r): &(Vec3, f64)| (y - c).norm() - r;
        let mut near = 0;
        for (b, blk) in self.blocks.iter().enumerate() {
            if lower(&blk.ball) < lower(&self.blocks[near].ball) {
                near = b;
            }
        }
        let (mut first, mut far) = (0, f64::INFINITY);
        for k in self.block_cells(near) {
            let (c, r) = &self.balls[k];
            let ub = (y - c).norm() + r;
            if ub < far {
                (first, far) = (k, ub);
            }
        }
        let (mut best, mut sb) = (f64::INFINITY, [self.lo[0], self.lo[1]]);
        self.sample_cell(y, first, &mut best, &mut sb);
        // a block or cell whose ball is farther than the best sample cannot hold the foot point
        let beyond = |lb: f64, best: f64| lb > 0.0 && lb * lb > best;
        for b in 0..self.blocks.len() {
            if beyond(lower(&self.blocks[b].ball), best) {
                continue;
            }
            for k in self.block_cells(b) {
                if k != first && !beyond(lower(&self.balls[k]), best) {
                    self.sample_cell(y, k, &mut best, &mut sb);
                }
            }
        }
        self.newton(y, sb)
    }

    /// The cells of block `b` (indices into the cell arrays).
    fn block_cells(&self, b: usize) -> impl Iterator<Item = usize> + '_ {
        let blk = &self.blocks[b];
        let n2 = self.cells[1];
        (blk.i.0..blk.i.1).flat_map(move |i| (blk.j.0..blk.j.1).map(move |j| i * n2 + j))
    }

    /// The nearest of a 5 × 5 grid of samples of cell `k`, if nearer than `best`.
    fn sample_cell(&self, y: &Vec3, k: usize, best: &mut f64, sb: &mut [f64; 2]) {
        let (i, j) = (k / self.cells[1], k % self.cells[1]);
        for a in 0..5 {
            for b in 0..5 {
                let (t1, t2) = (a as f64 / 4.0, b as f64 / 4.0);
                let d = (y - self.value(&self.coef[k], t1, t2)).norm_squared();
                if d < *best {
                    *best = d;
                    *sb = [self.lo[0] + self.h[0] * (i as f64 + t1), self.lo[1] + self.h[1] * (j as f64 + t2)];
                }
            }
        }
    }

    /// The value in cell `c` at `τ`.
    #[inline]
    fn value(&self, c: &[[Vec3; 4]; 4], t1: f64, t2: f64) -> Vec3 {
        let mut out = Vec3::zeros();
        let mut a = 1.0;
        for cp in c {
            let mut b = 1.0;
            for cpq in cp {
                out += cpq * (a * b);
                b *= t2;
            }
            a *= t1;
        }
        out
    }

    /// Damped Newton on `½|y - r(s)|²` from `s` (clamped to a natural direction's range).
    pub fn newton(&self, y: &Vec3, s0: [f64; 2]) -> [f64; 2] {
        let mut s = self.clamp(s0);
        let mut j = self.eval(s);
        let mut phi = 0.5 * (y - j[0]).norm_squared();
        for _ in 0..50 {
            let d = y - j[0];
            let grad = nalgebra::Vector2::new(-d.dot(&j[1]), -d.dot(&j[2]));
            let metric = nalgebra::Matrix2::new(j[1].dot(&j[1]), j[1].dot(&j[2]), j[2].dot(&j[1]), j[2].dot(&j[2]));
            let hess = metric - nalgebra::Matrix2::new(d.dot(&j[3]), d.dot(&j[4]), d.dot(&j[4]), d.dot(&j[5]));
            let pd = hess[(0, 0)] > 0.0 && hess.determinant() > 0.0;
            let m = if pd { hess } else { metric };
            let Some(mi) = m.try_inverse() else { break };
            let mut step = -(mi * grad);
            // at most one cell per iteration
            let cap = (step.x.abs() / self.h[0]).max(step.y.abs() / self.h[1]);
            if cap > 1.0 {
                step /= cap;
            }
            let mut moved = false;
            for _ in 0..30 {
                let t = self.clamp([s[0] + step.x, s[1] + step.y]);
                let jt = self.eval(t);
                let pt = 0.5 * (y - jt[0]).norm_squared();
                // rounding hides φ's decrease near the root (it changes with the square of the
                // step); a step that raises φ by no more than that still approaches the root
                if pt <= phi * (1.0 + 1e-13) + 1e-300 {
                    moved = (t[0] - s[0]).abs() > 1e-15 * self.h[0] || (t[1] - s[1]).abs() > 1e-15 * self.h[1];
                    (s, j, phi) = (t, jt, pt);
                    break;
                }
                step *= 0.5;
            }
            if !moved {
                break;
            }
        }
        s
    }

    /// Whether the parameter lies on the edge of a natural direction (a boundary foot point).
    pub fn on_edge(&self, s: [f64; 2]) -> [bool; 2] {
        let r = self.range();
        [0, 1].map(|k| !self.periodic[k] && (s[k] <= r[k].0 || s[k] >= r[k].1))
    }

    /// Per-cell bounding balls (centre, radius), for the broad phase.
    pub fn balls(&self) -> &[(Vec3, f64)] {
        &self.balls
    }
}
