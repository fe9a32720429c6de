//! Gauss–Seidel in two domains, swept at the same time.
//!
//! A sweep is sequential: each contact's local problem sees the impulses just found for the
//! contacts before it. Two contacts that share no body do not see each other, though (their
//! local problems read and write only their own bodies' entries of `z = Y r`). So the bodies of a
//! large problem on free bodies are cut in two halves of the contact graph; the contacts within
//! each half are swept on two threads at once, then the contacts between the halves. That is
//! Gauss–Seidel exactly, in the order "half A, half B, interface" (each part in the caller's
//! order), whatever the number of threads: the impulses do not depend on it, bit for bit.
//!
//! The cut: levels of a breadth-first search from a pseudo-peripheral body (the last one reached
//! from the last one reached from a body of most contacts), the first half of the bodies by level
//! on side A (bodies of other islands, unreached, last).
//! Level sets are fronts across the graph's longest extent, so the interface is one front: on a
//! pour of 100 spheres, 15–25 of about 200 contacts, and 4 % more sweeps than bottom-up order
//! (124 dumped problems, Anderson-accelerated to 1e-4). The problem is then copied into that order
//! (contacts A, B, interface; bodies A, B) so that each half's impulses and velocities are one
//! slice, handed to its thread without sharing.

use super::factored::Packed;
use crate::solver::nsgs::LocalBlock3;

/// Contacts from which a factored Gauss–Seidel solve is split: the integrator's
/// [`PARALLEL_MIN_CONTACTS`](crate::integrator::moreau_jean::PARALLEL_MIN_CONTACTS), from which
/// the halves go to two threads. Below, a split would only change the order (about 6 % more
/// sweeps than bottom-up on eight starts of the 100-sphere pour) and copy the problem.
pub(super) const SPLIT_MIN_CONTACTS: usize = crate::integrator::moreau_jean::PARALLEL_MIN_CONTACTS;

/// Sweeps a solve allows at least to be split (a single sweep, e.g. the fallback of a Newton
/// step, does not repay the copies).
pub(super) const SPLIT_MIN_SWEEPS: usize = 8;

/// Largest share of the contacts on the interface (swept by one thread) for a split to pay.
const MAX_INTERFACE_SHARE: f64 = 0.3;

/// The split problem and its scratch (kept across steps: no allocation once grown).
#[derive(Debug, Clone, Default)]
pub(super) struct Domains {
    /// Compact body of each velocity run's first index plus one (0: none), over `nu`.
    body_of: Vec<usize>,
    /// First velocity of each compact body.
    iu_of: Vec<usize>,
    /// The bodies' contact graph (compressed rows).
    adj_ptr: Vec<usize>,
    adj: Vec<usize>,
    level: Vec<usize>,
    queue: Vec<usize>,
    count: Vec<usize>,
    side: Vec<u8>,
    /// New first velocity of each compact body (bodies of side A first).
    new_iu: Vec<usize>,
    /// Contacts in sweep order (A, B, interface), by their index in the problem.
    pub(super) perm: Vec<usize>,
    /// Contacts of side A and of side B; velocities of side A.
    pub(super) na: usize,
    pub(super) nb: usize,
    pub(super) nza: usize,
    /// The problem in sweep order; each half's rows point into its own slice of `z`.
    pub(super) packed: Vec<Packed>,
    pub(super) local: Vec<LocalBlock3>,
    /// The normal regularization of each contact (compliant laws; empty if all are rigid).
    pub(super) reg: Vec<f64>,
    pub(super) q: Vec<f64>,
    pub(super) mu: Vec<f64>,
    pub(super) r: Vec<f64>,
    pub(super) z: Vec<f64>,
    /// Scratch for the sweep's terms when they go to no acceleration.
    f: Vec<f64>,
}

