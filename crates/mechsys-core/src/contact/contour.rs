//! Contours: the contact geometry a body carries, given in the body frame.
//!
//! Spatial contours are solids (a point, a sphere, a half-space, a box, a capsule, a cylinder).
//! Planar contours live in the body's x-y plane and are extruded along the body's z axis: a circle
//! is an infinite cylinder, a line a half-space whose normal lies in the x-y plane, a polygon an
//! infinite prism. They model plane motion, where every body moves in the common x-y plane.

use crate::ensure;
use crate::error::Result;
use crate::math::{Mat3, Vec3};
use crate::spatial::Pose;

use super::broad::Aabb;
use crate::geometry::curve::Curve;
use crate::geometry::mesh::TriMesh;
use crate::geometry::revolution::Revolution;
use crate::geometry::surface::Patch;
use std::sync::Arc;

/// 2-vector of `f64` (the coordinates of planar contours in the body's x-y plane).
pub type Vec2 = nalgebra::Vector2<f64>;

/// A contour on a body; every parameter is in the body frame.
#[derive(Debug, Clone, PartialEq)]
pub enum Contour {
    /// A single point (a vertex, a pin, the tip of a rod).
    Point {
        /// The point.
        p: Vec3,
    },
    /// A ball.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius (> 0).
        radius: f64,
    },
    /// The half-space `(x - point)·normal ≤ 0`; the solid lies below the normal.
    Plane {
        /// A point on the boundary plane.
        point: Vec3,
        /// Outward normal (nonzero; normalized when a pair is built).
        normal: Vec3,
    },
    /// A rectangular box.
    Box {
        /// Centre.
        center: Vec3,
        /// Rotation box frame → body frame (orthonormal, determinant +1).
        rotation: Mat3,
        /// Half the edge lengths along the box axes (> 0).
        half_extents: Vec3,
    },
    /// The points within `radius` of the segment `a`–`b`.
    Capsule {
        /// First end of the axis segment.
        a: Vec3,
        /// Second end (≠ `a`; a capsule of zero length is a [`Contour::Sphere`]).
        b: Vec3,
        /// Radius (> 0).
        radius: f64,
    },
    /// A solid circular cylinder with flat ends.
    Cylinder {
        /// Centre (midpoint of the axis).
        center: Vec3,
        /// Axis direction (nonzero; normalized when a pair is built).
        axis: Vec3,
        /// Radius (> 0).
        radius: f64,
        /// Half the length along the axis (> 0).
        half_length: f64,
    },
    /// A torus (a wheel's rim, a thin disc when `tube` is 0): the points within `tube` of the
    /// circle of `radius` about the axis through `center`.
    Torus {
        /// Centre of the rim circle.
        center: Vec3,
        /// Axis of the wheel (nonzero; normalized when a pair is built).
        axis: Vec3,
        /// Radius of the rim circle (> 0).
        radius: f64,
        /// Tube radius (≥ 0, < radius).
        tube: f64,
    },
    /// A solid ellipsoid (section 2.2.7.2): `(x - c)ᵀ R diag(a, b, c)⁻² Rᵀ (x - c) ≤ 1`.
    Ellipsoid {
        /// Centre.
        center: Vec3,
        /// Rotation ellipsoid frame → body frame (orthonormal, determinant +1).
        rotation: Mat3,
        /// Semi-axes along the ellipsoid's x, y, z axes (> 0).
        semi_axes: Vec3,
    },
    /// A spherical cavity (a bowl, a ball race seen from within): the solid lies outside the
    /// sphere of `radius` about `center`.
    Bowl {
        /// Centre.
        center: Vec3,
        /// Radius (> 0).
        radius: f64,
    },
    /// A cylindrical cavity (a bore, a bearing shell), infinite along `axis`: the solid lies
    /// outside the cylinder of `radius` about the axis through `center`.
    Bore {
        /// A point of the axis.
        center: Vec3,
        /// Axis direction (nonzero; normalized when a pair is built).
        axis: Vec3,
        /// Radius (> 0).
        radius: f64,
    },
    /// Planar: a point of the x-y plane.
    Point2 {
        /// The point.
        p: Vec2,
    },
    /// Planar: a disc (an infinite cylinder along the body z axis).
    Circle {
        /// Centre.
        center: Vec2,
        /// Radius (> 0).
        radius: f64,
    },
    /// Planar: the half-plane `(x - point)·normal ≤ 0`, solid behind the normal.
    Line {
        /// A point on the boundary line.
        point: Vec2,
        /// Outward normal (nonzero; normalized when a pair is built).
        normal: Vec2,
    },
    /// Planar: a convex polygon, vertices counter-clockwise about the body z axis. The `Vec` is
    /// built with the model; the per-step functions only read it.
    Polygon {
        /// Vertices (at least 3, convex, counter-clockwise; collinear vertices are allowed).
        vertices: Vec<Vec2>,
    },
    /// Planar: a parametric contour (ellipse, spline, cam; see [`crate::geometry::curve`]),
    /// validated when it was built.
    Curve(Box<Curve>),
    /// A triangle mesh, solid behind its triangles' outward normals (see
    /// [`crate::geometry::mesh`]), validated with its bounding-volume hierarchy when it was
    /// built; shared, so the pairs of a contact group do not copy it.
    Mesh(Arc<TriMesh>),
    /// A surface of revolution: a planar profile turned about an axis
    /// ([`crate::geometry::revolution`]), validated when it was built.
    Revolution(Box<Revolution>),
    /// A bicubic spline patch `r(s1, s2)` through a grid of points, solid below its normal
    /// `r_1 × r_2` ([`crate::geometry::surface`]), validated when it was built.
    Patch(Box<Patch>),
}

