//! Building a [`Model`] from a [`ModelDescription`]: every check a user's input can fail, each
//! error naming the item and the key path (`bodies[2] 'arm': mass must be > 0, got -1`).

use std::collections::{HashMap, HashSet};

use nalgebra::SymmetricEigen;

use super::contact_description::{FrictionDescription, NormalDescription};
use super::description::*;
use super::*;
use crate::error::{Error, Result};

fn err(msg: String) -> Error {
    Error::Model(msg)
}

/// A name is part of its signals' names (`body/<name>/position`) and of the results file's
/// paths: not empty, no '/', no control characters, not "." or "..", at most 200 bytes.
pub(crate) fn check_name(name: &str, what: &str) -> Result<()> {
    crate::ensure!(!name.trim().is_empty(), Model, "{what}: name must not be empty");
    let bad = name.chars().find(|c| *c == '/' || c.is_control());
    crate::ensure!(
        bad.is_none(),
        Model,
        "{what} {name:?}: a name must not contain {} (names are parts of signal names such as body/<name>/position)",
        match bad {
            Some('/') => "'/'".to_string(),
            Some(c) => format!("the control character {:?}", c),
            None => String::new(),
        }
    );
    crate::ensure!(name != "." && name != "..", Model, "{what}: '{name}' is not a usable name");
    crate::ensure!(name.len() <= 200, Model, "{what}: a name of {} bytes is too long (at most 200)", name.len());
    Ok(())
}

/// The curve of one path joint described alone (JSON of a joint entry), for looking at a path
/// before any model holds it. Errors name the joint.
pub fn path_curve_from_json(json: &str) -> Result<crate::kinematics::path::PathCurve> {
    let j: JointDescription =
        serde_json::from_str(json).map_err(|e| Error::Description { path: "joint".into(), message: e.to_string() })?;
    path_curve(&j, &format!("joint '{}'", j.name), j.oriented.unwrap_or(true))
}

/// The keys of a path joint's curves, with whether each is given.
fn path_keys(j: &JointDescription) -> [(bool, &'static str); 11] {
    [
        (j.curve.is_some(), "curve"),
        (j.radius.is_some(), "radius"),
        (j.pitch.is_some(), "pitch"),
        (j.clothoid_a.is_some(), "A"),
        (j.kappa0.is_some(), "kappa0"),
        (j.points.is_some(), "points"),
        (j.closed.is_some(), "closed"),
        (j.up.is_some(), "up"),
        (j.parameters.is_some(), "parameters"),
        (j.tangents.is_some(), "tangents"),
        (j.second_derivatives.is_some(), "second_derivatives"),
    ]
}

/// The curve of a path joint (`kinematics::path`) from its keys, each checked; `what` names the
/// joint. An oriented joint's spline must keep its tangent away from the frame's `up`.
pub fn path_curve(j: &JointDescription, what: &str, oriented: bool) -> Result<crate::kinematics::path::PathCurve> {
    use crate::kinematics::path::{Clothoid, Helix, PathCurve, Spline};
    let curve = j.curve.as_deref().unwrap_or("helix").to_ascii_lowercase();
    crate::ensure!(
        !(j.kind.eq_ignore_ascii_case("helix") && curve != "helix"),
        Model,
        "{what}.curve: a joint of type 'helix' is a helix; use type = \"path\" for a {curve}"
    );
    let own: &[&str] = match curve.as_str() {
        "helix" | "circle" => &["radius", "pitch"],
        "clothoid" | "euler_spiral" => &["A", "kappa0"],
        "spline" => &["points", "closed", "up"],
        "hermite" => &["parameters", "points", "tangents", "second_derivatives", "closed", "up"],
        other => {
            return Err(err(format!(
                "{what}.curve: unknown path curve '{other}' (expected helix, clothoid, spline or hermite)"
            )))
        }
    };
    for (given, key) in path_keys(j) {
        crate::ensure!(
            !given || key == "curve" || own.contains(&key),
            Model,
            "{what}.{key}: a {curve} path has no {key} (its keys: {})",
            own.join(", ")
        );
    }
    let to_vec = |a: &[f64; 3]| Vec3::new(a[0], a[1], a[2]);
    let spline = |r: std::result::Result<Spline, String>| -> Result<PathCurve> {
        let sp = r.map_err(|m| err(format!("{what}.{m}")))?;
        if oriented {
            let (clear, at) = sp.up_clearance;
            let min = 5f64.to_radians().sin();
            crate::ensure!(
                clear >= min,
                Model,
                "{what}.up: the path runs within {:.2}° of the frame's reference direction up = [{:.4}, {:.4}, {:.4}] \
                 (near s = {at:.4} m), where its binormal is undefined; an oriented path needs 5° or more: give an `up` \
                 across the path, or oriented = false",
                clear.asin().to_degrees(),
                sp.up.x,
                sp.up.y,
                sp.up.z
            );
        }
        Ok(PathCurve::Spline(std::sync::Arc::new(sp)))
    };
    match curve.as_str() {
        "helix" | "circle" => {
            let radius =
                j.radius.ok_or_else(|| err(format!("{what}.radius: a path joint needs the helix radius (m)")))?;
            crate::ensure!(
                radius.is_finite() && radius > 0.0,
                Model,
                "{what}.radius: must be > 0, got {radius} (a straight path is a prismatic joint)"
            );
            let pitch = j.pitch.unwrap_or(0.0);
            crate::ensure!(pitch.is_finite(), Model, "{what}.pitch: must be finite, got {pitch}");
            Ok(PathCurve::Helix(Helix { radius, lead: pitch / std::f64::consts::TAU }))
        }
        "clothoid" | "euler_spiral" => {
            let a = j
                .clothoid_a
                .ok_or_else(|| err(format!("{what}.A: a clothoid needs its parameter A (m; κ = κ0 + s/A²)")))?;
            crate::ensure!(a.is_finite() && a > 0.0, Model, "{what}.A: must be > 0, got {a}");
            let kappa0 = j.kappa0.unwrap_or(0.0);
            crate::ensure!(kappa0.is_finite(), Model, "{what}.kappa0: must be finite, got {kappa0}");
            Ok(PathCurve::Clothoid(Clothoid { a, kappa0 }))
        }
        "spline" => {
            let pts = j
                .points
                .as_ref()
                .ok_or_else(|| err(format!("{what}.points: a spline needs the points it passes through")))?;
            let pts: Vec<Vec3> = pts.iter().map(to_vec).collect();
            spline(Spline::through_points(&pts, j.closed.unwrap_or(false), j.up.as_ref().map(to_vec)))
        }
        _ => {
            let need = |v: &Option<Vec<[f64; 3]>>, key: &str| -> Result<Vec<Vec3>> {
                v.as_ref().map(|x| x.iter().map(to_vec).collect()).ok_or_else(|| {
                    err(format!(
                        "{what}.{key}: a hermite path needs parameters, points, tangents and second_derivatives"
                    ))
                })
            };
            let p = j.parameters.clone().ok_or_else(|| {
                err(format!(
                    "{what}.parameters: a hermite path needs parameters, points, tangents and second_derivatives"
                ))
            })?;
            let (r, d1, d2) = (
                need(&j.points, "points")?,
                need(&j.tangents, "tangents")?,
                need(&j.second_derivatives, "second_derivatives")?,
            );
            spline(Spline::hermite(&p, &r, &d1, &d2, j.closed.unwrap_or(false), j.up.as_ref().map(to_vec)))
        }
    }
}

fn finite3(v: &[f64; 3], what: &str) -> Result<Vec3> {
    crate::ensure!(v.iter().all(|x| x.is_finite()), Model, "{what}: must be finite, got {v:?}");
    Ok(Vec3::new(v[0], v[1], v[2]))
}

/// A symmetric 6×6 matrix from 6 diagonal values or 36 row-major values (empty: zero).
fn matrix6(v: &[f64], what: &str) -> Result<nalgebra::Matrix6<f64>> {
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(err(format!("{what}[{i}]: must be finite, got {}", v[i])));
    }
    let m = match v.len() {
        0 => nalgebra::Matrix6::zeros(),
        6 => nalgebra::Matrix6::from_diagonal(&nalgebra::Vector6::from_column_slice(v)),
        36 => nalgebra::Matrix6::from_row_slice(v),
        n => return Err(err(format!("{what}: expected 6 diagonal values or a 6x6 matrix (36 values), got {n}"))),
    };
    let asym = (m - m.transpose()).abs().max();
    crate::ensure!(asym <= 1e-12 * m.abs().max().max(1.0), Model, "{what}: the 6x6 matrix must be symmetric");
    let low = m.symmetric_eigen().eigenvalues.min();
    crate::ensure!(
        low >= -1e-12 * m.abs().max(),
        Model,
        "{what}: must be positive semidefinite (smallest eigenvalue {low:.3e})"
    );
    Ok(m)
}