impl Domains {
    /// Cuts the contacts `packed` (3-D, on free bodies; visited in `order` if it is a permutation,
    /// else by index) over `nu` velocities in two domains. Returns `false`, leaving nothing to
    /// use, when the interface would hold more than [`MAX_INTERFACE_SHARE`] of the contacts or a
    /// half none.
    pub(super) fn plan(&mut self, packed: &[Packed], order: &[usize], nu: usize) -> bool {
        let n = packed.len();
        // compact bodies and the graph's degrees
        if self.body_of.len() < nu {
            self.body_of.resize(nu, 0);
        }
        self.iu_of.clear();
        for p in packed {
            for k in 0..p.bodies() {
                let iu = p.iu()[k];
                if self.body_of[iu] == 0 {
                    self.iu_of.push(iu);
                    self.body_of[iu] = self.iu_of.len();
                }
            }
        }
        let nbod = self.iu_of.len();
        self.adj_ptr.clear();
        self.adj_ptr.resize(nbod + 1, 0);
        for p in packed.iter().filter(|p| p.bodies() == 2) {
            let [a, b] = self.pair(p);
            self.adj_ptr[a + 1] += 1;
            self.adj_ptr[b + 1] += 1;
        }
        for k in 0..nbod {
            self.adj_ptr[k + 1] += self.adj_ptr[k];
        }
        self.adj.clear();
        self.adj.resize(self.adj_ptr[nbod], 0);
        self.count.clear();
        self.count.extend_from_slice(&self.adj_ptr[..nbod]);
        for p in packed.iter().filter(|p| p.bodies() == 2) {
            let [a, b] = self.pair(p);
            self.adj[self.count[a]] = b;
            self.count[a] += 1;
            self.adj[self.count[b]] = a;
            self.count[b] += 1;
        }
        // levels from a pseudo-peripheral body (three searches), starting from a body of most
        // contacts (in the largest island, not a stray sphere of its own)
        let mut start = (0..nbod).max_by_key(|&k| (self.adj_ptr[k + 1] - self.adj_ptr[k], usize::MAX - k)).unwrap_or(0);
        for _ in 0..3 {
            start = self.search(start, nbod);
        }
        // the first half of the bodies by level (stable within a level) on side A
        let top = self.level.iter().copied().filter(|&l| l != usize::MAX).max().unwrap_or(0) + 1;
        self.count.clear();
        self.count.resize(top + 2, 0);
        for &l in &self.level {
            self.count[l.min(top) + 1] += 1;
        }
        for l in 0..=top {
            self.count[l + 1] += self.count[l];
        }
        self.side.clear();
        self.side.resize(nbod, 1);
        for k in 0..nbod {
            let l = self.level[k].min(top);
            if self.count[l] < nbod / 2 {
                self.side[k] = 0;
            }
            self.count[l] += 1;
        }
        // the contacts' parts
        self.perm.clear();
        let ordered = order.len() == n;
        for part in 0..3u8 {
            for ii in 0..n {
                let a = if ordered { order[ii] } else { ii };
                let p = &packed[a];
                let s0 = self.side[self.body_of[p.iu()[0]] - 1];
                let s = if p.bodies() == 2 && self.side[self.body_of[p.iu()[1]] - 1] != s0 { 2 } else { s0 };
                if s == part {
                    self.perm.push(a);
                }
            }
            match part {
                0 => self.na = self.perm.len(),
                1 => self.nb = self.perm.len() - self.na,
                _ => {}
            }
        }
        let interface = n - self.na - self.nb;
        let ok = self.na > 0 && self.nb > 0 && (interface as f64) <= MAX_INTERFACE_SHARE * n as f64;
        if ok {
            // the bodies' new velocities: side A's, then side B's
            self.new_iu.clear();
            self.new_iu.resize(nbod, 0);
            let mut next = 0;
            for s in 0..2u8 {
                for k in 0..nbod {
                    if self.side[k] == s {
                        self.new_iu[k] = next;
                        next += 6;
                    }
                }
                if s == 0 {
                    self.nza = next;
                }
            }
            self.z.clear();
            self.z.resize(next, 0.0);
        } else {
            self.finish();
        }
        ok
    }

