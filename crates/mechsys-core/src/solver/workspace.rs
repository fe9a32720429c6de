//! Scratch storage of the solvers, sized once so that solves do not allocate.

use super::anderson::Anderson;
use super::apgd::ApgdWork;
use super::lemke::LemkeWork;
use super::newton::NewtonWork;
use super::{Method, Problem};
use crate::error::{Error, Result};

/// Buffer sizes a (problem, method) pair needs; every field is a length or count.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Needs {
    /// Velocities `u` or `w` (unknowns).
    pub u: usize,
    /// Cached diagonal blocks (contacts).
    pub diag: usize,
    /// Size of the LCP Lemke pivots on.
    pub lemke: usize,
    /// Size of the LCP built from a friction-contact problem (0 if none).
    pub lcp: usize,
    /// Side of the dense copy of a block-sparse `W` (0 if none).
    pub dense: usize,
    /// Unknowns of a Newton solve (0 if none).
    pub newton: usize,
    /// Unknowns of an APGD solve (0 if none).
    pub apgd: usize,
    /// Unknowns of an Anderson-accelerated Gauss–Seidel solve (0 if none).
    pub anderson: usize,
}

impl Needs {
    fn max(self, o: Needs) -> Needs {
        Needs {
            u: self.u.max(o.u),
            diag: self.diag.max(o.diag),
            lemke: self.lemke.max(o.lemke),
            lcp: self.lcp.max(o.lcp),
            dense: self.dense.max(o.dense),
            newton: self.newton.max(o.newton),
            apgd: self.apgd.max(o.apgd),
            anderson: self.anderson.max(o.anderson),
        }
    }

    fn covers(&self, o: &Needs) -> bool {
        self.max(*o) == *self
    }
}

/// All scratch of the solvers. Create once with [`Workspace::for_problem`] (or [`Workspace::new`]
/// and [`Workspace::reserve`]) for the largest problem and each method a caller uses; reserving
/// again for a problem that fits is free, so an integrator whose active set changes size calls
/// `reserve` before every solve and allocates only when the set grows beyond anything seen.
#[derive(Debug, Clone, Default)]
pub struct Workspace {
    cap: Needs,
    pub(crate) u: Vec<f64>,
    pub(crate) diag: Vec<[f64; 9]>,
    /// The 3-D diagonal blocks prepared for the local solves of the sweeps.
    pub(crate) local3: Vec<super::nsgs::LocalBlock3>,
    pub(crate) lemke: LemkeWork,
    /// Friction LCP: `M` (row-major), `q`, `z`.
    pub(crate) lcp_m: Vec<f64>,
    pub(crate) lcp_q: Vec<f64>,
    pub(crate) lcp_z: Vec<f64>,
    pub(crate) dense: Vec<f64>,
    pub(crate) newton: NewtonWork,
    pub(crate) apgd: ApgdWork,
    pub(crate) anderson: Anderson,
    /// Gauss–Seidel's visiting order of the contacts (empty: by index), see [`Workspace::set_order`].
    pub(crate) order: Vec<usize>,
}

impl Workspace {
    /// An empty workspace; call [`Workspace::reserve`] before solving.
    pub fn new() -> Self {
        Self::default()
    }

    /// A workspace sized for `problem` and `method`.
    pub fn for_problem<P: Problem + ?Sized>(problem: &P, method: &Method) -> Result<Self> {
        let mut ws = Self::new();
        ws.reserve(problem, method)?;
        Ok(ws)
    }

    /// Grows the buffers so that `problem` can be solved with `method`; never shrinks.
    /// Fails if the method does not apply to the problem.
    pub fn reserve<P: Problem + ?Sized>(&mut self, problem: &P, method: &Method) -> Result<()> {
        problem.validate()?;
        let need = problem.needs(method)?;
        if self.cap.covers(&need) {
            return Ok(());
        }
        let cap = self.cap.max(need);
        grow(&mut self.u, cap.u);
        if self.diag.len() < cap.diag {
            self.diag.resize(cap.diag, [0.0; 9]);
            self.local3.resize(cap.diag, super::nsgs::LocalBlock3::default());
        }
        self.lemke.reserve(cap.lemke);
        grow(&mut self.lcp_m, cap.lcp * cap.lcp);
        grow(&mut self.lcp_q, cap.lcp);
        grow(&mut self.lcp_z, cap.lcp);
        grow(&mut self.dense, cap.dense * cap.dense);
        self.newton.reserve(cap.newton);
        self.apgd.reserve(cap.apgd);
        self.anderson.reserve(cap.anderson, 0);
        self.cap = cap;
        Ok(())
    }

    /// Makes Gauss–Seidel sweeps (NSGS, and Newton's fallback sweeps) visit the contacts by
    /// ascending `key` (ties by index) in the following solves of problems with `key.len()`
    /// contacts; an empty `key` restores the index order. A problem of another size is swept by
    /// index. Allocates only when the number of contacts grows beyond anything seen.
    ///
    /// The time-stepping scheme orders by height along gravity, so that a sweep carries the
    /// weights of a pile down through it in one pass instead of one contact per sweep.
    pub fn set_order(&mut self, key: &[f64]) {
        self.order.clear();
        self.order.extend(0..key.len());
        // an unstable sort with the index as tie-break: deterministic and allocation-free
        self.order.sort_unstable_by(|&a, &b| key[a].total_cmp(&key[b]).then(a.cmp(&b)));
    }

    pub(crate) fn check(&self, need: &Needs) -> Result<()> {
        if self.cap.covers(need) {
            Ok(())
        } else {
            Err(Error::Settings(format!(
                "solver: the workspace is too small for this problem (has {:?}, needs {:?}); call Workspace::reserve first",
                self.cap, need
            )))
        }
    }
}

fn grow(v: &mut Vec<f64>, len: usize) {
    if v.len() < len {
        v.resize(len, 0.0);
    }
}
