//! Broad phase: which contours may touch, from their world axis-aligned bounding boxes.
//!
//! Sweep and prune: the boxes are kept sorted by their lower bound along one sweep axis; a pair
//! can overlap only if their intervals on that axis do, so a sweep over the sorted list visits
//! each box's successors until their lower bound passes its upper bound, and tests the two other
//! axes. The order is kept between calls: bodies move little in one step, the list stays almost
//! sorted, and an insertion sort restores it in about `n + (number of swaps)` operations. A list
//! that is far from sorted (the first call, a new sweep axis, large jumps) falls back to a full
//! sort once the insertion sort has done `4n` moves.
//!
//! The sweep axis is the one with the largest variance of the box centres, switched only when
//! another axis's variance exceeds the current one's by half (each switch costs a full sort).
//! Unbounded boxes (half-spaces, planar contours) sort first and are tested against every box
//! whose interval they meet.

use crate::math::Vec3;

/// An axis-aligned box `[min, max]` in world coordinates; bounds may be infinite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Aabb {
    /// The box containing everything.
    pub const EVERYTHING: Aabb = Aabb {
        min: Vec3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
        max: Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
    };
    /// The empty box (the identity of [`Aabb::union`]).
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
        max: Vec3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
    };

    /// The degenerate box of one point.
    #[inline]
    pub fn point(p: &Vec3) -> Aabb {
        Aabb { min: *p, max: *p }
    }

    /// Grown by `margin` on every side (a contact margin, or a sphere's radius).
    #[inline]
    pub fn inflated(&self, margin: f64) -> Aabb {
        let m = Vec3::repeat(margin);
        Aabb { min: self.min - m, max: self.max + m }
    }

    /// The smallest box containing both.
    #[inline]
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb { min: self.min.inf(&o.min), max: self.max.sup(&o.max) }
    }

    /// Whether the closed boxes intersect (touching counts).
    #[inline]
    pub fn overlaps(&self, o: &Aabb) -> bool {
        (0..3).all(|k| self.min[k] <= o.max[k] && o.min[k] <= self.max[k])
    }

    /// Whether `p` lies in the closed box.
    #[inline]
    pub fn contains_point(&self, p: &Vec3) -> bool {
        (0..3).all(|k| self.min[k] <= p[k] && p[k] <= self.max[k])
    }
}

/// One box in sweep order, bounds copied for locality: `lo`, `hi` on the sweep axis, `o` the
/// bounds on the two other axes (`[min, max, min, max]`), `id` its index in the caller's list.
#[derive(Debug, Clone, Copy)]
struct Entry {
    lo: f64,
    hi: f64,
    o: [f64; 4],
    id: usize,
}

/// Sweep-and-prune broad phase; keeps the sweep order between calls.
///
/// # Example
/// ```
/// use mechsys_core::contact::{Aabb, SweepAndPrune};
/// use mechsys_core::math::Vec3;
/// let boxes = [
///     Aabb::point(&Vec3::new(0.0, 0.0, 0.0)).inflated(0.5),
///     Aabb::point(&Vec3::new(0.8, 0.0, 0.0)).inflated(0.5),
///     Aabb::point(&Vec3::new(5.0, 0.0, 0.0)).inflated(0.5),
/// ];
/// let mut sap = SweepAndPrune::new();
/// let mut pairs = Vec::new();
/// sap.update(&boxes, &mut pairs);
/// assert_eq!(pairs, vec![(0, 1)]);
/// ```
#[derive(Debug, Clone, Default)]
pub struct SweepAndPrune {
    entries: Vec<Entry>,
    axis: usize,
    moves: usize,
    full: bool,
}

impl SweepAndPrune {
    /// An empty broad phase.
    pub fn new() -> Self {
        Self::default()
    }

    /// With room for `n` boxes (so the first update does not allocate for them).
    pub fn with_capacity(n: usize) -> Self {
        SweepAndPrune { entries: Vec::with_capacity(n), ..Self::default() }
    }

    /// The current sweep axis (0, 1, 2 = x, y, z).
    pub fn axis(&self) -> usize {
        self.axis
    }

