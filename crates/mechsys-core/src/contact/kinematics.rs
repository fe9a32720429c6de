//! Relative contact kinematics (section 2.2.7): relative velocities `ġ_N`, `ġ_T` of the two
//! bodies at each candidate and the velocity-product parts `w̄_N`, `w̄_T` of their derivatives.
//!
//! With `v_i(x) = v_i + ω_i × x` the velocity of body i's material point at `x` and
//! `a_i(x) = a_i + α_i × x + ω_i × v_i(x)` its acceleration (world convention, see
//! [`crate::kinematics`]):
//!
//! - `ġ_N = n·(v_1(P1) - v_2(P2))` (eqs. 2.110, 2.122): the rate of the gap between the material
//!   points at `P1` and `P2` — exactly `d g_N/dt`, because `P1 - P2 = g_N n` and the contact
//!   points slide tangentially over their contours (one exception below);
//! - `ġ_T,k = t_k·(v_1(P1) - v_2(P2))` — body 1's sliding velocity relative to body 2;
//! - `g̈_N = n·(a_1(P1) - a_2(P2)) + ṅ·Δv + n·(ω_1 × σ_1 - ω_2 × σ_2)`, where `Δv` is the relative
//!   velocity above and `σ_i = Ṗ_i - v_i(P_i)` the velocity of the contact point over contour i
//!   (the `κ ṡ` terms of eqs. 2.100–2.101, 2.115, from the closed-form rates of each pair: the
//!   rotation of the normal and the motion of the contact points over the surfaces);
//! - `d ġ_T,k/dt` likewise with `t_k` and `ṫ_k`.
//!
//! **W-part.** The only term that depends on the body accelerations is
//! `n·(a_1(P1) - a_2(P2))`, the relative acceleration of the material points at the contact. In
//! a multibody system `a_i(P_i) = J_Pi u̇ + (velocity-product part)` with `J_Pi` the translational
//! Jacobian of the body point at `P_i` ([`crate::kinematics::point_jacobian`]), so
//! `g̈_N = w_Nᵀ u̇ + w̄_N` with `w_N = J_P1ᵀ n - J_P2ᵀ n`, `W_T = [J_P1ᵀ t_k - J_P2ᵀ t_k]`
//! (eqs. 2.112–2.114, 2.131, 2.132). [`contact_kinematics`] is affine in the body accelerations
//! it is given: given the velocity-product accelerations (the tree's accelerations at `u̇ = 0`,
//! see [`BodyMotion::from_data`]) it returns `w̄_N`, `w̄_T`; given the full accelerations it
//! returns `g̈_N` and `d ġ_T/dt` themselves.
//!
//! Exactness: the rates are the time derivatives of the narrow phase's closed forms wherever
//! those are smooth (a fixed face/edge/corner region of a box or of a mesh's nearest triangle,
//! fixed clamping of capsule segment parameters). Where a mesh's nearest face changes over a
//! concave edge the normal jumps, and so does `ġ_N`. Not exact: at the degenerate configurations listed in [`super::narrow`] (the
//! normal is then taken as turning with body 2) and for exactly parallel capsule axes, where the
//! overlap-midpoint rule fixes the parameter on segment 1. Box–box: every candidate has
//! `ġ_N = d g_N/dt` but a crossing of the clipped manifold (an incident edge crossing a side plane
//! of the reference face), whose `ġ_N` is the rate of the incident box's material point there;
//! the crossing's own gap changes by `(m·e) ṡ` more when that edge is tilted against the reference
//! face and the crossing slides along it (see [`super::narrow::box_box`]).

use crate::data::Data;
use crate::error::{Error, Result};
use crate::forces::Callbacks;
use crate::math::Vec3;
use crate::model::contact::Contact;

use super::narrow::warm::SearchHint;
use super::narrow::{ContactPair, ContactPoint, Raw, Tangents};

pub use crate::kinematics::BodyMotion;

