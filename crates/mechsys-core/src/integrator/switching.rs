//! Steps that end at switches: a system's switching functions (the gaps of compliant contacts
//! and their forces before the cut-off, [`crate::forces::compliant::switching`]) change sign
//! where its right-hand side has a kink; a step across one loses the scheme's order there. After
//! an accepted step whose end shows a sign change, [`Locator::locate`] finds the first change on
//! the step's continuous extension (regula falsi with the Illinois modification, safeguarded by
//! bisection) and the scheme retakes the step up to just past it, so the next step starts on the
//! far side of the kink.

use super::OdeSystem;
use crate::error::Result;

/// Buffers of the search (sized once per run).
#[derive(Debug, Clone, Default)]
pub(crate) struct Locator {
    start: Vec<f64>,
    probe: Vec<f64>,
    end: Vec<f64>,
    y: Vec<f64>,
}

/// Relative width (of the step) to which a switch is located.
const WIDTH: f64 = 1e-13;

/// How far past the located change (relative to the step) the retaken step ends.
const MARGIN: f64 = 1e-7;

/// The sides of a switching function: ≥ 0 (open, or a force not cut off) and < 0.
#[inline]
fn side(v: f64) -> bool {
    v >= 0.0
}

impl Locator {
    /// Buffers for `sys`.
    pub(crate) fn new<S: OdeSystem>(sys: &S) -> Self {
        let m = sys.switches();
        Locator {
            start: vec![0.0; m],
            probe: vec![0.0; m],
            end: vec![0.0; m],
            y: if m > 0 { vec![0.0; sys.dim()] } else { Vec::new() },
        }
    }

    /// Whether the system has switching functions.
    pub(crate) fn active(&self) -> bool {
        !self.start.is_empty()
    }

    fn changed(&self, values: &[f64]) -> bool {
        self.start.iter().zip(values).any(|(a, b)| side(*a) != side(*b))
    }

    /// For the step `[t, t + h]` from `y0` to `y1` with continuous extension `dense(θ, out)`:
    /// the fraction θ ∈ (0, 1) just past the first sign change of a switching function, or None
    /// when none changes (or the change is within 1e-9 of the step from its start or end).
    pub(crate) fn locate<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t: f64,
        h: f64,
        y0: &[f64],
        y1: &[f64],
        mut dense: impl FnMut(f64, &mut [f64]),
    ) -> Result<Option<f64>> {
        if !self.active() {
            return Ok(None);
        }
        sys.switching(t, y0, &mut self.start)?;
        sys.switching(t + h, y1, &mut self.end)?;
        if !self.changed(&self.end) {
            return Ok(None);
        }
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        // the switch whose change the linear estimate puts first; after its change is found, a
        // check that no other one changed before it (else the search goes on below)
        for _ in 0..8 {
            let (start, end) = (&self.start, &self.end);
            let Some(i) = (0..start.len()).filter(|&k| side(start[k]) != side(end[k])).min_by(|&a, &b| {
                let est = |k: usize| lo + (hi - lo) * start[k] / (start[k] - end[k]);
                est(a).total_cmp(&est(b))
            }) else {
                break;
            };
            let (s0, mut flo, mut fhi) = (start[i], start[i], end[i]);
            if lo > 0.0 {
                // the bracket's lower end is not the step's start: its value there
                dense(lo, &mut self.y);
                sys.switching(t + lo * h, &self.y, &mut self.probe)?;
                flo = self.probe[i];
            }
            let (mut last, mut k, mut width) = (0i8, 0u32, hi - lo);
            while hi - lo > WIDTH && k < 400 {
                k += 1;
                // Illinois steps; a bisection whenever two steps did not halve the bracket
                let mut mid = lo + (hi - lo) * flo / (flo - fhi);
                if k % 3 == 0 {
                    if hi - lo > 0.5 * width {
                        mid = 0.5 * (lo + hi);
                    }
                    width = hi - lo;
                }
                if !(mid > lo && mid < hi) {
                    mid = 0.5 * (lo + hi);
                }
                dense(mid, &mut self.y);
                sys.switching(t + mid * h, &self.y, &mut self.probe)?;
                let v = self.probe[i];
                if side(v) == side(s0) {
                    (lo, flo) = (mid, v);
                    if last == -1 {
                        fhi *= 0.5;
                    }
                    last = -1;
                } else {
                    (hi, fhi) = (mid, v);
                    self.end.copy_from_slice(&self.probe);
                    if last == 1 {
                        flo *= 0.5;
                    }
                    last = 1;
                }
            }
            if lo > 0.0 {
                dense(lo, &mut self.y);
                sys.switching(t + lo * h, &self.y, &mut self.probe)?;
                if self.changed(&self.probe) {
                    // another switch changed before this one: its change lies below lo
                    hi = lo;
                    lo = 0.0;
                    self.end.copy_from_slice(&self.probe);
                    continue;
                }
            }
            break;
        }
        // a little past the change, so that the retaken step (whose end differs from the
        // continuous extension by the local error) ends on the far side; a change at the step's
        // very start or end leaves a negligible sliver across it
        let th = hi + MARGIN;
        Ok(if hi > 1e-9 && th < 1.0 - 1e-9 { Some(th) } else { None })
    }
}
