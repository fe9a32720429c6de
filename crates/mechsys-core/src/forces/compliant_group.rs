//! Compliant contact groups as force elements: the pairs of a group's contours that the broad
//! phase keeps ([`crate::contact::group::GroupPhase`], boxes not grown: only contours whose
//! boxes overlap now can overlap each other now) get the narrow phase and the compliant law of
//! [`super::compliant`] at every right-hand-side evaluation, so a pile of N members costs about
//! O(N) per evaluation instead of the N(N−1)/2 explicit contacts it stands for.
//!
//! Per pair, the law (K from the pair's curvatures and E*) is resolved once, when the pair first
//! comes close, and kept with the pair's slot; the approach speeds at onset that the dissipative
//! laws tuned by a restitution need are kept per candidate point and committed after accepted
//! steps ([`commit`]). A slot allocates when it is created; evaluations then allocate nothing.
//!
//! Switches are not located in groups: locating every onset and release of a pile would end
//! a step at each of thousands of contact changes, and the Hertz-type forces (`K δ^{3/2}`, with
//! or without the `(1 + α δ̇)` factor) and the regularized friction are continuous at `δ = 0`,
//! so an adaptive scheme steps over an onset with its error control (a few rejected steps) and
//! keeps its tolerance. (A Kelvin–Voigt law with damping jumps by `d δ̇` at the onset; the error
//! control still holds the tolerance, at the cost of more rejected steps.) Explicit compliant
//! contacts keep their located switches.
//!
//! Recorded per group ([`crate::model::compliant::GROUP_OUTPUTS`]): the sum of the normal
//! forces, the stored energy, the dissipated energy (one extra ODE state, the group's slot),
//! the number of touching pairs; the largest overlap and approach rate, the number of pairs
//! the broad phase kept and of touching points; then the first touching points (two per member
//! at most) with the force on their first contour, for the viewer.

use super::compliant::{apply_point, point_force, PairLaw, Work};
use super::Callbacks;
use crate::contact::group::GroupPhase;
use crate::data::Data;
use crate::error::Result;
use crate::model::compliant::{CompliantGroup, CompliantLaw, GROUP_OUTPUTS, STATES_PER_POINT};

/// One compliant group's broad phase, pair laws and history, sized as pairs come close.
#[derive(Debug, Clone, Default)]
pub struct GroupWork {
    phase: GroupPhase,
    /// The law of each pair slot.
    laws: Vec<CompliantLaw>,
    /// First index of each slot's candidates in `onset`.
    first: Vec<usize>,
    /// Approach speed at the onset of the current contact, per candidate point (0 while open).
    onset: Vec<f64>,
    /// Slots kept by the broad phase at the current commit.
    mark: Vec<bool>,
}

impl GroupWork {
    /// Sized for `g`.
    pub fn new(g: &CompliantGroup) -> Self {
        let phase = GroupPhase::new(&g.geometry);
        let cap = phase.slots.capacity();
        GroupWork {
            phase,
            laws: Vec::with_capacity(cap),
            first: Vec::with_capacity(cap),
            onset: Vec::with_capacity(cap),
            mark: Vec::with_capacity(cap),
        }
    }

    /// Broad and narrow phase at the state in `data`, and the laws of the pairs met first.
    fn update(&mut self, g: &CompliantGroup, data: &Data) -> Result<()> {
        self.phase.update(&g.geometry, data, 0.0, 0.0)?;
        while self.laws.len() < self.phase.slots.len() {
            let s = &self.phase.slots[self.laws.len()];
            self.laws.push(g.law(s.key.0 as usize, s.key.1 as usize)?);
            self.first.push(self.onset.len());
            self.onset.extend(std::iter::repeat(0.0).take(s.kin.len()));
            self.mark.push(false);
        }
        Ok(())
    }

    /// Pairs met so far (slots of the pair cache).
    pub fn pairs_met(&self) -> usize {
        self.phase.slots.len()
    }
}

