"""Results files: HDF5 round trip (arrays, units, attributes), CSV export, unreadable files."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest

import mechsys as ms
from mechsys.errors import ResultsError


@pytest.fixture(scope="module")
def results() -> ms.Results:
    m = ms.Model("slider-pendulum", gravity=(0.0, -9.81, 0.0))
    cart = m.add_body("cart", mass=2.0, inertia=[0.01, 0.01, 0.01])
    rod = m.add_body("rod", mass=0.5, inertia=[1e-4, 0.02, 0.02], com=(0.3, 0.0, 0.0))
    m.add_joint(ms.joints.Prismatic("slide", parent=m.ground, child=cart, axis=(1.0, 0.0, 0.0),
                                    spring=ms.forces.JointSpring(k=50.0), damper=ms.forces.JointDamper(d=0.5)))
    m.add_joint(ms.joints.Revolute("hinge", parent=cart, child=rod, axis=(0.0, 0.0, 1.0)))
    return ms.simulate(m, t_end=0.3, integrator=ms.RK4(dt=1e-3), output_dt=1e-2, q0={"slide": 0.1, "hinge": 0.4})


def test_hdf5_round_trip(results, tmp_path):
    path = results.save(tmp_path / "deep" / "run.h5")
    assert path.exists()
    loaded = ms.load(path)
    assert sorted(loaded.names()) == sorted(results.names())
    assert loaded.names()[0] == "t"
    for name in results.names():
        a, b = results[name], loaded[name]
        assert a.shape == b.shape, name
        assert b.dtype == np.float64, name
        np.testing.assert_array_equal(a, b, err_msg=name)
        assert loaded.unit(name) == results.unit(name), name
    assert loaded.unit("joint/slide/q") == "m"
    assert loaded.unit("joint/hinge/u") == "rad/s"
    assert loaded.unit("momentum/angular") == "N m s"
    assert loaded.model == results.model
    assert loaded.model["name"] == "slider-pendulum"
    assert loaded.settings == results.settings
    # RK4 over 300 steps: 4 evaluations a step plus the one at the first sample
    assert loaded.stats == results.stats == {"steps": 300, "rejected": 0, "evaluations": 4 * 300 + 1, "jacobians": 0,
                                             "events": 0, "transitions": 0, "transition_seconds": 0.0}
    assert len(loaded.t) == 31


def test_hdf5_layout(results, tmp_path):
    """The file is plain HDF5 that other tools can read: one dataset per signal with a unit."""
    path = results.save(tmp_path / "run.h5")
    with h5py.File(path, "r") as f:
        assert f.attrs["format"] == "mechsys-results"
        assert f["joint/hinge/q"].attrs["unit"] == "rad"
        assert f["body/rod/position"].shape == (31, 3)
        assert json.loads(f.attrs["model"])["joints"][0]["name"] == "slide"


def test_save_then_load_keeps_loaded_results_savable(results, tmp_path):
    first = ms.load(results.save(tmp_path / "a.h5"))
    second = ms.load(first.save(tmp_path / "b.h5"))
    for name in results.names():
        np.testing.assert_array_equal(second[name], results[name], err_msg=name)
        assert second.unit(name) == results.unit(name)


def test_csv_header_units_and_rows(results, tmp_path):
    path = results.to_csv(tmp_path / "out.csv", ["joint/slide/q", "joint/hinge/q", "momentum/linear"])
    lines = path.read_text().splitlines()
    assert lines[0] == (
        "t [s],joint/slide/q [m],joint/hinge/q [rad],"
        "momentum/linear[0] [N s],momentum/linear[1] [N s],momentum/linear[2] [N s]"
    )
    assert len(lines) == 1 + len(results.t)
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    assert data.shape == (31, 6)
    np.testing.assert_allclose(data[:, 0], results.t, rtol=1e-15)
    np.testing.assert_allclose(data[:, 2], results["joint/hinge/q"], rtol=1e-15)
    np.testing.assert_allclose(data[:, 3:], results["momentum/linear"], rtol=1e-15)


def test_csv_all_signals(results, tmp_path):
    path = results.to_csv(tmp_path / "all.csv")
    header = path.read_text().splitlines()[0].split(",")
    assert header[0] == "t [s]"
    assert "energy/total [J]" in header
    assert "body/cart/orientation[3] [1]" in header
    assert not any(h.startswith(("q ", "u ", "udot ")) for h in header)


def test_csv_unknown_signal(results, tmp_path):
    with pytest.raises(ResultsError, match="unknown signal 'joint/slid/q'"):
        results.to_csv(tmp_path / "x.csv", ["joint/slid/q"])


def test_unknown_signal_and_unit(results):
    with pytest.raises(ResultsError, match="unknown signal 'energy/totl'"):
        results["energy/totl"]
    with pytest.raises(ResultsError, match="unknown signal"):
        results.unit("nothing")
    assert "energy/total" in results and "energy/totl" not in results


def test_load_errors(tmp_path):
    with pytest.raises(ResultsError, match="does not exist"):
        ms.load(tmp_path / "missing.h5")
    text = tmp_path / "text.h5"
    text.write_text("not an HDF5 file\n")
    with pytest.raises(ResultsError, match="is not an HDF5 results file"):
        ms.load(text)
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as f:
        f["x"] = np.arange(3.0)
    with pytest.raises(ResultsError, match="not mechsys results"):
        ms.load(other)
