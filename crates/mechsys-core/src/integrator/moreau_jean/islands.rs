//! Independent contact islands: the connected components of the contact graph (two contact
//! points are linked when their Delassus block `W_ij` is nonzero, i.e. they move a common body
//! or a common tree). The friction-contact problem is block-diagonal over the islands, so each
//! island is a problem of its own: solved apart (a small island converges in its own few
//! sweeps instead of waiting for the slowest), and in parallel on rayon's threads.
//!
//! Every island owns its problem, workspace and impulses, refilled in place each step (storage
//! grows to the largest step seen, then no allocation). An island's solve reads only its own
//! data, so the impulses are the same bit for bit whether the islands run one after the other
//! or on any number of threads; the combined report is formed in island order.

use rayon::prelude::*;

use crate::error::Result;
use crate::solver::{self, BlockDelassus, Delassus, FrictionContact, Method, Report, Workspace};

/// One island's problem and scratch.
#[derive(Debug, Clone, Default)]
struct Island {
    problem: Option<FrictionContact>,
    ws: Workspace,
    r: Vec<f64>,
    diag: Vec<f64>,
    upper: Vec<(usize, usize)>,
    upper_val: Vec<f64>,
    /// Sweep-order keys of its contacts (empty: by index).
    key: Vec<f64>,
    report: Option<Report>,
}

/// The partition of the step's contacts into islands and the islands' problems.
#[derive(Debug, Clone, Default)]
pub(super) struct Islands {
    /// Union-find parents (per contact), then the island of each contact.
    of: Vec<usize>,
    /// Position of each contact inside its island.
    local: Vec<usize>,
    /// Contacts of island k: `members[start[k]..start[k + 1]]`, ascending.
    start: Vec<usize>,
    members: Vec<usize>,
    count: usize,
    pool: Vec<Island>,
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

impl Islands {
    /// Number of islands of the last partition.
    pub(super) fn count(&self) -> usize {
        self.count
    }

    /// Contacts in the islands of more than `above` contacts (after [`Islands::partition`]).
    pub(super) fn in_islands_above(&self, above: usize) -> usize {
        if self.count <= 1 {
            let n = if self.count == 1 { self.of.len() } else { 0 };
            return if n > above { n } else { 0 };
        }
        (0..self.count).map(|k| self.start[k + 1] - self.start[k]).filter(|&c| c > above).sum()
    }

    /// Contacts in the largest island (after [`Islands::partition`]).
    pub(super) fn largest(&self) -> usize {
        if self.count <= 1 {
            return if self.count == 1 { self.of.len() } else { 0 };
        }
        (0..self.count).map(|k| self.start[k + 1] - self.start[k]).max().unwrap_or(0)
    }

    /// One island of `n` contacts (the dense assembly couples every contact through `M̃⁻¹`), or
    /// none if `n` is 0.
    pub(super) fn single(&mut self, n: usize) {
        self.count = usize::from(n > 0);
    }

    /// Partitions `n` contacts linked by the pairs `upper` (the coupled pairs, or any set of
    /// links with the same connected components).
    pub(super) fn partition(&mut self, n: usize, upper: &[(usize, usize)]) {
        self.of.clear();
        self.of.extend(0..n);
        for &(i, j) in upper {
            let (a, b) = (find(&mut self.of, i), find(&mut self.of, j));
            if a != b {
                // the smaller root wins, so the labels do not depend on the pairs' order
                let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                self.of[hi] = lo;
            }
        }
        // label islands in the order of their first contact
        self.local.clear();
        self.local.resize(n, 0);
        self.start.clear();
        self.count = 0;
        for i in 0..n {
            let root = find(&mut self.of, i);
            if root == i {
                self.local[i] = self.count; // the island's label, for now
                self.count += 1;
            }
        }
        if self.count <= 1 {
            // one island (or none): the problem is solved whole, the members are not needed
            return;
        }
        for i in 0..n {
            let root = self.of[i];
            self.of[i] = self.local[root];
        }
        // counting sort of the contacts by island
        self.start.resize(self.count + 2, 0);
        for i in 0..n {
            self.start[self.of[i] + 2] += 1;
        }
        for k in 0..self.count {
            self.start[k + 2] += self.start[k + 1];
        }
        self.members.clear();
        self.members.resize(n, 0);
        // start[k + 1] is island k's next free slot while filling, then island k + 1's start
        for i in 0..n {
            let k = self.of[i];
            let s = self.start[k + 1];
            self.members[s] = i;
            self.start[k + 1] += 1;
        }
        self.start.truncate(self.count + 1);
        for k in 0..self.count {
            for (l, &i) in self.members[self.start[k]..self.start[k + 1]].iter().enumerate() {
                self.local[i] = l;
            }
        }
        if self.pool.len() < self.count {
            self.pool.resize_with(self.count, Island::default);
        }
    }

