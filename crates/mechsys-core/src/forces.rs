//! Force elements (section 2.1.2: active forces applied at the cuts): gravity is handled by the
//! dynamics as a base acceleration; this stage turns every other element into body wrenches
//! (`Data::f_ext`, world components about the inertial origin) and generalized forces (`Data::tau_applied`).

pub mod bearing;
pub mod compliant;
pub mod compliant_group;
pub mod damping;
pub mod jenkins;

use crate::data::Data;
use crate::error::{Error, Result};
use crate::kinematics::{point_position, point_velocity};
use crate::math::Vec3;
use crate::model::{ForceElement, ForceFrame, Model, TimeFunction};
use crate::spatial::Force;

/// Which array of a user velocity constraint `W(q, t)ᵀ u + w(q, t) = 0` (eq. 2.70) a callback
/// returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VelocityArray {
    /// `Wᵀ` (rows × nu, row-major), from `f(t, q)`.
    W,
    /// `w` (rows), from `f(t, q)`.
    Offset,
    /// `d(Wᵀ)/dt u + ẇ` (rows), from `f(t, q, u)`.
    Rate,
}

impl VelocityArray {
    /// The name the user gave the array (`W`, `w`, `Wdot`), for error messages.
    pub fn label(self) -> &'static str {
        match self {
            VelocityArray::W => "W",
            VelocityArray::Offset => "w",
            VelocityArray::Rate => "Wdot",
        }
    }
}

/// User callbacks (Python callables through the bindings). Calling them is slow.
pub trait Callbacks {
    /// Value of time function `id` at `t`.
    fn time_function(&self, id: usize, t: f64) -> Result<f64>;
    /// Generalized forces of callback element `id`, added to `out` (length nu).
    fn generalized_force(&self, id: usize, t: f64, q: &[f64], u: &[f64], out: &mut [f64]) -> Result<()>;
    /// Array `which` of the user velocity constraint callback `id` with `rows` rows at (t, q), and
    /// u for [`VelocityArray::Rate`] (empty otherwise), written to `out` (rows × nu or rows). An
    /// implementation checks the shape and that every value is finite.
    #[allow(clippy::too_many_arguments)]
    fn velocity_constraint(
        &self,
        id: usize,
        which: VelocityArray,
        t: f64,
        q: &[f64],
        u: &[f64],
        rows: usize,
        out: &mut [f64],
    ) -> Result<()> {
        let _ = (t, q, u, rows, out);
        Err(Error::Callback(format!("{} callback {id} was not provided", which.label())))
    }
    /// A user gap function's term `id` at (t, q, u): returns `[g, ġ, w̄]` (value, rate along
    /// `q̇ = u` including `∂g/∂t`, and the velocity-product part of `g̈`) and writes `∂g/∂q`
    /// into `grad` (nq). An implementation checks that every value is finite.
    fn gap_function(&self, id: usize, t: f64, q: &[f64], u: &[f64], grad: &mut [f64]) -> Result<[f64; 3]> {
        let _ = (t, q, u, grad);
        Err(Error::Callback(format!("gap function callback {id} was not provided")))
    }
    /// A compliant contact's user law `F(δ, δ̇)` (callback `id`): the normal force before the
    /// cut-off at overlap `delta` and overlap rate `rate`. An implementation checks it is finite.
    fn contact_force(&self, id: usize, delta: f64, rate: f64) -> Result<f64> {
        let _ = (delta, rate);
        Err(Error::Callback(format!("contact law callback {id} was not provided")))
    }
}

/// No callbacks: any model referring to one fails when built into a simulation.
pub struct NoCallbacks;

impl Callbacks for NoCallbacks {
    fn time_function(&self, id: usize, _t: f64) -> Result<f64> {
        Err(Error::Callback(format!("time function callback {id} was not provided")))
    }
    fn generalized_force(&self, id: usize, _t: f64, _q: &[f64], _u: &[f64], _out: &mut [f64]) -> Result<()> {
        Err(Error::Callback(format!("force callback {id} was not provided")))
    }
}

