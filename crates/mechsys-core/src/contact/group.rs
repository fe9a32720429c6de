//! Contact groups at run time: which pairs of a [`ContactGroup`] may touch in this step, and
//! their contact kinematics.
//!
//! Per step, at the configuration where the contact problem is posed:
//! 1. every member and every `against` contour gets its world bounding box
//!    ([`Contour::aabb`]), grown by `h (|v(c)| + |ω| ρ) + margin`, with `v(c)` the velocity of the
//!    box centre `c`, `ω` the body's angular velocity and `ρ` the half diagonal of the box: a bound
//!    on how far any point of the contour moves within the step;
//! 2. sweep and prune ([`SweepAndPrune`]) lists the overlapping boxes; pairs of two `against`
//!    contours and pairs on one body are dropped;
//! 3. each remaining pair gets its prepared [`ContactPair`] from a cache keyed by the two contour
//!    indices, created the first time the pair comes close and kept for the rest of the run (with
//!    its candidates' kinematics and last impulses for warm starts), so a step allocates nothing
//!    unless a pair of contours comes close for the first time;
//! 4. the narrow phase runs on those pairs only, at velocity level ([`contact_velocities_warm`]:
//!    gaps, frames, relative velocities; no `w̄`, which neither of the users, Moreau–Jean and the
//!    compliant groups, reads).
//!
//! Pair `(i, j)` has member `i` as contour 1 and member `j > i` (or `against[k]`) as contour 2,
//! so its normal points towards member `i`; live pairs are visited in the order of `(i, j)` (the
//! `against` contours numbered after the members), the order in which the equivalent explicit
//! contacts would be declared member by member.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::contact::ContactGroup;

use super::{contact_velocities_warm, Aabb, BodyMotion, ContactKinematics, ContactPair, SweepAndPrune};

/// A hasher for the packed `(i, j)` keys of the pair cache (one multiply; the keys are small
/// distinct integers, no hostile input).
#[derive(Default, Clone, Copy)]
pub struct PairKeyHasher(u64);

impl Hasher for PairKeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 = (self.0 ^ *b as u64).wrapping_mul(0x100_0000_01b3);
        }
    }
    fn write_u64(&mut self, k: u64) {
        self.0 = (k ^ (k >> 29)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
}

/// A pair of the group that came close at least once.
#[derive(Debug, Clone)]
pub struct PairSlot {
    /// Contour indices: member `i`, and member `j > i` or `against[j - members]`.
    pub key: (u32, u32),
    /// Body of contour 1.
    pub body1: usize,
    /// Body of contour 2.
    pub body2: usize,
    /// The prepared pair.
    pub pair: ContactPair,
    /// Kinematics of its candidates at the last evaluation, at velocity level (`w̄` zero).
    pub kin: Vec<ContactKinematics>,
    /// Last impulses `[Λ_N, Λ_T1, Λ_T2]` and state code of each candidate (valid if the pair
    /// took part in the previous step, see `stamp`).
    pub last: Vec<([f64; 3], f64)>,
    /// The step in which `last` was written.
    pub stamp: u64,
    /// Each candidate's compliant-layer deflection (m) and the step that wrote it (on compliant
    /// groups; a candidate's own step, since the others of its pair may have taken part without it).
    pub layer: Vec<(f64, u64)>,
}

/// Broad phase, pair cache and narrow phase of one contact group.
#[derive(Debug, Clone, Default)]
pub struct GroupPhase {
    members: usize,
    boxes: Vec<Aabb>,
    sap: SweepAndPrune,
    pairs: Vec<(usize, usize)>,
    cache: HashMap<u64, usize, BuildHasherDefault<PairKeyHasher>>,
    /// Pairs met so far.
    pub slots: Vec<PairSlot>,
    /// Slots whose boxes overlap at the last update, in `(i, j)` order.
    pub live: Vec<usize>,
}

impl GroupPhase {
    /// Sized for `group` (boxes, sweep list, a first guess of the number of pairs).
    pub fn new(group: &ContactGroup) -> Self {
        let n = group.members.len() + group.against.len();
        let guess = 8 * n + 16;
        GroupPhase {
            members: group.members.len(),
            boxes: vec![Aabb::EMPTY; n],
            sap: SweepAndPrune::with_capacity(n),
            pairs: Vec::with_capacity(guess),
            cache: HashMap::with_capacity_and_hasher(guess, Default::default()),
            slots: Vec::with_capacity(guess),
            live: Vec::with_capacity(guess),
        }
    }

    fn contour<'g>(&self, group: &'g ContactGroup, k: usize) -> &'g crate::model::contact::GroupContour {
        if k < self.members {
            &group.members[k]
        } else {
            &group.against[k - self.members]
        }
    }

    /// Broad phase at the state in `data` (placements `x_abs`, twists `v`), boxes grown by the
    /// motion within `h` plus `margin`, then the velocity-level kinematics of every live pair's
    /// candidates (`data.a` is not read).
    pub fn update(&mut self, group: &ContactGroup, data: &Data, h: f64, margin: f64) -> Result<()> {
        let n = self.boxes.len();
        for k in 0..n {
            let gc = self.contour(group, k);
            let b = gc.contour.aabb(&data.x_abs[gc.body]);
            let tw = &data.v[gc.body];
            let grow = if tw.w == crate::math::Vec3::zeros() && tw.v == crate::math::Vec3::zeros() {
                0.0
            } else {
                let c = (b.min + b.max) * 0.5;
                let rho = 0.5 * (b.max - b.min).norm();
                let speed = (tw.v + tw.w.cross(&c)).norm() + tw.w.norm() * rho;
                // unbounded boxes (planes) have no finite centre: no growth needed on the open sides
                if speed.is_finite() {
                    h * speed
                } else {
                    0.0
                }
            };
            self.boxes[k] = b.inflated(grow + margin);
        }
        self.sap.update(&self.boxes, &mut self.pairs);
        self.live.clear();
        for p in 0..self.pairs.len() {
            let (i, j) = self.pairs[p];
            if i >= self.members {
                continue; // two `against` contours
            }
            let (ci, cj) = (self.contour(group, i), self.contour(group, j));
            if ci.body == cj.body {
                continue;
            }
            let key = ((i as u64) << 32) | j as u64;
            let slot = match self.cache.get(&key) {
                Some(&s) => s,
                None => {
                    let label = |k: usize| {
                        if k < self.members {
                            format!("members[{k}]")
                        } else {
                            format!("against[{}]", k - self.members)
                        }
                    };
                    let name = format!("{}: {}–{}", group.name, label(i), label(j));
                    let pair = ContactPair::new(&name, ci.contour.clone(), cj.contour.clone())?;
                    let m = pair.candidates();
                    self.slots.push(PairSlot {
                        key: (i as u32, j as u32),
                        body1: ci.body,
                        body2: cj.body,
                        pair,
                        kin: vec![ContactKinematics::default(); m],
                        last: vec![([0.0; 3], 0.0); m],
                        stamp: u64::MAX,
                        layer: vec![(0.0, u64::MAX); m],
                    });
                    self.cache.insert(key, self.slots.len() - 1);
                    self.slots.len() - 1
                }
            };
            self.live.push(slot);
        }
        let slots = &self.slots;
        self.live.sort_unstable_by_key(|&s| slots[s].key);
        for &s in &self.live {
            let slot = &mut self.slots[s];
            let (b1, b2) = (BodyMotion::from_data(data, slot.body1), BodyMotion::from_data(data, slot.body2));
            contact_velocities_warm(&slot.pair, &b1, &b2, &mut slot.kin, None)
                .map_err(|e| Error::Solver(format!("contact group '{}': {e}", group.name)))?;
        }
        Ok(())
    }
}

