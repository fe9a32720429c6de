//! Sparse assembly of the local contact problem on a kinematic tree (models without bilateral
//! constraints).
//!
//! The row `w_a` of a contact (its normal or a tangent, `w_a = J_P1ᵀ e - J_P2ᵀ e`) is nonzero
//! only on the velocities of the root paths of its two bodies, a set closed under ancestors in
//! the velocity tree. With the tree factor `M = Lᵀ D L` (no fill, see
//! [`crate::dynamics::sparse`]), `M⁻¹ = L⁻¹ D⁻¹ L⁻ᵀ` and `y_a = D^{-1/2} L⁻ᵀ w_a` keeps the
//! pattern of `w_a` (the back substitution runs from the leaves to the root), so the Delassus
//! matrix `Wᵀ M⁻¹ W` has the blocks `W_ij = Σ_k y_i,k y_j,kᵀ` over the velocities `k` the two
//! contacts share. Two patterns meet exactly when the contacts have a tree in common, i.e. share
//! the root velocity of one of their bodies' paths: contacts are bucketed by those roots and only
//! pairs within a bucket are formed. The impulses act through `u⁺ = u_free + M⁻¹ Σ_a w_a Λ_a`,
//! one scatter and one O(nu) solve.
//!
//! Cost per step: O(Σ pattern lengths × d) for the rows, O(Σ_pairs shared velocities × d²) for
//! the blocks, O(nu) for the update — for N free bodies with a bounded number of contacts each,
//! O(N). All storage grows to the largest problem seen and is reused: no allocation afterwards.

mod body_newton;
mod domains;
mod factored;

use crate::math::Vec3;
use crate::model::Model;
use crate::spatial::Motion;

/// `M = Lᵀ D L` on the velocity tree: a copy of the dynamics stage's factor
/// ([`crate::dynamics::sparse::Saddle`], the same ancestor layout), with `D^{-1/2}`, so that the
/// contact rows can be reduced on their own patterns.
#[derive(Debug, Clone)]
pub(super) struct TreeFactor {
    nu: usize,
    /// Ancestors of velocity k, nearest first: `anc_idx[anc_ptr[k]..anc_ptr[k + 1]]`.
    anc_ptr: Vec<usize>,
    anc_idx: Vec<usize>,
    /// `L(k, ancestor)`.
    off: Vec<f64>,
    /// D.
    diag: Vec<f64>,
    /// `D^{-1/2}`.
    inv_sqrt_d: Vec<f64>,
}

impl TreeFactor {
    fn new(model: &Model) -> Self {
        let nu = model.nu;
        let (_, _, anc_ptr, anc_idx) = crate::dynamics::sparse::velocity_ancestors(model);
        TreeFactor {
            nu,
            off: vec![0.0; anc_idx.len()],
            anc_ptr,
            anc_idx,
            diag: vec![0.0; nu],
            inv_sqrt_d: vec![0.0; nu],
        }
    }

    /// Takes the factor of M just computed by [`crate::dynamics::sparse::Saddle::factor_mass`]
    /// (factoring M a second time here gave the same numbers).
    pub(super) fn copy_from(&mut self, saddle: &crate::dynamics::sparse::Saddle) {
        let (off, diag) = saddle.mass_factor();
        self.off.copy_from_slice(off);
        self.diag.copy_from_slice(diag);
        for (s, d) in self.inv_sqrt_d.iter_mut().zip(&self.diag) {
            *s = 1.0 / d.sqrt();
        }
    }

    /// `x ← M⁻¹ x`.
    pub(super) fn solve(&self, x: &mut [f64]) {
        for k in (0..self.nu).rev() {
            let xk = x[k];
            if xk != 0.0 {
                for p in self.anc_ptr[k]..self.anc_ptr[k + 1] {
                    x[self.anc_idx[p]] -= self.off[p] * xk;
                }
            }
        }
        for k in 0..self.nu {
            let mut s = x[k] / self.diag[k];
            for p in self.anc_ptr[k]..self.anc_ptr[k + 1] {
                s -= self.off[p] * x[self.anc_idx[p]];
            }
            x[k] = s;
        }
    }
}

/// Contact rows on their patterns, their reduced form `y`, and the Delassus blocks.
#[derive(Debug, Clone)]
pub(super) struct SparseRows {
    pub(super) factor: TreeFactor,
    dim: usize,
    /// Root velocity of body b's path (usize::MAX for the ground and bodies without velocities).
    root: Vec<usize>,
    /// Per body: the first velocity of its joint if its root path is one free joint on the ground
    /// and it has no elastic coordinates (its rows take [`SparseRows::add_free_contact`]), else
    /// usize::MAX.
    free: Vec<usize>,
    /// Per body: the ground or a free body in the sense of `free`, both without elastic
    /// coordinates.
    fast: Vec<bool>,
    /// Pattern of contact a: `pat_idx[pat_ptr[a]..pat_ptr[a + 1]]`, ascending.
    pat_ptr: Vec<usize>,
    pat_idx: Vec<usize>,
    /// The pattern of contact a as runs of consecutive velocities (one per joint on the two root
    /// paths): `(first velocity, length, first pattern entry)` in `runs[run_ptr[a]..run_ptr[a + 1]]`.
    run_ptr: Vec<usize>,
    runs: Vec<(usize, usize, usize)>,
    /// Runs of the root path of body b (joint velocity ranges), ascending.
    body_runs_ptr: Vec<usize>,
    body_runs: Vec<(usize, usize)>,
    /// Rows on the pattern, `dim` values per pattern entry (entry e, row r at `e dim + r`).
    w: Vec<f64>,
    /// `D^{-1/2} L⁻ᵀ w` on the pattern, same layout.
    y: Vec<f64>,
    /// The two roots of each contact (usize::MAX if none).
    roots: Vec<[usize; 2]>,
    /// Scratch: position of a velocity in the current pattern (nu).
    pos: Vec<usize>,
    /// Contacts bucketed by root velocity.
    bucket_ptr: Vec<usize>,
    bucket: Vec<usize>,
    /// Row-major diagonal blocks (n d²).
    pub(super) diag: Vec<f64>,
    /// Off-diagonal pairs (i < j) and their row-major blocks.
    pub(super) upper: Vec<(usize, usize)>,
    pub(super) upper_val: Vec<f64>,
    /// Each contact that shares a root with an earlier one, linked to the first contact of that
    /// root: the same connected components as `upper` with fewer links (for the islands).
    pub(super) links: Vec<(usize, usize)>,
    /// Scratch (nu).
    f: Vec<f64>,
    /// `Y r` of the factored Gauss–Seidel solve (nu).
    z: Vec<f64>,
    /// The reduced rows packed for the factored sweeps when every contact is on free bodies
    /// and the ground (see `factored`).
    packed: Vec<factored::Packed>,
    /// The 3-D diagonal blocks prepared for the local solves of one Gauss–Seidel solve.
    local3: Vec<crate::solver::nsgs::LocalBlock3>,
    /// Anderson acceleration of the factored sweeps.
    aa: crate::solver::anderson::Anderson,
    /// The two domains of a large factored Gauss–Seidel solve.
    dom: domains::Domains,
    /// Whether the two domains are swept on two of rayon's threads (the impulses do not depend
    /// on it).
    pub(in crate::integrator::moreau_jean) parallel: bool,
    /// The body-space Newton method's scratch and held factorization.
    pub(super) newton: body_newton::BodyNewton,
    /// The regularization `c/h²` of each contact's normal direction (compliant Signorini
    /// laws), already added to its diagonal block: the sweeps, whose `Y r` products carry only
    /// `W r`, add `c/h² r_N` back. Empty where every contact is rigid.
    pub(super) reg: Vec<f64>,
}

