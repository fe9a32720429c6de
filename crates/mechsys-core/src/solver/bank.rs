//! A bank of small LCPs with solutions verified by hand, run through every LCP solver.
//!
//! Each case lists `M` (row-major), `q`, and what is known: the unique solution, "any solution"
//! (checked by complementarity), or "no solution" (Lemke must end in ray termination).

/// What the case's answer is.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Known {
    /// Exactly this `z`.
    Unique(Vec<f64>),
    /// Solutions exist but are not unique; any complementary `z` passes.
    Any,
    /// Infeasible.
    None,
}

#[derive(Debug, Clone)]
pub(crate) struct Case {
    pub name: &'static str,
    pub m: Vec<f64>,
    pub q: Vec<f64>,
    pub known: Known,
    /// Projected Gauss–Seidel applies (positive diagonal) and converges (symmetric PSD, or checked by hand).
    pub pgs: bool,
}

fn case(name: &'static str, m: &[f64], q: &[f64], known: Known, pgs: bool) -> Case {
    Case { name, m: m.to_vec(), q: q.to_vec(), known, pgs }
}

pub(crate) fn cases() -> Vec<Case> {
    use Known::*;
    vec![
        // 1×1, every sign of M and q: w = m z + q
        case("1x1 m>0 q>0: z = 0, w = q", &[2.0], &[4.0], Unique(vec![0.0]), true),
        case("1x1 m>0 q<0: z = -q/m", &[2.0], &[-4.0], Unique(vec![2.0]), true),
        case("1x1 m>0 q=0: z = 0", &[2.0], &[0.0], Unique(vec![0.0]), true),
        case("1x1 m=0 q>0: z = 0", &[0.0], &[3.0], Unique(vec![0.0]), false),
        case("1x1 m=0 q<0: w = q < 0 always", &[0.0], &[-3.0], None, false),
        case("1x1 m=0 q=0: every z ≥ 0", &[0.0], &[0.0], Any, false),
        // z = 0 and z = 2 both solve it
        case("1x1 m<0 q>0: two solutions", &[-1.0], &[2.0], Any, false),
        case("1x1 m<0 q<0: w = -z - 1 < 0", &[-1.0], &[-1.0], None, false),
        // 2×2 P-matrices. M = [[2,1],[1,2]], both basic: z = M⁻¹(5,6) = (4/3, 7/3)
        case("2x2 SPD both active", &[2.0, 1.0, 1.0, 2.0], &[-5.0, -6.0], Unique(vec![4.0 / 3.0, 7.0 / 3.0]), true),
        // z1 = 1/2, w2 = 1/2 + 2 = 2.5
        case("2x2 SPD one active", &[2.0, 1.0, 1.0, 2.0], &[-1.0, 2.0], Unique(vec![0.5, 0.0]), true),
        // non-symmetric P-matrix; both basic gives z1 = -1, z1 alone gives w2 = -1: only z = (0, 1), w = (1, 0)
        case("2x2 non-symmetric P-matrix", &[1.0, 2.0, 0.0, 1.0], &[-1.0, -1.0], Unique(vec![0.0, 1.0]), true),
        // degenerate: all q_i tie in the first ratio test; M (1,1,1)ᵀ/3 = (1,1,1)ᵀ, det M = 9
        case(
            "3x3 cyclic P-matrix, tied first pivot",
            &[1.0, 2.0, 0.0, 0.0, 1.0, 2.0, 2.0, 0.0, 1.0],
            &[-1.0, -1.0, -1.0],
            Unique(vec![1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0]),
            false,
        ),
        // degenerate: q_2 = 0 gives a zero right-hand side; z = (1/2, 0, 1/2), w = (0, 1, 0)
        case(
            "3x3 SPD with zero q entry",
            &[2.0, 1.0, 0.0, 1.0, 2.0, 1.0, 0.0, 1.0, 2.0],
            &[-1.0, 0.0, -1.0],
            Unique(vec![0.5, 0.0, 0.5]),
            true,
        ),
        // PSD, solutions z1 + z2 = 1
        case("2x2 PSD rank 1, a segment of solutions", &[1.0, 1.0, 1.0, 1.0], &[-1.0, -1.0], Any, true),
        // PSD, solutions (1 + t, t)
        case("2x2 PSD, a ray of solutions", &[1.0, -1.0, -1.0, 1.0], &[-1.0, 1.0], Any, true),
        // PSD but w1 + w2 = -2 for every z
        case("2x2 PSD infeasible", &[1.0, -1.0, -1.0, 1.0], &[-1.0, -1.0], None, false),
        // skew-symmetric (PSD): w1 = -z2 - 1 < 0
        case("2x2 skew infeasible", &[0.0, -1.0, 1.0, 0.0], &[-1.0, -1.0], None, false),
        // q ≥ 0: z = 0 without pivoting
        case(
            "3x3 trivial q ≥ 0",
            &[1.0, 5.0, -2.0, 0.0, 1.0, 7.0, 3.0, 3.0, 1.0],
            &[1.0, 0.0, 2.0],
            Unique(vec![0.0; 3]),
            false,
        ),
    ]
}
