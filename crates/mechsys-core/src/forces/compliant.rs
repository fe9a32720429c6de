//! Compliant contacts as force elements (the laws and their formulas: [`crate::model::compliant`]).
//!
//! Each evaluation runs the pair's narrow phase and relative kinematics (the same as a rigid
//! contact's, [`crate::contact::contact_kinematics`]), turns the overlap `δ = −g_N` and its rate
//! `δ̇ = −ġ_N` into a normal force `F_N ≥ 0` and the sliding velocity into a tangential force, and
//! applies `F_N n + F_T` to body 1 at its contact point and the opposite to body 2 at its own —
//! the generalized forces `w_N F_N + W_T F_T` of eq. 2.112's Jacobians.
//!
//! History: the dissipative laws tuned by a restitution take the approach speed at the onset of
//! each contact ([`Work::onset_speed`], committed after accepted steps by [`commit`]); the
//! dissipated energy and the LuGre bristle deflections are extra states of the smooth schemes
//! ([`crate::model::compliant::STATES_PER_POINT`] per point), whose values the caller puts into
//! [`Work::states`] before an evaluation and whose rates it reads from [`Work::rates`].
//!
//! Switching functions: per point the gap `g_N` and the force before its cut-off (while closed);
//! an adaptive scheme ends its steps where either changes sign ([`switching`]), so no step
//! straddles the kink of the onset, the release or the cut-off.

use crate::contact::{ContactKinematics, Contour};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::forces::Callbacks;
use crate::math::Vec3;
use crate::model::compliant::{
    johnson_energy, johnson_x, CompliantContact, CompliantLaw, Dissipation, Elastic, HertzEllipse, Tangential,
    OUTPUTS_PER_POINT, STATES_PER_POINT,
};
use crate::model::{ForceElement, Model};
use crate::spatial::Force;

/// The compliant contacts' working memory and history, sized once per model.
#[derive(Debug, Clone, Default)]
pub struct Work {
    kin: Vec<ContactKinematics>,
    /// Extra states (STATES_PER_POINT per point: dissipated energy, bristles z1, z2), set by the
    /// caller before an evaluation (zero if it carries none).
    pub states: Vec<f64>,
    /// Their rates at the last evaluation.
    pub rates: Vec<f64>,
    /// Approach speed at the onset of the current contact, per point (0 while open or unset).
    pub onset_speed: Vec<f64>,
    /// Whether each point was closed at the last commit.
    pub closed: Vec<bool>,
    /// Points that changed (closed or opened) at the last commit, as (point, closed).
    pub changed: Vec<(usize, bool)>,
    /// The compliant groups' broad phases, pair laws and histories, in model order.
    pub groups: Vec<super::compliant_group::GroupWork>,
}

impl Work {
    /// Sized for `model`.
    pub fn new(model: &Model) -> Work {
        let n = model.n_compliant_points;
        let most = model
            .forces
            .iter()
            .filter_map(|f| if let ForceElement::Contact(c) = f { Some(c.points()) } else { None })
            .max()
            .unwrap_or(0);
        Work {
            kin: vec![ContactKinematics::default(); most],
            states: vec![0.0; STATES_PER_POINT * n],
            rates: vec![0.0; STATES_PER_POINT * n],
            onset_speed: vec![0.0; n],
            closed: vec![false; n],
            changed: Vec::with_capacity(n),
            groups: model
                .forces
                .iter()
                .filter_map(|f| match f {
                    ForceElement::ContactGroup(g) => Some(super::compliant_group::GroupWork::new(g)),
                    _ => None,
                })
                .collect(),
        }
    }
}

/// The contact's kinematics into `w.kin[..points]`; errors name the contact.
fn kinematics(c: &CompliantContact, data: &Data, w: &mut Work, t: f64) -> Result<()> {
    let b1 = crate::contact::BodyMotion::from_data(data, c.body1);
    let b2 = crate::contact::BodyMotion::from_data(data, c.body2);
    crate::contact::contact_kinematics(&c.pair, &b1, &b2, &mut w.kin[..c.points()])
        .map_err(|e| crate::contact::at_contact(e, &c.name, t))
}

/// One compliant pair as its laws see it: an explicit contact, or a pair of a compliant group.
pub(crate) struct PairLaw<'a> {
    /// The law.
    pub law: &'a CompliantLaw,
    /// The two contours (body-frame data), for curvatures.
    pub contours: [&'a Contour; 2],
    /// Body of contour 1.
    pub body1: usize,
    /// Body of contour 2.
    pub body2: usize,
    /// The contact's (or group's) name, for errors.
    pub name: &'a str,
}