impl TimeFunction {
    /// Value at time t.
    #[inline]
    pub fn eval(&self, t: f64, cb: &dyn Callbacks) -> Result<f64> {
        Ok(match self {
            TimeFunction::Constant(v) => *v,
            TimeFunction::Ramp { slope, t0, final_value } => {
                let v = if t <= *t0 { 0.0 } else { slope * (t - t0) };
                match final_value {
                    Some(f) if (*slope >= 0.0 && v > *f) || (*slope < 0.0 && v < *f) => *f,
                    _ => v,
                }
            }
            TimeFunction::Harmonic { amplitude, omega, phase, offset } => {
                offset + amplitude * (omega * t + phase).sin()
            }
            TimeFunction::Table { t: ts, values } => interp(ts, values, t),
            TimeFunction::Callback(id) => cb.time_function(*id, t)?,
        })
    }
}

/// Piecewise-linear interpolation, constant outside the table.
#[inline]
pub fn interp(x: &[f64], y: &[f64], xi: f64) -> f64 {
    let n = x.len();
    if xi <= x[0] {
        return y[0];
    }
    if xi >= x[n - 1] {
        return y[n - 1];
    }
    let k = x.partition_point(|v| *v <= xi).clamp(1, n - 1);
    let s = (xi - x[k - 1]) / (x[k] - x[k - 1]);
    y[k - 1] + s * (y[k] - y[k - 1])
}

/// ∫ of the piecewise-linear table from 0 to xi (potential of a tabulated spring), extrapolating
/// with the end values as `interp` does. Exact trapezoids between the table's nodes; no allocation.
pub fn interp_integral(x: &[f64], y: &[f64], xi: f64) -> f64 {
    let (lo, hi) = if xi >= 0.0 { (0.0, xi) } else { (xi, 0.0) };
    let mut s = 0.0;
    let mut a = lo;
    let mut fa = interp(x, y, a);
    for &node in x.iter().filter(|v| **v > lo && **v < hi) {
        let fb = interp(x, y, node);
        s += 0.5 * (node - a) * (fa + fb);
        a = node;
        fa = fb;
    }
    s += 0.5 * (hi - a) * (fa + interp(x, y, hi));
    if xi >= 0.0 {
        s
    } else {
        -s
    }
}

/// Deflection-dependent force of a spring–damper (tension positive) and its potential energy.
#[inline]
fn spring_force(k: f64, k3: f64, table: &(Vec<f64>, Vec<f64>), delta: f64) -> f64 {
    let mut f = k * delta + k3 * delta * delta * delta;
    if !table.0.is_empty() {
        f += interp(&table.0, &table.1, delta);
    }
    f
}

/// Potential energy stored in a spring–damper's elastic part at deflection `delta`.
pub fn spring_energy(k: f64, k3: f64, table: &(Vec<f64>, Vec<f64>), delta: f64) -> f64 {
    let mut e = 0.5 * k * delta * delta + 0.25 * k3 * delta.powi(4);
    if !table.0.is_empty() {
        e += interp_integral(&table.0, &table.1, delta);
    }
    e
}

/// Adds a force `f_i` (I components) acting at the body point `p_b` to body `b`'s wrench.
#[inline]
fn add_point_force(data: &mut Data, b: usize, p_b: &Vec3, f_i: &Vec3) {
    if b == 0 {
        return;
    }
    let p = point_position(data, b, p_b);
    data.f_ext[b] += Force::new(p.cross(f_i), *f_i);
    add_node_force(data, b, p_b, f_i);
}

/// A force `f_i` at an elastic node of body b also loads the elastic coordinates, `(A φ_nk)ᵀ f`;
/// returns its power on the deflection rates (zero elsewhere).
#[inline]
fn add_node_force(data: &mut Data, b: usize, p_b: &Vec3, f_i: &Vec3) -> f64 {
    add_node_load(data, b, p_b, f_i, false)
}