/// Relative kinematics of one candidate.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactKinematics {
    /// Geometry (gap, normal, points, tangents).
    pub point: ContactPoint,
    /// `ġ_N`, relative normal velocity (< 0 approaching).
    pub gd_n: f64,
    /// `ġ_T` along `t1`, `t2` (planar pairs: only the first is a friction direction).
    pub gd_t: [f64; 2],
    /// `w̄_N` (`g̈_N` if the full accelerations were given).
    pub wbar_n: f64,
    /// `w̄_T` (`d ġ_T/dt` if the full accelerations were given).
    pub wbar_t: [f64; 2],
    /// Relative angular velocity `ω1 - ω2` in the contact frame: `[n·Δω` (spin, drilling),
    /// `t1·Δω, t2·Δω]` (rolling); rad/s.
    pub omega_rel: [f64; 3],
    /// The rheonomic parts `w̃ = [w̃_N, w̃_T1, w̃_T2]` of eq. 2.112, `ġ = Wᵀ u + w̃`: a moving
    /// surface's speed (a conveyor belt) in the tangential entries, a time-dependent user gap
    /// function's `∂g/∂t`; zero for contours at rest on their bodies.
    pub w_tilde: [f64; 3],
}

/// Fills `out[..pair.candidates()]` for body 1 in state `b1` and body 2 in `b2`. No allocation;
/// an error only when `out` is too short.
///
/// # Example
/// ```
/// use mechsys_core::contact::{contact_kinematics, BodyMotion, ContactKinematics, ContactPair, Contour};
/// use mechsys_core::math::Vec3;
/// use mechsys_core::spatial::{Motion, Pose};
/// let pair = ContactPair::new(
///     "ball",
///     Contour::Sphere { center: Vec3::zeros(), radius: 0.1 },
///     Contour::Plane { point: Vec3::zeros(), normal: Vec3::z() },
/// )?;
/// // falling at 2 m/s while sliding along x at 1 m/s
/// let ball = BodyMotion {
///     pose: Pose::new(nalgebra::Matrix3::identity(), Vec3::new(0.0, 0.0, 0.1)),
///     twist: Motion::new(Vec3::zeros(), Vec3::new(1.0, 0.0, -2.0)),
///     acc: Motion::ZERO,
/// };
/// let mut out = [ContactKinematics::default(); 1];
/// contact_kinematics(&pair, &ball, &BodyMotion::GROUND, &mut out)?;
/// assert!((out[0].gd_n + 2.0).abs() < 1e-15);
/// assert!((out[0].gd_t[0].abs() - 1.0).abs() < 1e-15 || (out[0].gd_t[1].abs() - 1.0).abs() < 1e-15);
/// # Ok::<(), mechsys_core::Error>(())
/// ```
pub fn contact_kinematics(
    pair: &ContactPair,
    b1: &BodyMotion,
    b2: &BodyMotion,
    out: &mut [ContactKinematics],
) -> Result<()> {
    contact_kinematics_warm(pair, b1, b2, out, None)
}