fn unit_axis(v: &[f64; 3], what: &str) -> Result<Vec3> {
    let a = finite3(v, what)?;
    let n = a.norm();
    crate::ensure!(n > 1e-12, Model, "{what}: axis must not be zero, got {v:?}");
    Ok(a / n)
}

/// A unit vector from a nonzero finite direction; the error names the key.
fn nonzero_direction(v: &[f64; 3], what: &str) -> Result<Vec3> {
    let a = finite3(v, what)?;
    let n = a.norm();
    crate::ensure!(n > 1e-12, Model, "{what}: must not be the zero vector, got {v:?}");
    Ok(a / n)
}

fn rotation(r: &Option<RotationDescription>, what: &str) -> Result<Mat3> {
    let Some(r) = r else { return Ok(Mat3::identity()) };
    match r {
        RotationDescription::Quaternion(q) => {
            crate::ensure!(q.iter().all(|x| x.is_finite()), Model, "{what}: quaternion must be finite, got {q:?}");
            let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
            crate::ensure!(n > 1e-12, Model, "{what}: quaternion must not be zero");
            Ok(joint::quat_matrix(q[0] / n, q[1] / n, q[2] / n, q[3] / n))
        }
        RotationDescription::Matrix(m) => {
            let a = Mat3::from_fn(|i, j| m[i][j]);
            crate::ensure!(a.iter().all(|x| x.is_finite()), Model, "{what}: rotation matrix must be finite");
            let e = (a.transpose() * a - Mat3::identity()).norm();
            crate::ensure!(
                e < 1e-6 && a.determinant() > 0.0,
                Model,
                "{what}: rotation matrix must be orthonormal with determinant +1 (|AᵀA - E| = {e:.2e})"
            );
            Ok(a)
        }
        RotationDescription::Angles(ang) => {
            let given = [ang.cardan.is_some(), ang.euler.is_some(), ang.rotvec.is_some()];
            crate::ensure!(
                given.iter().filter(|g| **g).count() == 1,
                Model,
                "{what}: give exactly one of cardan, euler, rotvec"
            );
            if let Some(c) = ang.cardan {
                let c = finite3(&c, what)?;
                let (x, y, z) = (Vec3::x(), Vec3::y(), Vec3::z());
                // eq. 2.19: A_IB = A_α A_β A_γ
                Ok(joint::axis_rotation(&x, c[0]) * joint::axis_rotation(&y, c[1]) * joint::axis_rotation(&z, c[2]))
            } else if let Some(e) = ang.euler {
                let e = finite3(&e, what)?;
                let (x, z) = (Vec3::x(), Vec3::z());
                // eq. 2.15: A_IB = A_ψ A_ϑ A_φ
                Ok(joint::axis_rotation(&z, e[0]) * joint::axis_rotation(&x, e[1]) * joint::axis_rotation(&z, e[2]))
            } else {
                let r = finite3(&ang.rotvec.unwrap_or_default(), what)?;
                let n = r.norm();
                if n < 1e-300 {
                    Ok(Mat3::identity())
                } else {
                    Ok(joint::axis_rotation(&(r / n), n))
                }
            }
        }
    }
}

fn frame(f: &FrameDescription, what: &str) -> Result<Pose> {
    Ok(Pose::new(rotation(&f.rotation, what)?, finite3(&f.position, &format!("{what}.position"))?))
}

/// Checks and returns an inertia tensor about the centre of mass.
pub(crate) fn inertia(desc: &InertiaDescription, what: &str) -> Result<Mat3> {
    let m = match desc {
        InertiaDescription::Matrix(m) => Mat3::from_fn(|i, j| m[i][j]),
        InertiaDescription::List(v) => match v.len() {
            3 => Mat3::from_diagonal(&Vec3::new(v[0], v[1], v[2])),
            6 => Mat3::new(v[0], v[3], v[4], v[3], v[1], v[5], v[4], v[5], v[2]),
            n => {
                return Err(err(format!(
                    "{what}: give 3 (diagonal), 6 (Ixx Iyy Izz Ixy Ixz Iyz) or 3×3 values, got {n}"
                )))
            }
        },
    };
    crate::ensure!(m.iter().all(|x| x.is_finite()), Model, "{what}: must be finite, got {m:?}");
    let scale = m.abs().max().max(f64::MIN_POSITIVE);
    crate::ensure!((m - m.transpose()).abs().max() <= 1e-9 * scale, Model, "{what}: inertia tensor must be symmetric");
    let mut eig: Vec<f64> = SymmetricEigen::new(m).eigenvalues.iter().copied().collect();
    eig.sort_by(|x, y| x.total_cmp(y));
    let (a, b, c) = (eig[0], eig[1], eig[2]);
    // zero moments are allowed (a point mass, a thin rod about its axis): a coordinate that then
    // moves nothing with inertia is reported by name when a run starts
    let floor = -1e-12 * scale;
    crate::ensure!(
        a >= floor && b >= floor && c >= floor,
        Model,
        "{what}: inertia tensor has a negative principal moment (principal moments {a:.6e}, {b:.6e}, {c:.6e})"
    );
    // triangle inequalities of the principal moments: each ≤ sum of the other two
    let tol = 1e-9 * (a + b + c);
    crate::ensure!(
        a <= b + c + tol && b <= a + c + tol && c <= a + b + tol,
        Model,
        "{what}: principal moments {a:.6e}, {b:.6e}, {c:.6e} violate the triangle inequality (no mass distribution has them)"
    );
    Ok(m)
}

fn time_function(f: &Option<TimeFunctionDescription>, what: &str, n_cb: &mut usize) -> Result<TimeFunction> {
    let Some(f) = f else { return Ok(TimeFunction::Constant(1.0)) };
    let check = |x: f64, k: &str| -> Result<()> {
        crate::ensure!(x.is_finite(), Model, "{what}.{k}: must be finite, got {x}");
        Ok(())
    };
    Ok(match f {
        TimeFunctionDescription::Constant { value } => {
            check(*value, "value")?;
            TimeFunction::Constant(*value)
        }
        TimeFunctionDescription::Ramp { slope, t0, final_value } => {
            check(*slope, "slope")?;
            check(*t0, "t0")?;
            if let Some(v) = final_value {
                check(*v, "final_value")?;
            }
            TimeFunction::Ramp { slope: *slope, t0: *t0, final_value: *final_value }
        }
        TimeFunctionDescription::Harmonic { amplitude, omega, phase, offset } => {
            for (x, k) in [(amplitude, "amplitude"), (omega, "omega"), (phase, "phase"), (offset, "offset")] {
                check(*x, k)?;
            }
            TimeFunction::Harmonic { amplitude: *amplitude, omega: *omega, phase: *phase, offset: *offset }
        }
        TimeFunctionDescription::Table { t, values } => {
            table(t, values, what, "t", "values")?;
            TimeFunction::Table { t: t.clone(), values: values.clone() }
        }
        TimeFunctionDescription::Callback { id } => {
            crate::ensure!(*id < 1 << 32, Model, "{what}.id: callback index {id} is out of range");
            *n_cb = (*n_cb).max(id + 1);
            TimeFunction::Callback(*id)
        }
    })
}