/// The kind of a contour, for dispatch tables and messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ContourKind {
    /// [`Contour::Point`]
    Point,
    /// [`Contour::Sphere`]
    Sphere,
    /// [`Contour::Plane`]
    Plane,
    /// [`Contour::Box`]
    Box,
    /// [`Contour::Capsule`]
    Capsule,
    /// [`Contour::Cylinder`]
    Cylinder,
    /// [`Contour::Torus`]
    Torus,
    /// [`Contour::Ellipsoid`]
    Ellipsoid,
    /// [`Contour::Bowl`]
    Bowl,
    /// [`Contour::Bore`]
    Bore,
    /// [`Contour::Point2`]
    Point2,
    /// [`Contour::Circle`]
    Circle,
    /// [`Contour::Line`]
    Line,
    /// [`Contour::Polygon`]
    Polygon,
    /// [`Contour::Curve`]
    Curve,
    /// [`Contour::Mesh`]
    Mesh,
    /// [`Contour::Revolution`]
    Revolution,
    /// [`Contour::Patch`]
    Patch,
}

impl ContourKind {
    /// Lower-case name used in messages ("sphere", "plane", ...).
    pub fn name(self) -> &'static str {
        match self {
            ContourKind::Point => "point",
            ContourKind::Sphere => "sphere",
            ContourKind::Plane => "plane",
            ContourKind::Box => "box",
            ContourKind::Capsule => "capsule",
            ContourKind::Cylinder => "cylinder",
            ContourKind::Torus => "torus",
            ContourKind::Ellipsoid => "ellipsoid",
            ContourKind::Bowl => "bowl",
            ContourKind::Bore => "bore",
            ContourKind::Point2 => "point2",
            ContourKind::Circle => "circle",
            ContourKind::Line => "line",
            ContourKind::Polygon => "polygon",
            ContourKind::Curve => "curve",
            ContourKind::Mesh => "mesh",
            ContourKind::Revolution => "revolution",
            ContourKind::Patch => "patch",
        }
    }

    /// Whether the contour lives in the body's x-y plane.
    pub fn is_planar(self) -> bool {
        matches!(
            self,
            ContourKind::Point2 | ContourKind::Circle | ContourKind::Line | ContourKind::Polygon | ContourKind::Curve
        )
    }
}

impl std::fmt::Display for ContourKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

fn finite3(v: &Vec3, what: &str, key: &str) -> Result<()> {
    ensure!(v.iter().all(|x| x.is_finite()), Model, "{what}: {key} must be finite, got {:?}", v.as_slice());
    Ok(())
}

fn finite2(v: &Vec2, what: &str, key: &str) -> Result<()> {
    ensure!(v.iter().all(|x| x.is_finite()), Model, "{what}: {key} must be finite, got {:?}", v.as_slice());
    Ok(())
}

/// A finite centre and a finite, nonzero axis (a cylinder, a torus, a bore).
fn point_and_axis(center: &Vec3, axis: &Vec3, what: &str, shape: &str) -> Result<()> {
    finite3(center, what, &format!("{shape} center"))?;
    finite3(axis, what, &format!("{shape} axis"))?;
    ensure!(
        axis.norm() > MIN_DIRECTION,
        Model,
        "{what}: {shape} axis must not be the zero vector, got {:?}",
        axis.as_slice()
    );
    Ok(())
}

/// A solid with a centre, a rotation of its axes and three positive extents along them (a box, an
/// ellipsoid).
fn oriented_solid(center: &Vec3, rotation: &Mat3, extents: &Vec3, what: &str, shape: &str, extent: &str) -> Result<()> {
    finite3(center, what, &format!("{shape} center"))?;
    ensure!(rotation.iter().all(|x| x.is_finite()), Model, "{what}: {shape} rotation must be finite");
    let e = (rotation.transpose() * rotation - Mat3::identity()).norm();
    ensure!(
        e < 1e-6 && rotation.determinant() > 0.0,
        Model,
        "{what}: {shape} rotation must be orthonormal with determinant +1 (|AᵀA - E| = {e:.2e})"
    );
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        positive(extents[k], what, &format!("{shape} {extent} along {axis}"))?;
    }
    Ok(())
}

fn positive(x: f64, what: &str, key: &str) -> Result<()> {
    // `!(x > 0)` also rejects NaN; the upper bound rejects infinity
    ensure!(x > 0.0 && x.is_finite(), Model, "{what}: {key} must be > 0 and finite, got {x}");
    Ok(())
}

/// Direction vectors shorter than this are rejected as zero.
const MIN_DIRECTION: f64 = 1e-12;