/// [`contact_kinematics`] with the contact search warm-started from `search` (one
/// [`SearchHint`] per candidate, kept by the caller from one evaluation of this pair to the next;
/// the empty default searches cold): planar parametric contours refine the last roots while the
/// relative motion since the last full search provably keeps them (see
/// [`super::narrow::warm`]), the same roots as the cold search to Newton's tolerance. `None`:
/// always cold. No allocation.
pub fn contact_kinematics_warm(
    pair: &ContactPair,
    b1: &BodyMotion,
    b2: &BodyMotion,
    out: &mut [ContactKinematics],
    search: Option<&mut [SearchHint]>,
) -> Result<()> {
    pair.check_len(out.len())?;
    if let Some(s) = &search {
        pair.check_len(s.len())?;
    }
    let (tw1, tw2) = (&b1.twist, &b2.twist);
    // a moving surface: its material slides over its contour at the body-fixed velocity u_i,
    // so it moves at v_i(P) + A_i u_i; tangential, so ġ_N and the W-part are unchanged
    let surface = pair.surface_velocity();
    let (ws1, ws2) = surface_motion(surface, b1, b2);
    let dws = ws1 - ws2;
    // the candidates of a face manifold or a box on a plane share their normal (and its rate):
    // their tangents are computed once
    let mut shared: Option<(Vec3, Vec3, Tangents)> = None;
    let mut last: Option<(usize, Raw)> = None;
    // one evaluation of the pair: shared work (a box–box manifold) is done once for all candidates
    let each = |k: usize, r: &Raw| {
        // the unused candidates of a manifold are one and the same
        if let Some((j, p)) = &last {
            if same_bits(p, r, true) {
                out[k] = out[*j];
                return;
            }
        }
        last = Some((k, *r));
        let t = match shared {
            Some((n, nd, t)) if n == r.n && nd == r.nd => t,
            _ => {
                let t = pair.tangents(&b2.pose, &r.n, Some((&tw2.w, &r.nd)));
                shared = Some((r.n, r.nd, t));
                t
            }
        };
        let (v1, v2) = (b1.point_velocity(&r.p1), b2.point_velocity(&r.p2));
        let dv = v1 - v2;
        // σ_i: motion of the contact point over contour i
        let (s1, s2) = (r.p1d - v1, r.p2d - v2);
        // d/dt v_i(P_i(t)) = a_i(P_i) + ω_i × σ_i
        let da = b1.point_acceleration(&r.p1) - b2.point_acceleration(&r.p2) + tw1.w.cross(&s1) - tw2.w.cross(&s2);
        let surf = [t.t1.dot(&dws), t.t2.dot(&dws)];
        let dw = tw1.w - tw2.w;
        // d/dt (A_i u_i) = ω_i × A_i u_i for a constant body-fixed surface velocity
        let dws_dt = tw1.w.cross(&ws1) - tw2.w.cross(&ws2);
        out[k] = ContactKinematics {
            point: ContactPoint { g_n: r.g, n: r.n, p1: r.p1, p2: r.p2, t1: t.t1, t2: t.t2 },
            gd_n: r.n.dot(&dv),
            gd_t: [t.t1.dot(&dv) + surf[0], t.t2.dot(&dv) + surf[1]],
            // eqs. 2.114, 2.115 / 2.128
            wbar_n: r.nd.dot(&dv) + r.n.dot(&da),
            wbar_t: [
                t.t1d.dot(&(dv + dws)) + t.t1.dot(&(da + dws_dt)),
                t.t2d.dot(&(dv + dws)) + t.t2.dot(&(da + dws_dt)),
            ],
            w_tilde: [0.0, surf[0], surf[1]],
            omega_rel: [r.n.dot(&dw), t.t1.dot(&dw), t.t2.dot(&dw)],
        };
    };
    match search {
        Some(s) => pair.each_candidate_warm(&b1.pose, &b2.pose, Some((tw1, tw2)), s, each),
        None => pair.each_candidate(&b1.pose, &b2.pose, Some((tw1, tw2)), each),
    }
    Ok(())
}