/// Evaluates group `g` (its recorded values from `o` on): applies the forces of its touching
/// pairs to `data.f_ext`, writes the rate of its dissipated energy and returns that power.
pub fn evaluate(
    g: &CompliantGroup,
    data: &mut Data,
    w: &mut Work,
    o: usize,
    t: f64,
    cb: &dyn Callbacks,
) -> Result<f64> {
    let Work { groups, rates, states, .. } = w;
    let gw = &mut groups[g.index];
    gw.update(g, data)?;
    let (mut f_sum, mut energy, mut power, mut touching) = (0.0, 0.0, 0.0, 0usize);
    let (mut max_d, mut max_rate) = (0.0f64, 0.0f64);
    // the first touching points, for drawing: position and force on the first contour
    let (drawn, mut points) = (g.drawn(), 0usize);
    let width = g.outputs();
    data.element_force[o + GROUP_OUTPUTS..o + width].fill(0.0);
    data.element_deflection[o + GROUP_OUTPUTS..o + width].fill(0.0);
    for &sl in &gw.phase.live {
        let slot = &gw.phase.slots[sl];
        let (i, j) = (slot.key.0 as usize, slot.key.1 as usize);
        let pl = PairLaw {
            law: &gw.laws[sl],
            contours: [&g.contour(i).contour, &g.contour(j).contour],
            body1: slot.body1,
            body2: slot.body2,
            name: &g.geometry.name,
        };
        let planar = slot.pair.tangent_dim() == 1;
        let mut touched = false;
        for (k, kin) in slot.kin.iter().enumerate() {
            let delta = -kin.point.g_n;
            if delta <= 0.0 {
                continue;
            }
            let pf = point_force(&pl, data, kin, gw.onset[gw.first[sl] + k], [0.0; 2], planar, t, cb)?;
            apply_point(data, slot.body1, slot.body2, kin, &pf);
            if points < drawn {
                let f = kin.point.n * pf.f_n + kin.point.t1 * pf.f_t[0] + kin.point.t2 * pf.f_t[1];
                let (p1, b) = (&kin.point.p1, o + GROUP_OUTPUTS + 6 * points);
                data.element_force[b..b + 6].copy_from_slice(&[p1.x, p1.y, p1.z, f.x, f.y, f.z]);
            }
            points += 1;
            touched = true;
            f_sum += pf.f_n;
            energy += pf.energy;
            power += pf.power;
            max_d = max_d.max(delta);
            max_rate = max_rate.max(-kin.gd_n);
        }
        touching += touched as usize;
    }
    let s = STATES_PER_POINT * g.slot;
    rates[s] = power;
    rates[s + 1] = 0.0;
    rates[s + 2] = 0.0;
    data.contact_energy += energy;
    let fo = &mut data.element_force[o..o + GROUP_OUTPUTS];
    fo.copy_from_slice(&[f_sum, energy, states[s], touching as f64]);
    let d = &mut data.element_deflection[o..o + GROUP_OUTPUTS];
    d.copy_from_slice(&[max_d, max_rate, gw.phase.live.len() as f64, points as f64]);
    Ok(power)
}

/// After an accepted step (kinematics of its end in `data`): the approach speeds of the points
/// that closed, and the reset of those that opened or left the broad phase.
pub fn commit(g: &CompliantGroup, data: &Data, gw: &mut GroupWork, _t: f64) -> Result<()> {
    gw.update(g, data)?;
    for &sl in &gw.phase.live {
        gw.mark[sl] = true;
        let f = gw.first[sl];
        for (k, kin) in gw.phase.slots[sl].kin.iter().enumerate() {
            let (gn, gd) = (kin.point.g_n, kin.gd_n);
            // touching and approaching counts as closed (as for explicit contacts)
            let closed = gn < 0.0 || (gn == 0.0 && gd < 0.0);
            if !closed {
                gw.onset[f + k] = 0.0;
            } else if gw.onset[f + k] == 0.0 {
                gw.onset[f + k] = (-gd).max(f64::MIN_POSITIVE);
            }
        }
    }
    for sl in 0..gw.mark.len() {
        if !gw.mark[sl] {
            let n = gw.phase.slots[sl].kin.len();
            let f = gw.first[sl];
            gw.onset[f..f + n].fill(0.0);
        }
        gw.mark[sl] = false;
    }
    Ok(())
}