impl Contour {
    /// The contour's kind.
    pub fn kind(&self) -> ContourKind {
        match self {
            Contour::Point { .. } => ContourKind::Point,
            Contour::Sphere { .. } => ContourKind::Sphere,
            Contour::Plane { .. } => ContourKind::Plane,
            Contour::Box { .. } => ContourKind::Box,
            Contour::Capsule { .. } => ContourKind::Capsule,
            Contour::Cylinder { .. } => ContourKind::Cylinder,
            Contour::Torus { .. } => ContourKind::Torus,
            Contour::Ellipsoid { .. } => ContourKind::Ellipsoid,
            Contour::Bowl { .. } => ContourKind::Bowl,
            Contour::Bore { .. } => ContourKind::Bore,
            Contour::Point2 { .. } => ContourKind::Point2,
            Contour::Circle { .. } => ContourKind::Circle,
            Contour::Line { .. } => ContourKind::Line,
            Contour::Polygon { .. } => ContourKind::Polygon,
            Contour::Curve(_) => ContourKind::Curve,
            Contour::Mesh(_) => ContourKind::Mesh,
            Contour::Revolution(_) => ContourKind::Revolution,
            Contour::Patch(_) => ContourKind::Patch,
        }
    }

    /// Checks the parameters; errors start with `what` (e.g. "contact 'tip': contour 1").
    ///
    /// # Example
    /// ```
    /// use mechsys_core::contact::Contour;
    /// use mechsys_core::math::Vec3;
    /// let bad = Contour::Sphere { center: Vec3::zeros(), radius: -1.0 };
    /// let e = bad.validate("contact 'ball'").unwrap_err();
    /// assert!(e.to_string().contains("contact 'ball': sphere radius must be > 0"));
    /// ```
    pub fn validate(&self, what: &str) -> Result<()> {
        match self {
            Contour::Point { p } => finite3(p, what, "point p"),
            Contour::Sphere { center, radius } => {
                finite3(center, what, "sphere center")?;
                positive(*radius, what, "sphere radius")
            }
            Contour::Plane { point, normal } => {
                finite3(point, what, "plane point")?;
                finite3(normal, what, "plane normal")?;
                ensure!(
                    normal.norm() > MIN_DIRECTION,
                    Model,
                    "{what}: plane normal must not be the zero vector, got {:?}",
                    normal.as_slice()
                );
                Ok(())
            }
            Contour::Box { center, rotation, half_extents } => {
                oriented_solid(center, rotation, half_extents, what, "box", "half extent")
            }
            Contour::Capsule { a, b, radius } => {
                finite3(a, what, "capsule end a")?;
                finite3(b, what, "capsule end b")?;
                positive(*radius, what, "capsule radius")?;
                ensure!(
                    (b - a).norm() > MIN_DIRECTION,
                    Model,
                    "{what}: capsule ends a and b must differ (a capsule of zero length is a sphere), got {:?}",
                    a.as_slice()
                );
                Ok(())
            }
            Contour::Cylinder { center, axis, radius, half_length } => {
                point_and_axis(center, axis, what, "cylinder")?;
                positive(*radius, what, "cylinder radius")?;
                positive(*half_length, what, "cylinder half_length")
            }
            Contour::Ellipsoid { center, rotation, semi_axes } => {
                oriented_solid(center, rotation, semi_axes, what, "ellipsoid", "semi-axis")
            }
            Contour::Torus { center, axis, radius, tube } => {
                point_and_axis(center, axis, what, "torus")?;
                positive(*radius, what, "torus radius")?;
                ensure!(
                    *tube >= 0.0 && *tube < *radius,
                    Model,
                    "{what}: torus tube must be ≥ 0 and smaller than the radius {radius}, got {tube}"
                );
                Ok(())
            }
            Contour::Bowl { center, radius } => {
                finite3(center, what, "bowl center")?;
                positive(*radius, what, "bowl radius")
            }
            Contour::Bore { center, axis, radius } => {
                point_and_axis(center, axis, what, "bore")?;
                positive(*radius, what, "bore radius")
            }
            Contour::Point2 { p } => finite2(p, what, "point2 p"),
            Contour::Circle { center, radius } => {
                finite2(center, what, "circle center")?;
                positive(*radius, what, "circle radius")
            }
            Contour::Line { point, normal } => {
                finite2(point, what, "line point")?;
                finite2(normal, what, "line normal")?;
                ensure!(
                    normal.norm() > MIN_DIRECTION,
                    Model,
                    "{what}: line normal must not be the zero vector, got {:?}",
                    normal.as_slice()
                );
                Ok(())
            }
            Contour::Polygon { vertices } => validate_polygon(vertices, what),
            // checked by their constructors
            Contour::Curve(_) | Contour::Mesh(_) | Contour::Revolution(_) | Contour::Patch(_) => Ok(()),
        }
    }

    /// A copy with unit normals and axes and an exactly orthonormal box rotation (what a pair
    /// stores, so the per-step code never normalizes). Call after [`Contour::validate`].
    pub fn normalized(&self) -> Contour {
        match self {
            Contour::Plane { point, normal } => Contour::Plane { point: *point, normal: normal.normalize() },
            Contour::Line { point, normal } => Contour::Line { point: *point, normal: normal.normalize() },
            Contour::Cylinder { center, axis, radius, half_length } => Contour::Cylinder {
                center: *center,
                axis: axis.normalize(),
                radius: *radius,
                half_length: *half_length,
            },
            Contour::Bore { center, axis, radius } => {
                Contour::Bore { center: *center, axis: axis.normalize(), radius: *radius }
            }
            Contour::Torus { center, axis, radius, tube } => {
                Contour::Torus { center: *center, axis: axis.normalize(), radius: *radius, tube: *tube }
            }
            Contour::Box { center, rotation, half_extents } => {
                // Gram–Schmidt on the columns; the third is the cross product so det = +1
                let x = rotation.column(0).normalize();
                let y = rotation.column(1) - x * x.dot(&rotation.column(1));
                let y = y.normalize();
                let z = x.cross(&y);
                Contour::Box { center: *center, rotation: Mat3::from_columns(&[x, y, z]), half_extents: *half_extents }
            }
            other => other.clone(),
        }
    }