    /// Splits `whole` (block-sparse `W`, diagonal blocks `diag`, coupled pairs `upper` with
    /// values `upper_val`) into the islands' problems, warm-started from `r`; `key` (one per
    /// contact, or empty) orders each island's Gauss–Seidel sweeps.
    pub(super) fn fill(
        &mut self,
        whole: &FrictionContact,
        diag: &[f64],
        upper: &[(usize, usize)],
        upper_val: &[f64],
        r: &[f64],
        key: &[f64],
    ) {
        let d = whole.dim;
        let dd = d * d;
        for isl in &mut self.pool[..self.count] {
            isl.diag.clear();
            isl.upper.clear();
            isl.upper_val.clear();
            isl.r.clear();
            isl.key.clear();
            let p = isl.problem.get_or_insert_with(|| FrictionContact {
                dim: d,
                w: Delassus::Blocks(BlockDelassus::default()),
                q: Vec::new(),
                mu: Vec::new(),
            });
            p.dim = d;
            p.q.clear();
            p.mu.clear();
        }
        for k in 0..self.count {
            let isl = &mut self.pool[k];
            let p = isl.problem.as_mut().expect("filled above");
            for &i in &self.members[self.start[k]..self.start[k + 1]] {
                isl.diag.extend_from_slice(&diag[i * dd..(i + 1) * dd]);
                p.q.extend_from_slice(&whole.q[i * d..(i + 1) * d]);
                p.mu.push(whole.mu[i]);
                isl.r.extend_from_slice(&r[i * d..(i + 1) * d]);
                if let Some(k) = key.get(i) {
                    isl.key.push(*k);
                }
            }
        }
        for (e, &(i, j)) in upper.iter().enumerate() {
            let isl = &mut self.pool[self.of[i]];
            debug_assert_eq!(self.of[i], self.of[j]);
            isl.upper.push((self.local[i], self.local[j]));
            isl.upper_val.extend_from_slice(&upper_val[e * dd..(e + 1) * dd]);
        }
        for k in 0..self.count {
            let n = self.start[k + 1] - self.start[k];
            let isl = &mut self.pool[k];
            let p = isl.problem.as_mut().expect("filled above");
            let Delassus::Blocks(bw) = &mut p.w else { unreachable!("block Delassus") };
            bw.refill(d, n, &isl.diag, &isl.upper, &isl.upper_val);
        }
    }

    /// Refreshes the islands' friction coefficients from the whole problem's (a re-solve after
    /// a break-away changes some) and their warm starts from `r`.
    pub(super) fn refresh(&mut self, whole: &FrictionContact, r: &[f64]) {
        let d = whole.dim;
        for k in 0..self.count {
            let isl = &mut self.pool[k];
            let p = isl.problem.as_mut().expect("filled");
            for (l, &i) in self.members[self.start[k]..self.start[k + 1]].iter().enumerate() {
                p.mu[l] = whole.mu[i];
                isl.r[l * d..(l + 1) * d].copy_from_slice(&r[i * d..(i + 1) * d]);
            }
        }
    }

