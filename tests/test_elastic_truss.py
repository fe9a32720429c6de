"""An elastic body from external FE matrices with translational nodes only (issue 16): the
space-truss boom of benches/truss_boom.py (84 nodes, 3 DOFs each, assembled in NumPy) through
``elastic.fe_model`` with the rotation DOFs fixed.

References that do not come from the reduction: the full (unreduced) FE static solution and
eigenvalues by dense linear algebra on the assembled matrices, the Euler–Bernoulli cantilever of
the boom's equivalent section (a lattice is also sheared, so that one holds to a few per cent), the
axial stiffness of the four chords, and — when Exudyn is installed — Exudyn's reduced-order
floating-frame body on the same matrices and modes (the benchmark's pendulum, 0.2 s).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benches"))
from truss_boom import mechsys_body, truss_boom  # noqa: E402

BAR_AREA, E = 2e-5, 210e9
EI = E * BAR_AREA * 4 * 0.025**2  # four chords at (±w/2, ±w/2) from the axis
TIP_FORCE = np.array([30.0, -200.0, 80.0])


@pytest.fixture(scope="module")
def boom():
    return truss_boom(bar_area=BAR_AREA, E=E)


def full_tip_static(boom):
    load = np.zeros(3 * boom.n_nodes)
    for i in boom.tip:
        load[3 * i : 3 * i + 3] = TIP_FORCE / 4
    return boom.static(load).reshape(-1, 3)[boom.tip].mean(0)


def test_the_boom_is_the_lattice_it_claims(boom):
    assert boom.n_nodes == 84 and len(boom.bars) == 265
    length = np.linalg.norm(boom.nodes[boom.bars[:, 1]] - boom.nodes[boom.bars[:, 0]], axis=1).sum()
    np.testing.assert_allclose(boom.mass, 7850.0 * BAR_AREA * length, rtol=1e-12)
    # K has exactly the six rigid-body motions as its null space
    assert np.sum(np.linalg.eigvalsh(boom.K) < 1e-6 * np.abs(boom.K).max()) == 6


def test_static_tip_load_through_the_engine_is_the_full_fe_solution(boom):
    """Craig–Bampton with the tip nodes as interface spans the static response to tip loads
    exactly: the engine's static equilibrium gives the full FE tip displacement to round-off."""
    body = mechsys_body(boom, 4, craig_bampton_nodes=boom.tip)
    m = ms.Model("truss_static")
    b = m.add_elastic_body("boom", body, stiffening=False)
    m.add_joint(ms.joints.Fixed("clamp", m.ground, b))
    for i in boom.tip:
        m.add_force(ms.forces.BodyForce(f"tip{i}", b, force=tuple(TIP_FORCE / 4), point=b.node(i)))
    q = ms.analysis.static_equilibrium(m)["q"]
    tip = (body.modes[boom.tip, :3, :] @ q).mean(0)
    ref = full_tip_static(boom)
    np.testing.assert_allclose(tip, ref, rtol=1e-8)
    # and the full solution is the boom's: chords in tension (F/(4 E A)), bending F L³/(3 E I)
    # plus the lattice's shear flexibility (1.5 % here)
    np.testing.assert_allclose(ref[0], TIP_FORCE[0] / (4 * E * BAR_AREA), rtol=1e-6)
    np.testing.assert_allclose(ref[1:], TIP_FORCE[1:] / (3 * EI), rtol=0.03)
    assert abs(ref[1]) > abs(TIP_FORCE[1]) / (3 * EI)


def test_modal_truncation_converges_to_the_static_solution(boom):
    ref = full_tip_static(boom)
    errs = []
    for n in (8, 30):
        body = mechsys_body(boom, n)
        kq = np.zeros(n)
        for i in boom.tip:
            kq += body.modes[i, :3, :].T @ (TIP_FORCE / 4)
        q = np.linalg.solve(body.K, kq)
        errs.append(abs((body.modes[boom.tip, 1, :] @ q).mean() - ref[1]) / abs(ref[1]))
    assert errs[0] < 5e-3 and errs[1] < 2e-4


def test_clamped_frequencies_are_the_full_eigenvalues(boom):
    body = mechsys_body(boom, 8)
    w2, _ = boom.clamped_modes(8)
    np.testing.assert_allclose(body.frequencies(), np.sqrt(w2) / (2 * np.pi), rtol=1e-9)
    # the first pair bends about y and z: the cantilever 1.8751² √(EI / (ρA L⁴)), less a little shear
    f_eb = 1.8751**2 * np.sqrt(EI / boom.mass) / (2 * np.pi)
    np.testing.assert_allclose(body.frequencies()[:2], f_eb, rtol=0.04)
    assert np.all(body.frequencies()[:2] < f_eb)
    # the body frame is the root section: the reduced rigid-body mass is the boom's
    np.testing.assert_allclose(body.mass, boom.mass, rtol=1e-12)
    np.testing.assert_allclose(body.center_of_mass, [0.5, 0.0, 0.0], atol=1e-12)


def test_pendulum_agrees_with_exudyns_reduced_order_ffrf(boom):
    """The boom hinged at its root, released horizontal under gravity: mechsys against Exudyn's
    ObjectFFRFreducedOrder (its TrapezoidalIndex2 at a fine step) with the same 4 clamped modes,
    0.2 s. The tip deflections (root-section frame, up to 0.05 mm) agree to 0.13 % of their peak
    at Exudyn's step 1e-5, shrinking as h² (0.73 % at 2e-5, 0.025 % at 5e-6); the hinge angles
    to 3e-7 rad, a floor that does not shrink with the step and is absent without gravity (a
    free spin agrees to 1e-11 rad): the two codes' gravity loads differ at that level."""
    pytest.importorskip("exudyn")
    import elastic_exudyn as bench

    body = mechsys_body(boom, 4)
    fem = bench.exudyn_fem(boom, 4)
    np.testing.assert_allclose(np.sqrt(np.asarray(fem.eigenValues[:4])) / (2 * np.pi), body.frequencies(), rtol=1e-9)
    ours = bench.mechsys_run(bench.mechsys_model(body, "pendulum"), boom, ms.DOPRI5(rtol=1e-10, atol=1e-13), t_end=0.2)
    theirs = bench.ExudynRun(boom, fem, "pendulum").run("trapezoidal", 1e-5, t_end=0.2)
    tip_err, angle_err = bench.errors(theirs, ours)
    assert abs(ours[1][-1]) > 0.15  # it swings: 0.2 s of a 1 m pendulum from the horizontal
    assert np.abs(ours[2]).max() > 3e-5
    assert angle_err < 1e-6
    assert tip_err < 0.005