    /// The world axis-aligned bounding box of the contour on a body at `pose`.
    ///
    /// Half-spaces are unbounded except along a world axis their normal is aligned with; planar
    /// contours are unbounded along every world axis the body's z axis has a component on.
    pub fn aabb(&self, pose: &Pose) -> Aabb {
        match self {
            Contour::Point { p } => Aabb::point(&pose.point_to_parent(p)),
            Contour::Sphere { center, radius } => Aabb::point(&pose.point_to_parent(center)).inflated(*radius),
            Contour::Plane { point, normal } => half_space_aabb(&pose.point_to_parent(point), &(pose.a * normal)),
            Contour::Box { center, rotation, half_extents } => {
                // the extent along world axis k is Σ_j |A_kj| h_j
                let a = pose.a * rotation;
                let c = pose.point_to_parent(center);
                let e = a.abs() * half_extents;
                Aabb { min: c - e, max: c + e }
            }
            Contour::Capsule { a, b, radius } => {
                let (pa, pb) = (pose.point_to_parent(a), pose.point_to_parent(b));
                Aabb { min: pa.inf(&pb), max: pa.sup(&pb) }.inflated(*radius)
            }
            Contour::Cylinder { center, axis, radius, half_length } => {
                let c = pose.point_to_parent(center);
                let u = pose.a * axis.normalize();
                // a disc of radius R with unit normal u spans R √(1 - u_k²) along axis k
                let e = Vec3::from_fn(|k, _| u[k].abs() * half_length + radius * (1.0 - u[k] * u[k]).max(0.0).sqrt());
                Aabb { min: c - e, max: c + e }
            }
            Contour::Torus { center, axis, radius, tube } => {
                let c = pose.point_to_parent(center);
                let u = pose.a * axis.normalize();
                // the rim circle spans R √(1 - u_k²) along axis k, the tube adds its radius
                let e = Vec3::from_fn(|k, _| radius * (1.0 - u[k] * u[k]).max(0.0).sqrt() + tube);
                Aabb { min: c - e, max: c + e }
            }
            Contour::Ellipsoid { center, rotation, semi_axes } => {
                // the extent along world axis k is √(Σ_j (A_kj a_j)²)
                let a = pose.a * rotation;
                let c = pose.point_to_parent(center);
                let e = Vec3::from_fn(|k, _| (0..3).map(|j| (a[(k, j)] * semi_axes[j]).powi(2)).sum::<f64>().sqrt());
                Aabb { min: c - e, max: c + e }
            }
            // a cavity's solid surrounds it: unbounded
            Contour::Bowl { .. } | Contour::Bore { .. } => Aabb::EVERYTHING,
            Contour::Point2 { p } => extruded(pose, Aabb::point(&lift(p))),
            Contour::Circle { center, radius } => {
                let c = lift(center);
                extruded(
                    pose,
                    Aabb { min: c - Vec3::new(*radius, *radius, 0.0), max: c + Vec3::new(*radius, *radius, 0.0) },
                )
            }
            Contour::Line { point, normal } => {
                half_space_aabb(&pose.point_to_parent(&lift(point)), &(pose.a * lift(normal)))
            }
            Contour::Polygon { vertices } => {
                let mut b = Aabb::EMPTY;
                for v in vertices {
                    b = b.union(&Aabb::point(&lift(v)));
                }
                extruded(pose, b)
            }
            Contour::Curve(c) if c.is_closed() => {
                let (center, radius) = c.bound();
                let h = Vec3::new(radius, radius, 0.0);
                extruded(pose, Aabb { min: lift(&center) - h, max: lift(&center) + h })
            }
            // an open curve continues along its end tangents
            Contour::Curve(_) => Aabb::EVERYTHING,
            Contour::Mesh(m) => {
                // the extent along world axis k is Σ_j |A_kj| h_j about the box centre
                let b = m.bounds();
                let c = pose.point_to_parent(&((b.min + b.max) * 0.5));
                let e = pose.a.abs() * ((b.max - b.min) * 0.5);
                Aabb { min: c - e, max: c + e }
            }
            Contour::Revolution(r) => match r.bound() {
                Some(radius) => Aabb::point(&pose.point_to_parent(&r.center)).inflated(radius),
                // an open profile continues along its end tangents
                None => Aabb::EVERYTHING,
            },
            Contour::Patch(p) => {
                let mut b = Aabb::EMPTY;
                for (c, r) in p.balls() {
                    b = b.union(&Aabb::point(&pose.point_to_parent(c)).inflated(*r));
                }
                b
            }
        }
    }
}