    /// Solves every island with `method` (in parallel if `parallel`), writes the impulses into
    /// `r` and returns the islands' largest iteration count, their worst residual (each relative
    /// to its own free velocity) and whether all converged.
    pub(super) fn solve(&mut self, method: &Method, parallel: bool, r: &mut [f64]) -> Result<Report> {
        let run = |isl: &mut Island| -> Result<()> {
            let p = isl.problem.as_ref().expect("filled");
            isl.ws.reserve(p, method)?;
            isl.ws.set_order(&isl.key);
            let warm = isl.r.iter().any(|v| *v != 0.0);
            isl.report = Some(solver::solve(p, method, &mut isl.r, warm, &mut isl.ws)?);
            Ok(())
        };
        let islands = &mut self.pool[..self.count];
        if parallel {
            islands.par_iter_mut().try_for_each(run)?;
        } else {
            islands.iter_mut().try_for_each(run)?;
        }
        let d = self.pool.first().and_then(|i| i.problem.as_ref()).map_or(3, |p| p.dim);
        let mut out = Report { iterations: 0, residual: 0.0, converged: true };
        for k in 0..self.count {
            let isl = &self.pool[k];
            for (l, &i) in self.members[self.start[k]..self.start[k + 1]].iter().enumerate() {
                r[i * d..(i + 1) * d].copy_from_slice(&isl.r[l * d..(l + 1) * d]);
            }
            let rep = isl.report.expect("solved");
            out.iterations = out.iterations.max(rep.iterations);
            out.residual = out.residual.max(rep.residual);
            out.converged &= rep.converged;
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::fixtures::random_friction_contact;
    use crate::solver::NsgsOptions;

    #[test]
    fn partition_labels_islands_by_their_first_contact_and_numbers_their_members() {
        let mut isl = Islands::default();
        isl.partition(6, &[(3, 5), (1, 2), (0, 3)]);
        assert_eq!(isl.count(), 3);
        assert_eq!(isl.of, [0, 1, 1, 0, 2, 0]);
        assert_eq!(isl.start, [0, 3, 5, 6]);
        assert_eq!(isl.members, [0, 3, 5, 1, 2, 4]);
        assert_eq!(isl.local, [0, 0, 1, 1, 0, 2]);
        isl.partition(0, &[]);
        assert_eq!(isl.count(), 0);
    }

    #[test]
    fn in_islands_above_counts_the_contacts_of_the_islands_above_a_size() {
        // islands {0, 3, 5}, {1, 2}, {4} (counted by hand): above 0 all six, above 1 five, above
        // 2 three, above 3 none
        let mut isl = Islands::default();
        isl.partition(6, &[(3, 5), (1, 2), (0, 3)]);
        let counts: Vec<usize> = (0..4).map(|a| isl.in_islands_above(a)).collect();
        assert_eq!(counts, [6, 5, 3, 0]);
        // one island: every contact if above the size (its members are not sorted then); none: 0
        isl.partition(4, &[(0, 1), (1, 2), (2, 3)]);
        assert_eq!((isl.count(), isl.in_islands_above(3), isl.in_islands_above(4)), (1, 4, 0));
        isl.partition(0, &[]);
        assert_eq!(isl.in_islands_above(0), 0);
        assert_eq!(isl.largest(), 0);
        isl.partition(6, &[(3, 5), (1, 2), (0, 3)]);
        assert_eq!(isl.largest(), 3);
    }

    /// Two random problems of 5 and 4 contacts, interleaved into one block-diagonal problem.
    fn two_problems() -> (FrictionContact, Vec<f64>, Vec<(usize, usize)>, Vec<f64>) {
        let (a, b) = (random_friction_contact(3, 5, 0.4, 11).unwrap(), random_friction_contact(3, 4, 0.4, 12).unwrap());
        // global contact k: even k < 10 from a, the rest from b
        let owner = |k: usize| if k % 2 == 0 && k < 10 { (0, k / 2) } else { (1, if k < 10 { k / 2 } else { k - 5 }) };
        let n = 9;
        let (mut diag, mut upper, mut upper_val, mut q, mut mu) = (vec![], vec![], vec![], vec![], vec![]);
        let block = |p: &FrictionContact, i: usize, j: usize| -> Vec<f64> {
            let Delassus::Dense(w) = &p.w else { unreachable!() };
            let m = 3 * p.contacts();
            (0..9).map(|e| w[(3 * i + e / 3) * m + 3 * j + e % 3]).collect()
        };
        for k in 0..n {
            let (pk, i) = owner(k);
            let p = if pk == 0 { &a } else { &b };
            diag.extend(block(p, i, i));
            q.extend_from_slice(&p.q[3 * i..3 * i + 3]);
            mu.push(p.mu[i]);
            for l in k + 1..n {
                let (pl, j) = owner(l);
                if pl == pk {
                    upper.push((k, l));
                    upper_val.extend(block(p, i, j));
                }
            }
        }
        let mut bw = BlockDelassus::default();
        bw.refill(3, n, &diag, &upper, &upper_val);
        (FrictionContact::new(3, Delassus::Blocks(bw), q, mu).unwrap(), diag, upper, upper_val)
    }

    #[test]
    fn islands_solve_like_the_whole_problem_and_the_same_on_threads() {
        let (whole, diag, upper, upper_val) = two_problems();
        let method =
            Method::Nsgs(NsgsOptions { tol: 1e-13, max_iter: 100_000, relaxation: 1.0, anderson: 0, stall: 0 });
        let mut ws = Workspace::for_problem(&whole, &method).unwrap();
        let mut r_whole = vec![0.0; 27];
        assert!(solver::solve(&whole, &method, &mut r_whole, false, &mut ws).unwrap().converged);
        let mut runs = Vec::new();
        for parallel in [false, true] {
            let mut isl = Islands::default();
            isl.partition(9, &upper);
            assert_eq!(isl.count(), 2);
            let mut r = vec![0.0; 27];
            isl.fill(&whole, &diag, &upper, &upper_val, &r.clone(), &[]);
            let rep = isl.solve(&method, parallel, &mut r).unwrap();
            assert!(rep.converged && rep.residual <= 1e-13, "{rep:?}");
            let scale = 1.0 + r_whole.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for (x, y) in r.iter().zip(&r_whole) {
                assert!((x - y).abs() < 1e-9 * scale, "{x} vs {y}");
            }
            // the whole problem's residual at the islands' solution
            assert!(whole.residual(&r).unwrap() < 1e-12);
            runs.push(r);
        }
        assert_eq!(runs[0], runs[1], "serial and threaded islands differ");
    }
}
