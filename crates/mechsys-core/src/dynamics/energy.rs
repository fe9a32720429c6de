//! Energies and momenta of the whole system (sections 2.3.2, 2.3.3, 2.4.2, 2.4.3):
//! kinetic energy `T = Σ ½ v_iᵀ I_i v_i` (eq. 2.183), potential energy of gravity and springs,
//! linear momentum `p = Σ m_i v_ci` and moment of momentum about the inertial origin.

use crate::data::Data;
use crate::forces::damping::progressive_energy;
use crate::forces::jenkins;
use crate::forces::spring_energy;
use crate::kinematics::point_position;
use crate::math::Vec3;
use crate::model::{ForceElement, Model};

/// Spatial momentum (world, about the origin) and kinetic energy of body i (requires kinematics
/// and inertias); an elastic body adds its elastic velocities' share, `C q̇_e` and
/// `Vᵀ C q̇_e + ½ q̇_eᵀ M_ee q̇_e` (eq. 2.192 after the Ritz separation).
#[inline]
pub fn body_momentum(model: &Model, data: &Data, i: usize) -> (crate::spatial::Force, f64) {
    let v = &data.v[i];
    let mut h = data.inertia[i].mul_motion(v);
    let mut t = 0.5 * v.dot(&h);
    if let Some(k) = model.bodies[i].elastic {
        let (e, w) = (&model.elastic[k], &data.elastic[k]);
        for j in 0..e.ne {
            h += w.c[j] * w.qd[j];
        }
        t += crate::elastic::kinetic_energy_extra(e, w, v);
    }
    (h, t)
}

/// Kinetic energy of body i (requires kinematics and inertias).
#[inline]
pub fn body_kinetic_energy(model: &Model, data: &Data, i: usize) -> f64 {
    body_momentum(model, data, i).1
}

/// Total kinetic energy.
pub fn kinetic_energy(model: &Model, data: &Data) -> f64 {
    (1..model.nbodies()).map(|i| body_kinetic_energy(model, data, i)).sum()
}

/// Gravitational potential energy of body i, zero at the inertial origin: `-m g · r_c`.
#[inline]
pub fn body_gravity_energy(model: &Model, data: &Data, i: usize) -> f64 {
    // h = m r_c in world components
    -model.gravity.dot(&data.inertia[i].h)
}

/// Potential energy of gravity, point-to-point springs and joint springs.
pub fn potential_energy(model: &Model, data: &Data, q: &[f64]) -> f64 {
    let mut v: f64 = (1..model.nbodies()).map(|i| body_gravity_energy(model, data, i)).sum();
    for f in &model.forces {
        match f {
            ForceElement::SpringDamper { body1, point1, body2, point2, k, k3, l0, table, travel, .. } => {
                let l = (point_position(data, *body2, point2) - point_position(data, *body1, point1)).norm();
                v += if *travel > 0.0 {
                    spring_energy(0.0, *k3, table, l - l0) + progressive_energy(*k, l - l0, *travel)
                } else {
                    spring_energy(*k, *k3, table, l - l0)
                };
            }
            ForceElement::Bushing { body1, frame1, body2, frame2, k, travel, .. } => {
                let a1 = data.x_abs[*body1].a * frame1.a;
                let a2 = data.x_abs[*body2].a * frame2.a;
                let dr = a1.transpose()
                    * (point_position(data, *body2, &frame2.r) - point_position(data, *body1, &frame1.r));
                let th =
                    crate::math::rotation::matrix_to_rotvec(&(a1.transpose() * a2)).unwrap_or_else(|_| Vec3::zeros());
                let x = nalgebra::Vector6::new(dr.x, dr.y, dr.z, th.x, th.y, th.z);
                v += match travel {
                    None => 0.5 * x.dot(&(k * x)),
                    Some(s) => (0..6).map(|i| progressive_energy(k[(i, i)], x[i], s[i])).sum(),
                };
            }
            ForceElement::Jenkins(j) => v += jenkins::energy(j, data, q),
            // the compliant contacts' stored energy, from the last force evaluation
            ForceElement::Contact(_) | ForceElement::ContactGroup(_) => {}
            _ => {}
        }
    }
    v += data.contact_energy;
    for e in &model.elastic {
        v += crate::elastic::strain_energy(e, &q[e.iq..e.iq + e.ne]);
    }
    for j in &model.joints {
        if let Some(s) = &j.spring {
            for k in 0..j.nu() {
                let d = q[j.iq + k] - s.q_free[k];
                v += 0.5 * s.k[k] * d * d;
            }
        }
    }
    v
}

/// Linear momentum and moment of momentum about the inertial origin, both I components.
pub fn momentum(model: &Model, data: &Data) -> (Vec3, Vec3) {
    let mut p = Vec3::zeros();
    let mut l = Vec3::zeros();
    for i in 1..model.nbodies() {
        // world convention: I v is (moment of momentum about the origin, momentum) directly
        let h = body_momentum(model, data, i).0;
        p += h.f;
        l += h.n;
    }
    (p, l)
}