fn table(x: &[f64], y: &[f64], what: &str, kx: &str, ky: &str) -> Result<()> {
    crate::ensure!(!x.is_empty(), Model, "{what}.{kx}: table must not be empty");
    crate::ensure!(x.len() == y.len(), Model, "{what}: {kx} has {} entries but {ky} has {}", x.len(), y.len());
    crate::ensure!(x.iter().chain(y).all(|v| v.is_finite()), Model, "{what}: table entries must be finite");
    crate::ensure!(x.windows(2).all(|w| w[1] > w[0]), Model, "{what}.{kx}: must be strictly increasing");
    Ok(())
}

fn per_dof(v: &[f64], n: usize, what: &str) -> Result<Vec<f64>> {
    crate::ensure!(v.iter().all(|x| x.is_finite()), Model, "{what}: must be finite, got {v:?}");
    if v.len() == 1 {
        Ok(vec![v[0]; n])
    } else {
        let expected = if n == 1 { "1 value".to_string() } else { format!("1 or {n} values (one per joint velocity)") };
        crate::ensure!(v.len() == n, Model, "{what}: expected {expected}, got {}", v.len());
        Ok(v.to_vec())
    }
}

impl Model {
    /// Parses a JSON model description and validates it.
    pub fn from_json(text: &str) -> Result<Model> {
        Model::from_description(ModelDescription::from_json(text)?)
    }