impl<'a> PairLaw<'a> {
    fn of(c: &'a CompliantContact) -> Self {
        PairLaw {
            law: &c.law,
            contours: [&c.contours[0], &c.contours[1]],
            body1: c.body1,
            body2: c.body2,
            name: &c.name,
        }
    }
}

/// What one closed point applies and records.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct PointForce {
    /// Normal force (≥ 0).
    pub f_n: f64,
    /// Tangential force along t1, t2.
    pub f_t: [f64; 2],
    /// Stored energy (elastic, and the bristles').
    pub energy: f64,
    /// Damping coefficient in use.
    pub alpha: f64,
    /// Power dissipated.
    pub power: f64,
    /// Bristle rates (LuGre).
    pub zd: [f64; 2],
}

/// The elastic force and stored energy at overlap `delta > 0` (kinematics `kin`).
fn elastic(p: &PairLaw, data: &Data, kin: &ContactKinematics, delta: f64, t: f64) -> Result<(f64, f64)> {
    Ok(match &p.law.elastic {
        Elastic::KelvinVoigt { k, .. } => (k * delta, 0.5 * k * delta * delta),
        Elastic::Hertz { k } => (k * delta * delta.sqrt(), 0.4 * k * delta * delta * delta.sqrt()),
        Elastic::HertzCurved { e_star } => {
            let (a, b) = relative_curvatures(p, data, kin).unwrap_or((f64::NAN, f64::NAN));
            if !(a > 0.0 && b.is_finite()) {
                return Err(Error::Solver(format!(
                    "contact '{}' at t = {t:.6} s: the relative curvature at the contact point is {a:.4e} 1/m, no Hertz contact (conforming or flat)",
                    p.name
                )));
            }
            let k = HertzEllipse::new(a, b).stiffness(a, *e_star);
            (k * delta * delta.sqrt(), 0.4 * k * delta * delta * delta.sqrt())
        }
        Elastic::Line { radius, length, e_star } => {
            let x = johnson_x(delta, *radius).ok_or_else(|| {
                Error::Solver(format!(
                    "contact '{}': overlap {delta:.4e} m at t = {t:.6} s is beyond the range of Johnson's line law (below 4R/e² = {:.4e} m)",
                    p.name,
                    4.0 * radius * (-2.0f64).exp()
                ))
            })?;
            (std::f64::consts::PI * length * e_star * x, johnson_energy(x, *radius, *length, *e_star))
        }
        Elastic::User { .. } => (0.0, 0.0),
    })
}

/// Hertz's relative curvatures `A ≤ B` at the contact point: half the eigenvalues of the sum of
/// the two surfaces' curvature tensors in the contact's tangent plane (`t1`, `t2`), so that two
/// doubly curved bodies whose principal directions cross at any angle are covered (Johnson,
/// Contact Mechanics, 4.2). None where a contour has no curvature there.
fn relative_curvatures(p: &PairLaw, data: &Data, kin: &ContactKinematics) -> Option<(f64, f64)> {
    let (t1, t2) = (&kin.point.t1, &kin.point.t2);
    let c1 = p.contours[0].curvature_tensor_at(&data.x_abs[p.body1], &kin.point.p1, t1, t2)?;
    let c2 = p.contours[1].curvature_tensor_at(&data.x_abs[p.body2], &kin.point.p2, t1, t2)?;
    let (s11, s12, s22) = (c1[0] + c2[0], c1[1] + c2[1], c1[2] + c2[2]);
    let (m, d) = (0.5 * (s11 + s22), (0.25 * (s11 - s22).powi(2) + s12 * s12).sqrt());
    Some((0.5 * (m - d), 0.5 * (m + d)))
}

/// The damping coefficient α at approach rate `rate`, with the approach speed `onset` of the
/// current contact once committed (0 before).
fn alpha(law: &CompliantLaw, onset: f64, rate: f64) -> f64 {
    match law.dissipation {
        Dissipation::None => 0.0,
        Dissipation::Alpha(a) => a,
        Dissipation::Restitution { map, eps } => {
            let v = if onset > 0.0 { onset } else { rate };
            if v > 0.0 {
                map.alpha(eps, v)
            } else {
                0.0
            }
        }
    }
}