/// A planar vector as a 3-vector of the body's x-y plane.
impl Contour {
    /// The curvature tensor (second fundamental form, 1/m; convex > 0) of the contour's surface at
    /// the world point `p` on it, the body at `pose`, in the world tangent directions `t1`, `t2`
    /// (orthonormal, tangent to the surface at `p`): `[c11, c12, c22]` with `c_ij = t_iᵀ C t_j`.
    /// Two bodies touching at `p` with a common tangent plane have the relative curvature tensor
    /// `C₁ + C₂`, whose eigenvalues are twice Hertz's A and B whatever the angle between their
    /// principal directions. None where the curvature is undefined (edges, vertices, rims) or not
    /// available (meshes, parametric contours).
    ///
    /// # Example
    /// ```
    /// use mechsys_core::contact::Contour;
    /// use mechsys_core::math::Vec3;
    /// use mechsys_core::spatial::Pose;
    /// // a capsule along x: curved 1/R across its axis, straight along it
    /// let rod = Contour::Capsule { a: Vec3::new(-1.0, 0.0, 0.0), b: Vec3::new(1.0, 0.0, 0.0), radius: 0.5 };
    /// let c = rod.curvature_tensor_at(&Pose::IDENTITY, &Vec3::new(0.0, 0.0, 0.5), &Vec3::x(), &Vec3::y()).unwrap();
    /// assert!((c[0] - 0.0).abs() < 1e-15 && (c[2] - 2.0).abs() < 1e-15 && c[1].abs() < 1e-15);
    /// ```
    pub fn curvature_tensor_at(&self, pose: &Pose, p: &Vec3, t1: &Vec3, t2: &Vec3) -> Option<[f64; 3]> {
        let l = pose.a.transpose() * (p - pose.r);
        // tangent directions in body components
        let (u1, u2) = (pose.a.transpose() * t1, pose.a.transpose() * t2);
        let iso = |k: f64| Some([k, 0.0, k]);
        // principal curvature `ka` across a direction `d` (body frame, unit) along which the
        // curvature is `kb`, on a surface with unit normal `n`: C = ka (I − n nᵀ − d dᵀ) + kb d dᵀ
        let with_axis = |ka: f64, kb: f64, d: &Vec3, n: &Vec3| {
            let f = |x: &Vec3, y: &Vec3| {
                ka * (x.dot(y) - x.dot(n) * y.dot(n) - x.dot(d) * y.dot(d)) + kb * x.dot(d) * y.dot(d)
            };
            Some([f(&u1, &u1), f(&u1, &u2), f(&u2, &u2)])
        };
        match self {
            Contour::Sphere { radius, .. } => iso(1.0 / radius),
            Contour::Bowl { radius, .. } => iso(-1.0 / radius),
            Contour::Plane { .. } => iso(0.0),
            Contour::Ellipsoid { center, rotation, semi_axes } => {
                // the shape operator from the gradient and Hessian of F = ½ yᵀ D⁻² y
                let y = rotation.transpose() * (l - center);
                let dinv = Vec3::from_fn(|k, _| 1.0 / (semi_axes[k] * semi_axes[k]));
                let gn = y.component_mul(&dinv).norm();
                let (v1, v2) = (rotation.transpose() * u1, rotation.transpose() * u2);
                let h = |a: &Vec3, b: &Vec3| a.component_mul(&dinv).dot(b) / gn;
                Some([h(&v1, &v1), h(&v1, &v2), h(&v2, &v2)])
            }
            Contour::Torus { center, axis, radius, tube } if *tube > 0.0 => {
                // 1/ρ about the tube, cos φ / (R + ρ cos φ) along the rim (the circumferential
                // direction u × e_r)
                let u = axis.normalize();
                let y = l - center;
                let z = y.dot(&u);
                let radial = y - u * z;
                let rho = radial.norm();
                if rho <= 0.0 {
                    return None;
                }
                let e_r = radial / rho;
                let ring = e_r * *radius;
                let n = (y - ring).normalize();
                let cphi = ((rho - radius) / tube).clamp(-1.0, 1.0);
                with_axis(1.0 / tube, cphi / (radius + tube * cphi), &u.cross(&e_r), &n)
            }
            Contour::Capsule { a, b, radius } => {
                let d = b - a;
                let s = (l - a).dot(&d) / d.norm_squared();
                if s > 0.0 && s < 1.0 {
                    let axis = d.normalize();
                    let foot = a + d * s;
                    let n = (l - foot).normalize();
                    with_axis(1.0 / radius, 0.0, &axis, &n)
                } else {
                    iso(1.0 / radius)
                }
            }
            Contour::Cylinder { center, axis, radius, half_length } => {
                let u = axis.normalize();
                let y = l - center;
                let z = y.dot(&u);
                let radial = y - u * z;
                let rho = radial.norm();
                let tol = 1e-9 * radius.max(*half_length);
                let side = (rho - radius).abs() <= tol;
                let cap = (z.abs() - half_length).abs() <= tol;
                match (side, cap) {
                    (true, false) => with_axis(1.0 / radius, 0.0, &u, &(radial / rho)),
                    (false, true) => iso(0.0),
                    _ => None,
                }
            }
            _ => None,
        }
    }