    /// Element moves of the last update's insertion sort (its cost beyond one pass).
    pub fn last_sort_moves(&self) -> usize {
        self.moves
    }

    /// Whether the last update needed a full sort (first call, new size, new axis or a list far
    /// from sorted).
    pub fn last_sort_was_full(&self) -> bool {
        self.full
    }

    /// Replaces `pairs` with every `(i, j)`, `i < j`, whose boxes overlap (closed boxes; in no
    /// particular order). `boxes[i]` is the box of proxy `i`; filtering pairs on one body is the
    /// caller's. Allocates only when the number of boxes changes or `pairs` runs out of capacity.
    pub fn update(&mut self, boxes: &[Aabb], pairs: &mut Vec<(usize, usize)>) {
        pairs.clear();
        let mut full = false;
        if self.entries.len() != boxes.len() {
            self.entries.clear();
            self.entries.extend((0..boxes.len()).map(|id| Entry { lo: 0.0, hi: 0.0, o: [0.0; 4], id }));
            full = true;
        }
        let best = widest_axis(boxes, self.axis);
        if best != self.axis {
            self.axis = best;
            full = true;
        }
        let (ax, o1, o2) = (self.axis, (self.axis + 1) % 3, (self.axis + 2) % 3);
        for e in self.entries.iter_mut() {
            let b = &boxes[e.id];
            e.lo = b.min[ax];
            e.hi = b.max[ax];
            e.o = [b.min[o1], b.max[o1], b.min[o2], b.max[o2]];
        }
        self.moves = 0;
        if !full {
            full = !self.insertion_sort(4 * self.entries.len() + 16);
        }
        if full {
            // sort_unstable_by sorts in place: no allocation
            self.entries.sort_unstable_by(|a, b| a.lo.total_cmp(&b.lo));
        }
        self.full = full;
        let e = &self.entries;
        for (i, a) in e.iter().enumerate() {
            for b in &e[i + 1..] {
                // sorted by lo: no later box can start before this one ends
                if b.lo > a.hi {
                    break;
                }
                // `&` rather than `&&`: one predictable branch instead of four
                let hit = (a.o[0] <= b.o[1]) & (b.o[0] <= a.o[1]) & (a.o[2] <= b.o[3]) & (b.o[2] <= a.o[3]);
                if hit {
                    pairs.push(if a.id < b.id { (a.id, b.id) } else { (b.id, a.id) });
                }
            }
        }
    }

    /// Insertion sort by `lo`; gives up (returns false) after `budget` moves, leaving a
    /// permutation for the full sort.
    fn insertion_sort(&mut self, budget: usize) -> bool {
        let e = &mut self.entries;
        for i in 1..e.len() {
            let key = e[i];
            let mut j = i;
            while j > 0 && e[j - 1].lo.total_cmp(&key.lo).is_gt() {
                e[j] = e[j - 1];
                j -= 1;
            }
            e[j] = key;
            self.moves += i - j;
            if self.moves > budget {
                return false;
            }
        }
        true
    }
}

