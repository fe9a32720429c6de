//! Bilateral constraints as model elements: what each constraint holds, its rows and which
//! velocities they may involve. The constraint stage ([`crate::constraints`]) evaluates them.

use crate::contact::gap::GapFunction;
use crate::contact::ContactPair;
use crate::math::Vec3;
use crate::spatial::Pose;

use super::{Model, TimeFunction};

/// What a constraint holds.
#[derive(Debug, Clone, PartialEq)]
pub enum ConstraintKind {
    /// Point `p1` on `body1` coincides with point `p2` on `body2` (3 rows, force on body1 in I).
    Point {
        /// First body.
        body1: usize,
        /// Point on body1, body frame.
        p1: Vec3,
        /// Second body.
        body2: usize,
        /// Point on body2, body frame.
        p2: Vec3,
    },
    /// |r_P1 - r_P2| = length (1 row; λ is the force on body1 along the unit vector from P2 to
    /// P1, so a rod in tension has λ < 0).
    Distance {
        /// First body.
        body1: usize,
        /// Point on body1, body frame.
        p1: Vec3,
        /// Second body.
        body2: usize,
        /// Point on body2, body frame.
        p2: Vec3,
        /// Distance (m), > 0.
        length: f64,
    },
    /// q[iq_a] = ratio · q[iq_b] + offset between single coordinates (velocities iu_a, iu_b).
    Coupler {
        /// Coordinate index of the driven coordinate.
        iq_a: usize,
        /// Velocity index of the driven coordinate.
        iu_a: usize,
        /// Coordinate index of the driving coordinate.
        iq_b: usize,
        /// Velocity index of the driving coordinate.
        iu_b: usize,
        /// Ratio.
        ratio: f64,
        /// Offset.
        offset: f64,
    },
    /// q[iq] = f(t) (1 row): a driven joint; λ is the driving force or torque.
    Prescribed {
        /// Coordinate index.
        iq: usize,
        /// Velocity index.
        iu: usize,
        /// The motion.
        function: TimeFunction,
    },
    /// Point `p1` on `body1` stays on the line through `p2` of `body2` (2 rows): the offset
    /// `d = r₁ - r₂` has no component along the two body2-fixed unit normals `n` of the line.
    PointOnLine {
        /// First body.
        body1: usize,
        /// Point on body1, body frame.
        p1: Vec3,
        /// Second body.
        body2: usize,
        /// Point of the line, body2 frame.
        p2: Vec3,
        /// Two orthonormal unit vectors perpendicular to the line direction, body2 frame.
        n: [Vec3; 2],
    },
    /// Point `p1` on `body1` stays in the plane through `p2` of `body2` with unit normal `n`
    /// (body2 frame): `Φ = n·(r₁ - r₂)` (1 row; λ is the normal force on body1).
    PointOnPlane {
        /// First body.
        body1: usize,
        /// Point on body1, body frame.
        p1: Vec3,
        /// Second body.
        body2: usize,
        /// Point of the plane, body2 frame.
        p2: Vec3,
        /// Unit normal, body2 frame.
        n: Vec3,
    },
    /// A loop-closing joint between frame `f1` on `body1` and frame `f2` on `body2`.
    Loop {
        /// Which joint.
        joint: LoopJoint,
        /// First body.
        body1: usize,
        /// Frame on body1 (placement relative to the body frame).
        f1: Pose,
        /// Second body.
        body2: usize,
        /// Frame on body2.
        f2: Pose,
    },
    /// Prescribed motion of the frame `frame` on `body` (rheonomic driving constraint): its
    /// origin follows `position(t)` (world components, 3 rows) and, if given, its orientation
    /// follows the Cardan angles x-y-z `orientation(t)`, `A_p = Rx(α) Ry(β) Rz(γ)` (eq. 2.19), by
    /// `Φ = ½ vee(Q - Qᵀ)` with `Q = A_f A_pᵀ` (3 more rows, sin θ · axis in world axes). λ is the
    /// driving force on the body at the frame origin (N, world axes), then the driving moment
    /// (N m, world axes where the orientation is on its prescribed course, `E(I) = I`).
    PrescribedBody {
        /// The driven body.
        body: usize,
        /// The driven frame on the body.
        frame: Pose,
        /// World x, y, z of the frame origin.
        position: [TimeFunction; 3],
        /// Cardan angles x-y-z of the frame (None: only the origin is driven).
        orientation: Option<[TimeFunction; 3]>,
    },
    /// A user-given non-holonomic constraint `W(q, t)ᵀ u + w(q, t) = 0` (eq. 2.70), `rows`
    /// velocity rows with `G = Wᵀ` and `b = -w` from callbacks (no position rows). `γ` comes from
    /// the `rate` callback `d(Wᵀ)/dt u + ẇ`, or else by central differences of `Wᵀ u + w` along
    /// the motion (step `ε^(1/3) / max(1, |u|∞)`; needs [`crate::constraints::accelerations`]). λ: the generalized
    /// constraint force is `W λ`.
    Velocity {
        /// Number of rows, ≥ 1.
        rows: usize,
        /// Callback id of `Wᵀ(t, q)` (rows × nu).
        w_matrix: usize,
        /// Callback id of `w(t, q)` (rows); None: `w = 0`.
        w_offset: Option<usize>,
        /// Callback id of `d(Wᵀ)/dt u + ẇ` at (t, q, u) (rows); None: central differences.
        w_rate: Option<usize>,
    },
    /// Knife edge / sledge: the velocity of point `p` of `body` along the body-fixed unit
    /// direction `e` is zero (1 non-holonomic row; λ is the lateral force on the blade).
    KnifeEdge {
        /// The body.
        body: usize,
        /// Contact point, body frame.
        p: Vec3,
        /// Unit blocked direction, body frame.
        e: Vec3,
    },
    /// Disc of `radius` about the body-fixed unit `axis` through `center` rolling without slipping
    /// on the ground plane z = 0: the material point at the contact has zero velocity (3 rows:
    /// the normal row, holonomic — the contact point's height is zero — then the x and y rows,
    /// non-holonomic). λ is the contact force (N) on the disc, in world (z, x, y) order.
    RollingDisc {
        /// The disc body.
        body: usize,
        /// Disc centre, body frame.
        center: Vec3,
        /// Unit axis, body frame.
        axis: Vec3,
        /// Radius (m), > 0.
        radius: f64,
    },
    /// A contact held closed (a contact with the bilateral normal law, MBSim's bilateral
    /// constraint): the gap `g_N` of the pair's first candidate stays zero (1 holonomic row, λ the
    /// normal force on body1 along the contact normal, N, negative when it pulls) and, when
    /// `rolling`, its tangential relative velocity too (1 non-holonomic row per friction
    /// direction: 1 for a planar pair, 2 in space; λ the tangential forces on body1 along t1, t2).
    Contact {
        /// Body carrying contour 1.
        body1: usize,
        /// Body carrying contour 2.
        body2: usize,
        /// The pair (one candidate), boxed: the other kinds are small.
        pair: Box<ContactPair>,
        /// Whether the contact also rolls without slipping.
        rolling: bool,
        /// Whether g_N = 0 is held (row 0); without it the rows are the tangents alone.
        normal: bool,
    },
    /// A gap contact held closed: its gap function `g_N(q, t) = 0` (1 holonomic row, λ the
    /// generalized force along `∂g/∂q`) and, when `rolling`, the rates of its tangential
    /// coordinates (1 non-holonomic row each).
    Gap {
        /// The function (its rows in `GapWork::rows` at `slot`).
        function: Box<GapFunction>,
        /// Its index among the model's gap functions.
        slot: usize,
        /// Whether the tangential coordinates are held too.
        rolling: bool,
    },
}

