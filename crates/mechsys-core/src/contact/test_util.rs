//! Test helpers: a seeded generator and prescribed smooth body motions with analytic twists and
//! accelerations, against which the contact kinematics are differenced.

use nalgebra::{Rotation3, Unit};

use super::kinematics::BodyMotion;
use crate::math::{Mat3, Vec3};
use crate::spatial::{Motion, Pose};

/// xorshift64* — deterministic, no dependency.
pub(crate) struct Rng(u64);

impl Rng {
    pub(crate) fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    pub(crate) fn uniform(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
    pub(crate) fn vec3(&mut self, s: f64) -> Vec3 {
        Vec3::new(self.uniform(-s, s), self.uniform(-s, s), self.uniform(-s, s))
    }
    pub(crate) fn unit(&mut self) -> Vec3 {
        loop {
            let v = self.vec3(1.0);
            let n = v.norm();
            if n > 0.1 && n < 1.0 {
                return v / n;
            }
        }
    }
    pub(crate) fn rotation(&mut self) -> Mat3 {
        let axis = self.unit();
        rot(&axis, self.uniform(-3.0, 3.0))
    }
}

pub(crate) fn rot(axis: &Vec3, angle: f64) -> Mat3 {
    Rotation3::from_axis_angle(&Unit::new_normalize(*axis), angle).into_inner()
}

/// A smooth rigid motion `A(t) = R(k1, θ1(t)) R(k2, θ2(t)) A0`, `r(t) = r0 + r1 t + r2 t²`,
/// `θi = ci0 + ci1 t + ci2 t²`, with its twist and acceleration in the world convention.
#[derive(Clone, Copy)]
pub(crate) struct Trajectory {
    k1: Vec3,
    k2: Vec3,
    th1: [f64; 3],
    th2: [f64; 3],
    a0: Mat3,
    r: [Vec3; 3],
    /// Restrict to plane motion: rotation about z, translation in x-y.
    pub(crate) planar: bool,
}

impl Trajectory {
    /// A random motion about `pose` with angular rates ~`rate` and speeds ~`speed`.
    pub(crate) fn random(rng: &mut Rng, pose: &Pose, rate: f64, speed: f64) -> Self {
        Trajectory {
            k1: rng.unit(),
            k2: rng.unit(),
            th1: [0.0, rng.uniform(-rate, rate), rng.uniform(-rate, rate)],
            th2: [0.0, rng.uniform(-rate, rate), rng.uniform(-rate, rate)],
            a0: pose.a,
            r: [pose.r, rng.vec3(speed), rng.vec3(speed)],
            planar: false,
        }
    }
    /// A random plane motion (about z, in x-y) about `pose`.
    pub(crate) fn random_planar(rng: &mut Rng, pose: &Pose, rate: f64, speed: f64) -> Self {
        let mut t = Self::random(rng, pose, rate, speed);
        t.k1 = Vec3::z();
        t.k2 = Vec3::z();
        t.r[1].z = 0.0;
        t.r[2].z = 0.0;
        t.planar = true;
        t
    }
    /// At rest at `pose` (the ground).
    pub(crate) fn fixed(pose: &Pose) -> Self {
        Trajectory {
            k1: Vec3::z(),
            k2: Vec3::x(),
            th1: [0.0; 3],
            th2: [0.0; 3],
            a0: pose.a,
            r: [pose.r, Vec3::zeros(), Vec3::zeros()],
            planar: false,
        }
    }

    pub(crate) fn at(&self, t: f64) -> BodyMotion {
        let q = |c: &[f64; 3]| (c[0] + c[1] * t + c[2] * t * t, c[1] + 2.0 * c[2] * t, 2.0 * c[2]);
        let (q1, q1d, q1dd) = q(&self.th1);
        let (q2, q2d, q2dd) = q(&self.th2);
        let r1 = rot(&self.k1, q1);
        let a = r1 * rot(&self.k2, q2) * self.a0;
        let k2w = r1 * self.k2;
        // ω = θ̇1 k1 + θ̇2 R1 k2; the second axis turns with θ̇1 k1
        let w = self.k1 * q1d + k2w * q2d;
        let al = self.k1 * q1dd + k2w * q2dd + self.k1.cross(&k2w) * (q1d * q2d);
        let r = self.r[0] + self.r[1] * t + self.r[2] * (t * t);
        let rd = self.r[1] + self.r[2] * (2.0 * t);
        let rdd = self.r[2] * 2.0;
        // world convention: ṙ = v + ω × r, r̈ = a + α × r + ω × ṙ
        let v = rd - w.cross(&r);
        let acc = rdd - al.cross(&r) - w.cross(&rd);
        BodyMotion { pose: Pose::new(a, r), twist: Motion::new(w, v), acc: Motion::new(al, acc) }
    }
}

/// `|a - b| ≤ tol · max(1, |b|)`.
pub(crate) fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1.0)
}

