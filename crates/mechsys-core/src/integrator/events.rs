//! The record of contact events, kept the same way by the event-driven and the time-stepping
//! schemes: what happened at which contact point and when (section 2.5.2: a contact becomes
//! active when its gap closes, and stops being so only through its forces: the normal force
//! vanishing opens it, the friction reserve vanishing lets it slide), the impulses an event
//! applied and the kinetic energy it took, the generalized velocities around an impact, and the
//! Painlevé situations met on the way.

/// What happened at a contact point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EventKind {
    /// An impulse at a closing contact (Newton's or Poisson's law).
    Impact,
    /// The gap closed without an impulse (an approach slower than the velocity tolerance).
    Close,
    /// The contact opened: its normal force reached zero.
    Open,
    /// Sliding stopped and the contact sticks.
    Stick,
    /// The contact started to slide (from rest: its friction reserve reached zero) or reversed.
    Slip,
    /// A Painlevé situation: with the sliding friction the contact problem has no solution, or
    /// several.
    Painleve,
}

impl EventKind {
    /// The kind's name in records and in Python (`impact`, `close`, `open`, `stick`, `slip`,
    /// `painleve`).
    pub fn as_str(self) -> &'static str {
        match self {
            EventKind::Impact => "impact",
            EventKind::Close => "close",
            EventKind::Open => "open",
            EventKind::Stick => "stick",
            EventKind::Slip => "slip",
            EventKind::Painleve => "painleve",
        }
    }
}

/// What was found at a Painlevé situation (one sliding contact point).
#[derive(Debug, Clone, PartialEq)]
pub struct Painleve {
    /// The sliding coefficient in use.
    pub mu: f64,
    /// The coefficient at which the normal acceleration per unit normal force of the sliding
    /// point, `w_Nᵀ M̃⁻¹ (w_N − µ W_T ŝ)`, reaches zero (infinite if friction only adds to it).
    pub mu_critical: f64,
    /// False: no solution (the point is pressed into its contact); true: two (it could open or
    /// stay closed).
    pub non_unique: bool,
    /// The points closed in the two solutions of a non-unique state (global indices), the one
    /// taken first.
    pub solutions: [Vec<usize>; 2],
    /// The sliding was stopped by an impulse (an impact without collision) and the run went on.
    pub resolved_by_impulse: bool,
}

/// One contact event.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactEvent {
    /// Time (s); for time-stepping, the end of the first step that showed the change.
    pub t: f64,
    /// The contact point (global index over all explicit contacts).
    pub point: usize,
    /// What happened.
    pub kind: EventKind,
    /// Normal and tangential (t1, t2) impulses applied at the point by the event (N s).
    pub impulse: [f64; 3],
    /// Kinetic energy the event's impulses took at the point (J).
    pub energy: f64,
    /// Offset of the generalized velocities before and after the event (`2 nu` values) in
    /// [`EventLog::velocities`], for impacts.
    pub velocities: Option<usize>,
    /// Details of a Painlevé situation.
    pub painleve: Option<Painleve>,
    /// Consecutive steps merged into this event (1 for the event-driven scheme).
    pub steps: usize,
}

/// The events of a run, in time order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EventLog {
    /// The events.
    pub events: Vec<ContactEvent>,
    /// Generalized velocities around impacts: `u⁻` then `u⁺`, `nu` each, per stored pair.
    pub velocities: Vec<f64>,
}

impl EventLog {
    /// Appends an event with no impulse.
    pub fn push(&mut self, t: f64, point: usize, kind: EventKind) -> &mut ContactEvent {
        self.events.push(ContactEvent {
            t,
            point,
            kind,
            impulse: [0.0; 3],
            energy: 0.0,
            velocities: None,
            painleve: None,
            steps: 1,
        });
        self.events.last_mut().expect("just pushed")
    }

    /// Stores the generalized velocities before and after an event; returns their offset.
    pub fn store_velocities(&mut self, before: &[f64], after: &[f64]) -> usize {
        let k = self.velocities.len();
        self.velocities.extend_from_slice(before);
        self.velocities.extend_from_slice(after);
        k
    }

    /// The velocities stored at `offset` for `nu` coordinates: (before, after).
    pub fn velocities_at(&self, offset: usize, nu: usize) -> (&[f64], &[f64]) {
        (&self.velocities[offset..offset + nu], &self.velocities[offset + nu..offset + 2 * nu])
    }
}

/// The Painlevé test of one sliding point from its Delassus block `w` (`d × d`, row-major:
/// normal, then tangents) and unit sliding direction `s` (tangent components): returns the
/// normal acceleration per unit normal force with the friction force `−µ λ_N ŝ`,
/// `c = W_NN − µ W_NT ŝ`, and the critical coefficient `W_NN / (W_NT ŝ)` at which it vanishes
/// (infinite when friction only adds to it). `c ≤ 0` is a Painlevé situation.
pub fn painleve_margin(w: &[f64], d: usize, mu: f64, s: [f64; 2]) -> (f64, f64) {
    let w_nn = w[0];
    let w_nt: f64 = (1..d).map(|k| w[k] * s[k - 1]).sum();
    let c = w_nn - mu * w_nt;
    let mu_critical = if w_nt > 0.0 { w_nn / w_nt } else { f64::INFINITY };
    (c, mu_critical)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn painleve_margin_of_a_sliding_rod_tip() {
        // slender rod (mass 1, length 1) at 30° with its tip on the floor: per unit normal force
        // the tip's normal acceleration is 1 + 3 cos θ (cos θ − µ sin θ) when friction pushes
        // the tip towards the rod's side; zero at µ = (1 + 3 cos²θ) / (3 cos θ sin θ)
        let th = 30f64.to_radians();
        let (c, s) = (th.cos(), th.sin());
        // Delassus block of the tip in (normal, tangent): 1/m + r×-terms with I = m L²/12, r = L/2
        let (m, i, r) = (1.0, 1.0 / 12.0, 0.5);
        let w = [1.0 / m + r * r * c * c / i, r * r * c * s / i, r * r * c * s / i, 1.0 / m + r * r * s * s / i];
        for mu in [0.5, 2.0, 3.0] {
            let (cc, crit) = painleve_margin(&w, 2, mu, [1.0, 0.0]);
            assert!((cc - (1.0 + 3.0 * c * (c - mu * s))).abs() < 1e-12, "{cc}");
            assert!((crit - (1.0 + 3.0 * c * c) / (3.0 * c * s)).abs() < 1e-12);
        }
        // sliding the other way friction only adds to the normal acceleration
        let (cc, crit) = painleve_margin(&w, 2, 3.0, [-1.0, 0.0]);
        assert!((cc - (1.0 + 3.0 * c * (c + 3.0 * s))).abs() < 1e-12 && crit.is_infinite());
    }
}
