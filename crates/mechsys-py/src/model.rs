//! The validated model as a Python object, with a workspace for single evaluations.

use std::sync::Mutex;

use mechsys_core::data::Data;
use mechsys_core::dynamics::Workspace;
use mechsys_core::model::Model;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{settings, PyMechsysError};

/// A validated, immutable model (built from a JSON description).
#[pyclass(name = "Model", module = "mechsys._core", frozen)]
pub struct PyModel {
    pub model: Model,
    /// Workspace for single calls (aba, crba, ...); simulations use their own.
    pub data: Mutex<Data>,
    /// The dynamics stage's own workspace for single calls, next to `data` (locked after it).
    pub ws: Mutex<Workspace>,
}

#[pymethods]
impl PyModel {
    #[new]
    fn new(description_json: &str) -> PyResult<Self> {
        let model = Model::from_json(description_json).map_err(PyMechsysError::from)?;
        let (data, ws) = (Mutex::new(Data::new(&model)), Mutex::new(Workspace::new(&model)));
        Ok(PyModel { model, data, ws })
    }
    #[getter]
    fn name(&self) -> &str {
        &self.model.name
    }
    #[getter]
    fn nq(&self) -> usize {
        self.model.nq
    }
    #[getter]
    fn nu(&self) -> usize {
        self.model.nu
    }
    #[getter]
    fn n_callbacks(&self) -> usize {
        self.model.n_callbacks
    }
    #[getter]
    fn gravity(&self) -> [f64; 3] {
        [self.model.gravity.x, self.model.gravity.y, self.model.gravity.z]
    }
    /// Body names in the engine's order, ground first.
    #[getter]
    fn body_names(&self) -> Vec<String> {
        self.model.bodies.iter().map(|b| b.name.clone()).collect()
    }
    /// One dict per body (ground excluded): name, mass, com, inertia, parent_joint, markers.
    fn bodies<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let mut out = vec![];
        for (i, b) in self.model.bodies.iter().enumerate().skip(1) {
            let d = PyDict::new(py);
            d.set_item("name", &b.name)?;
            d.set_item("index", i)?;
            d.set_item("mass", b.mass)?;
            d.set_item("com", b.com.as_slice().to_vec())?;
            let rows: Vec<Vec<f64>> = (0..3).map(|r| (0..3).map(|c| b.inertia[(r, c)]).collect()).collect();
            d.set_item("inertia", rows)?;
            d.set_item("parent_joint", &self.model.joints[i - 1].name)?;
            d.set_item("variable_mass", b.mass_rate != 0.0)?;
            let markers: Vec<(String, Vec<f64>)> =
                b.markers.iter().map(|m| (m.name.clone(), m.pose.r.as_slice().to_vec())).collect();
            d.set_item("markers", markers)?;
            // the markers' rotations too (A_BM, row-major 3x3), for marker sensors
            let frames: Vec<(String, Vec<f64>, Vec<f64>)> = b
                .markers
                .iter()
                .map(|m| {
                    let a = m.pose.a;
                    (m.name.clone(), m.pose.r.as_slice().to_vec(), (0..9).map(|k| a[(k / 3, k % 3)]).collect())
                })
                .collect();
            d.set_item("marker_frames", frames)?;
            out.push(d);
        }
        Ok(out)
    }
    /// One dict per joint in the engine's (topological) order: name, type, parent, child, iq, nq, iu, nu.
    /// The elastic bodies: body name, coordinate and velocity offsets, number of elastic
    /// coordinates, node names.
    fn elastic<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let mut out = vec![];
        for e in &self.model.elastic {
            let d = PyDict::new(py);
            d.set_item("body", &self.model.bodies[e.body].name)?;
            d.set_item("iq", e.iq)?;
            d.set_item("iu", e.iu)?;
            d.set_item("ne", e.ne)?;
            d.set_item("nodes", e.nodes.iter().map(|n| n.name.clone()).collect::<Vec<_>>())?;
            let k: Vec<Vec<f64>> = (0..e.ne).map(|r| (0..e.ne).map(|c| e.k[(r, c)]).collect()).collect();
            d.set_item("stiffness", k)?;
            // per node, per coordinate, the translation (body frame)
            let t: Vec<Vec<Vec<f64>>> =
                e.nodes.iter().map(|n| n.translation.iter().map(|v| vec![v.x, v.y, v.z]).collect()).collect();
            d.set_item("node_translation", t)?;
            // and the small rotation (eq. 2.134), zero where the body gives none
            let r: Vec<Vec<Vec<f64>>> = e
                .nodes
                .iter()
                .map(|n| (0..e.ne).map(|k| n.rotation.get(k).map_or(vec![0.0; 3], |v| vec![v.x, v.y, v.z])).collect())
                .collect();
            d.set_item("node_rotation", r)?;
            out.push(d);
        }
        Ok(out)
    }

    fn joints<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let mut out = vec![];
        for j in &self.model.joints {
            let d = PyDict::new(py);
            d.set_item("name", &j.name)?;
            d.set_item("type", j.kind.type_name())?;
            d.set_item("parent", &self.model.bodies[j.parent].name)?;
            d.set_item("child", &self.model.bodies[j.child].name)?;
            d.set_item("iq", j.iq)?;
            d.set_item("nq", j.nq())?;
            d.set_item("iu", j.iu)?;
            d.set_item("nu", j.nu())?;
            d.set_item("q0", j.q0.clone())?;
            d.set_item("u0", j.u0.clone())?;
            if let mechsys_core::model::JointKind::Path { curve, oriented } = &j.kind {
                // the path's geometry as the engine has it, at the initial s (for the path
                // signals and reports; `path_geometry` gives it at any s)
                let p = curve.point(j.q0[0]);
                d.set_item("curve", curve.kind_name())?;
                d.set_item("oriented", *oriented)?;
                d.set_item("curvature", p.curvature)?;
                d.set_item("torsion", p.torsion)?;
                d.set_item("constant_curvature", curve.constant_darboux())?;
                if let mechsys_core::kinematics::path::PathCurve::Spline(sp) = curve {
                    d.set_item("length", sp.length())?;
                    d.set_item("closed", sp.closed())?;
                }
            }
            out.push(d);
        }
        Ok(out)
    }
    /// Number of constraint equations.
    #[getter]
    fn nc(&self) -> usize {
        self.model.nc
    }
    /// One dict per constraint: name, type, row, rows, unit (of λ), violation_unit.
    /// Contacts: name, bodies, first candidate point, number of points, tangent directions, the
    /// compliance and damping of a compliant Signorini layer (0 rigid).
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let mut out = vec![];
        for c in &self.model.contacts {
            let d = PyDict::new(py);
            d.set_item("name", &c.name)?;
            d.set_item("body1", &self.model.bodies[c.body1].name)?;
            d.set_item("body2", &self.model.bodies[c.body2].name)?;
            d.set_item("first", c.first)?;
            d.set_item("points", c.points())?;
            d.set_item("tangents", c.tangent_dim())?;
            d.set_item("kind", if c.gap().is_some() { "gap" } else { "contours" })?;
            d.set_item("compliance", c.compliance)?;
            d.set_item("damping", c.damping)?;
            out.push(d);
        }
        Ok(out)
    }

    /// One dict per contact group: name, members, against (counts), kinds (contour kinds of the
    /// members, then of `against`), planar, compliance and damping (of a compliant Signorini
    /// layer; 0 rigid).
    fn contact_groups<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let mut out = vec![];
        for g in &self.model.contact_groups {
            let d = PyDict::new(py);
            d.set_item("name", &g.name)?;
            d.set_item("members", g.members.len())?;
            d.set_item("against", g.against.len())?;
            let kinds = |l: &[mechsys_core::model::contact::GroupContour]| {
                let mut k: Vec<&'static str> = Vec::new();
                for c in l {
                    let n = c.contour.kind().name();
                    if !k.contains(&n) {
                        k.push(n);
                    }
                }
                k
            };
            d.set_item("member_kinds", kinds(&g.members))?;
            d.set_item("against_kinds", kinds(&g.against))?;
            d.set_item("planar", g.planar)?;
            d.set_item("compliance", g.compliance)?;
            d.set_item("damping", g.damping)?;
            out.push(d);
        }
        Ok(out)
    }

    fn constraints<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        use mechsys_core::constraints::ConstraintKind as K;
        use mechsys_core::constraints::LoopJoint;
        use mechsys_core::model::JointKind;
        // unit of the coordinate with velocity index iu (revolute-like: rad; prismatic-like: m)
        let coord_units = |iu: usize| -> (&'static str, &'static str) {
            for j in &self.model.joints {
                if iu >= j.iu && iu < j.iu + j.nu() {
                    let k = iu - j.iu;
                    let angular = match j.kind {
                        JointKind::Revolute { .. } | JointKind::Universal { .. } => true,
                        JointKind::Cylindrical { .. } => k == 0,
                        JointKind::Planar => k == 2,
                        _ => false,
                    };
                    return if angular { ("N m", "rad") } else { ("N", "m") };
                }
            }
            ("", "")
        };
        let mut out = vec![];
        for c in &self.model.constraints {
            let d = PyDict::new(py);
            let (t, (unit, vunit)) = match &c.kind {
                K::Point { .. } => ("point", ("N", "m")),
                K::Distance { .. } => ("distance", ("N", "m")),
                K::Coupler { iu_a, .. } => ("coupler", coord_units(*iu_a)),
                K::Prescribed { iu, .. } => ("prescribed", coord_units(*iu)),
                K::PointOnLine { .. } => ("point_on_line", ("N", "m")),
                K::PointOnPlane { .. } => ("point_on_plane", ("N", "m")),
                K::Loop { joint: LoopJoint::Spherical, .. } => ("loop_spherical", ("N", "m")),
                // rows 0-2 forces and origin offsets, the rest moments and (small) angles
                K::Loop { joint: LoopJoint::Revolute, .. } => ("loop_revolute", ("N, N m", "m, rad")),
                K::Loop { joint: LoopJoint::Fixed, .. } => ("loop_fixed", ("N, N m", "m, rad")),
                K::Loop { joint: LoopJoint::Prismatic, .. } => ("loop_prismatic", ("N, N m", "m, rad")),
                K::Loop { joint: LoopJoint::Cylindrical, .. } => ("loop_cylindrical", ("N, N m", "m, rad")),
                K::Loop { joint: LoopJoint::Universal, .. } => ("loop_universal", ("N, N m", "m, rad")),
                K::Loop { joint: LoopJoint::Planar, .. } => ("loop_planar", ("N, N m", "m, rad")),
                K::PrescribedBody { orientation: None, .. } => ("prescribed_body", ("N", "m")),
                K::PrescribedBody { orientation: Some(_), .. } => ("prescribed_body", ("N, N m", "m, rad")),
                // the unit of λ depends on how the user scaled the rows of W
                K::Velocity { .. } => ("velocity", ("", "")),
                // non-holonomic rows have no position violation (recorded as 0)
                K::KnifeEdge { .. } => ("knife_edge", ("N", "m")),
                K::RollingDisc { .. } => ("rolling_disc", ("N", "m")),
                K::Contact { .. } => ("contact", ("N", "m")),
                // a gap in m gives a force in N; in other units the user's scaling decides
                K::Gap { .. } => ("gap", ("", "")),
            };
            d.set_item("name", &c.name)?;
            d.set_item("type", t)?;
            d.set_item("row", c.row)?;
            d.set_item("rows", c.rows())?;
            d.set_item("holonomic_rows", c.holonomic_rows())?;
            if let Some(sel) = &c.select {
                // a planar model's in-plane rows: name them (the units then follow the rows)
                d.set_item("columns", sel.names[..sel.n].to_vec())?;
                let units: Vec<(&str, &str)> =
                    sel.names[..sel.n].iter().map(|n| if *n == "rz" { ("N m", "rad") } else { ("N", "m") }).collect();
                d.set_item("column_units", units.iter().map(|u| u.0).collect::<Vec<_>>())?;
                d.set_item("column_violation_units", units.iter().map(|u| u.1).collect::<Vec<_>>())?;
            }
            if let K::Contact { normal, .. } = &c.kind {
                // a held contact: its normal force, then the rolling rows' tangential forces (the
                // tangents alone where another law carries the normal)
                let skip = usize::from(!*normal);
                d.set_item("columns", ["normal", "t1", "t2"][skip..skip + c.rows()].to_vec())?;
                d.set_item("column_units", vec!["N"; c.rows()])?;
                d.set_item("column_violation_units", vec!["m"; c.rows()])?;
            }
            d.set_item("unit", unit)?;
            d.set_item("violation_unit", vunit)?;
            out.push(d);
        }
        Ok(out)
    }
    /// Force element (name, type) pairs.
    fn forces(&self) -> Vec<(String, String)> {
        use mechsys_core::model::ForceElement as F;
        self.model
            .forces
            .iter()
            .map(|f| {
                let t = match f {
                    F::SpringDamper { .. } => "spring_damper",
                    F::BodyForce { .. } => "body_force",
                    F::JointForce { .. } => "joint_force",
                    F::Servo { .. } => "servo",
                    F::Callback { .. } => "callback",
                    F::Bushing { .. } => "bushing",
                    F::SqueezeFilm { .. } => "squeeze_film",
                    F::JournalBearing { .. } => "journal_bearing",
                    F::Jenkins(_) => "jenkins",
                    F::HydrodynamicBearing(_) => "hydrodynamic_bearing",
                    F::Contact(_) => "compliant_contact",
                    F::ContactGroup(_) => "compliant_group",
                };
                (f.name().to_string(), t.to_string())
            })
            .collect()
    }
    /// The recorded force and deflection values of each force element: dicts with name, type,
    /// first (column), width, force_unit and deflection_unit.
    fn force_outputs<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        use mechsys_core::model::{ForceElement as F, JointKind};
        let mut out = Vec::new();
        let mut first = 0usize;
        for f in &self.model.forces {
            let width = f.outputs(self.model.nu);
            let joint_units = |j: usize| match self.model.joints[j].kind {
                JointKind::Revolute { .. } => ("N m", "rad"),
                JointKind::Prismatic { .. } => ("N", "m"),
                _ => ("mixed", "mixed"),
            };
            let (kind, fu, du) = match f {
                F::SpringDamper { .. } => ("spring_damper", "N", "m"),
                F::Bushing { .. } => ("bushing", "N, N m", "m, rad"),
                F::SqueezeFilm { .. } => ("squeeze_film", "N", "m"),
                F::JournalBearing { joint, .. } => ("journal_bearing", joint_units(*joint).0, "rad"),
                F::Jenkins(j) => {
                    let (a, b) = joint_units(j.joint);
                    ("jenkins", a, b)
                }
                F::BodyForce { .. } => ("body_force", "N, N m", ""),
                F::JointForce { joint, .. } => ("joint_force", joint_units(*joint).0, ""),
                F::Servo { joint, position, .. } => {
                    let (a, b) = joint_units(*joint);
                    (
                        "servo",
                        a,
                        if *position {
                            b
                        } else if b == "rad" {
                            "rad/s"
                        } else {
                            "m/s"
                        },
                    )
                }
                F::Callback { .. } => ("python_force", "mixed", ""),
                // force: F_x, F_y (shell frame), torque; deflection: ε, position angle, attitude angle
                F::HydrodynamicBearing(_) => ("hydrodynamic_bearing", "N, N, N m", "1, rad, rad"),
                // per point, force: F_N, F_T1, F_T2, stored and dissipated energy, point (m), friction force (N);
                // deflection: δ, δ̇, ġ_T1, ġ_T2, α, normal (1), unused
                F::Contact(_) => {
                    ("compliant_contact", "N, N, N, J, J, m, m, m, N, N, N", "m, m/s, m/s, m/s, s/m, 1, 1, 1, 1, 1, 1")
                }
                // force: ΣF_N, stored and dissipated energy, touching pairs, then per drawn point its
                // position and force; deflection: max δ, max δ̇, broad-phase pairs, touching points
                F::ContactGroup(_) => ("compliant_group", "N, J, J, 1, (m, N) per point", "m, m/s, 1, 1"),
            };
            if width > 0 {
                let d = PyDict::new(py);
                d.set_item("name", f.name())?;
                d.set_item("type", kind)?;
                d.set_item("first", first)?;
                d.set_item("width", width)?;
                d.set_item("force_unit", fu)?;
                d.set_item("deflection_unit", du)?;
                if let F::Contact(c) = f {
                    d.set_item("points", c.points())?;
                    d.set_item("tangents", c.pair.tangent_dim())?;
                }
                out.push(d);
            }
            first += width;
        }
        Ok(out)
    }
    /// The model's initial coordinates.
    fn q0<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.q0())
    }
    /// The model's initial velocities.
    fn u0<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.u0())
    }
    /// The neutral configuration.
    fn neutral<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.neutral())
    }
    /// q ⊕ u dt on the configuration manifold.
    fn integrate<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray1<'py, f64>,
        u: PyReadonlyArray1<'py, f64>,
        dt: f64,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = check_len(&q, self.model.nq, "q")?;
        let u = check_len(&u, self.model.nu, "u")?;
        let mut out = vec![0.0; self.model.nq];
        self.model.integrate(q, u, dt, &mut out);
        Ok(PyArray1::from_vec(py, out))
    }
    /// The description as JSON (what results files store).
    fn description_json(&self) -> String {
        self.model.description.to_json()
    }
    fn __repr__(&self) -> String {
        format!(
            "Model('{}', bodies={}, joints={}, nq={}, nu={})",
            self.model.name,
            self.model.nbodies() - 1,
            self.model.joints.len(),
            self.model.nq,
            self.model.nu
        )
    }
}