#[test]
fn trajectory_twist_and_acceleration_match_finite_differences() {
    let mut rng = Rng::new(3);
    for _ in 0..5 {
        let x = Pose::new(rng.rotation(), rng.vec3(1.0));
        let tr = Trajectory::random(&mut rng, &x, 1.0, 1.0);
        let pb = rng.vec3(1.0);
        let pos = |t: f64| tr.at(t).pose.point_to_parent(&pb);
        let (t, h) = (0.3, 1e-4);
        let m = tr.at(t);
        let p = pos(t);
        let v = m.point_velocity(&p);
        let a = m.point_acceleration(&p);
        let vfd = (pos(t + h) - pos(t - h)) / (2.0 * h);
        let afd = (pos(t + h) - 2.0 * p + pos(t - h)) / (h * h);
        assert!((v - vfd).norm() < 1e-7, "{v} {vfd}");
        assert!((a - afd).norm() < 1e-5, "{a} {afd}");
        // ω from Ȧ Aᵀ
        let ad = (tr.at(t + h).pose.a - tr.at(t - h).pose.a) / (2.0 * h);
        let w = crate::math::untilde(&(ad * m.pose.a.transpose()));
        assert!((w - m.twist.w).norm() < 1e-7);
        let wd = (tr.at(t + h).twist.w - tr.at(t - h).twist.w) / (2.0 * h);
        assert!((wd - m.acc.w).norm() < 1e-7);
    }
}

use super::contour::{lift, Contour, Vec2};