    /// Copies the problem into sweep order (after a successful [`Domains::plan`]): rows,
    /// prepared blocks, `q`, `mu`, the impulses `r` and `z` (over the original velocities).
    pub(super) fn gather(
        &mut self,
        packed: &[Packed],
        (local, reg): (&[LocalBlock3], &[f64]),
        q: &[f64],
        mu: &[f64],
        r: &[f64],
        z: &[f64],
    ) {
        self.packed.clear();
        self.local.clear();
        self.reg.clear();
        self.q.clear();
        self.mu.clear();
        self.r.clear();
        for (i, &a) in self.perm.iter().enumerate() {
            // side B's rows point into its own slice, which starts after side A's velocities
            let shift = if i >= self.na && i < self.na + self.nb { self.nza } else { 0 };
            let p = &packed[a];
            let mut iu = p.iu();
            for v in iu.iter_mut().take(p.bodies()) {
                *v = self.new_iu[self.body_of[*v] - 1] - shift;
            }
            self.packed.push(p.moved(iu));
            self.local.push(local[a]);
            if !reg.is_empty() {
                self.reg.push(reg[a]);
            }
            self.q.extend_from_slice(&q[a * 3..a * 3 + 3]);
            self.mu.push(mu[a]);
            self.r.extend_from_slice(&r[a * 3..a * 3 + 3]);
        }
        self.f.clear();
        self.f.resize(self.r.len(), 0.0);
        self.gather_z(z);
    }

    /// One sweep: both halves (on two threads if `parallel`), then the interface. Each contact's
    /// term `W_NN Δr` goes to `f` (the split order's, for the Anderson acceleration) if
    /// `accelerate`, else to scratch; returns their sum of squares.
    pub(super) fn sweep(&mut self, f: Option<&mut [f64]>, omega: f64, parallel: bool) -> f64 {
        let (na, nb) = (self.na, self.nb);
        let accelerate = f.is_some();
        let f = f.unwrap_or(&mut self.f[..]);
        let (pa, rest) = self.packed.split_at(na);
        let (pb, pi) = rest.split_at(nb);
        let (la, rest) = self.local.split_at(na);
        let (lb, li) = rest.split_at(nb);
        // (no regularization: empty slices)
        let (ga, gb, gi) = if self.reg.is_empty() {
            (&[][..], &[][..], &[][..])
        } else {
            let (ga, rest) = self.reg.split_at(na);
            let (gb, gi) = rest.split_at(nb);
            (ga, gb, gi)
        };
        let (ma, rest) = self.mu.split_at(na);
        let (mb, mi) = rest.split_at(nb);
        let (qa, rest) = self.q.split_at(3 * na);
        let (qb, qi) = rest.split_at(3 * nb);
        let (ra, rest) = self.r.split_at_mut(3 * na);
        let (rb, ri) = rest.split_at_mut(3 * nb);
        let (fa, rest) = f.split_at_mut(3 * na);
        let (fb, fi) = rest.split_at_mut(3 * nb);
        let (ca, cb) = {
            let (za, zb) = self.z.split_at_mut(self.nza);
            let mut half_a = || sweep_part(pa, (la, ga), (qa, ma), ra, za, fa, (omega, accelerate));
            let mut half_b = || sweep_part(pb, (lb, gb), (qb, mb), rb, zb, fb, (omega, accelerate));
            if parallel {
                rayon::join(half_a, half_b)
            } else {
                (half_a(), half_b())
            }
        };
        let ci = sweep_part(pi, (li, gi), (qi, mi), ri, &mut self.z, fi, (omega, accelerate));
        (ca + cb) + ci
    }

    /// `z` (over the original velocities) into the split order.
    pub(super) fn gather_z(&mut self, z: &[f64]) {
        for (k, &iu) in self.iu_of.iter().enumerate() {
            let at = self.new_iu[k];
            self.z[at..at + 6].copy_from_slice(&z[iu..iu + 6]);
        }
    }