/// A model fixture for tests and benchmarks: `n` spheres of radius `radius` and mass `mass` on
/// free joints, on a lattice of spacing 2.2 `radius` (jittered by ±1 % of the radius, seeded)
/// filling a square box of inner half-width `half_width` layer by layer from 1 cm above its
/// floor, and one contact group "pile" (all spheres against each other, the floor `z = 0` and
/// the four walls) with Coulomb friction `mu` and Newton restitution `eps`.
pub fn sphere_pile(n: usize, radius: f64, mass: f64, half_width: f64, mu: f64, eps: f64, seed: u64) -> String {
    let per = ((2.0 * half_width / (2.2 * radius)).floor() as usize).max(1);
    let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    let mut jitter = || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.02 * radius
    };
    let i_s = 0.4 * mass * radius * radius;
    let (mut bodies, mut joints, mut members) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..n {
        let (ix, iy, iz) = (i % per, (i / per) % per, i / (per * per));
        let x = -half_width + 1.1 * radius + 2.2 * radius * ix as f64 + jitter();
        let y = -half_width + 1.1 * radius + 2.2 * radius * iy as f64 + jitter();
        let z = radius + 0.01 + 2.2 * radius * iz as f64;
        bodies.push(format!(r#"{{"name": "s{i}", "mass": {mass}, "inertia": [{i_s}, {i_s}, {i_s}]}}"#));
        joints.push(format!(
            r#"{{"name": "f{i}", "type": "free", "parent": "ground", "child": "s{i}", "q0": [{x}, {y}, {z}, 1, 0, 0, 0]}}"#
        ));
        members.push(format!(r#"{{"body": "s{i}", "contour": {{"type": "sphere", "radius": {radius}}}}}"#));
    }
    let h = half_width;
    let walls = [
        r#"{"body": "ground", "contour": {"type": "plane", "normal": [0, 0, 1]}}"#.to_string(),
        format!(
            r#"{{"body": "ground", "contour": {{"type": "plane", "point": [{}, 0, 0], "normal": [1, 0, 0]}}}}"#,
            -h
        ),
        format!(r#"{{"body": "ground", "contour": {{"type": "plane", "point": [{h}, 0, 0], "normal": [-1, 0, 0]}}}}"#),
        format!(
            r#"{{"body": "ground", "contour": {{"type": "plane", "point": [0, {}, 0], "normal": [0, 1, 0]}}}}"#,
            -h
        ),
        format!(r#"{{"body": "ground", "contour": {{"type": "plane", "point": [0, {h}, 0], "normal": [0, -1, 0]}}}}"#),
    ];
    format!(
        r#"{{"name": "sphere-pile", "gravity": [0, 0, -9.81], "bodies": [{}], "joints": [{}],
            "contact_groups": [{{"name": "pile", "members": [{}], "against": [{}],
              "friction": {{"type": "coulomb", "mu": {mu}}}, "impact": {{"type": "newton", "eps": {eps}}}}}]}}"#,
        bodies.join(","),
        joints.join(","),
        members.join(","),
        walls.join(",")
    )
}