/// One contour of every kind, with offsets from the body origin (and unnormalized directions,
/// so the pair's normalization is exercised).
pub(crate) fn sample(kind: &str) -> Contour {
    match kind {
        "point" => Contour::Point { p: Vec3::new(0.1, -0.2, 0.05) },
        "sphere" => Contour::Sphere { center: Vec3::new(0.1, 0.05, -0.1), radius: 0.4 },
        "sphere_b" => Contour::Sphere { center: Vec3::new(-0.05, 0.1, 0.02), radius: 0.25 },
        "plane" => Contour::Plane { point: Vec3::new(0.0, 0.0, -0.2), normal: Vec3::new(0.1, 0.2, 1.0) },
        "box" => Contour::Box {
            center: Vec3::new(0.05, 0.0, 0.1),
            rotation: rot(&Vec3::new(1.0, 2.0, 0.5), 0.5),
            half_extents: Vec3::new(0.3, 0.5, 0.2),
        },
        "capsule" => Contour::Capsule { a: Vec3::new(-0.3, 0.1, 0.0), b: Vec3::new(0.4, -0.1, 0.1), radius: 0.2 },
        "box_b" => Contour::Box {
            center: Vec3::new(0.05, -0.02, 0.03),
            rotation: nalgebra::Rotation3::from_euler_angles(0.2, -0.3, 0.5).into_inner(),
            half_extents: Vec3::new(0.2, 0.15, 0.1),
        },
        "capsule_b" => Contour::Capsule { a: Vec3::new(0.0, -0.4, 0.1), b: Vec3::new(0.1, 0.5, -0.2), radius: 0.15 },
        "cylinder" => Contour::Cylinder {
            center: Vec3::new(0.1, 0.0, 0.0),
            axis: Vec3::new(0.2, 0.1, 1.0),
            radius: 0.3,
            half_length: 0.4,
        },
        "point2" => Contour::Point2 { p: Vec2::new(0.2, -0.1) },
        "circle" => Contour::Circle { center: Vec2::new(0.1, 0.2), radius: 0.35 },
        "circle_b" => Contour::Circle { center: Vec2::new(-0.1, 0.05), radius: 0.2 },
        "line" => Contour::Line { point: Vec2::new(0.0, -0.1), normal: Vec2::new(0.3, 1.0) },
        "polygon" => Contour::Polygon {
            vertices: [(-0.3, -0.2), (0.2, -0.25), (0.35, 0.1), (0.0, 0.3), (-0.25, 0.15)]
                .iter()
                .map(|&(x, y)| Vec2::new(x, y))
                .collect(),
        },
        // round enough that the random placements' penetrations stay clear of the evolute, where
        // the foot point's higher derivatives (and so the differences' truncation) grow large
        "ellipsoid" => Contour::Ellipsoid {
            center: Vec3::new(0.05, -0.03, 0.02),
            rotation: rot(&Vec3::new(0.3, -1.0, 0.6), 0.8),
            semi_axes: Vec3::new(0.4, 0.3, 0.25),
        },
        "ellipsoid_b" => Contour::Ellipsoid {
            center: Vec3::new(-0.04, 0.02, 0.05),
            rotation: rot(&Vec3::new(1.0, 0.4, -0.2), -0.6),
            semi_axes: Vec3::new(0.22, 0.35, 0.28),
        },
        "torus" => Contour::Torus {
            center: Vec3::new(0.05, 0.1, -0.02),
            axis: Vec3::new(0.2, 1.0, 0.3),
            radius: 0.35,
            tube: 0.05,
        },
        "bowl" => Contour::Bowl { center: Vec3::new(0.05, -0.1, 0.02), radius: 1.3 },
        "bore" => Contour::Bore { center: Vec3::new(0.1, 0.0, -0.05), axis: Vec3::new(0.3, 1.0, 0.2), radius: 1.3 },
        "revolution" => surface_sample("revolution"),
        "patch" => surface_sample("patch"),
        "ellipse" => curve_sample("ellipse"),
        "ellipse_b" => curve_sample("ellipse_b"),
        "blob" => curve_sample("blob"),
        "cam" => curve_sample("cam"),
        "spline_bore" => curve_sample("bore"),
        "gear" => curve_sample("gear"),
        "gear_b" => curve_sample("gear_b"),
        // a closed, non-convex mesh: a once-subdivided icosahedron with jittered radii about 0.5
        "mesh" => {
            let (mut v, t) = icosphere(1, 1.0);
            let mut rng = Rng::new(9);
            for p in v.iter_mut() {
                *p = *p * rng.uniform(0.4, 0.6) + Vec3::new(0.03, -0.02, 0.05);
            }
            mesh_contour(&v, &t)
        }
        _ => unreachable!("unknown sample {kind}"),
    }
}

/// Spatial parametric surfaces: a closed profile with dimples at its poles (mixed convexity,
/// mirror-symmetric about its axis) turned about a tilted axis; a wavy terrain patch.
pub(crate) fn surface_sample(kind: &str) -> Contour {
    use crate::geometry::curve::{Curve, Solid};
    use crate::geometry::revolution::Revolution;
    use crate::geometry::surface::Patch;
    use std::f64::consts::TAU;
    match kind {
        "revolution" => {
            let pts: Vec<Vec2> = (0..48)
                .map(|i| TAU * i as f64 / 48.0)
                .map(|t| Vec2::new(t.cos(), t.sin()) * (0.3 + 0.08 * (2.0 * t).cos()))
                .collect();
            let profile = Curve::spline(&pts, true, Solid::Inside, "revolution").unwrap();
            let r = Revolution::new(
                Vec3::new(0.03, -0.02, 0.05),
                rot(&Vec3::new(0.4, 1.0, -0.3), 0.7),
                profile,
                "revolution",
            );
            Contour::Revolution(Box::new(r.unwrap()))
        }
        "patch" => {
            let n = 26;
            let pts: Vec<Vec<Vec3>> = (0..n)
                .map(|i| {
                    (0..n)
                        .map(|j| {
                            let (x, y) =
                                (-2.5 + 5.0 * i as f64 / (n - 1) as f64, -2.5 + 5.0 * j as f64 / (n - 1) as f64);
                            Vec3::new(x, y, 0.1 * (2.0 * x).sin() * (1.5 * y).cos() - 0.2)
                        })
                        .collect()
                })
                .collect();
            Contour::Patch(Box::new(Patch::new(&pts, (0.0, 1.0), (0.0, 1.0), [false, false], "patch").unwrap()))
        }
        _ => unreachable!("unknown surface sample {kind}"),
    }
}

