"""Batch simulation (ms.simulate_batch): every case equals the serial ms.simulate run bit for bit,
at any thread count; parameter sets through Model.with_values; errors name their case."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms

ROOT = Path(__file__).resolve().parents[1]


def pendulum_chain():
    m = ms.Model("chain3", gravity=(0.0, -9.81, 0.0))
    parent, at = m.ground, 0.0
    for i in range(3):
        b = m.add_body(f"l{i}", mass=1.0 + 0.2 * i, inertia=ms.inertia.rod(1.0, 0.5), com=(0.25, 0.0, 0.0))
        m.add_joint(ms.joints.Revolute(f"j{i}", parent=parent, child=b, parent_frame=(at, 0.0, 0.0), axis=(0, 0, 1),
                                       damper=ms.forces.RotaryDamper(d=0.01)))
        parent, at = b, 0.5
    return m


def free_body():
    m = ms.Model("tumbler")
    b = m.add_body("box", mass=1.0, inertia=np.diag([0.02, 0.035, 0.05]))
    m.add_joint(ms.joints.Free("free", parent=m.ground, child=b))
    return m


def states(n, seed=3):
    rng = np.random.default_rng(seed)
    return np.hstack([rng.uniform(-1.0, 1.0, (n, 3)), rng.uniform(-2.0, 2.0, (n, 3))])


@pytest.mark.parametrize("integrator", [ms.RK4(1e-3), ms.DOPRI5(rtol=1e-9, atol=1e-11), ms.Radau5(rtol=1e-7, atol=1e-9)])
def test_batch_equals_serial_runs_bit_for_bit(integrator):
    m = pendulum_chain()
    x0 = states(6)
    batch = ms.simulate_batch(m, t_end=0.5, integrator=integrator, output_dt=0.01, initial_states=x0, threads=2)
    assert batch.q.shape == (6, 51, 3) and batch.u.shape == (6, 51, 3)
    for i in range(6):
        res = ms.simulate(m, t_end=0.5, integrator=integrator, output_dt=0.01, q0=x0[i, :3], u0=x0[i, 3:])
        assert np.array_equal(batch.q[i], res["q"]), i
        assert np.array_equal(batch.u[i], res["u"]), i
        assert np.array_equal(batch["energy/kinetic"][i], res["energy/kinetic"]), i
    # the cases are different runs (equal arrays would make the check above vacuous)
    assert not np.allclose(batch.q[0], batch.q[1])


def test_thread_count_does_not_change_results():
    m = free_body()
    rng = np.random.default_rng(7)
    u0 = rng.uniform(-3, 3, (9, 6))
    runs = [ms.simulate_batch(m, t_end=1.0, integrator=ms.RK4(1e-3), output_dt=0.05, u0=u0, threads=k)
            for k in (1, 2, 4)]
    for r in runs[1:]:
        assert np.array_equal(r.q, runs[0].q) and np.array_equal(r.u, runs[0].u)
    # quaternions of free joints stay unit in every case
    assert np.max(np.abs(np.linalg.norm(runs[0].q[:, :, 3:], axis=2) - 1)) < 1e-14


def test_parameter_sets_through_with_values():
    m = pendulum_chain()
    masses = [0.5, 1.0, 2.0]
    values = [{"body.l2.mass": mass} for mass in masses]
    batch = ms.simulate_batch(m, t_end=0.3, integrator=ms.RK4(1e-3), output_dt=0.01, values=values,
                              q0=[[0.3, 0.0, 0.0]] * 3)
    for i, mass in enumerate(masses):
        res = ms.simulate(m.with_values({"body.l2.mass": mass}), t_end=0.3, integrator=ms.RK4(1e-3), output_dt=0.01,
                          q0=[0.3, 0.0, 0.0])
        assert np.array_equal(batch.q[i], res["q"])
    assert batch.results[2].attrs["case"] == 2
    # the heavier tip makes a different motion
    assert not np.allclose(batch.q[0], batch.q[2])


def test_sensors_select_the_stacked_signals():
    m = pendulum_chain()
    batch = ms.simulate_batch(m, t_end=0.2, integrator=ms.RK4(1e-3), output_dt=0.01, initial_states=states(4),
                              sensors=["joint/*/q", "energy/total"])
    assert batch["joint/j1/q"].shape == (4, 21)
    assert batch["energy/total"].shape == (4, 21)
    assert "body/l0/position" not in batch.names()


def test_errors_name_the_case():
    m = pendulum_chain()
    x0 = states(3)
    x0[1, 4] = np.nan
    with pytest.raises(ms.SettingsError, match=r"case 1: .*u0\[1\]"):
        ms.simulate_batch(m, t_end=0.2, integrator=ms.RK4(1e-3), initial_states=x0)
    with pytest.raises(ms.SettingsError, match="initial_states"):
        ms.simulate_batch(m, t_end=0.2, integrator=ms.RK4(1e-3), initial_states=np.zeros((3, 5)))
    with pytest.raises(ms.SettingsError, match="threads"):
        ms.simulate_batch(m, t_end=0.2, integrator=ms.RK4(1e-3), initial_states=states(2), threads=0)
    with pytest.raises(ms.SettingsError, match="values has 2 cases"):
        ms.simulate_batch(m, t_end=0.2, integrator=ms.RK4(1e-3), initial_states=states(3),
                          values=[{}, {}])
    with pytest.raises(ms.ModelError, match="case 0: .*l9"):
        ms.simulate_batch(m, t_end=0.2, integrator=ms.RK4(1e-3), values=[{"body.l9.mass": 1.0}])


def test_a_failing_case_is_kept_apart():
    """A case the engine refuses (a zero quaternion) leaves the others: on_error="keep" returns
    its error naming the case and NaN rows for it; "raise" raises that error."""
    m = free_body()
    q0 = np.array([[0, 0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 0, 0, 0], [0, 0, 0, 0.6, 0.8, 0, 0]], dtype=float)
    u0 = np.tile([0.1, 0.0, 0.0, 1.0, 2.0, 3.0], (3, 1))
    batch = ms.simulate_batch(m, t_end=0.2, integrator=ms.RK4(1e-3), output_dt=0.01, q0=q0, u0=u0, on_error="keep")
    assert batch.errors[0] is None and batch.errors[2] is None
    assert isinstance(batch.errors[1], ms.SettingsError)
    assert "case 1" in str(batch.errors[1]) and "'free'" in str(batch.errors[1])
    assert np.all(np.isnan(batch.q[1])) and batch.results[1] is None
    ok = ms.simulate(m, t_end=0.2, integrator=ms.RK4(1e-3), output_dt=0.01, q0=q0[2], u0=u0[2])
    assert np.array_equal(batch.q[2], ok["q"])
    with pytest.raises(ms.SettingsError, match="case 1: .*'free'"):
        ms.simulate_batch(m, t_end=0.2, integrator=ms.RK4(1e-3), q0=q0, u0=u0)


def test_a_case_is_its_results_by_number_and_bad_keys_are_named():
    """``batch[i]`` is case i's Results (negative from the end); a failed case, a number out of
    range or a key of another type are errors that say so (an integer had reached the signal
    lookup's spelling hints and crashed there with a TypeError)."""
    m = free_body()
    q0 = np.array([[0, 0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 0, 0, 0], [0, 0, 0, 0.6, 0.8, 0, 0]], dtype=float)
    u0 = np.tile([0.1, 0.0, 0.0, 1.0, 2.0, 3.0], (3, 1))
    batch = ms.simulate_batch(m, t_end=0.1, integrator=ms.RK4(1e-3), output_dt=0.01, q0=q0, u0=u0, on_error="keep")
    assert np.array_equal(batch[2]["q"], batch.q[2]) and np.array_equal(batch[-1]["u"], batch.u[2])
    assert np.array_equal(batch[np.int64(0)]["q"], batch.q[0])
    with pytest.raises(ms.ResultsError, match="batch case 1 failed: .*'free'"):
        batch[1]
    with pytest.raises(ms.ResultsError, match=r"batch case 3: the batch has 3 cases \(0 \.\. 2\)"):
        batch[3]
    with pytest.raises(ms.ResultsError, match="signal name or a case number, got 1.5"):
        batch[1.5]
    with pytest.raises(ms.ResultsError, match="named by a string such as 'joint/j1/q', got 0 \\(int\\)"):
        batch[0][0]


def test_cli_batch_writes_stacked_states(tmp_path):
    x0 = states(4)
    np.save(tmp_path / "states.npy", x0)
    model_file = tmp_path / "chain.py"
    model_file.write_text(
        "import sys\n"
        f"sys.path.insert(0, {str(Path(__file__).parent)!r})\n"
        "from test_batch import pendulum_chain\n"
        "model = pendulum_chain()\n"
    )
    out = tmp_path / "batch.npz"
    r = subprocess.run([sys.executable, "-m", "mechsys", "batch", str(model_file), "--states", str(tmp_path / "states.npy"),
                        "--t-end", "0.2", "--integrator", "rk4", "--dt", "1e-3", "--output-dt", "0.01",
                        "--threads", "2", "--out", str(out)], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    data = np.load(out)
    assert data["q"].shape == (4, 21, 3)
    ref = ms.simulate(pendulum_chain(), t_end=0.2, integrator=ms.RK4(1e-3), output_dt=0.01, q0=x0[3, :3], u0=x0[3, 3:])
    assert np.array_equal(data["q"][3], ref["q"])
    assert "4 cases" in r.stdout
    with_signal = subprocess.run([sys.executable, "-m", "mechsys", "batch", str(model_file), "--states",
                                  str(tmp_path / "states.npy"), "--t-end", "0.1", "--dt", "1e-3", "--output-dt", "0.01",
                                  "--sensors", "energy/total", "--out", str(tmp_path / "e.npz")],
                                 capture_output=True, text=True, cwd=ROOT)
    assert with_signal.returncode == 0, with_signal.stderr
    e = np.load(tmp_path / "e.npz")
    assert sorted(e.files) == ["q", "signal:energy/total", "t", "u"]
    assert e["signal:energy/total"].shape == (4, 11)
    bad = subprocess.run([sys.executable, "-m", "mechsys", "batch", str(model_file), "--states", str(tmp_path / "nope.npy"),
                          "--t-end", "0.2"], capture_output=True, text=True, cwd=ROOT)
    assert bad.returncode != 0 and "nope.npy" in bad.stderr
    json.dumps(r.stdout)  # plain text


def test_cancelling_stops_every_case_at_its_next_sample():
    """The engine side of Ctrl-C: a cancelled progress handle stops each case at its first sample
    (what ms.simulate_batch does on KeyboardInterrupt before raising it)."""
    import json as _json

    from mechsys import _core
    from mechsys.simulate import _settings

    m = pendulum_chain()
    prog = _core.Progress()
    prog.cancel()
    s = _settings(m, 5.0, ms.RK4(1e-3), 0.01, None, None, 0.0)
    out = _core.simulate_batch([m.build()], [_json.dumps(s)] * 3, 2, prog)
    assert len(out) == 3
    for raw, err in out:
        assert err is None and "cancelled" in raw["cancelled"] and len(raw["t"]) <= 1


def test_results_made_after_the_model_changed_carry_the_model_that_ran():
    # a batch's Results are made on first use, possibly after the caller changed the model: they
    # must still name the joints and columns of the model that ran, not of the changed one
    m = pendulum_chain()
    batch = ms.simulate_batch(m, t_end=0.05, integrator=ms.RK4(1e-3), output_dt=0.01, initial_states=states(2), threads=1)
    b = m.add_body("l3", mass=1.0, inertia=ms.inertia.rod(1.0, 0.5), com=(0.25, 0.0, 0.0))
    m.add_joint(ms.joints.Revolute("j3", parent="l2", child=b, parent_frame=(0.5, 0.0, 0.0), axis=(0, 0, 1)))
    assert '"j3"' in m.run_metadata()[0]
    for res in batch.results:
        assert '"j3"' not in res.attrs["model"] and '"j2"' in res.attrs["model"]
        assert res["q"].shape[1] == 3 and "joint/j3/q" not in res.names()
        np.testing.assert_array_equal(res["joint/j2/q"], res["q"][:, 2])