    /// Validates a description and builds the model.
    pub fn from_description(desc: ModelDescription) -> Result<Model> {
        let g = finite3(&desc.gravity, "gravity")?;

        // ---- bodies ----------------------------------------------------------------------------
        let mut names: HashMap<String, usize> = HashMap::new();
        names.insert("ground".to_string(), 0);
        for (i, b) in desc.bodies.iter().enumerate() {
            let what = format!("bodies[{i}] '{}'", b.name);
            check_name(&b.name, &format!("bodies[{i}]"))?;
            crate::ensure!(b.name != "ground", Model, "{what}: the name 'ground' is reserved for the inertial frame");
            crate::ensure!(
                names.insert(b.name.clone(), i + 1).is_none(),
                Model,
                "{what}: duplicate body name '{}'",
                b.name
            );
        }

        // ---- joints: tree structure ---------------------------------------------------------------
        let mut joint_names = HashSet::new();
        let mut parent_joint: HashMap<usize, usize> = HashMap::new(); // desc body idx -> desc joint idx
        for (i, j) in desc.joints.iter().enumerate() {
            let what = format!("joints[{i}] '{}'", j.name);
            check_name(&j.name, &format!("joints[{i}]"))?;
            crate::ensure!(joint_names.insert(j.name.clone()), Model, "{what}: duplicate joint name '{}'", j.name);
            let p = *names.get(&j.parent).ok_or_else(|| err(format!("{what}.parent: unknown body '{}'", j.parent)))?;
            let c = *names.get(&j.child).ok_or_else(|| err(format!("{what}.child: unknown body '{}'", j.child)))?;
            crate::ensure!(c != 0, Model, "{what}.child: the ground cannot be a child");
            crate::ensure!(p != c, Model, "{what}: parent and child are the same body '{}'", j.child);
            if let Some(other) = parent_joint.insert(c, i) {
                return Err(err(format!(
                    "{what}: body '{}' already has parent joint '{}'; a second one closes a loop (use a constraint)",
                    j.child, desc.joints[other].name
                )));
            }
        }
        for (i, b) in desc.bodies.iter().enumerate() {
            crate::ensure!(
                parent_joint.contains_key(&(i + 1)),
                Model,
                "bodies[{i}] '{}': no joint connects it (add a joint with child = '{}'; use type 'free' for a floating body)",
                b.name,
                b.name
            );
        }
        // topological order from the ground, keeping the user's order among siblings
        let mut order: Vec<usize> = Vec::with_capacity(desc.joints.len()); // desc joint indices
        let mut placed = vec![false; desc.bodies.len() + 1];
        placed[0] = true;
        while order.len() < desc.joints.len() {
            let before = order.len();
            for (i, j) in desc.joints.iter().enumerate() {
                let (p, c) = (names[&j.parent], names[&j.child]);
                if !placed[c] && placed[p] {
                    placed[c] = true;
                    order.push(i);
                }
            }
            if order.len() == before {
                let stuck: Vec<&str> =
                    desc.joints.iter().filter(|j| !placed[names[&j.child]]).map(|j| j.name.as_str()).collect();
                return Err(err(format!(
                    "joints {stuck:?} form a cycle not connected to the ground; joints must form a tree rooted at 'ground'"
                )));
            }
        }
        // new body index of each description body
        let mut new_index = vec![0usize; desc.bodies.len() + 1];
        for (k, &ji) in order.iter().enumerate() {
            new_index[names[&desc.joints[ji].child]] = k + 1;
        }

        // ---- bodies, checked -----------------------------------------------------------------------
        let mut bodies = vec![Body {
            name: "ground".into(),
            mass: 0.0,
            com: Vec3::zeros(),
            inertia: Mat3::zeros(),
            markers: markers(&desc.ground_markers, "ground_markers")?,
            mass_rate: 0.0,
            ejection_velocity: Vec3::zeros(),
            ejection_point: Vec3::zeros(),
            mass_final: 0.0,
            principal_axes: true,
            elastic: None,
        }];
        let mut variable_mass = false;
        for &ji in &order {
            let bi = names[&desc.joints[ji].child] - 1;
            let b = &desc.bodies[bi];
            let what = format!("bodies[{bi}] '{}'", b.name);
            crate::ensure!(b.mass.is_finite() && b.mass > 0.0, Model, "{what}.mass: must be > 0, got {}", b.mass);
            let com = finite3(&b.com, &format!("{what}.com"))?;
            let i_c = inertia(&b.inertia, &format!("{what}.inertia"))?;
            crate::ensure!(b.mass_rate.is_finite(), Model, "{what}.mass_rate: must be finite");
            let mass_final = if b.mass_rate != 0.0 {
                variable_mass = true;
                let mf = b.mass_final.ok_or_else(|| {
                    err(format!("{what}.mass_final: required with a mass_rate (the mass at which the flow stops)"))
                })?;
                crate::ensure!(mf.is_finite() && mf > 0.0, Model, "{what}.mass_final: must be > 0, got {mf}");
                crate::ensure!(
                    (b.mass_rate < 0.0 && mf < b.mass) || (b.mass_rate > 0.0 && mf > b.mass),
                    Model,
                    "{what}.mass_final: {mf} is not reached from mass {} with mass_rate {}",
                    b.mass,
                    b.mass_rate
                );
                mf
            } else {
                b.mass
            };
            bodies.push(Body {
                name: b.name.clone(),
                mass: b.mass,
                com,
                inertia: i_c,
                markers: markers(&b.markers, &format!("{what}.markers"))?,
                mass_rate: b.mass_rate,
                ejection_velocity: finite3(&b.ejection_velocity, &format!("{what}.ejection_velocity"))?,
                ejection_point: match &b.ejection_point {
                    Some(p) => finite3(p, &format!("{what}.ejection_point"))?,
                    None => com,
                },
                mass_final,
                principal_axes: i_c.iter().enumerate().all(|(k, v)| k % 4 == 0 || *v == 0.0),
                elastic: None,
            });
        }

        // ---- joints, checked -------------------------------------------------------------------------
        let mut joints = Vec::with_capacity(order.len());
        let (mut iq, mut iu) = (0usize, 0usize);
        for &ji in &order {
            let j = &desc.joints[ji];
            let what = format!("joints[{ji}] '{}'", j.name);
            let axis = |a: &Option<[f64; 3]>, d: [f64; 3], k: &str| unit_axis(&a.unwrap_or(d), &format!("{what}.{k}"));
            let kind = match j.kind.to_ascii_lowercase().as_str() {
                "fixed" => JointKind::Fixed,
                "revolute" => JointKind::Revolute { axis: axis(&j.axis, [0.0, 0.0, 1.0], "axis")? },
                "prismatic" => JointKind::Prismatic { axis: axis(&j.axis, [0.0, 0.0, 1.0], "axis")? },
                "cylindrical" => JointKind::Cylindrical { axis: axis(&j.axis, [0.0, 0.0, 1.0], "axis")? },
                "universal" => {
                    let a1 = axis(&j.axis, [1.0, 0.0, 0.0], "axis")?;
                    let a2 = axis(&j.axis2, [0.0, 1.0, 0.0], "axis2")?;
                    crate::ensure!(
                        a1.cross(&a2).norm() > 1e-6,
                        Model,
                        "{what}: axis and axis2 of a universal joint must not be parallel"
                    );
                    JointKind::Universal { axis1: a1, axis2: a2 }
                }
                "spherical" | "ball" => JointKind::Spherical,
                "planar" => JointKind::Planar,
                "free" | "floating" => JointKind::Free,
                "path" | "helix" => {
                    let oriented = j.oriented.unwrap_or(true);
                    JointKind::Path { curve: path_curve(j, &what, oriented)?, oriented }
                }
                other => {
                    return Err(err(format!(
                        "{what}.type: unknown joint type '{other}' (expected fixed, revolute, prismatic, cylindrical, universal, spherical, planar, free or path)"
                    )))
                }
            };
            if !matches!(kind, JointKind::Path { .. }) {
                for (given, key) in path_keys(j) {
                    crate::ensure!(!given, Model, "{what}.{key}: only a path joint has a {key}");
                }
                crate::ensure!(j.oriented.is_none(), Model, "{what}.oriented: only a path joint has an oriented");
            }
            if !matches!(
                kind,
                JointKind::Revolute { .. }
                    | JointKind::Prismatic { .. }
                    | JointKind::Cylindrical { .. }
                    | JointKind::Universal { .. }
            ) {
                crate::ensure!(j.axis.is_none(), Model, "{what}.axis: a {} joint has no axis", kind.type_name());
            }
            if !matches!(kind, JointKind::Universal { .. }) {
                crate::ensure!(j.axis2.is_none(), Model, "{what}.axis2: only universal joints have a second axis");
            }
            let (nq, nu) = (kind.nq(), kind.nu());
            let mut q0 = vec![0.0; nq];
            kind.neutral(&mut q0);
            if let Some(v) = &j.q0 {
                crate::ensure!(
                    v.len() == nq,
                    Model,
                    "{what}.q0: a {} joint has {nq} coordinates, got {}",
                    kind.type_name(),
                    v.len()
                );
                crate::ensure!(v.iter().all(|x| x.is_finite()), Model, "{what}.q0: must be finite, got {v:?}");
                q0.copy_from_slice(v);
                if kind.has_quaternion() {
                    let r = if matches!(kind, JointKind::Free) { 3..7 } else { 0..4 };
                    let n: f64 = q0[r].iter().map(|x| x * x).sum::<f64>().sqrt();
                    crate::ensure!(n > 1e-12, Model, "{what}.q0: the quaternion part must not be zero");
                    kind.normalize(&mut q0);
                }
            }
            let u0 = match &j.u0 {
                Some(v) => {
                    crate::ensure!(
                        v.len() == nu,
                        Model,
                        "{what}.u0: a {} joint has {nu} velocities, got {}",
                        kind.type_name(),
                        v.len()
                    );
                    crate::ensure!(v.iter().all(|x| x.is_finite()), Model, "{what}.u0: must be finite, got {v:?}");
                    v.clone()
                }
                None => vec![0.0; nu],
            };
            let spring = match &j.spring {
                Some(s) => {
                    crate::ensure!(
                        !kind.has_quaternion() && nu > 0,
                        Model,
                        "{what}.spring: joint springs need coordinate-per-velocity joints (not {})",
                        kind.type_name()
                    );
                    let k = per_dof(&s.k, nu, &format!("{what}.spring.k"))?;
                    let q_free = match &s.q_free {
                        Some(q) => per_dof(q, nq, &format!("{what}.spring.q_free"))?,
                        None => vec![0.0; nq],
                    };
                    Some(JointSpring { k, q_free })
                }
                None => None,
            };
            let damper = match &j.damper {
                Some(d) => {
                    crate::ensure!(nu > 0, Model, "{what}.damper: a fixed joint cannot have a damper");
                    per_dof(&d.d, nu, &format!("{what}.damper.d"))?
                }
                None => vec![],
            };
            let child_frame = frame(&j.child_frame, &format!("{what}.child_frame"))?;
            let parent_frame = frame(&j.parent_frame, &format!("{what}.parent_frame"))?;
            let coordinate_axis = match kind {
                JointKind::Revolute { axis } => (0..3).find(|&k| axis[k] == 1.0),
                _ => None,
            };
            joints.push(Joint {
                name: j.name.clone(),
                kind,
                parent: new_index[names[&j.parent]],
                child: new_index[names[&j.child]],
                parent_frame,
                child_frame,
                child_frame_inv: child_frame.inverse(),
                frames_plain: (parent_frame.rotation_is_identity(), child_frame.rotation_is_identity()),
                coordinate_axis,
                iq,
                iu,
                q0,
                u0,
                spring,
                damper,
            });
            iq += nq;
            iu += nu;
        }

        // ---- elastic bodies: their coordinates after every joint's ---------------------------------
        let mut elastic = Vec::new();
        for &ji in &order {
            let bi = names[&desc.joints[ji].child] - 1;
            let b = &desc.bodies[bi];
            if let Some(ed) = &b.elastic {
                let k = new_index[bi + 1];
                crate::ensure!(
                    b.mass_rate == 0.0,
                    Model,
                    "bodies[{bi}] '{}': an elastic body of variable mass is not supported",
                    b.name
                );
                let body = &bodies[k];
                let e = crate::elastic::validate(
                    ed,
                    k,
                    body.mass,
                    &body.com,
                    &body.inertia,
                    iq,
                    iu,
                    &format!("bodies[{bi}] '{}'", b.name),
                )?;
                iq += e.ne;
                iu += e.ne;
                bodies[k].elastic = Some(elastic.len());
                elastic.push(e);
            }
        }

        // a tree joint rides on its parent's reference frame: at a node that deflects it would
        // silently leave the node behind, so it must be a loop joint there (which follows the node)
        for (ji, j) in joints.iter().enumerate() {
            let Some(ke) = bodies[j.parent].elastic else { continue };
            let e = &elastic[ke];
            let p = &j.parent_frame.r;
            let tol = 1e-12 * (1.0 + p.norm());
            if let Some(node) = e.nodes.iter().find(|n| (n.position - p).amax() <= tol) {
                let moves = node.translation.iter().chain(&node.rotation).any(|v| v.amax() > 0.0);
                crate::ensure!(
                    !moves,
                    Model,
                    "joint '{}': its parent frame is at node '{}' of elastic body '{}', which deflects; a tree joint \
                     moves with the body's reference frame only. Give body '{}' a free (or planar) joint and attach it \
                     there with a loop joint (constraints.LoopRevolute, LoopFixed, ... with frame1 at the node), which \
                     follows the node's deflection and rotation",
                    j.name,
                    node.name,
                    bodies[j.parent].name,
                    bodies[ji + 1].name
                );
            }
        }

        // ---- force elements ------------------------------------------------------------------------
        let body = |n: &str, what: &str| -> Result<usize> {
            names.get(n).map(|&i| new_index[i]).ok_or_else(|| err(format!("{what}: unknown body '{n}'")))
        };
        let joint_index: HashMap<String, usize> = joints.iter().enumerate().map(|(i, j)| (j.name.clone(), i)).collect();
        let mut n_callbacks = 0usize;
        let mut n_sliders = 0usize;
        let mut force_names = HashSet::new();
        let mut forces = Vec::with_capacity(desc.forces.len());
        for (i, f) in desc.forces.iter().enumerate() {
            let name = match f {
                ForceDescription::SpringDamper { name, .. }
                | ForceDescription::BodyForce { name, .. }
                | ForceDescription::JointForce { name, .. }
                | ForceDescription::Servo { name, .. }
                | ForceDescription::Bushing { name, .. }
                | ForceDescription::SqueezeFilm { name, .. }
                | ForceDescription::JournalBearing { name, .. }
                | ForceDescription::Jenkins { name, .. }
                | ForceDescription::HydrodynamicBearing { name, .. }
                | ForceDescription::Callback { name, .. } => name.clone(),
            };
            let what = format!("forces[{i}] '{name}'");
            // a name is how its signals are found (force/<name>/...)
            check_name(&name, &format!("forces[{i}]"))?;
            crate::ensure!(force_names.insert(name.clone()), Model, "{what}: duplicate force element name");
            forces.push(match f {
                ForceDescription::SpringDamper {
                    body1,
                    point1,
                    body2,
                    point2,
                    k,
                    k3,
                    d,
                    l0,
                    table_deflection,
                    table_force,
                    travel,
                    ..
                } => {
                    for (x, key) in [(k, "k"), (k3, "k3"), (d, "d"), (l0, "l0")] {
                        crate::ensure!(x.is_finite(), Model, "{what}.{key}: must be finite, got {x}");
                    }
                    if let Some(s) = travel {
                        crate::ensure!(s.is_finite() && *s > 0.0, Model, "{what}.travel: must be > 0 (m), got {s}");
                    }
                    crate::ensure!(*l0 >= 0.0, Model, "{what}.l0: must be >= 0, got {l0}");
                    let b1 = body(body1, &format!("{what}.body1"))?;
                    let b2 = body(body2, &format!("{what}.body2"))?;
                    crate::ensure!(b1 != b2, Model, "{what}: body1 and body2 are the same body '{body1}'");
                    let tab = match (table_deflection, table_force) {
                        (None, None) => (vec![], vec![]),
                        (Some(x), Some(y)) => {
                            table(x, y, &what, "table_deflection", "table_force")?;
                            (x.clone(), y.clone())
                        }
                        _ => return Err(err(format!("{what}: give both table_deflection and table_force"))),
                    };
                    ForceElement::SpringDamper {
                        name,
                        body1: b1,
                        point1: finite3(point1, &format!("{what}.point1"))?,
                        body2: b2,
                        point2: finite3(point2, &format!("{what}.point2"))?,
                        k: *k,
                        k3: *k3,
                        d: *d,
                        l0: *l0,
                        table: tab,
                        travel: travel.unwrap_or(0.0),
                    }
                }
                ForceDescription::Bushing { body1, frame1, body2, frame2, k, d, travel, .. } => {
                    let b1 = body(body1, &format!("{what}.body1"))?;
                    let b2 = body(body2, &format!("{what}.body2"))?;
                    crate::ensure!(b1 != b2, Model, "{what}: body1 and body2 are the same body '{body1}'");
                    let km = matrix6(k, &format!("{what}.k"))?;
                    let dm = matrix6(d, &format!("{what}.d"))?;
                    if let Some(s) = travel {
                        crate::ensure!(
                            s.iter().all(|x| x.is_finite() && *x > 0.0),
                            Model,
                            "{what}.travel: every stop travel must be > 0, got {s:?}"
                        );
                        crate::ensure!(
                            k.len() <= 6 && d.len() <= 6,
                            Model,
                            "{what}.travel: a progressive bushing takes diagonal k and d (6 values each)"
                        );
                    }
                    ForceElement::Bushing {
                        name,
                        body1: b1,
                        frame1: frame(frame1, &format!("{what}.frame1"))?,
                        body2: b2,
                        frame2: frame(frame2, &format!("{what}.frame2"))?,
                        k: km,
                        d: dm,
                        travel: *travel,
                    }
                }
                ForceDescription::SqueezeFilm {
                    body1, point1, normal, body2, point2, eta, length, area, gap, ..
                } => {
                    let b1 = body(body1, &format!("{what}.body1"))?;
                    let b2 = body(body2, &format!("{what}.body2"))?;
                    crate::ensure!(b1 != b2, Model, "{what}: body1 and body2 are the same body '{body1}'");
                    for (x, key, unit) in [(eta, "eta", "Pa s"), (length, "length", "m"), (area, "area", "m²"), (gap, "gap", "m")] {
                        crate::ensure!(x.is_finite() && *x > 0.0, Model, "{what}.{key}: must be > 0 ({unit}), got {x}");
                    }
                    // eq. 2.211 is a thin-film (boundary-layer) law: h ≪ l
                    crate::ensure!(
                        *gap <= 0.1 * length,
                        Model,
                        "{what}.gap: {gap} m is outside the thin-film validity of eq. 2.211 (gap ≤ length/10 = {} m)",
                        0.1 * length
                    );
                    ForceElement::SqueezeFilm {
                        name,
                        body1: b1,
                        point1: finite3(point1, &format!("{what}.point1"))?,
                        normal: nonzero_direction(normal, &format!("{what}.normal"))?,
                        body2: b2,
                        point2: finite3(point2, &format!("{what}.point2"))?,
                        coeff: crate::forces::damping::squeeze_film_coefficient(*eta, *length, *area),
                        gap: *gap,
                        gap_max: 0.1 * length,
                    }
                }
                ForceDescription::JournalBearing { joint, radius, length, clearance, eta, eccentricity, .. } => {
                    let ji =
                        *joint_index.get(joint).ok_or_else(|| err(format!("{what}.joint: unknown joint '{joint}'")))?;
                    crate::ensure!(
                        matches!(joints[ji].kind, JointKind::Revolute { .. }),
                        Model,
                        "{what}.joint: joint '{joint}' must be revolute (the shaft turning in the bearing)"
                    );
                    for (x, key, unit) in
                        [(radius, "radius", "m"), (length, "length", "m"), (clearance, "clearance", "m"), (eta, "eta", "Pa s")]
                    {
                        crate::ensure!(x.is_finite() && *x > 0.0, Model, "{what}.{key}: must be > 0 ({unit}), got {x}");
                    }
                    // the boundary-layer theory behind eq. 2.212 needs a ≪ r0; relative clearances of
                    // real bearings are 0.05–0.3 %
                    crate::ensure!(
                        *clearance <= 0.02 * radius,
                        Model,
                        "{what}.clearance: {clearance} m is outside the validity of eq. 2.212 (clearance ≤ radius/50 = {} m)",
                        0.02 * radius
                    );
                    crate::ensure!(
                        eccentricity.is_finite() && (0.0..=crate::forces::damping::MAX_ECCENTRICITY).contains(eccentricity),
                        Model,
                        "{what}.eccentricity: must lie in [0, {}] (eq. 2.212 diverges as the shaft touches the shell), got {eccentricity}",
                        crate::forces::damping::MAX_ECCENTRICITY
                    );
                    ForceElement::JournalBearing {
                        name,
                        joint: ji,
                        c: crate::forces::damping::journal_bearing_coefficient(*radius, *length, *clearance, *eta, *eccentricity),
                    }
                }
                ForceDescription::HydrodynamicBearing {
                    journal,
                    journal_frame,
                    shell,
                    shell_frame,
                    radius,
                    length,
                    clearance,
                    viscosity,
                    theory,
                    ..
                } => {
                    let jb = body(journal, &format!("{what}.journal"))?;
                    let sb = body(shell, &format!("{what}.shell"))?;
                    crate::ensure!(jb != sb, Model, "{what}: journal and shell are the same body '{journal}'");
                    for (x, key, unit) in [
                        (radius, "radius", "m"),
                        (length, "length", "m"),
                        (clearance, "clearance", "m"),
                        (viscosity, "viscosity", "Pa s"),
                    ] {
                        crate::ensure!(x.is_finite() && *x > 0.0, Model, "{what}.{key}: must be > 0 ({unit}), got {x}");
                    }
                    crate::ensure!(
                        clearance < radius,
                        Model,
                        "{what}.clearance: must be smaller than the radius {radius} m, got {clearance} m"
                    );
                    let theory = BearingTheory::from_name(theory).ok_or_else(|| {
                        err(format!("{what}.theory: expected one of {:?}, got '{theory}'", BearingTheory::NAMES))
                    })?;
                    ForceElement::HydrodynamicBearing(HydrodynamicBearing {
                        name,
                        journal: jb,
                        journal_frame: frame(journal_frame, &format!("{what}.journal_frame"))?,
                        shell: sb,
                        shell_frame: frame(shell_frame, &format!("{what}.shell_frame"))?,
                        law: BearingLaw {
                            theory,
                            radius: *radius,
                            length: *length,
                            clearance: *clearance,
                            viscosity: *viscosity,
                        },
                    })
                }
                ForceDescription::Jenkins { joint, index, k, slip, shaft_stiffness, offset, .. } => {
                    let ji =
                        *joint_index.get(joint).ok_or_else(|| err(format!("{what}.joint: unknown joint '{joint}'")))?;
                    let jt = &joints[ji];
                    crate::ensure!(
                        !matches!(jt.kind, JointKind::Spherical | JointKind::Free),
                        Model,
                        "{what}.joint: joint '{joint}' has quaternion coordinates; use a joint whose coordinates are its velocities"
                    );
                    crate::ensure!(
                        *index < jt.nu(),
                        Model,
                        "{what}.index: joint '{joint}' has {} velocities, got index {index}",
                        jt.nu()
                    );
                    crate::ensure!(k.is_finite() && *k > 0.0, Model, "{what}.k: must be > 0, got {k}");
                    crate::ensure!(!slip.is_empty(), Model, "{what}.slip: give at least one slip force");
                    if let Some(i) = slip.iter().position(|x| !(x.is_finite() && *x > 0.0)) {
                        return Err(err(format!("{what}.slip[{i}]: slip forces must be > 0, got {}", slip[i])));
                    }
                    if let Some(ks) = shaft_stiffness {
                        crate::ensure!(ks.is_finite() && *ks > 0.0, Model, "{what}.shaft_stiffness: must be > 0, got {ks}");
                    }
                    crate::ensure!(offset.is_finite(), Model, "{what}.offset: must be finite, got {offset}");
                    let j = Jenkins::new(
                        name,
                        ji,
                        jt.iq + index,
                        jt.iu + index,
                        *k,
                        slip.clone(),
                        *shaft_stiffness,
                        *offset,
                        n_sliders,
                    )?;
                    n_sliders += j.len();
                    ForceElement::Jenkins(j)
                }
                ForceDescription::BodyForce { body: b, point, force, torque, frame, function, .. } => {
                    let bi = body(b, &format!("{what}.body"))?;
                    crate::ensure!(bi != 0, Model, "{what}.body: forces on the ground have no effect");
                    let frame = match frame.as_str() {
                        "inertial" | "world" => ForceFrame::Inertial,
                        "body" => ForceFrame::Body,
                        o => return Err(err(format!("{what}.frame: expected 'inertial' or 'body', got '{o}'"))),
                    };
                    ForceElement::BodyForce {
                        name,
                        body: bi,
                        point: finite3(point, &format!("{what}.point"))?,
                        force: finite3(force, &format!("{what}.force"))?,
                        torque: finite3(torque, &format!("{what}.torque"))?,
                        frame,
                        function: time_function(function, &format!("{what}.function"), &mut n_callbacks)?,
                    }
                }
                ForceDescription::JointForce { joint, value, function, .. } => {
                    let ji =
                        *joint_index.get(joint).ok_or_else(|| err(format!("{what}.joint: unknown joint '{joint}'")))?;
                    let n = joints[ji].nu();
                    crate::ensure!(n > 0, Model, "{what}.joint: joint '{joint}' has no degrees of freedom");
                    ForceElement::JointForce {
                        name,
                        joint: ji,
                        value: per_dof(value, n, &format!("{what}.value"))?,
                        function: time_function(function, &format!("{what}.function"), &mut n_callbacks)?,
                    }
                }
                ForceDescription::Servo { joint, index, mode, kp, kd, reference, max_torque, gear, .. } => {
                    let ji =
                        *joint_index.get(joint).ok_or_else(|| err(format!("{what}.joint: unknown joint '{joint}'")))?;
                    let n = joints[ji].nu();
                    crate::ensure!(
                        *index < n && joints[ji].kind.nq() == n,
                        Model,
                        "{what}.index: joint '{joint}' has {n} velocities whose coordinates are their integrals; got index {index}"
                    );
                    let position = match mode.as_str() {
                        "position" => true,
                        "velocity" => false,
                        m => return Err(err(format!("{what}.mode: must be \"position\" or \"velocity\", got \"{m}\""))),
                    };
                    for (k, v) in [("kp", kp), ("kd", kd)] {
                        crate::ensure!(v.is_finite() && *v >= 0.0, Model, "{what}.{k}: must be a finite gain >= 0, got {v}");
                    }
                    crate::ensure!(*kp > 0.0 || *kd > 0.0, Model, "{what}: give kp or kd (both are 0: the servo does nothing)");
                    crate::ensure!(
                        gear.is_finite() && *gear != 0.0,
                        Model,
                        "{what}.gear: must be a finite, nonzero ratio, got {gear}"
                    );
                    let limit = max_torque.unwrap_or(f64::INFINITY);
                    crate::ensure!(limit > 0.0 && !limit.is_nan(), Model, "{what}.max_torque: must be > 0, got {limit}");
                    ForceElement::Servo {
                        name,
                        joint: ji,
                        index: *index,
                        position,
                        kp: *kp,
                        kd: *kd,
                        reference: time_function(&Some(reference.clone()), &format!("{what}.reference"), &mut n_callbacks)?,
                        max_torque: limit,
                        gear: *gear,
                    }
                }
                ForceDescription::Callback { id, .. } => {
                    crate::ensure!(*id < 1 << 32, Model, "{what}.id: callback index {id} is out of range");
                    n_callbacks = n_callbacks.max(id + 1);
                    ForceElement::Callback { name, id: *id }
                }
            });
        }

        // ---- constraints ---------------------------------------------------------------------------
        let mut constraints = Vec::with_capacity(desc.constraints.len());
        let mut constraint_names = HashSet::new();
        let mut driven: HashMap<usize, String> = HashMap::new(); // velocity index -> drive name
        let mut row = 0usize;
        let single = |jname: &str, what: &str, key: &str| -> Result<usize> {
            let ji = *joint_index.get(jname).ok_or_else(|| err(format!("{what}.{key}: unknown joint '{jname}'")))?;
            Ok(ji)
        };
        for (ci, c) in desc.constraints.iter().enumerate() {
            let name = c.name().to_string();
            let what = format!("constraints[{ci}] '{name}'");
            check_name(&name, &format!("constraints[{ci}]"))?;
            crate::ensure!(constraint_names.insert(name.clone()), Model, "{what}: duplicate constraint name");
            let kind = match c {
                ConstraintDescription::Point { body1, point1, body2, point2, .. } => {
                    let b1 = body(body1, &format!("{what}.body1"))?;
                    let b2 = body(body2, &format!("{what}.body2"))?;
                    crate::ensure!(b1 != b2, Model, "{what}: body1 and body2 are the same body '{body1}'");
                    ConstraintKind::Point {
                        body1: b1,
                        p1: finite3(point1, &format!("{what}.point1"))?,
                        body2: b2,
                        p2: finite3(point2, &format!("{what}.point2"))?,
                    }
                }
                ConstraintDescription::Distance { body1, point1, body2, point2, length, .. } => {
                    let b1 = body(body1, &format!("{what}.body1"))?;
                    let b2 = body(body2, &format!("{what}.body2"))?;
                    crate::ensure!(b1 != b2, Model, "{what}: body1 and body2 are the same body '{body1}'");
                    crate::ensure!(
                        length.is_finite() && *length > 0.0,
                        Model,
                        "{what}.length: must be > 0, got {length}"
                    );
                    ConstraintKind::Distance {
                        body1: b1,
                        p1: finite3(point1, &format!("{what}.point1"))?,
                        body2: b2,
                        p2: finite3(point2, &format!("{what}.point2"))?,
                        length: *length,
                    }
                }
                ConstraintDescription::Coupler { joint1, joint2, ratio, offset, .. } => {
                    let (ja, jb) = (single(joint1, &what, "joint1")?, single(joint2, &what, "joint2")?);
                    crate::ensure!(ja != jb, Model, "{what}: joint1 and joint2 are the same joint '{joint1}'");
                    for (ji, key) in [(ja, "joint1"), (jb, "joint2")] {
                        let j = &joints[ji];
                        crate::ensure!(
                            j.nq() == 1 && j.nu() == 1,
                            Model,
                            "{what}.{key}: a coupler needs single-coordinate joints (revolute, prismatic), '{}' is {}",
                            j.name,
                            j.kind.type_name()
                        );
                    }
                    crate::ensure!(
                        ratio.is_finite() && offset.is_finite(),
                        Model,
                        "{what}: ratio and offset must be finite"
                    );
                    ConstraintKind::Coupler {
                        iq_a: joints[ja].iq,
                        iu_a: joints[ja].iu,
                        iq_b: joints[jb].iq,
                        iu_b: joints[jb].iu,
                        ratio: *ratio,
                        offset: *offset,
                    }
                }
                ConstraintDescription::Prescribed { joint, index, function, .. } => {
                    let ji = single(joint, &what, "joint")?;
                    let j = &joints[ji];
                    crate::ensure!(
                        !j.kind.has_quaternion() && *index < j.nu(),
                        Model,
                        "{what}.index: joint '{}' ({}) has no coordinate {index} that can be prescribed",
                        j.name,
                        j.kind.type_name()
                    );
                    if let Some(other) = driven.insert(j.iu + index, name.clone()) {
                        return Err(err(format!(
                            "{what}: coordinate {index} of joint '{}' is already driven by constraint '{other}' (two drives on one coordinate)",
                            j.name
                        )));
                    }
                    ConstraintKind::Prescribed {
                        iq: j.iq + index,
                        iu: j.iu + index,
                        function: time_function(
                            &Some(function.clone()),
                            &format!("{what}.function"),
                            &mut n_callbacks,
                        )?,
                    }
                }
                ConstraintDescription::PointOnLine { body1, point1, body2, point2, direction, .. }
                | ConstraintDescription::PointOnPlane { body1, point1, body2, point2, normal: direction, .. } => {
                    let b1 = body(body1, &format!("{what}.body1"))?;
                    let b2 = body(body2, &format!("{what}.body2"))?;
                    crate::ensure!(b1 != b2, Model, "{what}: body1 and body2 are the same body '{body1}'");
                    let (p1, p2) =
                        (finite3(point1, &format!("{what}.point1"))?, finite3(point2, &format!("{what}.point2"))?);
                    if let ConstraintDescription::PointOnLine { .. } = c {
                        let d = nonzero_direction(direction, &format!("{what}.direction"))?;
                        // two unit normals of the line, fixed in body2
                        let helper = if d.x.abs() < 0.6 { Vec3::x() } else { Vec3::y() };
                        let n1 = d.cross(&helper).normalize();
                        ConstraintKind::PointOnLine { body1: b1, p1, body2: b2, p2, n: [n1, d.cross(&n1)] }
                    } else {
                        let n = nonzero_direction(direction, &format!("{what}.normal"))?;
                        ConstraintKind::PointOnPlane { body1: b1, p1, body2: b2, p2, n }
                    }
                }
                ConstraintDescription::LoopSpherical(LoopFrames { body1, frame1, body2, frame2, .. })
                | ConstraintDescription::LoopRevolute(LoopFrames { body1, frame1, body2, frame2, .. })
                | ConstraintDescription::LoopFixed(LoopFrames { body1, frame1, body2, frame2, .. })
                | ConstraintDescription::LoopPrismatic(LoopFrames { body1, frame1, body2, frame2, .. })
                | ConstraintDescription::LoopCylindrical(LoopFrames { body1, frame1, body2, frame2, .. })
                | ConstraintDescription::LoopUniversal(LoopFrames { body1, frame1, body2, frame2, .. })
                | ConstraintDescription::LoopPlanar(LoopFrames { body1, frame1, body2, frame2, .. }) => {
                    let b1 = body(body1, &format!("{what}.body1"))?;
                    let b2 = body(body2, &format!("{what}.body2"))?;
                    crate::ensure!(b1 != b2, Model, "{what}: body1 and body2 are the same body '{body1}'");
                    let frame = |f: &FrameDescription, key: &str| -> Result<Pose> {
                        let w = format!("{what}.{key}");
                        Ok(Pose::new(
                            rotation(&f.rotation, &format!("{w}.rotation"))?,
                            finite3(&f.position, &format!("{w}.position"))?,
                        ))
                    };
                    let joint = match c {
                        ConstraintDescription::LoopSpherical(_) => LoopJoint::Spherical,
                        ConstraintDescription::LoopRevolute(_) => LoopJoint::Revolute,
                        ConstraintDescription::LoopPrismatic(_) => LoopJoint::Prismatic,
                        ConstraintDescription::LoopCylindrical(_) => LoopJoint::Cylindrical,
                        ConstraintDescription::LoopUniversal(_) => LoopJoint::Universal,
                        ConstraintDescription::LoopPlanar(_) => LoopJoint::Planar,
                        _ => LoopJoint::Fixed,
                    };
                    ConstraintKind::Loop {
                        joint,
                        body1: b1,
                        f1: frame(frame1, "frame1")?,
                        body2: b2,
                        f2: frame(frame2, "frame2")?,
                    }
                }
                ConstraintDescription::PrescribedBody { body: b, frame: f, position, orientation, .. } => {
                    let bi = body(b, &format!("{what}.body"))?;
                    crate::ensure!(
                        bi != 0,
                        Model,
                        "{what}.body: a prescribed body motion needs a moving body, got 'ground'"
                    );
                    let mut three = |list: &[TimeFunctionDescription], key: &str, meaning: &str| {
                        crate::ensure!(
                            list.len() == 3,
                            Model,
                            "{what}.{key}: expected 3 time functions ({meaning}), got {}",
                            list.len()
                        );
                        let mut out = [0, 1, 2].map(|_| TimeFunction::Constant(0.0));
                        for (k, fk) in list.iter().enumerate() {
                            let w = format!("{what}.{key}[{k}]");
                            out[k] = time_function(&Some(fk.clone()), &w, &mut n_callbacks)?;
                        }
                        Ok(out)
                    };
                    let position = three(position, "position", "world x, y, z of the frame origin")?;
                    let orientation = match orientation {
                        Some(o) => Some(three(o, "orientation", "Cardan angles x-y-z")?),
                        None => None,
                    };
                    let frame = frame(f, &format!("{what}.frame"))?;
                    ConstraintKind::PrescribedBody { body: bi, frame, position, orientation }
                }
                ConstraintDescription::Velocity { rows, w_matrix, w_offset, w_rate, .. } => {
                    crate::ensure!(*rows >= 1, Model, "{what}.rows: must be >= 1, got {rows}");
                    for (id, key) in [(Some(*w_matrix), "W"), (*w_offset, "w"), (*w_rate, "Wdot")] {
                        if let Some(id) = id {
                            crate::ensure!(id < 1 << 32, Model, "{what}.{key}: callback index {id} is out of range");
                            n_callbacks = n_callbacks.max(id + 1);
                        }
                    }
                    ConstraintKind::Velocity { rows: *rows, w_matrix: *w_matrix, w_offset: *w_offset, w_rate: *w_rate }
                }
                ConstraintDescription::KnifeEdge { body: b, point, direction, .. } => {
                    let bi = body(b, &format!("{what}.body"))?;
                    crate::ensure!(bi != 0, Model, "{what}.body: a knife edge needs a moving body, got 'ground'");
                    ConstraintKind::KnifeEdge {
                        body: bi,
                        p: finite3(point, &format!("{what}.point"))?,
                        e: nonzero_direction(direction, &format!("{what}.direction"))?,
                    }
                }
                ConstraintDescription::RollingDisc { body: b, center, axis, radius, .. } => {
                    let bi = body(b, &format!("{what}.body"))?;
                    crate::ensure!(bi != 0, Model, "{what}.body: a rolling disc needs a moving body, got 'ground'");
                    crate::ensure!(
                        radius.is_finite() && *radius > 0.0,
                        Model,
                        "{what}.radius: must be > 0, got {radius}"
                    );
                    ConstraintKind::RollingDisc {
                        body: bi,
                        center: finite3(center, &format!("{what}.center"))?,
                        axis: nonzero_direction(axis, &format!("{what}.axis"))?,
                        radius: *radius,
                    }
                }
            };
            let rows = kind.rows();
            constraints.push(Constraint { name, kind, row, select: None });
            row += rows;
        }

        // ---- contacts ------------------------------------------------------------------------------
        let mut contacts = Vec::with_capacity(desc.contacts.len());
        let mut contact_names = HashSet::new();
        let mut n_contact_points = 0;
        let mut n_compliant_points = 0;
        for (i, d) in desc.contacts.iter().enumerate() {
            crate::ensure!(
                contact_names.insert(d.name.clone()),
                Model,
                "contacts[{i}] '{}': duplicate contact name",
                d.name
            );
            if !matches!(d.normal, NormalDescription::Signorini { .. } | NormalDescription::Bilateral { .. }) {
                // compliant: a force element on the contact's geometry, not a unilateral contact
                let c = super::contact::validate_compliant(d, i, n_compliant_points, body, rotation, &mut n_callbacks)?;
                n_compliant_points += c.points();
                forces.push(ForceElement::Contact(Box::new(c)));
                continue;
            }
            let c = super::contact::validate(d, i, n_contact_points, body, rotation)?;
            if let NormalDescription::Bilateral { rolling, hold_normal } = d.normal {
                // held closed: a constraint, not a unilateral contact
                let what = format!("contacts[{i}] '{}'", d.name);
                crate::ensure!(
                    hold_normal || rolling,
                    Model,
                    "{what}.normal: hold_normal = false holds only the tangents, so it needs rolling = true"
                );
                crate::ensure!(
                    matches!(d.friction, FrictionDescription::None),
                    Model,
                    "{what}.friction: a bilateral contact takes no friction law (rolling = true holds it without slip)"
                );
                crate::ensure!(
                    c.points() == 1,
                    Model,
                    "{what}.points: a bilateral contact holds one contact point, the pair has {}",
                    c.points()
                );
                let pair = c.pair().expect("a contour contact").clone();
                crate::ensure!(
                    pair.surface_velocity().iter().all(|v| v.norm() == 0.0),
                    Model,
                    "{what}: a bilateral contact on a moving surface is not supported; use the unilateral law"
                );
                let kind = ConstraintKind::Contact {
                    body1: c.body1,
                    body2: c.body2,
                    pair: Box::new(pair),
                    rolling,
                    normal: hold_normal,
                };
                hold(&what, &d.name, kind, &mut constraint_names, &mut constraints, &mut row)?;
                continue;
            }
            n_contact_points += c.points();
            contacts.push(c);
        }

        // gap contacts come after the contour contacts (their points last)
        for (i, d) in desc.gap_contacts.iter().enumerate() {
            crate::ensure!(
                contact_names.insert(d.name.clone()),
                Model,
                "gap_contacts[{i}] '{}': duplicate contact name (contacts and gap contacts share one namespace)",
                d.name
            );
            let c = super::contact::validate_gap(d, i, n_contact_points, &joints, &mut n_callbacks)?;
            if let NormalDescription::Bilateral { rolling, hold_normal } = d.normal {
                let what = format!("gap_contacts[{i}] '{}'", d.name);
                crate::ensure!(
                    hold_normal,
                    Model,
                    "{what}.normal: hold_normal = false (the tangents alone) is for contour contacts; a gap contact holds its gap"
                );
                crate::ensure!(
                    matches!(d.friction, FrictionDescription::None),
                    Model,
                    "{what}.friction: a bilateral contact takes no friction law (rolling = true holds its tangents)"
                );
                let (function, slot) = c.gap().map(|(f, s)| (Box::new(f.clone()), s)).expect("a gap contact");
                hold(
                    &what,
                    &d.name,
                    ConstraintKind::Gap { function, slot, rolling },
                    &mut constraint_names,
                    &mut constraints,
                    &mut row,
                )?;
                continue;
            }
            n_contact_points += c.points();
            contacts.push(c);
        }

        let mut contact_groups = Vec::with_capacity(desc.contact_groups.len());
        let mut n_compliant_groups = 0;
        for (i, d) in desc.contact_groups.iter().enumerate() {
            crate::ensure!(
                contact_names.insert(d.name.clone()),
                Model,
                "contact_groups[{i}] '{}': duplicate name (contacts and contact groups share one namespace)",
                d.name
            );
            if !d.normal.is_signorini() {
                // compliant: a force element whose pairs the broad phase finds at every evaluation
                let g = super::contact::validate_compliant_group(
                    d,
                    i,
                    n_compliant_points,
                    n_compliant_groups,
                    body,
                    rotation,
                    &mut n_callbacks,
                )?;
                n_compliant_points += 1;
                n_compliant_groups += 1;
                forces.push(ForceElement::ContactGroup(Box::new(g)));
                continue;
            }
            contact_groups.push(super::contact::validate_group(d, i, body, rotation)?);
        }

        for (i, d) in desc.visuals.iter().enumerate() {
            super::contact::validate_visual(d, i, body, rotation)?;
        }

        let qdot_is_u = !joints.iter().any(|j| j.kind.has_quaternion());
        let body_index = bodies.iter().enumerate().map(|(i, b)| (b.name.clone(), i)).collect();
        let n_force_outputs = forces.iter().map(|f| f.outputs(iu)).sum();
        let planar = desc.planar;
        let mut model = Model {
            name: desc.name.clone(),
            gravity: g,
            bodies,
            joints,
            forces,
            constraints,
            contacts,
            contact_groups,
            elastic,
            n_contact_points,
            nc: row,
            planar,
            nq: iq,
            nu: iu,
            variable_mass,
            qdot_is_u,
            n_callbacks,
            n_sliders,
            n_force_outputs,
            n_compliant_points,
            description: desc,
            body_index,
            joint_index,
        };
        // the workspace's dense matrices, before anything allocates them
        let need = crate::resources::workspace_bytes(model.nbodies(), model.nu, model.nc);
        let budget = crate::resources::memory_budget();
        crate::ensure!(
            need < budget,
            Model,
            "model '{}': {} bodies, {} velocities and {} constraint equations need about {need:.3e} bytes of workspace \
             (dense mass and constraint matrices), more than the {budget:.3e} bytes this process may use (half the \
             memory available)",
            model.name,
            model.nbodies() - 1,
            model.nu,
            model.nc
        );
        if planar {
            super::planar::planarize(&mut model)?;
        }
        Ok(model)
    }
}