/// Parametric contours for the curve pairs.
pub(crate) fn curve_sample(kind: &str) -> Contour {
    use crate::geometry::curve::{Curve, Follower, Solid};
    use std::f64::consts::TAU;
    let c = match kind {
        "ellipse" => Curve::ellipse(Vec2::new(0.05, -0.02), 0.35, 0.2, 0.3, "ellipse").unwrap(),
        "ellipse_b" => Curve::ellipse(Vec2::new(-0.03, 0.04), 0.25, 0.12, -0.7, "ellipse_b").unwrap(),
        // a closed spline with a hollow flank (mixed convexity)
        "blob" => {
            let pts: Vec<Vec2> = (0..24)
                .map(|i| TAU * i as f64 / 24.0)
                .map(|t| Vec2::new(t.cos(), t.sin()) * (0.3 + 0.06 * (3.0 * t).cos()))
                .collect();
            Curve::spline(&pts, true, Solid::Inside, "blob").unwrap()
        }
        // a cam with a double dwell and a roller of 0.02
        "cam" => {
            let n = 72;
            let a: Vec<f64> = (0..=n).map(|i| TAU * i as f64 / n as f64).collect();
            let h: Vec<f64> = a.iter().map(|t| 0.03 * (1.0 - t.cos()) + 0.01 * (1.0 - (2.0 * t).cos())).collect();
            Curve::cam(&a, &h, 0.2, Follower::Roller { radius: 0.02, eccentricity: 0.01 }, 1.0, "cam").unwrap()
        }
        // a circular bore of radius 0.9 (solid outside)
        "bore" => {
            let pts: Vec<Vec2> =
                (0..40).map(|i| TAU * i as f64 / 40.0).map(|t| Vec2::new(t.cos(), t.sin()) * 0.9).collect();
            Curve::spline(&pts, true, Solid::Outside, "bore").unwrap()
        }
        // involute gears of about the samples' size, off their body origins
        "gear" => {
            use crate::geometry::gear::GearSpec;
            let spec =
                GearSpec { center: Vec2::new(0.02, -0.01), phase: 0.1, backlash: 0.002, ..GearSpec::new(0.04, 17) };
            Curve::gear(&spec, "gear").unwrap()
        }
        "gear_b" => {
            use crate::geometry::gear::GearSpec;
            let spec = GearSpec { shift: 0.3, pressure_angle: 0.4, ..GearSpec::new(0.05, 9) };
            Curve::gear(&spec, "gear_b").unwrap()
        }
        _ => unreachable!("unknown curve sample {kind}"),
    };
    Contour::Curve(Box::new(c))
}

/// The points of a gear contour where its pieces meet (its curvature jumps there), body frame;
/// empty for other contours.
pub(crate) fn curve_joints(c: &Contour) -> Vec<Vec2> {
    let Contour::Curve(c) = c else { return Vec::new() };
    let Some(g) = c.as_gear() else { return Vec::new() };
    let l = g.tooth_length();
    let mut out = Vec::new();
    for k in 0..g.teeth() {
        for (u, _) in g.joints() {
            out.push(g.tooth_eval(k, u, false)[0]);
            out.push(g.tooth_eval(k, l - u, true)[0]);
        }
        out.push(g.tooth_eval(k, 0.5 * l, false)[0]);
    }
    out
}

/// Pairs with a parametric contour, canonical order (sample names).
pub(crate) const CURVE_PAIRS: [(&str, &str); 13] = [
    ("point2", "ellipse"),
    ("circle_b", "ellipse"),
    ("polygon", "blob"),
    ("circle_b", "cam"),
    ("ellipse_b", "ellipse"),
    ("blob", "ellipse"),
    ("ellipse", "line"),
    ("cam", "line"),
    ("blob", "line"),
    ("ellipse_b", "cam"),
    ("circle_b", "gear"),
    ("gear_b", "gear"),
    ("gear", "line"),
];