/// A contiguous, finite f64 slice of the expected length, or a SettingsError naming the argument.
pub fn check_len<'a>(a: &'a PyReadonlyArray1<'_, f64>, n: usize, what: &str) -> PyResult<&'a [f64]> {
    let s = a.as_slice().map_err(|_| settings(format!("{what}: must be a contiguous float64 array")))?;
    if s.len() != n {
        return Err(settings(format!("{what}: expected length {n}, got {}", s.len())));
    }
    if let Some(i) = s.iter().position(|v| !v.is_finite()) {
        return Err(settings(format!("{what}[{i}]: must be finite, got {}", s[i])));
    }
    Ok(s)
}

/// The hot-path variant of [`check_len`]: a 1-D float64 numpy array read in place without numpy's
/// borrow registry (the GIL is held and the slice is only read during the call).
pub fn fast_slice<'a>(a: &'a Bound<'_, PyAny>, n: usize, what: &str) -> PyResult<&'a [f64]> {
    let arr = a
        .downcast::<numpy::PyArray1<f64>>()
        .map_err(|_| settings(format!("{what}: must be a 1-D float64 numpy array")))?;
    // SAFETY: read-only use while holding the GIL; no Rust code mutates the array meanwhile.
    let s = unsafe { numpy::PyArrayMethods::as_slice(arr) }
        .map_err(|_| settings(format!("{what}: must be a contiguous float64 array")))?;
    if s.len() != n {
        return Err(settings(format!("{what}: expected length {n}, got {}", s.len())));
    }
    if let Some(i) = s.iter().position(|v| !v.is_finite()) {
        return Err(settings(format!("{what}[{i}]: must be finite, got {}", s[i])));
    }
    Ok(s)
}

/// A configuration vector read in place and checked like `simulate` checks q0.
pub fn q_slice<'a>(model: &PyModel, a: &'a Bound<'_, PyAny>) -> PyResult<&'a [f64]> {
    let q = fast_slice(a, model.model.nq, "q")?;
    model.model.check_q(q, "q").map_err(crate::errors::PyMechsysError::from)?;
    Ok(q)
}

/// As [`q_slice`] for arguments already extracted as readonly arrays.
pub fn q_checked<'a>(model: &PyModel, a: &'a PyReadonlyArray1<'_, f64>) -> PyResult<&'a [f64]> {
    let q = check_len(a, model.model.nq, "q")?;
    model.model.check_q(q, "q").map_err(crate::errors::PyMechsysError::from)?;
    Ok(q)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyModel>()
}