impl SparseRows {
    /// Planned for `model`, contact dimension `dim`.
    pub(super) fn new(model: &Model, dim: usize) -> Self {
        let factor = TreeFactor::new(model);
        let nb = model.nbodies();
        let mut root = vec![usize::MAX; nb];
        let mut free = vec![usize::MAX; nb];
        let mut fast = vec![false; nb];
        let (mut body_runs_ptr, mut body_runs) = (vec![0; nb + 1], Vec::new());
        let mut buf = Vec::new();
        for b in 0..nb {
            let s0 = body_runs.len();
            let mut x = b;
            while x != 0 {
                let j = &model.joints[x - 1];
                if j.nu() > 0 {
                    body_runs.push((j.iu, j.nu()));
                }
                x = j.parent;
            }
            body_runs[s0..].reverse();
            // an elastic body's coordinates come after every joint's: its last run
            if let Some(k) = model.bodies[b].elastic {
                let e = &model.elastic[k];
                body_runs.push((e.iu, e.ne));
            }
            body_runs_ptr[b + 1] = body_runs.len();
            buf.clear();
            let mut x = b;
            while x != 0 {
                let j = &model.joints[x - 1];
                buf.extend(j.iu..j.iu + j.nu());
                x = j.parent;
            }
            buf.sort_unstable();
            root[b] = buf.first().copied().unwrap_or(usize::MAX);
            if b != 0 && model.bodies[b].elastic.is_none() {
                let j = &model.joints[b - 1];
                if j.parent == 0 && matches!(j.kind, crate::model::JointKind::Free) {
                    free[b] = j.iu;
                }
            }
            fast[b] = model.bodies[b].elastic.is_none() && (b == 0 || free[b] != usize::MAX);
        }
        SparseRows {
            factor,
            dim,
            root,
            free,
            fast,
            pat_ptr: vec![0],
            pat_idx: Vec::new(),
            run_ptr: vec![0],
            runs: Vec::new(),
            body_runs_ptr,
            body_runs,
            w: Vec::new(),
            y: Vec::new(),
            roots: Vec::new(),
            pos: vec![0; model.nu],
            bucket_ptr: vec![0; model.nu + 2],
            bucket: Vec::new(),
            diag: Vec::new(),
            upper: Vec::new(),
            upper_val: Vec::new(),
            links: Vec::new(),
            f: vec![0.0; model.nu],
            z: vec![0.0; model.nu],
            packed: Vec::new(),
            local3: Vec::new(),
            aa: Default::default(),
            dom: Default::default(),
            parallel: true,
            newton: Default::default(),
            reg: Vec::new(),
        }
    }

    /// Forgets the contacts of the previous step.
    pub(super) fn clear(&mut self) {
        self.pat_ptr.truncate(1);
        self.pat_idx.clear();
        self.run_ptr.truncate(1);
        self.runs.clear();
        self.w.clear();
        self.y.clear();
        self.roots.clear();
        self.reg.clear();
    }

    /// Number of contacts added since [`SparseRows::clear`].
    pub(super) fn len(&self) -> usize {
        self.roots.len()
    }