/// Every supported pair in canonical order (sample names).
pub(crate) const PAIRS: [(&str, &str); 36] = [
    ("point", "plane"),
    ("sphere", "plane"),
    ("box", "plane"),
    ("capsule", "plane"),
    ("cylinder", "plane"),
    ("point2", "line"),
    ("circle", "line"),
    ("polygon", "line"),
    ("point", "sphere"),
    ("sphere_b", "sphere"),
    ("point", "capsule"),
    ("sphere", "capsule"),
    ("capsule_b", "capsule"),
    ("point", "box"),
    ("sphere", "box"),
    ("point2", "circle"),
    ("circle_b", "circle"),
    ("ellipsoid", "plane"),
    ("torus", "plane"),
    ("point", "ellipsoid"),
    ("sphere_b", "ellipsoid"),
    ("ellipsoid_b", "ellipsoid"),
    ("revolution", "plane"),
    ("point", "revolution"),
    ("sphere_b", "revolution"),
    ("point", "patch"),
    ("sphere_b", "patch"),
    ("ellipsoid_b", "patch"),
    ("point", "bowl"),
    ("sphere", "bowl"),
    ("point", "bore"),
    ("sphere", "bore"),
    ("point", "mesh"),
    ("sphere_b", "mesh"),
    ("box_b", "mesh"),
    ("capsule_b", "mesh"),
];

/// Random placements of two bodies near each other (plane motion: rotations about z, z = 0).
pub(crate) fn random_poses(rng: &mut Rng, planar: bool) -> (Pose, Pose) {
    let rotation = |rng: &mut Rng| if planar { rot(&Vec3::z(), rng.uniform(-3.0, 3.0)) } else { rng.rotation() };
    let mut r2 = rng.vec3(0.3);
    let dir =
        if planar { Vec3::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), 0.0).normalize() } else { rng.unit() };
    let mut r1 = r2 + dir * rng.uniform(0.2, 1.2);
    if planar {
        r1.z = 0.0;
        r2.z = 0.0;
    }
    (Pose::new(rotation(rng), r1), Pose::new(rotation(rng), r2))
}

/// Signed distance of world point `x` to the contour on a body at `pose` (planar contours
/// extruded along the body z axis; points and polygons give the distance to the point set or
/// the largest edge distance, which is zero on the boundary).
pub(crate) fn sdf(c: &Contour, pose: &Pose, x: &Vec3) -> f64 {
    let xl = pose.a.transpose() * (x - pose.r);
    let seg = |a: &Vec3, b: &Vec3, p: &Vec3| {
        let d = b - a;
        let s = ((p - a).dot(&d) / d.dot(&d)).clamp(0.0, 1.0);
        (p - a - d * s).norm()
    };
    match c {
        Contour::Point { p } => (xl - p).norm(),
        Contour::Sphere { center, radius } => (xl - center).norm() - radius,
        Contour::Plane { point, normal } => normal.normalize().dot(&(xl - point)),
        Contour::Box { center, rotation, half_extents } => {
            let q = (rotation.transpose() * (xl - center)).abs() - half_extents;
            q.sup(&Vec3::zeros()).norm() + q.max().min(0.0)
        }
        Contour::Capsule { a, b, radius } => seg(a, b, &xl) - radius,
        Contour::Cylinder { center, axis, radius, half_length } => {
            let a = axis.normalize();
            let y = xl - center;
            let za = y.dot(&a);
            let rho = (y - a * za).norm();
            let d = nalgebra::Vector2::new(rho - radius, za.abs() - half_length);
            d.sup(&nalgebra::Vector2::zeros()).norm() + d.max().min(0.0)
        }
        Contour::Point2 { p } => (xl - lift(p)).norm(),
        Contour::Circle { center, radius } => {
            let d = xl - lift(center);
            (d.x * d.x + d.y * d.y).sqrt() - radius
        }
        Contour::Line { point, normal } => lift(&normal.normalize()).dot(&(xl - lift(point))),
        Contour::Polygon { vertices } => {
            let n = vertices.len();
            (0..n)
                .map(|i| {
                    let (a, b) = (vertices[i], vertices[(i + 1) % n]);
                    let e = (b - a).normalize();
                    let out = Vec2::new(e.y, -e.x);
                    out.dot(&(Vec2::new(xl.x, xl.y) - a))
                })
                .fold(f64::NEG_INFINITY, f64::max)
        }
        Contour::Curve(c) => curve_sdf(c, &Vec2::new(xl.x, xl.y)).0,
        Contour::Revolution(r) => {
            // the meridian plane: the profile's sampled distance
            let y = r.rotation.transpose() * (xl - r.center);
            curve_sdf(&r.profile, &Vec2::new(y.x.hypot(y.y), y.z)).0
        }
        Contour::Patch(p) => patch_sdf(p, &xl),
        Contour::Torus { center, axis, radius, tube } => {
            let a = axis.normalize();
            let y = xl - center;
            let z = y.dot(&a);
            let rho = (y - a * z).norm();
            (rho - radius).hypot(z) - tube
        }
        Contour::Ellipsoid { center, rotation, semi_axes } => {
            ellipsoid_sdf(&(rotation.transpose() * (xl - center)), semi_axes)
        }
        // inside the cavity is free space: positive distance to the wall
        Contour::Bowl { center, radius } => radius - (xl - center).norm(),
        Contour::Bore { center, axis, radius } => {
            let a = axis.normalize();
            let y = xl - center;
            radius - (y - a * a.dot(&y)).norm()
        }
        Contour::Mesh(m) => mesh_sdf(m, &xl),
    }
}