/// A contact held closed (the bilateral normal law) becomes constraint `kind` named `name`, its
/// rows from `row` on.
fn hold(
    what: &str,
    name: &str,
    kind: ConstraintKind,
    names: &mut HashSet<String>,
    constraints: &mut Vec<Constraint>,
    row: &mut usize,
) -> Result<()> {
    crate::ensure!(
        names.insert(name.to_string()),
        Model,
        "{what}: a constraint has the same name (a bilateral contact is a constraint)"
    );
    let rows = kind.rows();
    constraints.push(Constraint { name: name.to_string(), kind, row: *row, select: None });
    *row += rows;
    Ok(())
}

fn markers(list: &[MarkerDescription], what: &str) -> Result<Vec<Marker>> {
    let mut seen = HashSet::new();
    list.iter()
        .enumerate()
        .map(|(i, m)| {
            let w = format!("{what}[{i}] '{}'", m.name);
            check_name(&m.name, &format!("{what}[{i}]"))?;
            crate::ensure!(seen.insert(m.name.clone()), Model, "{w}: duplicate marker name");
            Ok(Marker {
                name: m.name.clone(),
                pose: Pose::new(rotation(&m.rotation, &w)?, finite3(&m.position, &format!("{w}.position"))?),
            })
        })
        .collect()
}