/// The velocity level of [`contact_kinematics_warm`]: the same `point`, `gd_n`, `gd_t`,
/// `omega_rel` and `w_tilde` (bit for bit), with `wbar_n`, `wbar_t` left zero. The geometry is
/// evaluated without its rates (`ṅ`, `Ṗ1`, `Ṗ2`, tangent rates) and no acceleration is read —
/// all a time-stepping scheme needs at its midpoint, at well under the cost. No allocation.
pub fn contact_velocities_warm(
    pair: &ContactPair,
    b1: &BodyMotion,
    b2: &BodyMotion,
    out: &mut [ContactKinematics],
    search: Option<&mut [SearchHint]>,
) -> Result<()> {
    pair.check_len(out.len())?;
    if let Some(s) = &search {
        pair.check_len(s.len())?;
    }
    let (tw1, tw2) = (&b1.twist, &b2.twist);
    // the same expressions as the full kinematics, in the same order (bit-identical results)
    let (ws1, ws2) = surface_motion(pair.surface_velocity(), b1, b2);
    let dws = ws1 - ws2;
    let dw = tw1.w - tw2.w;
    let mut shared: Option<(Vec3, Tangents)> = None;
    let mut last: Option<(usize, Raw)> = None;
    let each = |k: usize, r: &Raw| {
        if let Some((j, p)) = &last {
            if same_bits(p, r, false) {
                out[k] = out[*j];
                return;
            }
        }
        last = Some((k, *r));
        let t = match shared {
            Some((n, t)) if n == r.n => t,
            _ => {
                let t = pair.tangents(&b2.pose, &r.n, None);
                shared = Some((r.n, t));
                t
            }
        };
        let dv = b1.point_velocity(&r.p1) - b2.point_velocity(&r.p2);
        let surf = [t.t1.dot(&dws), t.t2.dot(&dws)];
        out[k] = ContactKinematics {
            point: ContactPoint { g_n: r.g, n: r.n, p1: r.p1, p2: r.p2, t1: t.t1, t2: t.t2 },
            gd_n: r.n.dot(&dv),
            gd_t: [t.t1.dot(&dv) + surf[0], t.t2.dot(&dv) + surf[1]],
            wbar_n: 0.0,
            wbar_t: [0.0; 2],
            w_tilde: [0.0, surf[0], surf[1]],
            omega_rel: [r.n.dot(&dw), t.t1.dot(&dw), t.t2.dot(&dw)],
        };
    };
    match search {
        Some(s) => pair.each_candidate_warm(&b1.pose, &b2.pose, None, s, each),
        None => pair.each_candidate(&b1.pose, &b2.pose, None, each),
    }
    Ok(())
}

/// Whether two candidates are the same bit for bit: geometry, and with `rates` their rates (a
/// repeated candidate then has the same kinematics, copied instead of recomputed).
#[inline]
fn same_bits(a: &Raw, b: &Raw, rates: bool) -> bool {
    let eq = |x: &Vec3, y: &Vec3| x.iter().zip(y.iter()).all(|(u, v)| u.to_bits() == v.to_bits());
    a.g.to_bits() == b.g.to_bits()
        && eq(&a.n, &b.n)
        && eq(&a.p1, &b.p1)
        && eq(&a.p2, &b.p2)
        && (!rates || (eq(&a.nd, &b.nd) && eq(&a.p1d, &b.p1d) && eq(&a.p2d, &b.p2d)))
}

/// World velocities `A_i u_i` of the contours' moving surfaces (zero, without products, for
/// contours at rest on their bodies: almost every pair).
#[inline]
fn surface_motion(surface: &[Vec3; 2], b1: &BodyMotion, b2: &BodyMotion) -> (Vec3, Vec3) {
    let world = |b: &BodyMotion, u: &Vec3| if *u == Vec3::zeros() { Vec3::zeros() } else { b.pose.a * u };
    (world(b1, &surface[0]), world(b2, &surface[1]))
}

/// The kinematics of every point of `con` into `out[..con.points()]`: from the bodies' motion in
/// `data` (the tree's kinematics at (q, u) done, `data.a` as the caller set it) for a pair of
/// contours; from the gap function at (t, q, u) for a gap contact, whose `w̄` is always the
/// velocity-product part and whose rows land in `data.gap`. Errors name the contact.
/// `search`: the contact's points' search state for a warm start (see
/// [`contact_kinematics_warm`]), `None` for a cold search.
#[allow(clippy::too_many_arguments)]
pub fn contact_point_kinematics(
    con: &Contact,
    data: &mut Data,
    t: f64,
    q: &[f64],
    u: &[f64],
    cb: &dyn Callbacks,
    out: &mut [ContactKinematics],
    search: Option<&mut [SearchHint]>,
) -> Result<()> {
    point_kinematics(con, data, t, q, u, cb, out, search, true)
}

/// [`contact_point_kinematics`] at velocity level: for a pair of contours
/// [`contact_velocities_warm`] (no `w̄`, no accelerations read; the other fields bit for bit the
/// same), for a gap contact the same as the full version. What Moreau–Jean needs at a step's
/// midpoint.
#[allow(clippy::too_many_arguments)]
pub fn contact_point_velocities(
    con: &Contact,
    data: &mut Data,
    t: f64,
    q: &[f64],
    u: &[f64],
    cb: &dyn Callbacks,
    out: &mut [ContactKinematics],
    search: Option<&mut [SearchHint]>,
) -> Result<()> {
    point_kinematics(con, data, t, q, u, cb, out, search, false)
}