/// Which loop-closing joint a [`ConstraintKind::Loop`] is. The joint axis is the z-axis of the
/// two frames. Rows come in the order: translation rows (λ a force on body1, N), then rotation
/// rows (λ a moment, N m).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoopJoint {
    /// Frame origins coincide (3 rows: force along world x, y, z).
    Spherical,
    /// Frame origins coincide and the z-axes stay parallel (5 rows: 3 world forces, then the
    /// moments about `z₁ × x₂` and `z₁ × y₂`).
    Revolute,
    /// Frame origins and orientations coincide (6 rows: 3 world forces, then the moment rows of
    /// `½ vee(R - Rᵀ)`, `R = A₂ᵀA₁`: frame-2 axes when assembled).
    Fixed,
    /// Frame 1's origin stays on the z-axis of frame 2 and the orientations coincide (5 rows:
    /// forces along x₂ and y₂, then the 3 moment rows of `Fixed`).
    Prismatic,
    /// Frame 1's origin stays on the z-axis of frame 2 and the z-axes stay parallel (4 rows:
    /// forces along x₂ and y₂, then the moments about `z₁ × x₂` and `z₁ × y₂`).
    Cylindrical,
    /// Hooke joint: the origins coincide and the cross's pins, x-axis of frame 1 (fixed in body1)
    /// and y-axis of frame 2 (fixed in body2), stay perpendicular (4 rows: 3 world forces, then
    /// the moment about `x₁ × y₂`); the shafts are the z-axes, aligned in the straight position.
    Universal,
    /// The z-axes stay parallel and frame 1's origin stays in the x-y plane of frame 2 (3 rows:
    /// the force along z₂, then the moments about `z₁ × x₂` and `z₁ × y₂`).
    Planar,
}