    /// Adds the rows `dirs[r]ᵀ (J_P1 - J_P2)`, r < dim, of a contact between `p1` on `b1` and `p2`
    /// on `b2` (world points), and reduces them (the factor must be current).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn add_contact(
        &mut self,
        model: &Model,
        s_all: &[[Motion; 6]],
        el: crate::kinematics::ElasticView<'_>,
        b1: usize,
        p1: &Vec3,
        b2: usize,
        p2: &Vec3,
        dirs: &[Vec3; 3],
    ) {
        if b1 != b2 && self.fast[b1] && self.fast[b2] {
            match self.dim {
                3 => self.add_free_contact::<3>(s_all, b1, p1, b2, p2, dirs),
                _ => self.add_free_contact::<2>(s_all, b1, p1, b2, p2, dirs),
            }
        } else {
            self.add_general_contact(model, s_all, el, b1, p1, b2, p2, dirs);
        }
    }

    /// [`SparseRows::add_contact`] on any two bodies (root paths of any joints, elastic points).
    #[allow(clippy::too_many_arguments)]
    fn add_general_contact(
        &mut self,
        model: &Model,
        s_all: &[[Motion; 6]],
        el: crate::kinematics::ElasticView<'_>,
        b1: usize,
        p1: &Vec3,
        b2: usize,
        p2: &Vec3,
        dirs: &[Vec3; 3],
    ) {
        let d = self.dim;
        let start = self.pat_idx.len();
        // pattern: the union of the two ascending paths, joint by joint (two runs are the same
        // joint or disjoint)
        let (mut x, xe) = (self.body_runs_ptr[b1], self.body_runs_ptr[b1 + 1]);
        let (mut z, ze) = (self.body_runs_ptr[b2], self.body_runs_ptr[b2 + 1]);
        while x < xe || z < ze {
            let a = if x < xe { self.body_runs[x] } else { (usize::MAX, 0) };
            let c = if z < ze { self.body_runs[z] } else { (usize::MAX, 0) };
            let run = if a.0 <= c.0 { a } else { c };
            if a.0 == run.0 {
                x += 1;
            }
            if c.0 == run.0 {
                z += 1;
            }
            let e0 = self.pat_idx.len() - start;
            self.runs.push((run.0, run.1, self.pat_idx.len()));
            for k in run.0..run.0 + run.1 {
                self.pos[k] = e0 + k - run.0;
                self.pat_idx.push(k);
            }
        }
        self.run_ptr.push(self.runs.len());
        let len = self.pat_idx.len() - start;
        self.pat_ptr.push(self.pat_idx.len());
        self.roots.push([self.root[b1], self.root[b2]]);
        let w0 = self.w.len();
        self.w.resize(w0 + len * d, 0.0);
        // eq. 2.112 ff.: w = J_P1ᵀ e - J_P2ᵀ e, J_P of a body point from the joint subspaces
        for (body, p, sign) in [(b1, p1, 1.0), (b2, p2, -1.0)] {
            let mut b = body;
            while b != 0 {
                let j = &model.joints[b - 1];
                for k in 0..j.nu() {
                    let s = &s_all[b][k];
                    let v = (s.v + s.w.cross(p)) * sign;
                    let e = w0 + self.pos[j.iu + k] * d;
                    for r in 0..d {
                        self.w[e + r] += dirs[r].dot(&v);
                    }
                }
                b = j.parent;
            }
            // a point at an elastic node: the node's deflection columns (one row at a time)
            if let Some((k, n)) = crate::kinematics::elastic_point_at(el, body, p) {
                let (w, a) = (&el.1[k], &el.0[body].a);
                let ne = w.q.len();
                for kk in 0..ne {
                    let c = a * w.phi[n * ne + kk];
                    let e = w0 + self.pos[w.iu + kk] * d;
                    for r in 0..d {
                        self.w[e + r] += sign * dirs[r].dot(&c);
                    }
                }
            }
        }
        // y = D^{-1/2} L⁻ᵀ w on the pattern, leaves first
        self.y.extend_from_slice(&self.w[w0..w0 + len * d]);
        let (f, y, pos, pat) = (&self.factor, &mut self.y, &self.pos, &self.pat_idx);
        for e in (0..len).rev() {
            let k = pat[start + e];
            let ye = w0 + e * d;
            // entry e's rows in registers while its ancestors are updated (they are other entries)
            let mut v = [0.0; 3];
            v[..d].copy_from_slice(&y[ye..ye + d]);
            for p in f.anc_ptr[k]..f.anc_ptr[k + 1] {
                let l = f.off[p];
                let ya = w0 + pos[f.anc_idx[p]] * d;
                for (t, vr) in y[ya..ya + d].iter_mut().zip(&v) {
                    *t -= l * vr;
                }
            }
        }
        for e in 0..len {
            let s = f.inv_sqrt_d[self.pat_idx[start + e]];
            for r in 0..d {
                self.y[w0 + e * d + r] *= s;
            }
        }
    }

    /// [`SparseRows::add_contact`] for two distinct bodies that are each the ground or a free
    /// body on the ground: the pattern is one block of six velocities per free body, and within
    /// it `L` is a dense unit triangle (velocity `iu + j` has the ancestors `iu + j - 1, ..., iu`),
    /// so the rows are built and reduced block by block without the pattern's indirection. The
    /// same sums in the same order as the general path: the results are identical.
    fn add_free_contact<const D: usize>(
        &mut self,
        s_all: &[[Motion; 6]],
        b1: usize,
        p1: &Vec3,
        b2: usize,
        p2: &Vec3,
        dirs: &[Vec3; 3],
    ) {
        let start = self.pat_idx.len();
        // the free sides in ascending velocity order (the pattern's)
        let mut sides = [(0usize, p1, 1.0f64, usize::MAX); 2];
        let mut ns = 0;
        for (b, p, sign) in [(b1, p1, 1.0), (b2, p2, -1.0)] {
            if b != 0 {
                sides[ns] = (b, p, sign, self.free[b]);
                ns += 1;
            }
        }
        if ns == 2 && sides[1].3 < sides[0].3 {
            sides.swap(0, 1);
        }
        for side in &sides[..ns] {
            let iu = side.3;
            self.runs.push((iu, 6, self.pat_idx.len()));
            self.pat_idx.extend(iu..iu + 6);
        }
        self.run_ptr.push(self.runs.len());
        self.pat_ptr.push(self.pat_idx.len());
        self.roots.push([self.root[b1], self.root[b2]]);
        let w0 = self.w.len();
        let f = &self.factor;
        for &(b, p, sign, iu) in &sides[..ns] {
            // fixed-size views: the loops below then run without bounds checks
            let s_b: &[Motion; 6] = &s_all[b];
            let base = f.anc_ptr[iu];
            let off: &[f64; 15] = f.off[base..base + 15].try_into().expect("a free joint's factor block");
            let isd: &[f64; 6] = f.inv_sqrt_d[iu..iu + 6].try_into().expect("a free joint's six velocities");
            // eq. 2.112 ff.: the six columns of J_P, projected on the directions
            let mut w = [[0.0; D]; 6];
            for (wk, s) in w.iter_mut().zip(s_b) {
                let v = (s.v + s.w.cross(p)) * sign;
                for r in 0..D {
                    // (0 + x as in the general path's accumulation: the same signed zeros)
                    wk[r] = 0.0 + dirs[r].dot(&v);
                }
            }
            // y = D^{-1/2} L⁻ᵀ w, leaves first; L(iu + j, iu + j - 1 - p) at off[TRI6[j] + p]
            // (the layout of a free joint's block in the mass factor, `Saddle`'s blocks of six)
            let mut y = w;
            for j in (1..6).rev() {
                let v = y[j];
                let lj = crate::dynamics::sparse::TRI6[j];
                for p in 0..j {
                    let l = off[lj + p];
                    for r in 0..D {
                        y[j - 1 - p][r] -= l * v[r];
                    }
                }
            }
            for (yk, s) in y.iter_mut().zip(isd) {
                for v in yk.iter_mut() {
                    *v *= s;
                }
            }
            self.w.extend_from_slice(w.as_flattened());
            self.y.extend_from_slice(y.as_flattened());
        }
        debug_assert_eq!(self.w.len(), w0 + (self.pat_idx.len() - start) * D);
    }

    /// The Delassus blocks of the contacts added: `diag` (n d², row-major) and the coupled pairs
    /// in `upper`, `upper_val`. A tangent row that is zero (a direction along which nothing can
    /// move, e.g. out of the plane of a planar mechanism) gets the normal's diagonal value so that
    /// its impulse comes out zero.
    #[cfg(test)]
    pub(super) fn delassus(&mut self) {
        self.couplings();
        self.pairs();
    }

    /// The diagonal blocks and which contacts are coupled ([`SparseRows::links`]): all a
    /// Gauss–Seidel solve on the factored operator needs ([`SparseRows::gauss_seidel`]).
    pub(super) fn couplings(&mut self) {
        // fixed-size blocks: no loop over the dimension nor library calls for d² copies
        match self.dim {
            3 => self.couplings_d::<3>(),
            _ => self.couplings_d::<2>(),
        }
    }

    /// The off-diagonal blocks (`upper`, `upper_val`), after [`SparseRows::couplings`].
    pub(super) fn pairs(&mut self) {
        match self.dim {
            3 => self.pairs_d::<3>(),
            _ => self.pairs_d::<2>(),
        }
    }

    /// Contact `a`'s diagonal block, row-major `d × d` in the first `d²` entries.
    pub(super) fn diag_block(&self, a: usize, out: &mut [f64; 9]) {
        let dd = self.dim * self.dim;
        out[..dd].copy_from_slice(&self.diag[a * dd..(a + 1) * dd]);
    }

    fn couplings_d<const D: usize>(&mut self) {
        let n = self.len();
        self.diag.clear();
        for a in 0..n {
            let (s, e) = (self.pat_ptr[a], self.pat_ptr[a + 1]);
            // accumulated in registers, every sum from 0 in pattern order
            let mut acc = [[0.0; D]; D];
            for y in self.y[s * D..e * D].chunks_exact(D) {
                for r in 0..D {
                    for c in 0..D {
                        acc[r][c] += y[r] * y[c];
                    }
                }
            }
            for r in 1..D {
                if self.w[s * D..e * D].chunks_exact(D).all(|w| w[r] == 0.0) {
                    acc[r][r] = acc[0][0].max(f64::MIN_POSITIVE);
                }
            }
            self.diag.extend_from_slice(acc.as_flattened());
        }
        // buckets of contacts by root velocity
        let nu = self.pos.len();
        self.bucket_ptr.clear();
        self.bucket_ptr.resize(nu + 2, 0);
        for rt in &self.roots {
            for (q, &r) in rt.iter().enumerate() {
                if r != usize::MAX && !(q == 1 && rt[0] == r) {
                    self.bucket_ptr[r + 2] += 1;
                }
            }
        }
        for k in 0..nu {
            self.bucket_ptr[k + 2] += self.bucket_ptr[k + 1];
        }
        let total = self.bucket_ptr[nu + 1];
        self.bucket.clear();
        self.bucket.resize(total, 0);
        for (a, rt) in self.roots.iter().enumerate() {
            for (q, &r) in rt.iter().enumerate() {
                if r != usize::MAX && !(q == 1 && rt[0] == r) {
                    let slot = self.bucket_ptr[r + 1];
                    self.bucket[slot] = a;
                    self.bucket_ptr[r + 1] += 1;
                }
            }
        }
        // bucket_ptr[r]..bucket_ptr[r + 1] now lists root r's contacts, ascending
        self.links.clear();
        for r in 0..nu {
            let (s, e) = (self.bucket_ptr[r], self.bucket_ptr[r + 1]);
            for x in s + 1..e {
                self.links.push((self.bucket[s], self.bucket[x]));
            }
        }
    }

    fn pairs_d<const D: usize>(&mut self) {
        let nu = self.pos.len();
        self.upper.clear();
        self.upper_val.clear();
        for r in 0..nu {
            let (s, e) = (self.bucket_ptr[r], self.bucket_ptr[r + 1]);
            for x in s..e {
                let i = self.bucket[x];
                let ri = self.roots[i];
                for z in x + 1..e {
                    let j = self.bucket[z];
                    let rj = self.roots[j];
                    // the pair is formed at the smallest root the two contacts share
                    let mut shared = usize::MAX;
                    for a in ri {
                        if a != usize::MAX && (a == rj[0] || a == rj[1]) && a < shared {
                            shared = a;
                        }
                    }
                    if shared != r {
                        continue;
                    }
                    // Σ over the shared velocities: the runs both patterns have (ascending), the
                    // block in registers (every sum from 0 in the same order)
                    let mut acc = [[0.0; D]; D];
                    let (mut p, pe) = (self.run_ptr[i], self.run_ptr[i + 1]);
                    let (mut q, qe) = (self.run_ptr[j], self.run_ptr[j + 1]);
                    while p < pe && q < qe {
                        let ((kp, len, ep), (kq, _, eq)) = (self.runs[p], self.runs[q]);
                        if kp < kq {
                            p += 1;
                        } else if kq < kp {
                            q += 1;
                        } else {
                            let (ya, yb) = (&self.y[ep * D..(ep + len) * D], &self.y[eq * D..(eq + len) * D]);
                            if len == 6 {
                                // a free joint's six velocities: fixed-size, unrolled
                                add_products::<D>(&mut acc, &ya[..6 * D], &yb[..6 * D]);
                            } else {
                                add_products::<D>(&mut acc, ya, yb);
                            }
                            p += 1;
                            q += 1;
                        }
                    }
                    self.upper_val.extend_from_slice(acc.as_flattened());
                    self.upper.push((i, j));
                }
            }
        }
    }

    /// `out[r] = w_{a,r}ᵀ u`, r < dim, for contact `a`.
    pub(super) fn local_velocity(&self, a: usize, u: &[f64], out: &mut [f64; 3]) {
        match self.dim {
            3 => self.local_velocity_d::<3>(a, u, out),
            _ => self.local_velocity_d::<2>(a, u, out),
        }
    }

    fn local_velocity_d<const D: usize>(&self, a: usize, u: &[f64], out: &mut [f64; 3]) {
        let mut g = [0.0; 3];
        let (s, e) = (self.pat_ptr[a], self.pat_ptr[a + 1]);
        for (k, w) in self.pat_idx[s..e].iter().zip(self.w[s * D..e * D].chunks_exact(D)) {
            let uk = u[*k];
            for r in 0..D {
                g[r] += w[r] * uk;
            }
        }
        *out = g;
    }

    /// [`SparseRows::local_velocity`] at two velocity vectors in one pass over the rows.
    pub(super) fn local_velocity2(&self, a: usize, u: &[f64], v: &[f64], out_u: &mut [f64; 3], out_v: &mut [f64; 3]) {
        match self.dim {
            3 => self.local_velocity2_d::<3>(a, u, v, out_u, out_v),
            _ => self.local_velocity2_d::<2>(a, u, v, out_u, out_v),
        }
    }

    fn local_velocity2_d<const D: usize>(
        &self,
        a: usize,
        u: &[f64],
        v: &[f64],
        out_u: &mut [f64; 3],
        out_v: &mut [f64; 3],
    ) {
        let (mut gu, mut gv) = ([0.0; 3], [0.0; 3]);
        let (s, e) = (self.pat_ptr[a], self.pat_ptr[a + 1]);
        for (k, w) in self.pat_idx[s..e].iter().zip(self.w[s * D..e * D].chunks_exact(D)) {
            let (uk, vk) = (u[*k], v[*k]);
            for r in 0..D {
                gu[r] += w[r] * uk;
                gv[r] += w[r] * vk;
            }
        }
        *out_u = gu;
        *out_v = gv;
    }

    /// `u += M⁻¹ Σ_a w_a Λ_a` for the impulses `lambda` (d per contact).
    pub(super) fn apply(&mut self, lambda: &[f64], u: &mut [f64]) {
        self.f.fill(0.0);
        match self.dim {
            3 => self.scatter::<3>(lambda),
            _ => self.scatter::<2>(lambda),
        }
        self.factor.solve(&mut self.f);
        for (ui, fi) in u.iter_mut().zip(&self.f) {
            *ui += fi;
        }
    }
}

