//! Warm starts of the planar parametric contact searches ([`super::curve_pair`]): the state one
//! evaluation of a pair leaves for the next, the bound on the relative motion since the last
//! cold search, and the margin that decides whether refining the previous roots is enough.
//!
//! **Why it is safe.** Each search minimises a function `φ(s)` over a parameter `s` of the
//! searched contour: the distance of a point to a curve (`s` on the curve), the height of a curve
//! over a line or the signed distance of a curve to another curve (`s` on the moving curve). For
//! a fixed parameter, `φ` is 1-Lipschitz in the position of the moving point, and a rigid motion
//! of body 1 relative to body 2 by `(Δc, ΔB)` moves every point of a contour within the circle
//! `(m, R)` by at most `δ = |ΔB m + Δc| + ‖ΔB‖₂ R`. A cold search splits the sampled `φ` into
//! basins (one per sampled local minimum, each refined by Newton to its minimum) and keeps the
//! `count` deepest roots; it records the *margin* `min(other basins' minima, pruned regions'
//! bound) - (deepest kept key)`. Later, every other basin is still above `φ_other - δ` and every
//! kept root below `key + δ` (its old material point is within `δ`), so while `2δ < margin` the
//! cold search would keep the same roots: Newton from the previous roots finds them. A warm root
//! must also stay between the neighbouring basins' seeds and below `key + δ` (else it is not its
//! basin's minimum), or the search runs cold. The assumption is the cold search's own: each
//! sampled basin holds one minimum of `φ`, the one Newton finds from its sampled minimum.
//!
//! With several points (or a negative gap) a warm root must also keep its chunks within the
//! pruning's reach of the closest point, else the cold search would not look there.
//!
//! Not warm-started (every evaluation cold): a search with a free candidate slot (any new root
//! would fill it), one whose basins did not all converge, contours overlapping deeper than the
//! pruning's bound (a pruned region could then lie inside the other contour), and gear pairs
//! (whether the cold search finds a root at a flank's end depends on its sampling, so the roots
//! through a tooth handover are no family Newton could follow).

use crate::geometry::curve::Vec2;

/// What one evaluation of a curve pair leaves for the next: written by a cold search, read (and
/// the roots' parameters moved) by warm ones. One per candidate point of a contact; the pair's
/// fields (validity, margin, reference placement) live in its first point's. The default is
/// empty: the next evaluation searches cold.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SearchHint {
    /// The pair fields hold a usable cold search.
    valid: bool,
    /// The last evaluation refined the previous roots (else: searched cold).
    warm: bool,
    /// How much more than `2δ` every other region's `φ` exceeded the deepest kept root (m).
    margin: f64,
    /// Relative placement at the cold search: `[A2ᵀ A1]_xy` (row-major) and `[A2ᵀ (r1 - r2)]_xy`;
    /// a point search keeps the point itself in `c` and zeros in `b`.
    b: [f64; 4],
    c: [f64; 2],
    /// This candidate holds a root (else it is unused).
    pub(crate) root: bool,
    /// The root's parameters `(s1, s2)` at the last evaluation.
    pub(crate) s: [f64; 2],
    /// The searched parameter may move within `(lo, hi)` (mod the period): the neighbouring
    /// basins' seeds at the cold search.
    pub(crate) window: [f64; 2],
    /// The root's key at the cold search.
    pub(crate) key: f64,
}

impl SearchHint {
    /// Whether the last evaluation of the pair refined the previous roots instead of searching
    /// (read from the pair's first point).
    pub fn was_warm(&self) -> bool {
        self.warm
    }

    /// Forgets the pair's search: the next evaluation searches cold.
    pub fn clear(&mut self) {
        *self = SearchHint::default();
    }

    /// The margin of the last cold search (m; `None` when it allows no warm start).
    pub fn margin(&self) -> Option<f64> {
        self.valid.then_some(self.margin)
    }

    /// Bound `δ` on how far any point of the circle `(m, r)` of body 1 moved in body 2's plane
    /// since the cold search (`∞` without one), for the placement `(b, c)`.
    pub(crate) fn moved(&self, b: &[f64; 4], c: &[f64; 2], m: &Vec2, r: f64) -> f64 {
        if !self.valid {
            return f64::INFINITY;
        }
        let d = [b[0] - self.b[0], b[1] - self.b[1], b[2] - self.b[2], b[3] - self.b[3]];
        let dm = Vec2::new(d[0] * m.x + d[1] * m.y + c[0] - self.c[0], d[2] * m.x + d[3] * m.y + c[1] - self.c[1]);
        dm.norm() + spectral_norm(&d) * r
    }

    /// Whether a motion `delta` keeps the cold search's roots (`2δ < margin`).
    pub(crate) fn allows(&self, delta: f64) -> bool {
        self.valid && 2.0 * delta < self.margin
    }

    /// Records a cold search: its margin (no warm start unless > 0) and placement.
    pub(crate) fn set_cold(&mut self, margin: f64, b: &[f64; 4], c: &[f64; 2]) {
        self.valid = margin > 0.0 && margin.is_finite();
        self.warm = false;
        self.margin = margin;
        self.b = *b;
        self.c = *c;
    }

    /// Marks the last evaluation as warm.
    pub(crate) fn set_warm(&mut self) {
        self.warm = true;
    }
}

/// Largest singular value of a 2×2 matrix (row-major): `√((F² + √(F⁴ - 4 det²)) / 2)`.
fn spectral_norm(m: &[f64; 4]) -> f64 {
    let f2 = m.iter().map(|x| x * x).sum::<f64>();
    let det = m[0] * m[3] - m[1] * m[2];
    (0.5 * (f2 + (f2 * f2 - 4.0 * det * det).max(0.0).sqrt())).sqrt()
}