    /// Principal curvatures (1/m; convex > 0, hollow < 0; `∞` at a point, a vertex or an edge,
    /// where no curvature is defined) of the contour's surface at the world point `p` on it, the
    /// body at `pose`. Planar contours are extruded along z, so their second curvature is 0.
    /// For queries and reports, not the step loop (a curve searches its parameter).
    ///
    /// # Example
    /// ```
    /// use mechsys_core::contact::Contour;
    /// use mechsys_core::math::Vec3;
    /// use mechsys_core::spatial::Pose;
    /// let ball = Contour::Sphere { center: Vec3::zeros(), radius: 0.5 };
    /// assert_eq!(ball.curvatures_at(&Pose::IDENTITY, &Vec3::new(0.0, 0.0, 0.5)), [2.0, 2.0]);
    /// ```
    pub fn curvatures_at(&self, pose: &Pose, p: &Vec3) -> [f64; 2] {
        let l = pose.a.transpose() * (p - pose.r);
        let inf = f64::INFINITY;
        match self {
            Contour::Point { .. } | Contour::Point2 { .. } => [inf, inf],
            Contour::Sphere { radius, .. } => [1.0 / radius, 1.0 / radius],
            Contour::Bowl { radius, .. } => [-1.0 / radius, -1.0 / radius],
            Contour::Torus { center, axis, radius, tube } => {
                // on the outer equator-like ring: the tube's curvature and the rim's (as seen
                // through the tube): 1/ρ about the tube, cos φ / (R + ρ cos φ) along the rim
                let u = axis.normalize();
                let y = l - center;
                let z = y.dot(&u);
                let rho = (y - u * z).norm();
                let cphi = ((rho - radius) / tube.max(1e-300)).clamp(-1.0, 1.0);
                if *tube > 0.0 {
                    [1.0 / tube, cphi / (radius + tube * cphi)]
                } else {
                    [inf, 1.0 / radius]
                }
            }
            Contour::Ellipsoid { center, rotation, semi_axes } => {
                // principal curvatures of the quadric at the point: the shape operator restricted to
                // the tangent plane, from the gradient and Hessian of F = ½ yᵀ D⁻² y
                let y = rotation.transpose() * (l - center);
                let dinv = Vec3::from_fn(|k, _| 1.0 / (semi_axes[k] * semi_axes[k]));
                let grad = y.component_mul(&dinv);
                let gn = grad.norm();
                let nrm = grad / gn;
                let t1 = if nrm.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
                let t1 = (t1 - nrm * nrm.dot(&t1)).normalize();
                let t2 = nrm.cross(&t1);
                let h = |u: &Vec3, v: &Vec3| u.component_mul(&dinv).dot(v) / gn;
                let (a11, a12, a22) = (h(&t1, &t1), h(&t1, &t2), h(&t2, &t2));
                let (m, d) = (0.5 * (a11 + a22), (0.25 * (a11 - a22).powi(2) + a12 * a12).sqrt());
                [m + d, m - d]
            }
            Contour::Bore { radius, .. } => [-1.0 / radius, 0.0],
            Contour::Plane { .. } | Contour::Line { .. } => [0.0, 0.0],
            Contour::Box { center, rotation, half_extents } => {
                // on a face: flat; on two or three faces at once (an edge, a corner): undefined
                let q = rotation.transpose() * (l - center);
                let tol = 1e-9 * half_extents.max();
                let on = (0..3).filter(|&k| (q[k].abs() - half_extents[k]).abs() <= tol).count();
                if on <= 1 {
                    [0.0, 0.0]
                } else {
                    [inf, inf]
                }
            }
            Contour::Capsule { a, b, radius } => {
                let d = b - a;
                let s = (l - a).dot(&d) / d.norm_squared();
                if s > 0.0 && s < 1.0 {
                    [1.0 / radius, 0.0]
                } else {
                    [1.0 / radius, 1.0 / radius]
                }
            }
            Contour::Cylinder { center, axis, radius, half_length } => {
                let u = axis.normalize();
                let y = l - center;
                let z = y.dot(&u);
                let rho = (y - u * z).norm();
                let tol = 1e-9 * radius.max(*half_length);
                let side = (rho - radius).abs() <= tol;
                let cap = (z.abs() - half_length).abs() <= tol;
                match (side, cap) {
                    (true, false) => [1.0 / radius, 0.0],
                    (false, true) => [0.0, 0.0],
                    _ => [inf, inf],
                }
            }
            Contour::Circle { radius, .. } => [1.0 / radius, 0.0],
            Contour::Polygon { vertices } => {
                let on_vertex = vertices.iter().any(|v| (Vec2::new(l.x, l.y) - v).norm() <= 1e-9 * (1.0 + v.norm()));
                if on_vertex {
                    [inf, 0.0]
                } else {
                    [0.0, 0.0]
                }
            }
            Contour::Curve(c) => {
                // the point lies on the offset contour: its foot on the base curve is the same
                let s = c.closest_parameter(&Vec2::new(l.x, l.y));
                [c.curvature(s), 0.0]
            }
            // flat faces; no curvature defined on an edge or at a vertex
            Contour::Mesh(m) => match m.closest(&l).feature {
                crate::geometry::mesh::Feature::Face => [0.0, 0.0],
                _ => [inf, inf],
            },
            Contour::Revolution(r) => {
                let (w, _) = Revolution::meridian(&r.local(&l));
                r.curvatures(r.foot(&w).0)
            }
            Contour::Patch(p) => Patch::curvatures(&p.eval(p.foot(&l))),
        }
    }
}