impl SparseRows {
    /// `f += Σ_a w_a Λ_a` on the patterns.
    fn scatter<const D: usize>(&mut self, lambda: &[f64]) {
        for a in 0..self.len() {
            let l: &[f64; D] = lambda[a * D..(a + 1) * D].try_into().unwrap();
            if l.iter().all(|v| *v == 0.0) {
                continue;
            }
            let (s, e) = (self.pat_ptr[a], self.pat_ptr[a + 1]);
            for (k, w) in self.pat_idx[s..e].iter().zip(self.w[s * D..e * D].chunks_exact(D)) {
                let mut s = 0.0;
                for r in 0..D {
                    s += w[r] * l[r];
                }
                self.f[*k] += s;
            }
        }
    }
}

/// `acc += Σ_k a_k b_kᵀ` over the D-vectors of `a` and `b`.
#[inline(always)]
fn add_products<const D: usize>(acc: &mut [[f64; D]; D], a: &[f64], b: &[f64]) {
    for (a, b) in a.chunks_exact(D).zip(b.chunks_exact(D)) {
        for r in 0..D {
            for c in 0..D {
                acc[r][c] += a[r] * b[c];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Data;
    use crate::dynamics::sparse::Saddle;
    use crate::model::ModelDescription;

    /// Two free bodies (off-centre mass) and an arm on a revolute joint.
    fn model() -> Model {
        let json = r#"{
            "name": "free", "gravity": [0, 0, -9.81],
            "bodies": [
                {"name": "a", "mass": 1.3, "inertia": [0.01, 0.02, 0.03], "com": [0.05, -0.02, 0.01]},
                {"name": "b", "mass": 0.7, "inertia": [0.004, 0.005, 0.006]},
                {"name": "arm", "mass": 0.5, "inertia": [0.001, 0.02, 0.02], "com": [0.2, 0, 0]}
            ],
            "joints": [
                {"name": "fa", "type": "free", "parent": "ground", "child": "a",
                 "q0": [0.1, 0.2, 0.3, 0.9, 0.1, -0.3, 0.2], "u0": [0.3, -0.2, 0.1, 1.0, -2.0, 0.5]},
                {"name": "fb", "type": "free", "parent": "ground", "child": "b",
                 "q0": [-0.2, 0.1, 0.5, 0.7, -0.4, 0.1, 0.5], "u0": [0.1, 0.2, -0.3, 0.4, 0.2, -1.0]},
                {"name": "j", "type": "revolute", "parent": "ground", "child": "arm", "axis": [0, 1, 0]}
            ]
        }"#;
        Model::from_description(ModelDescription::from_json(json).unwrap()).unwrap()
    }

    /// The test model at its initial state: kinematics done, mass matrix factored.
    fn factored_mass() -> (Model, Data, Saddle) {
        at_initial_state(model())
    }

    /// `model` at its initial state: kinematics done, mass matrix factored.
    fn at_initial_state(model: Model) -> (Model, Data, Saddle) {
        let mut data = Data::new(&model);
        let mut q = model.q0();
        model.normalize(&mut q);
        crate::kinematics::forward_pass(&model, &mut data, 0.0, &q, &model.u0());
        let mut saddle = Saddle::new(&model);
        {
            let Data { inertia, s, ic, elastic, .. } = &mut data;
            crate::dynamics::crba::composite_inertias(&model, inertia, s, ic, elastic, |r, c, v| {
                saddle.put_mass(r, c, v)
            });
        }
        assert!(saddle.factor_mass());
        (model, data, saddle)
    }

    /// Gauss–Seidel on the factored operator (`W = YᵀY`, no off-diagonal blocks) solves the
    /// problem the block solver solves: the same impulses and local velocities `W r + q` to
    /// round-off, sweep for sweep, in 2-D and 3-D, with contacts sliding, sticking and open.
    #[test]
    fn factored_gauss_seidel_is_the_block_solver_to_round_off() {
        use crate::solver::{self, BlockDelassus, Delassus, FrictionContact, Method, NsgsOptions, Workspace};
        let (model, data, saddle) = factored_mass();
        // with the revolute arm (general rows) and on free bodies only (the packed rows)
        let with_arm = [(1, 0), (0, 2), (1, 2), (2, 1), (2, 0), (3, 1), (0, 3)];
        let free_only = [(1, 0), (0, 2), (1, 2), (2, 1), (2, 0)];
        for (dim, pairs) in [(3, &with_arm[..]), (2, &with_arm[..]), (3, &free_only[..]), (2, &free_only[..])] {
            let mut sp = contact_rows((&model, &data, &saddle), dim, pairs);
            let nc = sp.len();
            let packs = if dim == 3 { sp.pack::<3>() } else { sp.pack::<2>() };
            assert_eq!(packs, pairs.len() == free_only.len(), "packed rows on free bodies only");
            let mut bw = BlockDelassus::default();
            bw.refill(dim, nc, &sp.diag, &sp.upper, &sp.upper_val);
            // approaching, separating and sliding free velocities; one frictionless contact
            let mut qv: Vec<f64> = (0..dim * nc).map(|i| ((i * 7 % 11) as f64 - 6.0) * 0.1).collect();
            let mut mu: Vec<f64> = (0..nc).map(|i| if i == 2 { 0.0 } else { 0.2 + 0.1 * i as f64 }).collect();
            // contact 0 pressed with little tangential motion and much friction: it sticks
            qv[0] = -0.6;
            qv[1..dim].fill(0.01);
            mu[0] = 3.0;
            let p = FrictionContact::new(dim, Delassus::Blocks(bw), qv.clone(), mu.clone()).unwrap();
            for (sweeps, relaxation) in [(1, 1.0), (3, 1.0), (200, 1.0), (3, 1.3), (200, 1.3), (200, 0.8)] {
                let o = NsgsOptions { tol: 1e-14, max_iter: sweeps, relaxation, anderson: 0, stall: 0 };
                let method = Method::Nsgs(o);
                let mut ws = Workspace::default();
                ws.reserve(&p, &method).unwrap();
                let mut r_blocks = vec![0.0; dim * nc];
                let rep = solver::solve(&p, &method, &mut r_blocks, false, &mut ws).unwrap();
                let (mut r_fact, mut u_fact) = (vec![0.0; dim * nc], vec![0.0; dim * nc]);
                let fact = sp.gauss_seidel((&qv, &mu), &[], &mut r_fact, &o, &mut u_fact);
                if relaxation == 1.0 {
                    assert_eq!(fact.iterations, rep.iterations, "dim {dim}, {sweeps} sweeps");
                } else {
                    // (round-off can move the relaxation's safeguard, or the last check across the
                    // tolerance, by a sweep)
                    let (a, b) = (fact.iterations, rep.iterations);
                    assert!(a.abs_diff(b) <= 1, "dim {dim}, {sweeps} sweeps, ω {relaxation}: {a} vs {b}");
                }
                assert!((fact.residual - rep.residual).abs() <= 1e-12 * (1.0 + rep.residual), "{fact:?} {rep:?}");
                let mut u_blocks = vec![0.0; dim * nc];
                p.velocity(&r_blocks, &mut u_blocks).unwrap();
                let big = r_blocks.iter().chain(&u_blocks).fold(0.0f64, |a, v| a.max(v.abs()));
                assert!(big > 0.1, "a problem with impulses");
                for k in 0..dim * nc {
                    assert!((r_fact[k] - r_blocks[k]).abs() <= 1e-12 * big, "r[{k}]: {} vs {}", r_fact[k], r_blocks[k]);
                    assert!((u_fact[k] - u_blocks[k]).abs() <= 1e-12 * big, "u[{k}]: {} vs {}", u_fact[k], u_blocks[k]);
                }
                if sweeps == 200 && relaxation == 1.0 {
                    // Anderson-accelerated: the same velocities at convergence (the impulses of the
                    // redundant contacts may differ along W's null space)
                    let oa = NsgsOptions { anderson: 3, max_iter: 400, ..o };
                    let ma = Method::Nsgs(oa);
                    ws.reserve(&p, &ma).unwrap();
                    let mut ra_blocks = vec![0.0; dim * nc];
                    let rep_a = solver::solve(&p, &ma, &mut ra_blocks, false, &mut ws).unwrap();
                    let (mut ra_fact, mut ua_fact) = (vec![0.0; dim * nc], vec![0.0; dim * nc]);
                    let fact_a = sp.gauss_seidel((&qv, &mu), &[], &mut ra_fact, &oa, &mut ua_fact);
                    assert!(rep_a.converged && fact_a.converged, "{rep_a:?} {fact_a:?}");
                    assert!(p.residual(&ra_fact).unwrap() <= 1e-14, "factored, accelerated");
                    for k in 0..dim * nc {
                        assert!(
                            (ua_fact[k] - u_blocks[k]).abs() <= 1e-9 * big,
                            "u[{k}]: {} vs {}",
                            ua_fact[k],
                            u_blocks[k]
                        );
                    }
                    assert!(fact.converged && fact.residual <= 1e-14, "{fact:?}");
                    // a sliding, a sticking and an open contact among them
                    let states: Vec<_> = (0..nc).map(|i| p.contact_state(i, &r_blocks, 1e-9).unwrap()).collect();
                    for s in [solver::ContactState::Open, solver::ContactState::Stick, solver::ContactState::Slip] {
                        assert!(states.contains(&s), "dim {dim}: {states:?}");
                    }
                }
            }
        }
    }

    /// Compliant layers regularize each normal diagonal by `R_a` (in `diag`, and in `reg` for the
    /// sweeps, whose `z = Y r` carries `W r` only): the factored sweeps, on general and on packed
    /// rows, and the two-domain sweeps of a large problem, solve the block problem with `W + R`,
    /// sweep for sweep to round-off; its regularized velocities `(W + R) r + q` come back in `u`.
    #[test]
    fn regularized_sweeps_solve_the_regularized_block_problem() {
        use crate::solver::{self, BlockDelassus, Delassus, FrictionContact, Method, NsgsOptions, Workspace};
        fn regularize(sp: &mut SparseRows, dim: usize) {
            let nc = sp.len();
            sp.reg = (0..nc).map(|a| 0.05 * (1 + a % 3) as f64 * sp.diag[a * dim * dim]).collect();
            for a in 0..nc {
                sp.diag[a * dim * dim] += sp.reg[a];
            }
        }
        // the block solver on W + R in `order` against the factored sweeps; returns the sweeps
        fn compare(
            sp: &mut SparseRows,
            dim: usize,
            qv: &[f64],
            mu: &[f64],
            order: &[usize],
            perm: &[usize],
            o: NsgsOptions,
        ) -> usize {
            let nc = sp.len();
            let mut bw = BlockDelassus::default();
            bw.refill(dim, nc, &sp.diag, &sp.upper, &sp.upper_val);
            let p = FrictionContact::new(dim, Delassus::Blocks(bw), qv.to_vec(), mu.to_vec()).unwrap();
            let method = Method::Nsgs(o);
            let mut ws = Workspace::default();
            ws.reserve(&p, &method).unwrap();
            ws.order = perm.to_vec();
            let mut r_blocks = vec![0.0; dim * nc];
            let rep = solver::solve(&p, &method, &mut r_blocks, false, &mut ws).unwrap();
            let (mut r, mut u) = (vec![0.0; dim * nc], vec![0.0; dim * nc]);
            let fact = sp.gauss_seidel((qv, mu), order, &mut r, &o, &mut u);
            assert_eq!(fact.iterations, rep.iterations, "dim {dim}");
            assert!(rep.converged && fact.converged, "{rep:?} {fact:?}");
            let mut u_blocks = vec![0.0; dim * nc];
            p.velocity(&r_blocks, &mut u_blocks).unwrap();
            let big = r_blocks.iter().chain(&u_blocks).fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(big > 1e-3, "a problem with impulses");
            for k in 0..dim * nc {
                assert!((r[k] - r_blocks[k]).abs() <= 1e-11 * big, "r[{k}]: {} vs {}", r[k], r_blocks[k]);
                assert!((u[k] - u_blocks[k]).abs() <= 1e-11 * big, "u[{k}]: {} vs {}", u[k], u_blocks[k]);
            }
            // the regularization is in the problem: a normal velocity R r_N below the rigid one
            let pressed = (0..nc).filter(|&a| r[a * dim] > 1e-9).count();
            assert!(pressed > 0, "pressed contacts");
            fact.iterations
        }
        let (model, data, saddle) = factored_mass();
        for dim in [3, 2] {
            let mut sp =
                contact_rows((&model, &data, &saddle), dim, &[(1, 0), (0, 2), (1, 2), (2, 1), (2, 0), (3, 1), (0, 3)]);
            regularize(&mut sp, dim);
            let nc = sp.len();
            let qv: Vec<f64> = (0..dim * nc).map(|i| ((i * 7 % 11) as f64 - 6.0) * 0.1).collect();
            let mu: Vec<f64> = (0..nc).map(|i| 0.2 + 0.1 * i as f64).collect();
            let o = NsgsOptions { tol: 1e-13, max_iter: 5000, relaxation: 1.0, anderson: 0, stall: 0 };
            compare(&mut sp, dim, &qv, &mu, &[], &[], o);
        }
        // 401 contacts on free bodies: two domains
        let mut sp = sphere_row_rows(201);
        regularize(&mut sp, 3);
        let nc = sp.len();
        let (qv, mu) = sphere_row_load(201, false);
        let order: Vec<usize> = (0..nc).rev().collect();
        assert!(sp.pack::<3>());
        assert!(sp.dom.plan(&sp.packed, &order, sp.z.len()), "split in two domains");
        let perm = sp.dom.perm.clone();
        sp.dom.finish();
        let o = NsgsOptions { tol: 1e-10, max_iter: 20_000, relaxation: 1.0, anderson: 0, stall: 0 };
        let split = compare(&mut sp, 3, &qv, &mu, &order, &perm, o);
        // the same problem rigid takes more sweeps than regularized (a pressed row of spheres)
        for a in 0..nc {
            sp.diag[a * 9] -= sp.reg[a];
        }
        sp.reg.clear();
        let (mut r, mut u) = (vec![0.0; 3 * nc], vec![0.0; 3 * nc]);
        let rigid = sp.gauss_seidel((&qv, &mu), &order, &mut r, &o, &mut u);
        assert!(rigid.iterations > split, "rigid {} sweeps, regularized {split}", rigid.iterations);
    }

    /// The rows of `pairs` of bodies of [`factored_mass`]'s model in contact (dimension `dim`),
    /// with their Delassus blocks.
    fn contact_rows(
        (model, data, saddle): (&Model, &Data, &Saddle),
        dim: usize,
        pairs: &[(usize, usize)],
    ) -> SparseRows {
        let mut sp = SparseRows::new(model, dim);
        sp.factor.copy_from(saddle);
        for (k, &(b1, b2)) in pairs.iter().enumerate() {
            let n = Vec3::new(0.3 - 0.1 * k as f64, -0.5, 0.8).normalize();
            let t1 = n.cross(&Vec3::x()).normalize();
            let p1 = Vec3::new(0.1 * k as f64, -0.2, 0.3 + 0.05 * k as f64);
            let el = (&data.x_abs[..], &data.elastic[..], &data.body_elastic[..]);
            sp.add_contact(model, &data.s, el, b1, &p1, b2, &(p1 - 1e-3 * n), &[n, t1, n.cross(&t1)]);
        }
        sp.delassus();
        sp
    }

    /// The rows of [`row_of_spheres`]: each sphere on the ground, each pair of neighbours side by
    /// side (2 ns − 1 contacts; the normal points from the second body to the first), with their
    /// Delassus blocks.
    fn sphere_row_rows(ns: usize) -> SparseRows {
        let (model, data, saddle) = row_of_spheres(ns);
        let mut sp = SparseRows::new(&model, 3);
        sp.factor.copy_from(&saddle);
        let el = (&data.x_abs[..], &data.elastic[..], &data.body_elastic[..]);
        let z = Vec3::z();
        for i in 0..ns {
            let c = Vec3::new(0.1 * i as f64, 0.0, 0.0);
            sp.add_contact(&model, &data.s, el, i + 1, &c, 0, &c, &[z, Vec3::x(), Vec3::y()]);
        }
        for i in 0..ns - 1 {
            let c = Vec3::new(0.1 * i as f64 + 0.05, 0.0, 0.05);
            sp.add_contact(&model, &data.s, el, i + 2, &c, i + 1, &c, &[Vec3::x(), Vec3::y(), z]);
        }
        sp.delassus();
        sp
    }

    /// The free velocities and friction coefficients of [`sphere_row_rows`]' contacts: pressed
    /// onto the ground and together, pushed sideways by varying amounts (sliding and sticking
    /// contacts); with `parting`, neighbours mostly parting (short pressed runs, a problem swept
    /// in tens of sweeps).
    fn sphere_row_load(ns: usize, parting: bool) -> (Vec<f64>, Vec<f64>) {
        let nc = 2 * ns - 1;
        let qv = (0..3 * nc)
            .map(|k| match k % 3 {
                0 if parting && k / 3 >= ns && (k / 3) % 4 != 0 => 0.002,
                0 => -0.01 - 0.002 * ((k / 3) % 5) as f64,
                1 => 0.004 * (((k / 3) * 7 % 11) as f64 - 5.0),
                _ => 0.001 * (((k / 3) * 3 % 7) as f64 - 3.0),
            })
            .collect();
        (qv, (0..nc).map(|a| 0.3 + 0.05 * (a % 4) as f64).collect())
    }

    /// A row of `n` free spheres (r = 5 cm, touching) on the ground at their initial state:
    /// kinematics done, mass matrix factored.
    fn row_of_spheres(n: usize) -> (Model, Data, Saddle) {
        let bodies: Vec<String> =
            (0..n).map(|i| format!(r#"{{"name": "s{i}", "mass": 0.1, "inertia": [1e-4, 1e-4, 1e-4]}}"#)).collect();
        let joints: Vec<String> = (0..n)
            .map(|i| {
                format!(
                    r#"{{"name": "f{i}", "type": "free", "parent": "ground", "child": "s{i}", "q0": [{}, 0, 0.05, 1, 0, 0, 0]}}"#,
                    0.1 * i as f64
                )
            })
            .collect();
        let json = format!(
            r#"{{"name": "row", "gravity": [0, 0, -9.81], "bodies": [{}], "joints": [{}]}}"#,
            bodies.join(","),
            joints.join(",")
        );
        at_initial_state(Model::from_description(ModelDescription::from_json(&json).unwrap()).unwrap())
    }

    /// A large problem on free bodies is swept in two domains: the halves share no body, the
    /// interface holds the contacts between them, every part keeps the caller's order, and the
    /// solve is Gauss–Seidel in that order (the block solver visiting the contacts in it gives the
    /// same sweeps to round-off), with impulses that do not depend on the threads, bit for bit.
    #[test]
    fn two_domain_sweeps_are_gauss_seidel_in_their_order_on_any_threads() {
        use crate::solver::{self, BlockDelassus, Delassus, FrictionContact, Method, NsgsOptions, Workspace};
        let ns = 201;
        let mut sp = sphere_row_rows(ns);
        let nc = sp.len();
        assert!(nc >= domains::SPLIT_MIN_CONTACTS);
        let (qv, mu) = sphere_row_load(ns, true);
        // visiting order: descending index (any permutation the caller gives is kept per part)
        let order: Vec<usize> = (0..nc).rev().collect();
        let o = NsgsOptions { tol: 1e-14, max_iter: 40, relaxation: 1.0, anderson: 0, stall: 0 };
        assert!(sp.pack::<3>());
        assert!(sp.dom.plan(&sp.packed, &order, sp.z.len()));
        let (na, nb, perm) = (sp.dom.na, sp.dom.nb, sp.dom.perm.clone());
        sp.dom.finish();
        // the parts: a permutation; A and B on disjoint bodies; the interface across them
        let mut seen = perm.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..nc).collect::<Vec<_>>());
        let bodies = |a: usize| {
            let p = &sp.packed[a];
            p.iu()[..p.bodies()].to_vec()
        };
        let side_a: std::collections::BTreeSet<usize> = perm[..na].iter().flat_map(|&a| bodies(a)).collect();
        let side_b: std::collections::BTreeSet<usize> = perm[na..na + nb].iter().flat_map(|&a| bodies(a)).collect();
        assert!(side_a.is_disjoint(&side_b), "the halves share a body");
        for &a in &perm[na + nb..] {
            let b = bodies(a);
            assert!(
                b.iter().any(|x| !side_b.contains(x)) && b.iter().any(|x| !side_a.contains(x)),
                "interface contact {a}"
            );
        }
        // a row cut in the middle: two halves of about 200 contacts, one contact between them
        assert!(na.abs_diff(nb) <= 2 && nc - na - nb == 1, "{na} {nb} {nc}");
        for part in [&perm[..na], &perm[na..na + nb], &perm[na + nb..]] {
            assert!(part.windows(2).all(|w| w[0] > w[1]), "the caller's order within a part");
        }
        // Gauss–Seidel in the order A, B, interface: the block solver's sweeps to round-off
        let mut bw = BlockDelassus::default();
        bw.refill(3, nc, &sp.diag, &sp.upper, &sp.upper_val);
        let p = FrictionContact::new(3, Delassus::Blocks(bw), qv.clone(), mu.clone()).unwrap();
        // the block solver from a cold start, visiting the contacts in the split's order
        let block = |opts: NsgsOptions| {
            let method = Method::Nsgs(opts);
            let mut ws = Workspace::default();
            ws.reserve(&p, &method).unwrap();
            ws.order = perm.clone();
            let mut r = vec![0.0; 3 * nc];
            let rep = solver::solve(&p, &method, &mut r, false, &mut ws).unwrap();
            (rep, r)
        };
        for sweeps in [8, 60] {
            let o = NsgsOptions { max_iter: sweeps, ..o };
            let (rep, r_blocks) = block(o);
            let mut runs = Vec::new();
            for (threads, parallel) in [(1, false), (2, true), (1, true)] {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                let (mut r, mut u) = (vec![0.0; 3 * nc], vec![0.0; 3 * nc]);
                sp.parallel = parallel;
                let fact = pool.install(|| sp.gauss_seidel((&qv, &mu), &order, &mut r, &o, &mut u));
                runs.push((fact, r, u));
            }
            let (fact, r, _) = &runs[0];
            assert_eq!(fact.iterations, rep.iterations, "{sweeps} sweeps");
            let big = r_blocks.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(big > 1e-3, "a problem with impulses");
            for k in 0..3 * nc {
                assert!((r[k] - r_blocks[k]).abs() <= 1e-12 * big, "r[{k}]: {} vs {}", r[k], r_blocks[k]);
            }
            for (f, r2, u2) in &runs[1..] {
                assert_eq!(f.iterations, runs[0].0.iterations);
                assert_eq!(f.residual.to_bits(), runs[0].0.residual.to_bits());
                assert!(r2.iter().zip(&runs[0].1).all(|(a, b)| a.to_bits() == b.to_bits()), "r on other threads");
                assert!(u2.iter().zip(&runs[0].2).all(|(a, b)| a.to_bits() == b.to_bits()), "u on other threads");
            }
        }
        // Anderson-accelerated to convergence (sliding spheres rolling against each other take
        // thousands of plain sweeps): the tolerance met on any threads, bit for bit
        let oa = NsgsOptions { anderson: 4, max_iter: 20_000, tol: 1e-10, ..o };
        let mut out = Vec::new();
        for (threads, parallel) in [(1, false), (2, true)] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let (mut r, mut u) = (vec![0.0; 3 * nc], vec![0.0; 3 * nc]);
            sp.parallel = parallel;
            let rep = pool.install(|| sp.gauss_seidel((&qv, &mu), &order, &mut r, &oa, &mut u));
            // (the block problem's own residual of the result: the factored one to round-off)
            let res = p.residual(&r).unwrap();
            assert!(rep.converged && rep.residual <= 1e-10, "{rep:?}");
            assert!((res - rep.residual).abs() <= 1e-13, "{res} against {rep:?}");
            out.push((rep, r));
        }
        assert_eq!(out[0].0.iterations, out[1].0.iterations);
        assert!(out[0].1.iter().zip(&out[1].1).all(|(a, b)| a.to_bits() == b.to_bits()));
        // with sliding and sticking contacts among them
        let states: Vec<_> = (0..nc).map(|i| p.contact_state(i, &out[0].1, 1e-9).unwrap()).collect();
        for s in [solver::ContactState::Stick, solver::ContactState::Slip, solver::ContactState::Open] {
            assert!(states.contains(&s), "{states:?}");
        }
        // a stall test with a short first window (4 sweeps) finds these slow plain sweeps stalled
        // and damps them: still the block solver's sweeps in the split's order, on any threads
        let od = NsgsOptions { stall: 4, max_iter: 200, ..o };
        let (rep_d, r_damped) = block(od);
        let (_, r_plain) = block(NsgsOptions { stall: 0, ..od });
        let big = r_plain.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let moved = r_damped.iter().zip(&r_plain).fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        assert!(moved > 1e-6 * big, "the damping changed nothing ({moved})");
        let mut first: Option<(crate::solver::Report, Vec<f64>)> = None;
        for (threads, parallel) in [(1, false), (2, true)] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let (mut r, mut u) = (vec![0.0; 3 * nc], vec![0.0; 3 * nc]);
            sp.parallel = parallel;
            let rep = pool.install(|| sp.gauss_seidel((&qv, &mu), &order, &mut r, &od, &mut u));
            assert_eq!(rep.iterations, rep_d.iterations);
            for k in 0..3 * nc {
                assert!((r[k] - r_damped[k]).abs() <= 1e-12 * big, "r[{k}]: {} vs {}", r[k], r_damped[k]);
            }
            match &first {
                None => first = Some((rep, r)),
                Some((f, r0)) => {
                    assert_eq!(f.residual.to_bits(), rep.residual.to_bits());
                    assert!(r.iter().zip(r0).all(|(a, b)| a.to_bits() == b.to_bits()), "damped r on two threads");
                }
            }
        }
    }

    /// The free-body rows and their reduction are the general path's bit for bit (any sign or
    /// index slip in the fixed-size code shows), and so are the Delassus blocks built from them.
    #[test]
    fn free_body_rows_are_the_general_rows_bit_for_bit() {
        let (model, data, saddle) = factored_mass();
        let n = Vec3::new(0.3, -0.5, 0.8).normalize();
        let t1 = n.cross(&Vec3::x()).normalize();
        let dirs = [n, t1, n.cross(&t1)];
        // (b1, b2): body and ground either way round, two free bodies in both orders
        let pairs = [(1, 0), (0, 2), (1, 2), (2, 1), (2, 0)];
        for dim in [3, 2] {
            let (mut fast, mut general) = (SparseRows::new(&model, dim), SparseRows::new(&model, dim));
            fast.factor.copy_from(&saddle);
            general.factor.copy_from(&saddle);
            for (k, &(b1, b2)) in pairs.iter().enumerate() {
                let p1 = Vec3::new(0.1 * k as f64, -0.2, 0.3 + 0.05 * k as f64);
                let p2 = p1 - 1e-3 * n;
                let el = (&data.x_abs[..], &data.elastic[..], &data.body_elastic[..]);
                fast.add_contact(&model, &data.s, el, b1, &p1, b2, &p2, &dirs);
                general.add_general_contact(&model, &data.s, el, b1, &p1, b2, &p2, &dirs);
            }
            assert_eq!(fast.pat_ptr, general.pat_ptr);
            assert_eq!(fast.pat_idx, general.pat_idx);
            assert_eq!(fast.run_ptr, general.run_ptr);
            assert_eq!(fast.runs, general.runs);
            assert_eq!(fast.roots, general.roots);
            assert!(fast.w.iter().any(|v| *v != 0.0) && fast.y.iter().any(|v| *v != 0.0));
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&fast.w), bits(&general.w), "rows (dim {dim})");
            assert_eq!(bits(&fast.y), bits(&general.y), "reduced rows (dim {dim})");
            fast.delassus();
            general.delassus();
            assert_eq!(fast.upper, general.upper);
            assert!(fast.upper.len() >= 4, "pairs {:?}", fast.upper);
            assert_eq!(bits(&fast.diag), bits(&general.diag));
            assert_eq!(bits(&fast.upper_val), bits(&general.upper_val));
        }
    }
}
