"""Moving surfaces (issue 14, part 6): a block put down on a conveyor belt slides until it moves
with the belt at t* = V / (mu g), having slid V² / (2 mu g); friction dissipates m V² / 2 and the
belt does m V² of work (closed forms), in both contact schemes."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def conveyor():
    spec = importlib.util.spec_from_file_location("conveyor", ROOT / "examples" / "conveyor.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("scheme", ["event-driven", "moreau-jean"])
def test_block_on_a_belt_sticks_at_the_closed_form_time_and_then_moves_with_it(conveyor, scheme):
    integ = ms.EventDriven() if scheme == "event-driven" else ms.MoreauJean(dt=1e-4)
    res = ms.simulate(conveyor.model, t_end=0.6, integrator=integ, output_dt=1e-4)
    ts = conveyor.stick_time(res)
    if scheme == "event-driven":
        assert ts == pytest.approx(conveyor.T_STICK, abs=1e-9)
    else:
        assert abs(ts - conveyor.T_STICK) <= 1.5e-4  # within the step
    v = res["joint/free/u"][:, 0]
    after = res.t > conveyor.T_STICK + 1e-3
    assert np.abs(v[after] - conveyor.V).max() < 1e-9
    # uniform acceleration mu g while sliding
    before = (res.t > 0.01) & (res.t < conveyor.T_STICK - 1e-3)
    acc = np.gradient(v, res.t)[before]
    assert np.abs(acc - conveyor.MU * conveyor.G).max() < 1e-6
    # slid over the belt: V t* - x(t*)
    x = float(np.interp(conveyor.T_STICK, res.t, res["joint/free/q"][:, 0]))
    assert conveyor.V * conveyor.T_STICK - x == pytest.approx(conveyor.SLIDE, abs=2e-8)
    # energy: the belt works m V², friction turns half of it into heat, the balance closes
    m, V = conveyor.MASS, conveyor.V
    assert res["energy/external_work"][-1] == pytest.approx(m * V**2, rel=1e-9)
    heat = res["energy/dissipated"][-1]
    assert heat == pytest.approx(0.5 * m * V**2, rel=1e-9)
    balance = res["energy/total"] + res["energy/dissipated"] - res["energy/external_work"]
    assert np.ptp(balance) < 1e-10
    # stuck to the belt: the sliding velocity relative to it is zero
    assert np.abs(res["contact/belt/gd_t"][after]).max() < 1e-9


def test_surface_velocity_errors_name_the_contact():
    m = ms.Model("bad", planar=True, gravity=(0, -9.81, 0))
    b = m.add_body("b", 1.0, ms.inertia.box(1.0, (0.1, 0.1, 0.1)))
    m.add_joint(ms.joints.Planar("free", m.ground, b))
    m.add_contact(ms.Contact("belt", b.contour(ms.contours.Point()),
                             m.ground.contour(ms.contours.Line(normal=(0, 1, 0), surface_velocity=(0.0, 1.0, 0.0)))))
    with pytest.raises(ms.ModelError, match=r"contacts\[0\] 'belt'.contour2.surface_velocity: .*must lie in the surface"):
        m.build()
    m2 = ms.Model("bad2", gravity=(0, 0, -9.81))
    b2 = m2.add_body("b", 1.0, ms.inertia.box(1.0, (0.1, 0.1, 0.1)))
    m2.add_joint(ms.joints.Free("free", m2.ground, b2))
    grp = ms.ContactGroup("pile", members=[b2.contour(ms.contours.Sphere(radius=0.05))],
                          against=[m2.ground.contour(ms.contours.Plane(surface_velocity=(1.0, 0.0, 0.0)))])
    m2.add_contact_group(grp)
    with pytest.raises(ms.ModelError, match="moving surfaces are supported on explicit contacts, not in groups"):
        m2.build()