#[inline]
pub(crate) fn lift(v: &Vec2) -> Vec3 {
    Vec3::new(v.x, v.y, 0.0)
}

/// World box of a body-frame box swept along the body z axis without bound.
fn extruded(pose: &Pose, b: Aabb) -> Aabb {
    let c = (b.min + b.max) * 0.5;
    let h = (b.max - b.min) * 0.5;
    let w = pose.point_to_parent(&c);
    let e = pose.a.abs() * h;
    let mut out = Aabb { min: w - e, max: w + e };
    let z = pose.a.column(2);
    for k in 0..3 {
        if z[k].abs() > 1e-12 {
            out.min[k] = f64::NEG_INFINITY;
            out.max[k] = f64::INFINITY;
        }
    }
    out
}

fn half_space_aabb(p: &Vec3, n: &Vec3) -> Aabb {
    let mut b = Aabb::EVERYTHING;
    let nn = n.norm();
    for k in 0..3 {
        // solid below the normal: bounded above along +axis k, below along -axis k
        if (n[k].abs() - nn).abs() <= 1e-12 * nn {
            if n[k] > 0.0 {
                b.max[k] = p[k];
            } else {
                b.min[k] = p[k];
            }
        }
    }
    b
}

fn validate_polygon(v: &[Vec2], what: &str) -> Result<()> {
    ensure!(v.len() >= 3, Model, "{what}: polygon needs at least 3 vertices, got {}", v.len());
    for (i, p) in v.iter().enumerate() {
        finite2(p, what, &format!("polygon vertex {i}"))?;
    }
    let n = v.len();
    let scale = v.iter().map(|p| p.norm()).fold(0.0, f64::max).max(1e-300);
    for i in 0..n {
        ensure!(
            (v[(i + 1) % n] - v[i]).norm() > 1e-12 * scale,
            Model,
            "{what}: polygon vertices {i} and {} coincide",
            (i + 1) % n
        );
    }
    let mut turning = 0.0;
    let mut area2 = 0.0;
    for i in 0..n {
        let (a, b, c) = (v[i], v[(i + 1) % n], v[(i + 2) % n]);
        let (e1, e2) = (b - a, c - b);
        let cross = e1.x * e2.y - e1.y * e2.x;
        let dot = e1.dot(&e2);
        // left turns only; a straight continuation (collinear, same direction) is allowed
        let straight = cross.abs() <= 1e-12 * e1.norm() * e2.norm() && dot > 0.0;
        ensure!(
            cross > 0.0 || straight,
            Model,
            "{what}: polygon must be convex and counter-clockwise, but it turns clockwise or back at vertex {}",
            (i + 1) % n
        );
        turning += cross.atan2(dot);
        area2 += a.x * b.y - a.y * b.x;
    }
    // a star winding twice around turns left everywhere too; one turn is 2π
    ensure!(
        (turning - std::f64::consts::TAU).abs() < 1e-6 && area2 > 0.0,
        Model,
        "{what}: polygon must wind once counter-clockwise (total turning {turning:.4} rad, expected 2π)"
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(c: &Contour) -> String {
        c.validate("contact 'c'").unwrap_err().to_string()
    }

    #[test]
    fn validation_names_item_and_value() {
        let z = Vec3::zeros();
        assert!(err(&Contour::Sphere { center: z, radius: 0.0 }).contains("contact 'c': sphere radius must be > 0"));
        assert!(err(&Contour::Sphere { center: z, radius: f64::NAN }).contains("sphere radius"));
        assert!(err(&Contour::Sphere { center: Vec3::new(f64::INFINITY, 0.0, 0.0), radius: 1.0 })
            .contains("sphere center must be finite"));
        assert!(err(&Contour::Plane { point: z, normal: z }).contains("plane normal must not be the zero vector"));
        assert!(err(&Contour::Line { point: Vec2::zeros(), normal: Vec2::zeros() }).contains("line normal"));
        assert!(err(&Contour::Capsule { a: z, b: z, radius: 1.0 }).contains("capsule ends a and b must differ"));
        assert!(err(&Contour::Cylinder { center: z, axis: z, radius: 1.0, half_length: 1.0 })
            .contains("cylinder axis must not be the zero vector"));
        assert!(err(&Contour::Cylinder { center: z, axis: Vec3::z(), radius: 1.0, half_length: -1.0 })
            .contains("cylinder half_length must be > 0"));
        let bad_rot = Mat3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0);
        assert!(err(&Contour::Box { center: z, rotation: bad_rot, half_extents: Vec3::repeat(1.0) })
            .contains("determinant +1"));
        assert!(err(&Contour::Box { center: z, rotation: Mat3::identity(), half_extents: Vec3::new(1.0, 0.0, 1.0) })
            .contains("box half extent along y must be > 0"));
        assert!(err(&Contour::Circle { center: Vec2::zeros(), radius: -2.0 }).contains("got -2"));
        // valid ones pass
        for c in [
            Contour::Point { p: z },
            Contour::Sphere { center: z, radius: 1.0 },
            Contour::Plane { point: z, normal: Vec3::new(0.0, 0.0, 3.0) },
            Contour::Box { center: z, rotation: Mat3::identity(), half_extents: Vec3::repeat(0.5) },
            Contour::Capsule { a: z, b: Vec3::x(), radius: 0.1 },
            Contour::Cylinder { center: z, axis: Vec3::y(), radius: 0.1, half_length: 0.2 },
            Contour::Point2 { p: Vec2::zeros() },
            Contour::Circle { center: Vec2::zeros(), radius: 1.0 },
            Contour::Line { point: Vec2::zeros(), normal: Vec2::new(0.0, 2.0) },
        ] {
            c.validate("c").unwrap();
        }
    }

    #[test]
    fn polygon_must_be_convex_ccw_and_simple() {
        let sq =
            |pts: &[(f64, f64)]| Contour::Polygon { vertices: pts.iter().map(|&(x, y)| Vec2::new(x, y)).collect() };
        sq(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]).validate("p").unwrap();
        // a collinear mid-edge vertex is allowed (more support points along an edge)
        sq(&[(0.0, 0.0), (0.5, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]).validate("p").unwrap();
        assert!(err(&sq(&[(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)])).contains("counter-clockwise"));
        assert!(err(&sq(&[(0.0, 0.0), (1.0, 0.0), (0.2, 0.2), (0.0, 1.0)])).contains("turns clockwise"));
        assert!(err(&sq(&[(0.0, 0.0), (1.0, 0.0)])).contains("at least 3"));
        assert!(err(&sq(&[(0.0, 0.0), (1.0, 0.0), (1.0, 0.0), (0.0, 1.0)])).contains("coincide"));
        // back and forth along a line
        assert!(err(&sq(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)])).contains("turns clockwise or back"));
        // a pentagram turns left at every vertex but winds twice
        let star: Vec<(f64, f64)> = (0..5)
            .map(|k| {
                let a = std::f64::consts::TAU * (2 * k) as f64 / 5.0;
                (a.cos(), a.sin())
            })
            .collect();
        assert!(err(&sq(&star)).contains("wind once"));
    }

    #[test]
    fn normalized_has_unit_directions_and_rotation() {
        let c = Contour::Plane { point: Vec3::zeros(), normal: Vec3::new(0.0, 3.0, 4.0) };
        let Contour::Plane { normal, .. } = c.normalized() else { unreachable!() };
        assert!((normal - Vec3::new(0.0, 0.6, 0.8)).norm() < 1e-15);
        let r = nalgebra::Rotation3::from_euler_angles(0.3, 0.2, 0.1).into_inner() + Mat3::repeat(1e-8);
        let b = Contour::Box { center: Vec3::zeros(), rotation: r, half_extents: Vec3::repeat(1.0) };
        let Contour::Box { rotation, .. } = b.normalized() else { unreachable!() };
        assert!((rotation.transpose() * rotation - Mat3::identity()).norm() < 1e-14);
        assert!((rotation.determinant() - 1.0).abs() < 1e-14);
    }

    #[test]
    fn aabbs_contain_the_contour() {
        let pose =
            Pose::new(nalgebra::Rotation3::from_euler_angles(0.4, -0.3, 1.2).into_inner(), Vec3::new(1.0, 2.0, 3.0));
        let cyl = Contour::Cylinder {
            center: Vec3::new(0.1, 0.0, 0.2),
            axis: Vec3::new(1.0, 1.0, 0.0),
            radius: 0.3,
            half_length: 0.5,
        };
        let b = cyl.aabb(&pose);
        // sample the rims: every point inside, and the box tight to 1e-3 on each side
        let (c, u) = (pose.point_to_parent(&Vec3::new(0.1, 0.0, 0.2)), pose.a * Vec3::new(1.0, 1.0, 0.0).normalize());
        let e1 = u.cross(&Vec3::z()).normalize();
        let e2 = u.cross(&e1);
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for s in [-0.5, 0.5] {
            for k in 0..2000 {
                let phi = std::f64::consts::TAU * k as f64 / 2000.0;
                let p = c + u * s + (e1 * phi.cos() + e2 * phi.sin()) * 0.3;
                assert!(b.contains_point(&p));
                lo = lo.inf(&p);
                hi = hi.sup(&p);
            }
        }
        assert!((lo - b.min).norm() < 1e-3 && (hi - b.max).norm() < 1e-3);
        let bx =
            Contour::Box { center: Vec3::zeros(), rotation: Mat3::identity(), half_extents: Vec3::new(1.0, 2.0, 3.0) };
        let bb = bx.aabb(&Pose::IDENTITY);
        assert_eq!(bb.min, Vec3::new(-1.0, -2.0, -3.0));
        // a ground plane z ≤ 0 is bounded above in z only
        let pl = Contour::Plane { point: Vec3::zeros(), normal: Vec3::z() }.aabb(&Pose::IDENTITY);
        assert_eq!(pl.max.z, 0.0);
        assert!(pl.min.z == f64::NEG_INFINITY && pl.max.x == f64::INFINITY);
        // planar contours are unbounded along z
        let ci = Contour::Circle { center: Vec2::new(1.0, 0.0), radius: 0.5 }.aabb(&Pose::IDENTITY);
        assert_eq!((ci.min.x, ci.max.x), (0.5, 1.5));
        assert!(ci.min.z == f64::NEG_INFINITY && ci.max.z == f64::INFINITY);
    }
}