/// Which generalized velocities a constraint's rows may involve (the structure that the sparse
/// constrained solve is planned from, once per model).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reach {
    /// The joints on the paths from the root to these bodies (0 = ground, reaches nothing).
    Bodies(usize, usize),
    /// These velocity indices only.
    Velocities(usize, usize),
    /// Possibly any velocity (treated as dense).
    All,
}

/// The rows a constraint keeps in a planar model: row `k` is `Σ_j s[k][j] · (full row j)`, a
/// constant combination of the kind's spatial rows. In a planar model the out-of-plane rows of a
/// loop closure vanish identically (they would only be redundant), and the in-plane ones are
/// fixed combinations because rotations about the world z-axis keep the z-components of
/// body-fixed vectors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Selection {
    /// Number of rows kept (≤ 3).
    pub n: usize,
    /// Combination coefficients over the kind's rows (≤ 6).
    pub s: [[f64; 6]; 3],
    /// Column names of the kept rows.
    pub names: [&'static str; 3],
}

/// A named constraint with its row offset in the stacked constraint vector.
#[derive(Debug, Clone, PartialEq)]
pub struct Constraint {
    /// Unique name.
    pub name: String,
    /// What it holds.
    pub kind: ConstraintKind,
    /// Offset of its rows.
    pub row: usize,
    /// The rows kept in a planar model (None: all of the kind's rows).
    pub select: Option<Selection>,
}

impl Constraint {
    /// Number of scalar equations (after the planar selection).
    pub fn rows(&self) -> usize {
        self.select.map_or_else(|| self.kind.rows(), |s| s.n)
    }
    /// Number of holonomic rows (the selected kinds are all holonomic).
    pub fn holonomic_rows(&self) -> usize {
        self.select.map_or_else(|| self.kind.holonomic_rows(), |s| s.n)
    }
}