/// An icosphere of `radius` about the origin: the icosahedron with each triangle split into four
/// `levels` times, vertices pushed onto the sphere; triangles counter-clockwise seen from outside
/// (20·4^levels triangles).
pub(crate) fn icosphere(levels: usize, radius: f64) -> (Vec<Vec3>, Vec<[usize; 3]>) {
    let p = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<Vec3> = [
        (-1.0, p, 0.0),
        (1.0, p, 0.0),
        (-1.0, -p, 0.0),
        (1.0, -p, 0.0),
        (0.0, -1.0, p),
        (0.0, 1.0, p),
        (0.0, -1.0, -p),
        (0.0, 1.0, -p),
        (p, 0.0, -1.0),
        (p, 0.0, 1.0),
        (-p, 0.0, -1.0),
        (-p, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut t: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut split = |a: usize, b: usize, v: &mut Vec<Vec3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push(((v[a] + v[b]) * 0.5).normalize());
                v.len() - 1
            })
        };
        let mut next = Vec::with_capacity(4 * t.len());
        for &[a, b, c] in &t {
            let (ab, bc, ca) = (split(a, b, &mut v), split(b, c, &mut v), split(c, a, &mut v));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        t = next;
    }
    (v.into_iter().map(|x| x * radius).collect(), t)
}

/// A mesh contour from vertices and triangles (valid by construction in the tests).
pub(crate) fn mesh_contour(v: &[Vec3], t: &[[usize; 3]]) -> Contour {
    Contour::Mesh(std::sync::Arc::new(crate::geometry::mesh::TriMesh::new(v, t, "test mesh").expect("valid mesh")))
}

/// Brute-force signed distance to a closed mesh (body frame), independent of its hierarchy and
/// pseudo-normals: the smallest distance to any triangle (the projection onto the face when it
/// falls inside, else the nearest point of the three edges), negative where the winding number
/// (the triangles' solid angles, van Oosterom–Strackee, over 4π) is 1 for an outward mesh or 0
/// for an inward one (a cavity).
pub(crate) fn mesh_sdf(m: &crate::geometry::mesh::TriMesh, y: &Vec3) -> f64 {
    let seg = |p: &Vec3, q: &Vec3| {
        let d = q - p;
        let s = ((y - p).dot(&d) / d.dot(&d)).clamp(0.0, 1.0);
        (y - p - d * s).norm()
    };
    let mut best = f64::INFINITY;
    let mut omega = 0.0;
    for k in 0..m.triangles().len() {
        let [a, b, c] = m.corners(k);
        let n = (b - a).cross(&(c - a)).normalize();
        let q = y - n * n.dot(&(y - a));
        let inside = [(a, b), (b, c), (c, a)].iter().all(|(p, r)| (r - p).cross(&(q - p)).dot(&n) >= 0.0);
        let d = if inside { n.dot(&(y - a)).abs() } else { seg(&a, &b).min(seg(&b, &c)).min(seg(&c, &a)) };
        best = best.min(d);
        let (ra, rb, rc) = (a - y, b - y, c - y);
        let (la, lb, lc) = (ra.norm(), rb.norm(), rc.norm());
        let num = ra.dot(&rb.cross(&rc));
        let den = la * lb * lc + ra.dot(&rb) * lc + rb.dot(&rc) * la + rc.dot(&ra) * lb;
        omega += 2.0 * num.atan2(den);
    }
    let winding = omega / (4.0 * std::f64::consts::PI);
    let solid = if m.volume() > 0.0 { winding > 0.5 } else { winding > -0.5 };
    if solid {
        -best
    } else {
        best
    }
}