/// The normal force before the cut-off, the elastic force, the stored energy and α.
fn normal(
    p: &PairLaw,
    data: &Data,
    kin: &ContactKinematics,
    onset: f64,
    t: f64,
    cb: &dyn Callbacks,
) -> Result<(f64, f64, f64, f64)> {
    let (delta, rate) = (-kin.point.g_n, -kin.gd_n);
    if let Elastic::User { callback } = p.law.elastic {
        let f = cb
            .contact_force(callback, delta, rate)
            .map_err(|e| Error::Callback(format!("contact '{}'.normal: {e}", p.name)))?;
        return Ok((f, 0.0, 0.0, 0.0));
    }
    let (f_el, v) = elastic(p, data, kin, delta, t)?;
    Ok(match p.law.elastic {
        Elastic::KelvinVoigt { d, .. } => (f_el + d * rate, f_el, v, 0.0),
        _ => {
            let a = alpha(p.law, onset, rate);
            (f_el * (1.0 + a * rate), f_el, v, a)
        }
    })
}

/// The forces of a closed point (overlap > 0) with kinematics `kin`, bristle deflections `z`;
/// `planar` pairs slide along t1 only.
pub(crate) fn point_force(
    p: &PairLaw,
    data: &Data,
    kin: &ContactKinematics,
    onset: f64,
    z: [f64; 2],
    planar: bool,
    t: f64,
    cb: &dyn Callbacks,
) -> Result<PointForce> {
    let rate = -kin.gd_n;
    let v = [kin.gd_t[0], if planar { 0.0 } else { kin.gd_t[1] }];
    let (raw, f_el, stored, a) = normal(p, data, kin, onset, t, cb)?;
    let mut out = PointForce { f_n: raw.max(0.0), energy: stored, alpha: a, ..PointForce::default() };
    let f_n = out.f_n;
    // what the overlap's rate feeds in beyond the stored energy's rate
    out.power = (f_n - f_el) * rate;
    let speed = (v[0] * v[0] + v[1] * v[1]).sqrt();
    match &p.law.tangential {
        Tangential::None => {}
        Tangential::Regularized { law, v_reg } => {
            if speed > 0.0 {
                let m = law.mu(speed) * f_n * (speed / v_reg).tanh() / speed;
                out.f_t = [-m * v[0], -m * v[1]];
            }
        }
        Tangential::LuGre { mu0, mu, v_s, sigma0, sigma1, sigma2 } => {
            let g = mu + (mu0 - mu) * (-(speed / v_s).powi(2)).exp();
            for i in 0..2 {
                let zd = v[i] - sigma0 * speed * z[i] / g;
                out.zd[i] = zd;
                out.f_t[i] = -f_n * (sigma0 * z[i] + sigma1 * zd + sigma2 * v[i]);
                // the bristles store ½ F_N σ0 z² (at the current F_N)
                out.energy += 0.5 * f_n * sigma0 * z[i] * z[i];
                out.power -= f_n * sigma0 * z[i] * zd;
            }
        }
    }
    out.power -= out.f_t[0] * v[0] + out.f_t[1] * v[1];
    Ok(out)
}

/// Applies the point's force `F_N n + F_T` to body 1 at its contact point and the opposite to
/// body 2 at its own.
#[inline]
pub(crate) fn apply_point(data: &mut Data, body1: usize, body2: usize, kin: &ContactKinematics, pf: &PointForce) {
    let f = kin.point.n * pf.f_n + kin.point.t1 * pf.f_t[0] + kin.point.t2 * pf.f_t[1];
    apply(data, body1, &kin.point.p1, &f);
    apply(data, body2, &kin.point.p2, &(-f));
}

/// Evaluates contact `c` (its recorded values from `o` on): applies its forces to `data.f_ext`,
/// writes the rates of its extra states and returns the power it dissipates.
pub fn evaluate(
    c: &CompliantContact,
    data: &mut Data,
    w: &mut Work,
    o: usize,
    t: f64,
    cb: &dyn Callbacks,
) -> Result<f64> {
    kinematics(c, data, w, t)?;
    let planar = c.pair.tangent_dim() == 1;
    let pl = PairLaw::of(c);
    let mut p_diss = 0.0;
    for k in 0..c.points() {
        let kin = w.kin[k];
        let slot = c.slot + k;
        let s = STATES_PER_POINT * slot;
        let (delta, rate) = (-kin.point.g_n, -kin.gd_n);
        let v = [kin.gd_t[0], if planar { 0.0 } else { kin.gd_t[1] }];
        let mut pf = PointForce::default();
        if delta > 0.0 {
            let z = [w.states[s + 1], w.states[s + 2]];
            pf = point_force(&pl, data, &kin, w.onset_speed[slot], z, planar, t, cb)?;
            apply_point(data, c.body1, c.body2, &kin, &pf);
        }
        w.rates[s] = pf.power;
        w.rates[s + 1] = pf.zd[0];
        w.rates[s + 2] = pf.zd[1];
        p_diss += pf.power;
        data.contact_energy += pf.energy;
        let (fo, d) = (&mut data.element_force, &mut data.element_deflection);
        let b = o + OUTPUTS_PER_POINT * k;
        // where it acts, for the viewer: the point on contour 1, the normal, the friction force
        let (pt, n) = (&kin.point.p1, &kin.point.n);
        let ft = kin.point.t1 * pf.f_t[0] + kin.point.t2 * pf.f_t[1];
        fo[b..b + OUTPUTS_PER_POINT].copy_from_slice(&[
            pf.f_n,
            pf.f_t[0],
            pf.f_t[1],
            pf.energy,
            w.states[s],
            pt.x,
            pt.y,
            pt.z,
            ft.x,
            ft.y,
            ft.z,
        ]);
        d[b..b + OUTPUTS_PER_POINT].copy_from_slice(&[delta, rate, v[0], v[1], pf.alpha, n.x, n.y, n.z, 0.0, 0.0, 0.0]);
    }
    Ok(p_diss)
}