/// The axis with the largest variance of the finite box centres; another axis replaces
/// `current` only if its variance is larger by half.
fn widest_axis(boxes: &[Aabb], current: usize) -> usize {
    let mut s = [0.0f64; 3];
    let mut s2 = [0.0f64; 3];
    let mut cnt = [0usize; 3];
    for b in boxes {
        for k in 0..3 {
            let c = 0.5 * (b.min[k] + b.max[k]);
            if c.is_finite() {
                s[k] += c;
                s2[k] += c * c;
                cnt[k] += 1;
            }
        }
    }
    let var = |k: usize| if cnt[k] == 0 { 0.0 } else { s2[k] / cnt[k] as f64 - (s[k] / cnt[k] as f64).powi(2) };
    let mut best = current;
    for k in 0..3 {
        if var(k) > 1.5 * var(best) {
            best = k;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::test_util::Rng;

    fn brute(boxes: &[Aabb]) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                if boxes[i].overlaps(&boxes[j]) {
                    out.push((i, j));
                }
            }
        }
        out
    }

    fn spheres(rng: &mut Rng, n: usize) -> Vec<(Vec3, f64)> {
        (0..n)
            .map(|_| {
                (
                    Vec3::new(rng.uniform(0.0, 1.0), rng.uniform(0.0, 2.0), rng.uniform(0.0, 0.5)),
                    rng.uniform(0.005, 0.03),
                )
            })
            .collect()
    }

    fn boxes_of(s: &[(Vec3, f64)]) -> Vec<Aabb> {
        s.iter().map(|(c, r)| Aabb::point(c).inflated(*r)).collect()
    }

    fn sorted(mut v: Vec<(usize, usize)>) -> Vec<(usize, usize)> {
        v.sort_unstable();
        v
    }

    /// 2000 random spheres (plus two ground planes and a far box): the same pair set as the
    /// O(n²) test of every pair.
    #[test]
    fn sweep_matches_brute_force() {
        let mut rng = Rng::new(7);
        let s = spheres(&mut rng, 2000);
        let mut boxes = boxes_of(&s);
        let mut sap = SweepAndPrune::new();
        let mut pairs = Vec::new();
        sap.update(&boxes, &mut pairs);
        assert_eq!(sorted(pairs.clone()), brute(&boxes));
        // the widest spread of the centres is along y
        assert_eq!(sap.axis(), 1);
        boxes.push(
            crate::contact::Contour::Plane { point: Vec3::new(0.0, 0.0, 0.1), normal: Vec3::z() }
                .aabb(&crate::spatial::Pose::IDENTITY),
        );
        boxes.push(Aabb::EVERYTHING);
        boxes.push(Aabb::point(&Vec3::repeat(100.0)));
        sap.update(&boxes, &mut pairs);
        let expect = brute(&boxes);
        assert!(expect.len() > 2000, "the test should have many overlaps, got {}", expect.len());
        assert_eq!(sorted(pairs), expect);
    }

    /// After small motions the list is almost sorted: the insertion sort is the path taken and
    /// its cost is a small fraction of n; far larger motions fall back to the full sort.
    #[test]
    fn resorting_an_almost_sorted_list_is_cheap() {
        let mut rng = Rng::new(11);
        let mut s = spheres(&mut rng, 2000);
        let mut sap = SweepAndPrune::with_capacity(2000);
        let mut pairs = Vec::new();
        sap.update(&boxes_of(&s), &mut pairs);
        assert!(sap.last_sort_was_full());
        for step in 0..5 {
            for (c, _) in s.iter_mut() {
                *c += Vec3::new(rng.uniform(-1e-3, 1e-3), rng.uniform(-1e-3, 1e-3), rng.uniform(-1e-3, 1e-3));
            }
            let boxes = boxes_of(&s);
            sap.update(&boxes, &mut pairs);
            assert!(!sap.last_sort_was_full(), "step {step}");
            // mean gap between neighbours along y is 1e-3, so each box passes about one other
            assert!(sap.last_sort_moves() < 2000, "step {step}: {} moves", sap.last_sort_moves());
            assert_eq!(sorted(pairs.clone()), brute(&boxes), "step {step}");
        }
        // shuffle everything: the budget runs out and the full sort takes over, still exact
        for (c, _) in s.iter_mut() {
            c.y = rng.uniform(0.0, 2.0);
        }
        let boxes = boxes_of(&s);
        sap.update(&boxes, &mut pairs);
        assert!(sap.last_sort_was_full());
        assert_eq!(sorted(pairs), brute(&boxes));
    }

    #[test]
    fn bad_boxes_do_not_panic() {
        let nan = Vec3::repeat(f64::NAN);
        let boxes = [Aabb { min: nan, max: nan }, Aabb::point(&Vec3::zeros()), Aabb { min: -nan, max: nan }];
        let mut sap = SweepAndPrune::new();
        let mut pairs = vec![(9, 9)];
        sap.update(&boxes, &mut pairs);
        assert!(pairs.is_empty());
        sap.update(&[], &mut pairs);
        assert!(pairs.is_empty());
    }
}