/// Signed distance from a point `y` (ellipsoid frame) to the ellipsoid with semi-axes `a`, by
/// dense sampling of the angle parameters refined by a shrinking pattern search (independent of
/// the engine's root of the foot-point equation).
pub(crate) fn ellipsoid_sdf(y: &Vec3, a: &Vec3) -> f64 {
    let p = |u: f64, v: f64| Vec3::new(a.x * u.cos() * v.cos(), a.y * u.sin() * v.cos(), a.z * v.sin());
    let d2 = |u: f64, v: f64| (y - p(u, v)).norm_squared();
    let (mut best, mut bu, mut bv) = (f64::INFINITY, 0.0, 0.0);
    for i in 0..360 {
        for j in 0..=180 {
            let (u, v) = (
                std::f64::consts::TAU * i as f64 / 360.0,
                -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * j as f64 / 180.0,
            );
            let d = d2(u, v);
            if d < best {
                (best, bu, bv) = (d, u, v);
            }
        }
    }
    let mut step = 0.02;
    while step > 1e-13 {
        let mut moved = false;
        for (du, dv) in [
            (step, 0.0),
            (-step, 0.0),
            (0.0, step),
            (0.0, -step),
            (step, step),
            (-step, -step),
            (step, -step),
            (-step, step),
        ] {
            let d = d2(bu + du, bv + dv);
            if d < best {
                (best, bu, bv, moved) = (d, bu + du, bv + dv, true);
            }
        }
        if !moved {
            step *= 0.5;
        }
    }
    let inside = y.component_div(a).norm() < 1.0;
    if inside {
        -best.sqrt()
    } else {
        best.sqrt()
    }
}

/// Signed distance from a body-frame point to a spline patch (positive above its normal), by
/// dense sampling of the parameters and a shrinking pattern search (independent of the foot
/// point's Newton iteration).
pub(crate) fn patch_sdf(p: &crate::geometry::surface::Patch, y: &Vec3) -> f64 {
    let [(a0, a1), (b0, b1)] = p.range();
    let n = 200;
    let d2 = |s: [f64; 2]| (y - p.eval(s)[0]).norm_squared();
    let (mut best, mut sb) = (f64::INFINITY, [a0, b0]);
    for i in 0..=n {
        for j in 0..=n {
            let s = [a0 + (a1 - a0) * i as f64 / n as f64, b0 + (b1 - b0) * j as f64 / n as f64];
            let v = d2(s);
            if v < best {
                (best, sb) = (v, s);
            }
        }
    }
    let mut step = (a1 - a0).max(b1 - b0) / n as f64;
    while step > 1e-15 {
        let mut moved = false;
        for (u, v) in
            [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0), (1.0, 1.0), (-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0)]
        {
            let s = p.clamp([sb[0] + u * step, sb[1] + v * step]);
            let d = d2(s);
            if d < best {
                (best, sb, moved) = (d, s, true);
            }
        }
        if !moved {
            step *= 0.5;
        }
    }
    let j = p.eval(sb);
    let nu = j[1].cross(&j[2]).normalize();
    if (y - j[0]).dot(&nu) < 0.0 {
        -best.sqrt()
    } else {
        best.sqrt()
    }
}

/// Signed distance from a body-frame point to a curve contour and the foot parameter, by dense
/// sampling and golden-section refinement of the squared distance (independent of the contact
/// search's Newton iteration). Offsets included.
pub(crate) fn curve_sdf(c: &crate::geometry::curve::Curve, y: &Vec2) -> (f64, f64) {
    let (lo, hi) = c.range();
    let n = 20000;
    let d2 = |s: f64| (y - c.eval(s)[0]).norm_squared();
    let (mut best, mut sb) = (f64::INFINITY, lo);
    for i in 0..=n {
        let s = lo + (hi - lo) * i as f64 / n as f64;
        let v = d2(s);
        if v < best {
            best = v;
            sb = s;
        }
    }
    let h = (hi - lo) / n as f64;
    let (mut a, mut b) = (sb - 2.0 * h, sb + 2.0 * h);
    let gr = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..200 {
        let (m1, m2) = (b - gr * (b - a), a + gr * (b - a));
        if d2(m1) < d2(m2) {
            b = m2;
        } else {
            a = m1;
        }
    }
    let s = 0.5 * (a + b);
    let j = c.eval(s);
    let nu = c.outward(&j[1]);
    let sign = if (y - j[0]).dot(&nu) < 0.0 { -1.0 } else { 1.0 };
    (sign * (y - j[0]).norm() - c.offset(), s)
}