/// Both levels of [`contact_point_kinematics`]: `full` with the `w̄` terms.
#[allow(clippy::too_many_arguments)]
fn point_kinematics(
    con: &Contact,
    data: &mut Data,
    t: f64,
    q: &[f64],
    u: &[f64],
    cb: &dyn Callbacks,
    out: &mut [ContactKinematics],
    search: Option<&mut [SearchHint]>,
    full: bool,
) -> Result<()> {
    match con.gap() {
        None => {
            let (mut b1, mut b2) = (BodyMotion::from_data(data, con.body1), BodyMotion::from_data(data, con.body2));
            if !data.elastic.is_empty() {
                if let Some([c1, c2]) = con.contours() {
                    node_motion(data, con.body1, c1, &mut b1);
                    node_motion(data, con.body2, c2, &mut b2);
                }
            }
            let pair = con.pair().expect("a contour contact");
            if full {
                contact_kinematics_warm(pair, &b1, &b2, out, search)
            } else {
                contact_velocities_warm(pair, &b1, &b2, out, search)
            }
        }
        Some((f, slot)) => f.evaluate(t, q, u, cb, &mut data.gap, slot, true, &mut out[0]).map_err(|e| match e {
            Error::Callback(m) => Error::Callback(format!("gap contact '{}': {m}", con.name)),
            other => other,
        }),
    }
}

/// A point contour at a node of an elastic body moves with the node (eq. 2.133): its body's
/// motion is replaced by that of a frame carried along with the node's deflection d, placed at
/// `r + A d`, moving with `v + A ḋ` and accelerating with `a + A d̈ + ω × A ḋ` (so the point's
/// classical acceleration gets the relative and Coriolis terms `A d̈ + 2 ω × A ḋ`).
fn node_motion(data: &Data, body: usize, contour: &crate::contact::Contour, m: &mut BodyMotion) {
    let p_b = match contour {
        crate::contact::Contour::Point { p } => *p,
        crate::contact::Contour::Point2 { p } => Vec3::new(p.x, p.y, 0.0),
        _ => return,
    };
    let Some((k, n)) = crate::kinematics::elastic_node(data, body, &p_b) else { return };
    let w = &data.elastic[k];
    let a = m.pose.a;
    let (d, dd, ddd) = (a * w.node_field(n, &w.q), a * w.node_field(n, &w.qd), a * w.node_field(n, &w.qdd));
    m.pose.r += d;
    m.acc.v += ddd + m.twist.w.cross(&dd);
    m.twist.v += dd;
}

/// An error of contact `name`'s kinematics at time `t` as the integrators report it: a solver
/// error naming the contact and time, a callback's error (a Python gap function's, possibly an
/// interrupt) passed on as it is.
pub fn at_contact(e: Error, name: &str, t: f64) -> Error {
    match e {
        Error::Callback(_) => e,
        other => Error::Solver(format!("contact '{name}' at t = {t:.6} s: {other}")),
    }
}

/// `k` of a gap contact with its full accelerations: `w̄ + W u̇` from its rows in `data.gap`
/// (the contour contacts get theirs from the full body accelerations instead).
pub fn gap_with_accelerations(con: &Contact, data: &Data, udot: &[f64], k: &mut ContactKinematics) {
    if let Some((_, slot)) = con.gap() {
        let nu = udot.len();
        let rows = &data.gap.rows[3 * slot * nu..3 * (slot + 1) * nu];
        let dot = |r: usize| rows[r * nu..(r + 1) * nu].iter().zip(udot).map(|(a, b)| a * b).sum::<f64>();
        k.wbar_n += dot(0);
        k.wbar_t[0] += dot(1);
        k.wbar_t[1] += dot(2);
    }
}

#[cfg(test)]
mod tests;