/// A torque `n_i` at an elastic node of body b loads the elastic coordinates through the node's
/// small rotations, `(A ψ_nk)ᵀ n`; returns its power on the rotation rates.
#[inline]
fn add_node_torque(data: &mut Data, b: usize, p_b: &Vec3, n_i: &Vec3) -> f64 {
    add_node_load(data, b, p_b, n_i, true)
}

/// The generalized elastic forces of a force (`rotation` false: through the node's translations φ)
/// or a torque (true: through its small rotations ψ) at the node at `p_b`, and their power.
fn add_node_load(data: &mut Data, b: usize, p_b: &Vec3, load_i: &Vec3, rotation: bool) -> f64 {
    if load_i.norm_squared() == 0.0 {
        return 0.0;
    }
    let Some((k, n)) = crate::kinematics::elastic_node(data, b, p_b) else { return 0.0 };
    let w = &data.elastic[k];
    let mut load_b = data.x_abs[b].a.transpose() * load_i;
    if rotation {
        // the node turns as exp(θ̃) at the rate J_l(θ) θ̇ (as its frames do, kinematics::frame_motion)
        load_b = crate::math::rotation::so3_left_jacobian(&w.node_rotation(n, &w.q)).transpose() * load_b;
    }
    let ne = w.q.len();
    let fields = if rotation { &w.psi } else { &w.phi };
    let mut power = 0.0;
    for kk in 0..ne {
        let g = fields[n * ne + kk].dot(&load_b);
        data.tau_applied[w.iu + kk] += g;
        if data.record_loads {
            data.tau_load[w.iu + kk] += g;
        }
        power += g * w.qd[kk];
    }
    power
}

/// Adds the wrench of force `f` through the world point `p` plus torque `n` (I components) to body b.
#[inline]
fn add_wrench_at(data: &mut Data, b: usize, p: &Vec3, f: &Vec3, n: &Vec3) {
    if b != 0 {
        data.f_ext[b] += Force::new(p.cross(f) + n, *f);
    }
}

/// The overlaps δ = −g_N (m; negative where open) of the explicit compliant contacts' points at
/// the last force evaluation (`Data::element_deflection`), contact by contact and point by point:
/// where their force laws have their kink (δ = 0), for derivatives by differences.
pub fn compliant_overlaps(model: &Model, data: &Data) -> Vec<f64> {
    let mut out = Vec::new();
    let mut next = 0;
    for fe in &model.forces {
        let o = next;
        next += fe.outputs(model.nu);
        if let ForceElement::Contact(c) = fe {
            out.extend(
                (0..c.points()).map(|k| data.element_deflection[o + crate::model::compliant::OUTPUTS_PER_POINT * k]),
            );
        }
    }
    out
}

/// Power balance of the force elements at one instant.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Powers {
    /// Power dissipated by dampers (W, ≥ 0 for positive damping).
    pub dissipated: f64,
    /// Power of the external loads: body forces, joint forces, callbacks, thrust (W).
    pub external: f64,
}

/// Power of a wrench `f` on body b's twist (both world components about the origin).
#[inline]
fn wrench_power(data: &Data, b: usize, f: &Force) -> f64 {
    data.v[b].dot(f)
}

/// The force stage's own working memory, kept next to the [`Data`] (whose force fields every later
/// stage reads): the slider problem of each Jenkins chain. Sized once per model by
/// [`Workspace::new`]; the evaluations then do not allocate.
#[derive(Debug, Clone, Default)]
pub struct Workspace {
    /// Lemke scratch of each Jenkins chain (press fits), in the order of the model's force
    /// elements ([`jenkins::chains`]).
    pub jenkins: Vec<jenkins::ChainWork>,
    /// The compliant contacts' scratch, history and extra states ([`compliant::Work`]).
    pub compliant: compliant::Work,
}

impl Workspace {
    /// Allocates the force stage's workspace for `model`.
    pub fn new(model: &Model) -> Self {
        Workspace { jenkins: jenkins::chains(model), compliant: compliant::Work::new(model) }
    }
}