#[inline]
pub(crate) fn apply(data: &mut Data, b: usize, p: &Vec3, f: &Vec3) {
    if b != 0 {
        data.f_ext[b] += Force::new(p.cross(f), *f);
    }
}

/// Number of switching functions of `model`'s compliant contacts (2 per point).
pub fn switches(model: &Model) -> usize {
    2 * model.n_compliant_points
}

/// The switching functions at the state whose kinematics `data` holds (positions and
/// velocities): per point the gap g_N and, while closed, the normal force before its cut-off
/// (1 while open, so that only a closed contact's force crossing zero counts).
pub fn switching(model: &Model, data: &Data, w: &mut Work, t: f64, cb: &dyn Callbacks, out: &mut [f64]) -> Result<()> {
    for f in &model.forces {
        let c = match f {
            ForceElement::Contact(c) => c,
            ForceElement::ContactGroup(g) => {
                // a group's onsets are stepped over under error control (module doc of
                // compliant_group): constant switching functions
                out[2 * g.slot] = 1.0;
                out[2 * g.slot + 1] = 1.0;
                continue;
            }
            _ => continue,
        };
        kinematics(c, data, w, t)?;
        for k in 0..c.points() {
            let kin = w.kin[k];
            let slot = c.slot + k;
            out[2 * slot] = kin.point.g_n;
            out[2 * slot + 1] = if kin.point.g_n < 0.0 && !matches!(c.law.elastic, Elastic::User { .. }) {
                normal(&PairLaw::of(c), data, &kin, w.onset_speed[slot], t, cb)?.0
            } else {
                1.0
            };
        }
    }
    Ok(())
}

/// After an accepted step (the last evaluation at its end): the onset speeds of the contacts
/// that closed, the reset of those that opened (their bristles relax), and the points that
/// changed in [`Work::changed`]. `states` are the extra states (reset in place).
pub fn commit(model: &Model, data: &Data, w: &mut Work, t: f64, states: &mut [f64]) -> Result<()> {
    w.changed.clear();
    for f in &model.forces {
        let c = match f {
            ForceElement::Contact(c) => c,
            ForceElement::ContactGroup(g) => {
                super::compliant_group::commit(g, data, &mut w.groups[g.index], t)?;
                continue;
            }
            _ => continue,
        };
        kinematics(c, data, w, t)?;
        for k in 0..c.points() {
            let slot = c.slot + k;
            // touching and approaching counts as closed (a step that ends exactly at the onset)
            let (g, gd) = (w.kin[k].point.g_n, w.kin[k].gd_n);
            let closed = g < 0.0 || (g == 0.0 && gd < 0.0);
            if closed && w.onset_speed[slot] == 0.0 {
                w.onset_speed[slot] = (-w.kin[k].gd_n).max(f64::MIN_POSITIVE);
            }
            if !closed {
                w.onset_speed[slot] = 0.0;
                let s = STATES_PER_POINT * slot;
                states[s + 1] = 0.0;
                states[s + 2] = 0.0;
            }
            if closed != w.closed[slot] {
                w.closed[slot] = closed;
                w.changed.push((slot, closed));
            }
        }
    }
    Ok(())
}

/// The contact and point of compliant point `slot` (for event records).
pub fn point_of(model: &Model, slot: usize) -> Option<(&str, usize)> {
    model.forces.iter().find_map(|f| match f {
        ForceElement::Contact(c) if slot >= c.slot && slot < c.slot + c.points() => {
            Some((c.name.as_str(), slot - c.slot))
        }
        _ => None,
    })
}