    /// The impulses back into the problem's order, `z` back over the original velocities.
    pub(super) fn scatter(&self, r: &mut [f64], z: &mut [f64]) {
        for (i, &a) in self.perm.iter().enumerate() {
            r[a * 3..a * 3 + 3].copy_from_slice(&self.r[i * 3..i * 3 + 3]);
        }
        for (k, &iu) in self.iu_of.iter().enumerate() {
            let at = self.new_iu[k];
            z[iu..iu + 6].copy_from_slice(&self.z[at..at + 6]);
        }
    }

    /// Forgets the compact numbering (after the solve: `body_of` is all zeros again).
    pub(super) fn finish(&mut self) {
        for &iu in &self.iu_of {
            self.body_of[iu] = 0;
        }
    }

    /// The compact bodies of a contact between two bodies.
    fn pair(&self, p: &Packed) -> [usize; 2] {
        let iu = p.iu();
        [self.body_of[iu[0]] - 1, self.body_of[iu[1]] - 1]
    }

    /// Breadth-first levels from `start` (`usize::MAX` where unreached); returns the last body
    /// reached.
    fn search(&mut self, start: usize, nbod: usize) -> usize {
        self.level.clear();
        self.level.resize(nbod, usize::MAX);
        self.queue.clear();
        if nbod == 0 {
            return 0;
        }
        self.level[start] = 0;
        self.queue.push(start);
        let mut head = 0;
        while head < self.queue.len() {
            let x = self.queue[head];
            head += 1;
            for e in self.adj_ptr[x]..self.adj_ptr[x + 1] {
                let y = self.adj[e];
                if self.level[y] == usize::MAX {
                    self.level[y] = self.level[x] + 1;
                    self.queue.push(y);
                }
            }
        }
        self.queue[self.queue.len() - 1]
    }
}

/// One Gauss–Seidel sweep (3-D, relaxed by `omega ≤ 1`: 1 until the sweeps stall) over `rows` in
/// order, on their impulses `r` and their bodies' entries of `z`: the loop of the factored sweeps
/// (`factored.rs`), the same arithmetic. Writes each contact's `W_NN Δr` into `f` if
/// `accelerate`; returns their sum of squares.
fn sweep_part(
    rows: &[Packed],
    (local, reg): (&[LocalBlock3], &[f64]),
    (q, mu): (&[f64], &[f64]),
    r: &mut [f64],
    z: &mut [f64],
    f: &mut [f64],
    (omega, accelerate): (f64, bool),
) -> f64 {
    let mut change = 0.0;
    for (a, (p, blk)) in rows.iter().zip(local).enumerate() {
        let w = blk.block();
        // b = Y_aᵀ z − W_aa r_a + q_a
        let mut b = p.times::<3>(z);
        let old: [f64; 3] = r[a * 3..a * 3 + 3].try_into().expect("three impulses");
        for c in 0..3 {
            let mut own = 0.0;
            for k in 0..3 {
                own += w[c * 3 + k] * old[k];
            }
            b[c] += q[a * 3 + c] - own;
        }
        if let Some(g) = reg.get(a) {
            // (the block holds W_aa + c/h² e_N e_Nᵀ; z only W r)
            b[0] += g * old[0];
        }
        let mut new = old;
        blk.solve(mu[a], &b, &mut new);
        if omega != 1.0 {
            // under-relaxed after a stall (inside the cone: a convex combination), as in the
            // serial factored sweeps
            for c in 0..3 {
                new[c] = omega * new[c] + (1.0 - omega) * old[c];
            }
        }
        let mut delta = [0.0; 3];
        for c in 0..3 {
            delta[c] = new[c] - old[c];
            let t = w[0] * delta[c];
            change += t * t;
            if accelerate {
                f[a * 3 + c] = t;
            }
        }
        if delta.iter().any(|v| *v != 0.0) {
            p.add_to::<3>(z, &delta);
            r[a * 3..a * 3 + 3].copy_from_slice(&new);
        }
    }
    change
}