/// Force stage: fills `f_ext` and `tau_applied`. Requires the kinematics of (q, u); `ws` is the
/// stage's own scratch.
pub fn evaluate(
    model: &Model,
    data: &mut Data,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
    u: &[f64],
    cb: &dyn Callbacks,
) -> Result<Powers> {
    data.f_ext.iter_mut().for_each(|f| *f = Force::ZERO);
    data.tau_applied.iter_mut().for_each(|x| *x = 0.0);
    // (the loads apart only for a scheme that asks: Moreau–Jean's work at its own velocities)
    let loads = data.record_loads;
    if loads {
        data.f_load.iter_mut().for_each(|f| *f = Force::ZERO);
        data.tau_load.iter_mut().for_each(|x| *x = 0.0);
    }
    data.contact_energy = 0.0;
    let mut p_diss = 0.0;
    let mut p_ext = 0.0;

    for j in &model.joints {
        if let Some(s) = &j.spring {
            for k in 0..j.nu() {
                data.tau_applied[j.iu + k] -= s.k[k] * (q[j.iq + k] - s.q_free[k]);
            }
        }
        for (k, d) in j.damper.iter().enumerate() {
            let uk = u[j.iu + k];
            data.tau_applied[j.iu + k] -= d * uk;
            p_diss += d * uk * uk;
        }
    }

    // variable mass: thrust ṁ w_rel at the ejection point (section 2.1.1)
    if model.variable_mass {
        for (i, b) in model.bodies.iter().enumerate().skip(1) {
            let mdot = b.mass_rate_at(t);
            if mdot != 0.0 {
                let x = &data.x_abs[i];
                let f = x.a * (b.ejection_velocity * mdot);
                let w = Force::new(x.point_to_parent(&b.ejection_point).cross(&f), f);
                p_ext += wrench_power(data, i, &w);
                data.f_ext[i] += w;
                if loads {
                    data.f_load[i] += w;
                }
            }
        }
    }

    // next: the first recorded value of the next element; chain: index among the Jenkins chains
    let (mut next, mut chain) = (0usize, 0usize);
    for fe in &model.forces {
        // this element's recorded values (taken first: an arm may `continue`)
        let o = next;
        next += fe.outputs(model.nu);
        match fe {
            ForceElement::SpringDamper { name, body1, point1, body2, point2, k, k3, d, l0, table, travel } => {
                let p1 = point_position(data, *body1, point1);
                let p2 = point_position(data, *body2, point2);
                let dr = p2 - p1;
                let l = dr.norm();
                if l < 1e-12 {
                    if *l0 > 0.0 || !table.0.is_empty() {
                        return Err(Error::Solver(format!(
                            "spring-damper '{name}': its two points coincide at t = {t} s, the force direction is undefined"
                        )));
                    }
                    // a pure damper through coincident points: no direction, no force
                    data.element_force[o] = 0.0;
                    data.element_deflection[o] = -l0;
                    continue;
                }
                let e = dr / l;
                let ldot = e.dot(&(point_velocity(data, *body2, point2) - point_velocity(data, *body1, point1)));
                let delta = l - l0;
                // a progressive (elastomer) law stiffens and damps the linear terms towards the stop
                let g = if *travel > 0.0 {
                    damping::progressive_factor(delta, *travel).ok_or_else(|| {
                        Error::Solver(format!(
                            "spring-damper '{name}': deflection {delta:.6} m reached its stop travel {travel} m at t = {t} s"
                        ))
                    })?
                } else {
                    1.0
                };
                let f = spring_force(k * g, *k3, table, delta) + d * g * ldot;
                p_diss += d * g * ldot * ldot;
                let fv = e * f;
                add_point_force(data, *body1, point1, &fv);
                add_point_force(data, *body2, point2, &(-fv));
                data.element_force[o] = f;
                data.element_deflection[o] = delta;
            }
            ForceElement::Bushing { name, body1, frame1, body2, frame2, k, d, travel } => {
                let (b1, b2) = (*body1, *body2);
                let a1 = data.x_abs[b1].a * frame1.a;
                let a2 = data.x_abs[b2].a * frame2.a;
                let p1 = point_position(data, b1, &frame1.r);
                let p2 = point_position(data, b2, &frame2.r);
                let w1 = data.v[b1].w;
                // deflection [Δr; θ] of frame 2 against frame 1 and its rate, frame-1 components
                let dr = a1.transpose() * (p2 - p1);
                let theta = crate::math::rotation::matrix_to_rotvec(&(a1.transpose() * a2))
                    .map_err(|e| Error::Solver(format!("bushing '{name}' at t = {t} s: {e}")))?;
                // the rotation vector flips sign at π (and J⁻ᵀ is 0/0 there): the law ends before it
                if theta.norm() > damping::MAX_BUSHING_ROTATION {
                    return Err(Error::Solver(format!(
                        "bushing '{name}': relative rotation {:.4} rad at t = {t} s is beyond the bushing law's range (below {:.4} rad)",
                        theta.norm(),
                        damping::MAX_BUSHING_ROTATION
                    )));
                }
                let dr_dot = a1.transpose()
                    * (point_velocity(data, b2, &frame2.r) - point_velocity(data, b1, &frame1.r))
                    - (a1.transpose() * w1).cross(&dr);
                let w_rel = a1.transpose() * (data.v[b2].w - w1);
                let x = nalgebra::Vector6::new(dr.x, dr.y, dr.z, theta.x, theta.y, theta.z);
                let v = nalgebra::Vector6::new(dr_dot.x, dr_dot.y, dr_dot.z, w_rel.x, w_rel.y, w_rel.z);
                let (fk, fd) = match travel {
                    None => (k * x, d * v),
                    Some(s) => {
                        let mut g = nalgebra::Vector6::zeros();
                        for i in 0..6 {
                            g[i] = damping::progressive_factor(x[i], s[i]).ok_or_else(|| {
                                Error::Solver(format!(
                                    "bushing '{name}': component {i} deflected {:.6} to its stop travel {} at t = {t} s",
                                    x[i], s[i]
                                ))
                            })?;
                        }
                        (k * x.component_mul(&g), d * v.component_mul(&g))
                    }
                };
                p_diss += v.dot(&fd);
                // the torque conjugate to θ: n = −J⁻ᵀ ∂V/∂θ keeps the rotational spring conservative
                let jt = damping::rotvec_jacobian_inv_t(&theta);
                let f1 = -(Vec3::new(fk[0], fk[1], fk[2]) + Vec3::new(fd[0], fd[1], fd[2]));
                let n1 = -(jt * Vec3::new(fk[3], fk[4], fk[5]) + Vec3::new(fd[3], fd[4], fd[5]));
                let (f, n) = (a1 * f1, a1 * n1);
                add_wrench_at(data, b2, &p2, &f, &n);
                add_wrench_at(data, b1, &p2, &(-f), &(-n));
                for i in 0..6 {
                    data.element_force[o + i] = fk[i] + fd[i];
                    data.element_deflection[o + i] = x[i];
                }
            }
            ForceElement::SqueezeFilm { name, body1, point1, normal, body2, point2, coeff, gap, gap_max } => {
                let (b1, b2) = (*body1, *body2);
                let n = data.x_abs[b1].a * normal;
                let p1 = point_position(data, b1, point1);
                let p2 = point_position(data, b2, point2);
                let h = gap + n.dot(&(p2 - p1));
                if !(h > 0.0 && h <= *gap_max) {
                    return Err(Error::Solver(format!(
                        "squeeze film '{name}': gap h = {h:.3e} m at t = {t} s is outside the thin-film range 0 < h ≤ {gap_max} m of eq. 2.211"
                    )));
                }
                // ḣ: the slider point against body1's material point under it
                let v1 = data.v[b1].v + data.v[b1].w.cross(&p2);
                let hdot = n.dot(&(point_velocity(data, b2, point2) - v1));
                let f = damping::squeeze_film_force(*coeff, h, hdot);
                p_diss += f * hdot;
                let fv = n * f;
                let zero = Vec3::zeros();
                add_wrench_at(data, b2, &p2, &(-fv), &zero);
                add_wrench_at(data, b1, &p2, &fv, &zero);
                data.element_force[o] = f;
                data.element_deflection[o] = h - gap;
            }
            ForceElement::JournalBearing { joint, c, .. } => {
                let j = &model.joints[*joint];
                let om = u[j.iu];
                data.tau_applied[j.iu] -= c * om;
                p_diss += c * om * om;
                data.element_force[o] = c * om;
                data.element_deflection[o] = q[j.iq];
            }
            ForceElement::HydrodynamicBearing(b) => {
                let (jb, sb) = (b.journal, b.shell);
                let a_s = data.x_abs[sb].a * b.shell_frame.a;
                let z_s = a_s.column(2).into_owned();
                let p_j = point_position(data, jb, &b.journal_frame.r);
                let p_s = point_position(data, sb, &b.shell_frame.r);
                // the offset and its rate seen in the shell frame (the shell's material point at p_j)
                let e = a_s.transpose() * (p_j - p_s);
                let v_s = data.v[sb].v + data.v[sb].w.cross(&p_j);
                let e_dot = a_s.transpose() * (point_velocity(data, jb, &b.journal_frame.r) - v_s);
                let omega_rel = z_s.dot(&(data.v[jb].w - data.v[sb].w));
                let load = b
                    .law
                    .shell_load([e.x, e.y], [e_dot.x, e_dot.y], omega_rel)
                    .map_err(|eps| bearing::touch_error(&b.name, eps, t))?;
                let f = a_s * Vec3::new(load.force[0], load.force[1], 0.0);
                let n = z_s * load.torque;
                add_wrench_at(data, jb, &p_j, &f, &n);
                add_wrench_at(data, sb, &p_j, &(-f), &(-n));
                // what the film takes out (negative while it feeds a whirl)
                p_diss -= load.force[0] * e_dot.x + load.force[1] * e_dot.y + load.torque * omega_rel;
                data.element_force[o] = load.force[0];
                data.element_force[o + 1] = load.force[1];
                data.element_force[o + 2] = load.torque;
                // ε, the position angle φ of the offset, the attitude ψ of the film force's load line
                let spin = if omega_rel >= 0.0 { 1.0 } else { -1.0 };
                data.element_deflection[o] = load.eps;
                data.element_deflection[o + 1] = e.y.atan2(e.x);
                data.element_deflection[o + 2] = (spin * load.f_t).atan2(-load.f_r);
            }
            ForceElement::Jenkins(jk) => {
                let f = jenkins::evaluate(jk, chain, data, &mut ws.jenkins, q, t)?;
                if jk.shaft.is_some() {
                    chain += 1;
                }
                // the sliders' dissipation is booked when a step is committed (jenkins::commit)
                data.tau_applied[jk.iu] -= f;
                data.element_force[o] = f;
                data.element_deflection[o] = q[jk.iq] - jk.offset;
            }
            ForceElement::BodyForce { body, point, force, torque, frame, function, .. } => {
                let s = function.eval(t, cb)?;
                let x = &data.x_abs[*body];
                let (f, n) = match frame {
                    ForceFrame::Inertial => (force * s, torque * s),
                    ForceFrame::Body => (x.a * force * s, x.a * torque * s),
                };
                let w = Force::new(n + point_position(data, *body, point).cross(&f), f);
                p_ext += wrench_power(data, *body, &w);
                data.f_ext[*body] += w;
                if loads {
                    data.f_load[*body] += w;
                }
                p_ext += add_node_force(data, *body, point, &f);
                p_ext += add_node_torque(data, *body, point, &n);
                // recorded: the applied force and the torque (about its point), inertial components
                for k in 0..3 {
                    data.element_force[o + k] = f[k];
                    data.element_force[o + 3 + k] = n[k];
                }
            }
            ForceElement::Servo { name, joint, index, position, kp, kd, reference, max_torque, gear } => {
                let j = &model.joints[*joint];
                let (x, v) = (q[j.iq + index], u[j.iu + index]);
                let (r, rd, _) = crate::constraints::function_derivatives(reference, t, cb)
                    .map_err(|e| Error::Callback(format!("servo '{name}'.reference: {e}")))?;
                // the tracking error (recorded as the element's deflection) and the motor torque
                let (err, tm) = if *position {
                    (r - x, kp * gear * (r - x) + kd * gear * (rd - v))
                } else {
                    (r - v, kd * gear * (r - v))
                };
                let tau = gear * tm.clamp(-max_torque, *max_torque);
                data.tau_applied[j.iu + index] += tau;
                if loads {
                    data.tau_load[j.iu + index] += tau;
                }
                p_ext += tau * v;
                data.element_force[o] = tau;
                data.element_deflection[o] = err;
            }
            ForceElement::JointForce { joint, value, function, .. } => {
                let s = function.eval(t, cb)?;
                let j = &model.joints[*joint];
                for (k, v) in value.iter().enumerate() {
                    data.tau_applied[j.iu + k] += v * s;
                    if loads {
                        data.tau_load[j.iu + k] += v * s;
                    }
                    p_ext += v * s * u[j.iu + k];
                    data.element_force[o + k] = v * s;
                }
            }
            ForceElement::Contact(c) => {
                p_diss += compliant::evaluate(c, data, &mut ws.compliant, o, t, cb)?;
            }
            ForceElement::ContactGroup(g) => {
                p_diss += compliant_group::evaluate(g, data, &mut ws.compliant, o, t, cb)?;
            }
            ForceElement::Callback { name, id } => {
                let before: f64 = data.tau_applied.iter().zip(u).map(|(a, b)| a * b).sum();
                let nu = model.nu;
                data.element_force[o..o + nu].copy_from_slice(&data.tau_applied[..nu]);
                cb.generalized_force(*id, t, q, u, &mut data.tau_applied)
                    .map_err(|e| Error::Callback(format!("force element '{name}': {e}")))?;
                let after: f64 = data.tau_applied.iter().zip(u).map(|(a, b)| a * b).sum();
                p_ext += after - before;
                // recorded: the generalized forces the callback added
                for i in 0..nu {
                    data.element_force[o + i] = data.tau_applied[i] - data.element_force[o + i];
                    if loads {
                        data.tau_load[i] += data.element_force[o + i];
                    }
                }
            }
        }
    }
    Ok(Powers { dissipated: p_diss, external: p_ext })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_interpolation_and_integral() {
        let x = [-1.0, 0.0, 2.0];
        let y = [-3.0, 0.0, 4.0];
        assert!((interp(&x, &y, 1.0) - 2.0).abs() < 1e-15);
        assert!((interp(&x, &y, -0.5) + 1.5).abs() < 1e-15);
        assert_eq!(interp(&x, &y, 5.0), 4.0);
        // ∫0^2 2x dx = 4; beyond the table the force stays 4: ∫2^3 4 = 4
        assert!((interp_integral(&x, &y, 2.0) - 4.0).abs() < 1e-12);
        assert!((interp_integral(&x, &y, 3.0) - 8.0).abs() < 1e-12);
        // ∫0^-1 3x dx = 1.5
        assert!((interp_integral(&x, &y, -1.0) - 1.5).abs() < 1e-12);
    }

    #[test]
    fn time_functions() {
        let cb = NoCallbacks;
        let r = TimeFunction::Ramp { slope: 2.0, t0: 1.0, final_value: Some(3.0) };
        assert_eq!(r.eval(0.5, &cb).unwrap(), 0.0);
        assert!((r.eval(2.0, &cb).unwrap() - 2.0).abs() < 1e-15);
        assert_eq!(r.eval(10.0, &cb).unwrap(), 3.0);
        let h = TimeFunction::Harmonic { amplitude: 2.0, omega: 3.0, phase: 0.5, offset: 1.0 };
        assert!((h.eval(0.7, &cb).unwrap() - (1.0 + 2.0 * (2.1f64 + 0.5).sin())).abs() < 1e-15);
        assert!(TimeFunction::Callback(0).eval(0.0, &cb).is_err());
    }
}