/// Most basins a cold search records (more: no warm start).
pub(crate) const MAX_BASINS: usize = 64;

/// One sampled local minimum of a cold search: its sample's parameter (of the searched contour)
/// and the minimum Newton found from it (`None`: it did not converge to a minimum).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Basin<R: Copy> {
    pub s: f64,
    pub root: Option<R>,
}

/// The basins of one cold search, in sample order.
pub(crate) struct Basins<R: Copy> {
    list: [Option<Basin<R>>; MAX_BASINS],
    len: usize,
    overflow: bool,
}

impl<R: Copy> Basins<R> {
    pub(crate) fn new() -> Self {
        Basins { list: [None; MAX_BASINS], len: 0, overflow: false }
    }

    pub(crate) fn push(&mut self, s: f64, root: Option<R>) {
        if self.len == MAX_BASINS {
            self.overflow = true;
        } else {
            self.list[self.len] = Some(Basin { s, root });
            self.len += 1;
        }
    }

    /// The smallest key of the basins that hold none of the `selected` roots (`same` tells a
    /// root's basin), and each selected root's window between the seeds of the nearest basins
    /// not its own (`period` of a closed contour, else open); `None` when a warm start is not
    /// possible: a free slot, an unconverged basin, a root without its basin (the search's
    /// fallback sample), too many basins.
    pub(crate) fn margin(
        &self,
        selected: &[Option<R>],
        param: impl Fn(&R) -> f64,
        key: impl Fn(&R) -> f64,
        same: impl Fn(&R, &R) -> bool,
        period: Option<f64>,
        windows: &mut [[f64; 2]],
    ) -> Option<f64> {
        if self.overflow {
            return None;
        }
        let basins = self.list[..self.len].iter().flatten();
        let mut other = f64::INFINITY;
        for b in basins.clone() {
            let r = b.root.as_ref()?;
            if !selected.iter().flatten().any(|s| same(s, r)) {
                other = other.min(key(r));
            }
        }
        for (sel, w) in selected.iter().zip(windows.iter_mut()) {
            let sel = sel.as_ref()?;
            let p = param(sel);
            if !basins.clone().any(|b| b.root.as_ref().is_some_and(|r| same(sel, r))) {
                return None;
            }
            let (mut before, mut after) = (f64::INFINITY, f64::INFINITY);
            for b in basins.clone().filter(|b| !b.root.as_ref().is_some_and(|r| same(sel, r))) {
                match period {
                    Some(per) => {
                        before = before.min((p - b.s).rem_euclid(per));
                        after = after.min((b.s - p).rem_euclid(per));
                    }
                    None if b.s < p => before = before.min(p - b.s),
                    None => after = after.min(b.s - p),
                }
            }
            *w = [p - before, p + after];
        }
        Some(other)
    }
}

/// Whether parameter `s` lies in `window` (shifted by whole periods of a closed contour).
pub(crate) fn in_window(s: f64, window: &[f64; 2], period: Option<f64>) -> bool {
    let [lo, hi] = *window;
    match period {
        Some(p) if lo.is_finite() => {
            let t = lo + (s - lo).rem_euclid(p);
            t > lo && t < hi
        }
        _ => s > lo && s < hi,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bound against the exact displacements of points on the circle for random placements.
    #[test]
    fn moved_bounds_every_point_of_the_circle() {
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for _ in 0..200 {
            let (t0, t1) = (6.0 * rnd(), 6.0 * rnd());
            let rot = |t: f64| [t.cos(), -t.sin(), t.sin(), t.cos()];
            let (b0, b1) = (rot(t0), rot(t1));
            let (c0, c1) = ([rnd(), rnd()], [rnd(), rnd()]);
            let (m, r) = (Vec2::new(rnd(), rnd()), rnd().abs());
            let mut h = SearchHint::default();
            h.set_cold(1.0, &b0, &c0);
            let delta = h.moved(&b1, &c1, &m, r);
            let map = |b: &[f64; 4], c: &[f64; 2], p: &Vec2| {
                Vec2::new(b[0] * p.x + b[1] * p.y + c[0], b[2] * p.x + b[3] * p.y + c[1])
            };
            let mut worst: f64 = 0.0;
            for k in 0..360 {
                let a = k as f64 * std::f64::consts::PI / 180.0;
                let p = m + Vec2::new(a.cos(), a.sin()) * r;
                worst = worst.max((map(&b1, &c1, &p) - map(&b0, &c0, &p)).norm());
            }
            assert!(worst <= delta * (1.0 + 1e-12), "{worst} > {delta}");
            // and tight: a planar rotation's difference ΔB is a scaled rotation, the bound is exact
            assert!(delta <= worst * (1.0 + 1e-3) + 1e-12, "{delta} vs {worst}");
        }
    }

    #[test]
    fn windows_wrap_on_closed_contours() {
        let p = 2.0 * std::f64::consts::PI;
        assert!(in_window(0.1, &[6.0, 6.5], Some(p)));
        assert!(in_window(6.2, &[6.0, 6.5], Some(p)));
        assert!(!in_window(0.3, &[6.0, 6.5], Some(p)));
        assert!(in_window(0.3, &[f64::NEG_INFINITY, f64::INFINITY], Some(p)));
        assert!(!in_window(2.0, &[0.0, 1.0], None));
    }
}
