"""``sensors=``: a run records only the signals asked for (issue 13, part 3). The selected signals
must equal those of a full recording exactly (the selection changes what is stored, never the
motion), what was not asked for must be absent (also from the engine's arrays), and a pattern
that matches nothing is refused before the run, naming it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms
from mechsys.errors import SettingsError
from mechsys.results import record_selection

ROOT = Path(__file__).resolve().parents[1]


def chain(n=6, loop=False):
    m = ms.Model(f"chain{n}", gravity=(0, -9.81, 0))
    parent = m.ground
    for i in range(n):
        b = m.add_body(f"b{i}", 1.0, ms.inertia.rod(1.0, 0.1), com=(0.05, 0, 0))
        b.add_marker("tip", (0.1, 0, 0))
        m.add_joint(ms.joints.Revolute(f"j{i}", parent, b, parent_frame=(0.1, 0, 0) if i else None, q0=0.2))
        parent = b
    m.add_force(ms.forces.JointForce("motor", "j0", 0.5))
    m.add_force(ms.forces.JointForce("brake", "j1", -0.1))
    if loop:
        m.add_constraint(ms.constraints.Distance("rope", body1=parent, point1=(0.1, 0, 0), body2=m.ground,
                                                 point2=(0.3, -0.3, 0), length=0.3))
    return m


@pytest.fixture(scope="module")
def full():
    return ms.simulate(chain(), 0.3, ms.RK4(dt=1e-3))


def test_selected_signals_equal_the_full_recording_and_nothing_else_is_kept(full):
    want = ["marker/b5/tip/position", "joint/j0/q", "energy/total", "body/b2/acceleration", "force/motor/force"]
    sel = ms.simulate(chain(), 0.3, ms.RK4(dt=1e-3), sensors=want)
    assert sorted(sel.names()) == sorted(want + ["t"])
    for n in want:
        assert np.array_equal(sel[n], full[n]), n
    assert "q" not in sel and "body/b0/position" not in sel and "constraint/rope/lambda" not in sel
    assert sel.columns("marker/b5/tip/position") == ["x", "y", "z"]


def test_patterns_choose_what_the_engine_records():
    core = chain(loop=True).build()
    # a marker needs its body's states only; no accelerations, constraints or forces
    rec, names = record_selection(core, ["marker/b3/tip/position"])
    assert rec == {"bodies": ["b3"], "accelerations": False, "constraints": False, "forces": False, "contacts": False}
    assert names == ["marker/b3/tip/position"]
    # the model's centre of mass needs every body; an acceleration switches accelerations on
    rec, _ = record_selection(core, ["com/acceleration"])
    assert rec["bodies"] == [f"b{i}" for i in range(6)] and rec["accelerations"]
    # reactions come from the accelerations; constraint and force values from their groups
    rec, names = record_selection(core, ["joint/j2/reaction_*", "constraint/rope/*", "force/*/force"])
    assert rec == {"bodies": [], "accelerations": True, "constraints": True, "forces": True, "contacts": False}
    assert "constraint/rope/velocity_violation" in names and "force/brake/force" in names
    # the engine's arrays shrink with the selection
    res = ms.simulate(chain(loop=True), 0.2, ms.RK4(dt=1e-3), sensors=["joint/j2/reaction_force", "constraint/rope/lambda"])
    full = ms.simulate(chain(loop=True), 0.2, ms.RK4(dt=1e-3))
    assert np.allclose(res["joint/j2/reaction_force"], full["joint/j2/reaction_force"], rtol=0, atol=1e-12)
    assert np.array_equal(res["constraint/rope/lambda"], full["constraint/rope/lambda"])


def test_a_selection_without_accelerations_gives_positions_and_velocities_only(full):
    sel = ms.simulate(chain(), 0.3, ms.RK4(dt=1e-3), sensors=["marker/b1/*", "body/b1/com_*"])
    names = set(sel.names())
    assert "marker/b1/tip/acceleration" in names  # asked for by the pattern: accelerations recorded
    sel2 = ms.simulate(chain(), 0.3, ms.RK4(dt=1e-3), sensors=["marker/b1/tip/velocity", "body/b1/com_position"])
    assert set(sel2.names()) == {"t", "marker/b1/tip/velocity", "body/b1/com_position"}
    assert np.array_equal(sel2["marker/b1/tip/velocity"], full["marker/b1/tip/velocity"])
    assert np.array_equal(sel2["body/b1/com_position"], full["body/b1/com_position"])


def sliding_boxes():
    """Two boxes on the floor, one stacked on the other, the pair thrown sideways: the lower one
    slides, the upper sticks, both come to rest (contact states change during the run)."""
    m = ms.Model("boxes", gravity=(0.0, 0.0, -9.81))
    shape = ms.contours.Box(half_extents=(0.1, 0.1, 0.05))
    low = m.add_body("low", 1.0, ms.inertia.box(1.0, (0.2, 0.2, 0.1)))
    m.add_joint(ms.joints.Free("free_low", m.ground, low, q0=[0, 0, 0.05, 1, 0, 0, 0], u0=[0.8, 0, 0, 0, 0, 0]))
    top = m.add_body("top", 1.0, ms.inertia.box(1.0, (0.2, 0.2, 0.1)))
    m.add_joint(ms.joints.Free("free_top", m.ground, top, q0=[0, 0, 0.15, 1, 0, 0, 0], u0=[0.8, 0, 0, 0, 0, 0]))
    m.add_contact(ms.Contact("floor", low.contour(shape), m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             friction=ms.laws.Coulomb(0.3)))
    m.add_contact(ms.Contact("on", top.contour(shape), low.contour(shape), friction=ms.laws.Coulomb(0.8)))
    return m


def test_a_selection_without_contact_signals_skips_them_and_leaves_the_motion_alone():
    """Moreau-Jean skips the contact points' kinematics at the samples when no contact signal is
    chosen: the bodies move the same bit for bit, the solver's signals and the contact energies
    are there, no contact point signal is, and the engine's arrays hold none (a 1000-sphere pile
    records thousands of candidate points per sample)."""
    integ = ms.MoreauJean(1e-3, solver="auto")
    full = ms.simulate(sliding_boxes(), 0.5, integ, output_dt=1e-3)
    # the scene changes state: the lower box slides, then stops
    slid = full["body/low/position"][-1, 0] - full["body/low/position"][0, 0]
    assert 0.05 < slid < 0.5 and abs(full["body/low/velocity"][-1, 0]) < 1e-6
    want = ["body/*/position", "body/*/velocity", "solver/*", "energy/dissipated_friction"]
    sel = ms.simulate(sliding_boxes(), 0.5, integ, output_dt=1e-3, sensors=want)
    assert not [n for n in sel.names() if n.startswith("contact/")]
    for n in ["body/low/position", "body/top/velocity", "solver/residual", "solver/iterations", "energy/dissipated_friction"]:
        assert np.array_equal(sel[n], full[n]), n
    assert full["energy/dissipated_friction"][-1] > 0.1
    # energy balance: the throw's kinetic energy, 2 · ½ · 1 kg · (0.8 m/s)², is all dissipated
    # (mostly by friction) once both boxes rest
    np.testing.assert_allclose(full["energy/dissipated"][-1], 0.64, rtol=1e-9)
    assert full["energy/dissipated_friction"][-1] > 0.6
    core = sliding_boxes().build()
    assert record_selection(core, want)[0]["contacts"] is False
    # one contact signal brings the points back, equal to the full recording's
    sel = ms.simulate(sliding_boxes(), 0.5, integ, output_dt=1e-3, sensors=["contact/on/lambda_n", "body/top/position"])
    assert np.array_equal(sel["contact/on/lambda_n"], full["contact/on/lambda_n"])
    assert np.array_equal(sel["body/top/position"], full["body/top/position"])
    # the weight of the upper box rests on its four corners at the end
    np.testing.assert_allclose(sel["contact/on/lambda_n"][-1].sum(), 9.81, rtol=1e-6)


def test_selective_results_save_and_load(tmp_path):
    sel = ms.simulate(chain(), 0.1, ms.RK4(dt=1e-3), sensors=["joint/*/q", "energy/*"])
    path = sel.save(tmp_path / "r.h5")
    back = ms.Results.load(path)
    assert sorted(back.names()) == sorted(sel.names())
    assert "joint/j3/q" in back and "energy/dissipated" in back and "joint/j3/u" not in back
    assert back.attrs["sensors"] == '["joint/*/q", "energy/*"]'


@pytest.mark.parametrize("bad, fragment", [
    (["marker/b9/tip/position"], "'marker/b9/tip/position' matches no signal of model 'chain6'; similar: marker/b"),
    (["joint/j0/qq"], "'joint/j0/qq' matches no signal"),
    ([], "sensors: empty list"),
    ([3], "sensors: expected signal names or patterns"),
    (5, "sensors: expected a list"),
])
def test_bad_sensor_selections_are_refused_naming_them(bad, fragment):
    with pytest.raises(SettingsError, match=fragment.replace("(", r"\(")):
        ms.simulate(chain(), 0.1, ms.RK4(dt=1e-3), sensors=bad)


def test_sensors_from_the_command_line_and_the_model_file(tmp_path):
    model = tmp_path / "chain.py"
    model.write_text(
        "import mechsys as ms\n"
        "model = ms.Model('chain', gravity=(0, -9.81, 0))\n"
        "parent = model.ground\n"
        "for i in range(4):\n"
        "    b = model.add_body(f'b{i}', 1.0, ms.inertia.rod(1.0, 0.1), com=(0.05, 0, 0))\n"
        "    model.add_joint(ms.joints.Revolute(f'j{i}', parent, b, parent_frame=(0.1, 0, 0) if i else None, q0=0.1))\n"
        "    parent = b\n"
        "simulation = dict(t_end=0.1, integrator=ms.RK4(dt=1e-3), sensors=['energy/total'])\n"
    )
    out = tmp_path / "r.h5"
    p = subprocess.run([sys.executable, "-m", "mechsys", "run", str(model), "--out", str(out), "--plot", str(tmp_path / "r.png")],
                       capture_output=True, text=True, cwd=ROOT)
    assert p.returncode == 0, p.stderr
    assert sorted(ms.Results.load(out).names()) == ["energy/total", "t"]
    p = subprocess.run([sys.executable, "-m", "mechsys", "run", str(model), "--out", str(out), "--sensors", "joint/j3/q,body/b3/position"],
                       capture_output=True, text=True, cwd=ROOT)
    assert p.returncode == 0, p.stderr
    assert sorted(ms.Results.load(out).names()) == ["body/b3/position", "joint/j3/q", "t"]
    p = subprocess.run([sys.executable, "-m", "mechsys", "run", str(model), "--out", str(out), "--sensors", "joint/j7/q"],
                       capture_output=True, text=True, cwd=ROOT)
    assert p.returncode != 0 and "sensors: 'joint/j7/q' matches no signal" in p.stderr and "Traceback" not in p.stderr


def test_event_driven_without_contact_signals_records_none_and_moves_the_same():
    """The event-driven scheme honours the selection too: its impulse integrals run either way
    (the energies are the same bit for bit), the points' signals are left out."""
    full = ms.simulate(sliding_boxes(), 0.05, ms.EventDriven(), output_dt=1e-3)
    sel = ms.simulate(sliding_boxes(), 0.05, ms.EventDriven(), output_dt=1e-3, sensors=["body/*/position", "energy/*"])
    assert not [n for n in sel.names() if n.startswith("contact/")]
    for n in ["body/low/position", "body/top/position", "energy/dissipated_friction", "energy/dissipated_impact"]:
        assert np.array_equal(sel[n], full[n]), n
    # the lower box slides on the floor from the start: friction takes energy within 0.05 s
    assert full["energy/dissipated_friction"][-1] > 1e-3
