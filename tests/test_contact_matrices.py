"""The contact matrices of a state through the Python API (issue 12): rows W, the Delassus matrix
W^T M~^-1 W, w-bar and the free relative accelerations, against closed forms and against
matrices built independently from the mass matrix and finite differences of the gap."""

from __future__ import annotations

import numpy as np
import pytest

import mechsys as ms

G = 9.81


def leaning_rod(theta, length=1.0, mass=1.0):
    m = ms.Model("rod", gravity=(0.0, -G, 0.0))
    b = m.add_body("rod", mass, ms.inertia.rod(mass, length))
    m.add_joint(ms.joints.Planar("plane", m.ground, b, q0=[0.5 * length * np.cos(theta), 0.5 * length * np.sin(theta), theta]))
    m.add_contact(ms.Contact("tip", b.contour(ms.contours.Point(position=(-0.5 * length, 0, 0))),
                             m.ground.contour(ms.contours.Line(normal=(0, 1, 0))), friction=ms.laws.Coulomb(0.5)))
    return m


@pytest.mark.parametrize("theta", [np.radians(30), np.radians(60)])
def test_delassus_of_a_leaning_rod_tip_in_closed_form(theta):
    """Slender rod (I = m L^2 / 12 about its centre), tip at r = -(L/2)(cos, sin) from the centre:
    W_NN = 1/m + (L/2)^2 cos^2 / I = (1 + 3 cos^2)/m, |W_NT| = 3 cos sin / m, W_TT = (1 + 3 sin^2)/m."""
    m = leaning_rod(theta)
    q = np.array([0.5 * np.cos(theta), 0.5 * np.sin(theta), theta])
    omega = 2.0
    c = ms.dynamics.contact_matrices(m, q, np.array([0.3, 0.5 * omega * np.cos(theta), omega]))
    w = c["delassus"]
    cs, sn = np.cos(theta), np.sin(theta)
    assert c["gap"][0] == pytest.approx(0.0, abs=1e-15)
    np.testing.assert_allclose([w[0, 0], abs(w[0, 1]), w[1, 1]], [1 + 3 * cs**2, 3 * cs * sn, 1 + 3 * sn**2], rtol=1e-12)
    np.testing.assert_allclose(w, w.T, atol=1e-14)
    # the tip's normal velocity: v_y + omega (-(L/2) cos) = 0 by construction; free normal
    # acceleration -g + omega^2 (L/2) sin (the centripetal part lifts the tip)
    assert c["velocity"][0, 0] == pytest.approx(0.0, abs=1e-14)
    assert c["free_acceleration"][0, 0] == pytest.approx(-G + omega**2 * 0.5 * sn, rel=1e-12)


def test_rows_and_delassus_match_the_mass_matrix_and_the_gap_by_differences():
    """A ball on a tilted plane under a pendulum arm (a tree with a revolute joint): W's normal row
    is the gradient of the gap (central differences of the recorded gap), and the Delassus matrix
    is W M^-1 W^T with M from the mass-matrix routine."""
    m = ms.Model("arm", gravity=(0, -G, 0))
    arm = m.add_body("arm", 2.0, ms.inertia.rod(2.0, 1.0), com=(0.5, 0, 0))
    m.add_joint(ms.joints.Revolute("hinge", m.ground, arm, axis=(0, 0, 1)))
    b = m.add_body("ball", 0.5, ms.inertia.sphere(0.5, 0.05))
    m.add_joint(ms.joints.Planar("slide", arm, b, parent_frame=(1.0, 0, 0)))
    m.add_contact(ms.Contact("hit", b.contour(ms.contours.Circle(radius=0.05)),
                             m.ground.contour(ms.contours.Line(point=(0, -1.2, 0), normal=(0.2, 1.0, 0))),
                             friction=ms.laws.Coulomb(0.3)))
    q = np.array([-1.2, 0.1, -0.05, 0.4])
    c = ms.dynamics.contact_matrices(m, q)
    w = c["w"][0]
    grad = np.zeros(m.nq)
    for i in range(m.nq):
        dq = np.zeros(m.nq)
        dq[i] = 1e-6
        gp = ms.dynamics.contact_matrices(m, q + dq)["gap"][0]
        gm = ms.dynamics.contact_matrices(m, q - dq)["gap"][0]
        grad[i] = (gp - gm) / 2e-6
    # (planar joints' velocities are the coordinates' rates here)
    np.testing.assert_allclose(w[0], grad, atol=1e-8)
    mm = ms.dynamics.mass_matrix(m, q)
    ww = w[:2]
    np.testing.assert_allclose(c["delassus"][:2, :2], ww @ np.linalg.solve(mm, ww.T), rtol=1e-12, atol=1e-14)


def test_contact_matrices_bad_state_names_the_argument():
    m = leaning_rod(0.5)
    with pytest.raises(ms.SettingsError, match="q"):
        ms.dynamics.contact_matrices(m, np.zeros(2))
    with pytest.raises(ms.SettingsError, match="u"):
        ms.dynamics.contact_matrices(m, np.zeros(3), np.zeros(5))
    with pytest.raises(ms.SettingsError, match=r"u\[1\]: must be finite"):
        ms.dynamics.contact_matrices(m, np.zeros(3), np.array([0.0, np.nan, 0.0]))
    with pytest.raises(ms.SettingsError, match="t: must be finite"):
        ms.dynamics.contact_matrices(m, np.zeros(3), np.zeros(3), t=np.inf)