impl ConstraintKind {
    /// Number of scalar equations.
    pub fn rows(&self) -> usize {
        match self {
            ConstraintKind::Point { .. } | ConstraintKind::RollingDisc { .. } => 3,
            ConstraintKind::PointOnLine { .. } => 2,
            ConstraintKind::PrescribedBody { orientation, .. } => 3 + 3 * usize::from(orientation.is_some()),
            ConstraintKind::Velocity { rows, .. } => *rows,
            ConstraintKind::Contact { pair, rolling, normal, .. } => {
                usize::from(*normal) + usize::from(*rolling) * if pair.is_planar() { 1 } else { 2 }
            }
            ConstraintKind::Gap { function, rolling, .. } => 1 + usize::from(*rolling) * function.tangents(),
            ConstraintKind::Loop { joint, .. } => match joint {
                LoopJoint::Spherical | LoopJoint::Planar => 3,
                LoopJoint::Cylindrical | LoopJoint::Universal => 4,
                LoopJoint::Revolute | LoopJoint::Prismatic => 5,
                LoopJoint::Fixed => 6,
            },
            _ => 1,
        }
    }
    /// Which velocities the rows may involve (see [`Reach`]).
    pub fn reach(&self) -> Reach {
        match self {
            ConstraintKind::Point { body1, body2, .. }
            | ConstraintKind::Distance { body1, body2, .. }
            | ConstraintKind::PointOnLine { body1, body2, .. }
            | ConstraintKind::PointOnPlane { body1, body2, .. }
            | ConstraintKind::Contact { body1, body2, .. }
            | ConstraintKind::Loop { body1, body2, .. } => Reach::Bodies(*body1, *body2),
            ConstraintKind::KnifeEdge { body, .. }
            | ConstraintKind::RollingDisc { body, .. }
            | ConstraintKind::PrescribedBody { body, .. } => Reach::Bodies(*body, 0),
            ConstraintKind::Coupler { iu_a, iu_b, .. } => Reach::Velocities(*iu_a, *iu_b),
            ConstraintKind::Prescribed { iu, .. } => Reach::Velocities(*iu, *iu),
            ConstraintKind::Velocity { .. } | ConstraintKind::Gap { .. } => Reach::All,
        }
    }
    /// Number of holonomic rows (they come first; the rest are non-holonomic velocity rows with
    /// `Φ = 0` that the position projection leaves out).
    pub fn holonomic_rows(&self) -> usize {
        match self {
            ConstraintKind::KnifeEdge { .. } | ConstraintKind::Velocity { .. } => 0,
            ConstraintKind::Contact { normal, .. } => usize::from(*normal),
            ConstraintKind::RollingDisc { .. } | ConstraintKind::Gap { .. } => 1,
            k => k.rows(),
        }
    }
}

/// Velocity indices of a joint-space path: the velocities of the joints from `body` to the root.
fn path_velocities(model: &Model, body: usize, out: &mut Vec<usize>) {
    // an elastic body's points at nodes move with its elastic coordinates too
    if let Some(k) = model.bodies[body].elastic {
        let e = &model.elastic[k];
        out.extend(e.iu..e.iu + e.ne);
    }
    let mut b = body;
    while b != 0 {
        let j = &model.joints[b - 1];
        out.extend(j.iu..j.iu + j.nu());
        b = j.parent;
    }
}

/// The pattern of `G`, planned once per model from each constraint's [`Reach`]: the velocities
/// row r may involve are `idx[ptr[r]..ptr[r + 1]]`, ascending (compressed rows; `ptr` has nc + 1
/// entries). The constraint rows write only there.
pub fn row_pattern(model: &Model) -> (Vec<usize>, Vec<usize>) {
    let (nu, nc) = (model.nu, model.nc);
    let parent = model.velocity_parents();
    let (mut row_ptr, mut row_idx) = (vec![0; nc + 1], Vec::new());
    let mut buf = Vec::new();
    for c in &model.constraints {
        buf.clear();
        match c.kind.reach() {
            Reach::Bodies(b1, b2) => {
                path_velocities(model, b1, &mut buf);
                path_velocities(model, b2, &mut buf);
            }
            Reach::Velocities(a, b) => {
                for v in [a, b] {
                    let mut x = v;
                    while x != usize::MAX {
                        buf.push(x);
                        x = parent[x];
                    }
                }
            }
            Reach::All => buf.extend(0..nu),
        }
        buf.sort_unstable();
        buf.dedup();
        for k in 0..c.rows() {
            row_idx.extend_from_slice(&buf);
            row_ptr[c.row + k + 1] = row_idx.len();
        }
    }
    (row_ptr, row_idx)
}
