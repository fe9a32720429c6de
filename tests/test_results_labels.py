"""Labelled results (issue 13, part 3): per-column names and units of vector signals, read-only
arrays, contact states as named integer levels (an HDF5 enum in files), pandas and xarray views."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

import mechsys as ms


def mixed_model() -> ms.Model:
    m = ms.Model("mixed", gravity=(0, 0, -9.81))
    arm = m.add_body("arm", 1.0, [0.01, 0.01, 0.01], com=(0.2, 0, 0))
    ball = m.add_body("ball", 0.5, ms.inertia.sphere(0.5, 0.05))
    m.add_joint(ms.joints.Revolute("hinge", m.ground, arm, axis=(0, 1, 0), q0=0.2))
    m.add_joint(ms.joints.Free("float", m.ground, ball, q0=[0, 0, 1, 1, 0, 0, 0], u0=[0.1, 0, 0, 0, 0, 2.0]))
    return m


@pytest.fixture(scope="module")
def res():
    return ms.simulate(mixed_model(), 0.2, ms.RK4(dt=1e-3), output_dt=0.01)


def test_vector_signals_name_their_columns_and_units(res):
    assert res.columns("q") == ["hinge.angle", "float.x", "float.y", "float.z", "float.qw", "float.qx", "float.qy",
                                "float.qz"]
    assert res.column_units("q") == ["rad", "m", "m", "m", "1", "1", "1", "1"]
    assert res.columns("u")[1:] == ["float.vx", "float.vy", "float.vz", "float.wx", "float.wy", "float.wz"]
    assert res.column_units("u") == ["rad/s"] + ["m/s"] * 3 + ["rad/s"] * 3
    assert res.column_units("udot") == ["rad/s^2"] + ["m/s^2"] * 3 + ["rad/s^2"] * 3
    assert res.columns("joint/float/q") == ["x", "y", "z", "qw", "qx", "qy", "qz"]
    assert res.column_units("joint/float/u") == ["m/s"] * 3 + ["rad/s"] * 3
    assert res.columns("body/ball/position") == ["x", "y", "z"] and res.columns("body/ball/orientation") == ["w", "x", "y", "z"]
    assert res.columns("joint/hinge/q") == ["q"] and res.column_units("joint/hinge/q") == ["rad"]
    # the columns are what they say: the free joint's z falls under gravity from 1 m
    z = res["q"][:, res.columns("q").index("float.z")]
    np.testing.assert_allclose(z, 1.0 - 0.5 * 9.81 * res.t**2, atol=1e-12)


def test_arrays_are_read_only(res):
    for name in ("q", "joint/hinge/q", "body/arm/position", "energy/total", "joint/hinge/reaction_force"):
        with pytest.raises(ValueError, match="read-only"):
            res[name][0] = 1.0
    copy = np.array(res["q"])
    copy[0, 0] = 5.0  # a copy can be changed
    assert res["q"][0, 0] != 5.0


def test_columns_survive_a_file_and_arrays_stay_read_only(res, tmp_path):
    path = res.save(tmp_path / "r.h5")
    back = ms.Results.load(path)
    assert back.columns("q") == res.columns("q") and back.column_units("u") == res.column_units("u")
    with pytest.raises(ValueError, match="read-only"):
        back["q"][0, 0] = 1.0


def test_contact_state_is_an_integer_level_and_an_hdf5_enum(tmp_path):
    m = ms.Model("drop", gravity=(0, 0, -9.81))
    ball = m.add_body("ball", 1.0, [4e-3] * 3)
    m.add_joint(ms.joints.Prismatic("z", m.ground, ball, axis=(0, 0, 1), q0=0.2))
    m.add_contact(ms.contacts.Contact("floor", m.ground.contour(ms.contours.Plane()), ball.contour(ms.contours.Sphere(radius=0.1))))
    r = ms.simulate(m, 0.5, ms.MoreauJean(dt=1e-3))
    st = r["contact/floor/state"]
    assert st.dtype == np.int8 and set(np.unique(st)) <= {0, 1, 2}
    assert st[0] == 0 and st[-1] == r.levels("contact/floor/state")["stick"] == 1
    assert r.levels("energy/total") is None
    path = r.save(tmp_path / "drop.h5")
    with h5py.File(path) as f:
        assert h5py.check_enum_dtype(f["contact/floor/state"].dtype) == {"open": 0, "stick": 1, "slip": 2}
    np.testing.assert_array_equal(ms.Results.load(path)["contact/floor/state"], st)


def test_to_pandas_and_to_xarray(res):
    pd = pytest.importorskip("pandas")
    df = res.to_pandas(["joint/hinge/q", "body/ball/position", "q"])
    assert isinstance(df, pd.DataFrame) and df.index.name == "t" and len(df) == len(res.t)
    assert list(df.columns[:4]) == ["joint/hinge/q", "body/ball/position.x", "body/ball/position.y", "body/ball/position.z"]
    assert df.attrs["units"]["q.float.qw"] == "1" and df.attrs["units"]["body/ball/position.z"] == "m"
    np.testing.assert_array_equal(df["q.float.z"].to_numpy(), res["q"][:, 3])
    xr = pytest.importorskip("xarray")
    ds = res.to_xarray(["joint/hinge/q", "q"])
    assert isinstance(ds, xr.Dataset) and ds["q"].dims == ("t", "q/column")
    assert list(ds["q"].coords["q/column"].values)[:2] == ["hinge.angle", "float.x"]
    assert ds["joint/hinge/q"].attrs["units"] == "rad" and ds["q"].attrs["column_units"][4] == "1"
    with pytest.raises(ms.ResultsError, match="unknown signal 'body/nobody/position'"):
        res.to_pandas(["body/nobody/position"])


def test_signals_are_laid_out_on_first_use_and_every_way_in_gives_the_same_tables(tmp_path):
    """`simulate` hands back results whose names, units and columns are laid out on first use
    (a parameter study reading one number does not pay for naming every signal). Whatever is
    touched first (a signal, the names, a pickle, a file, a selective recording), the tables are
    those of a layout done at once."""
    import pickle

    model, integ = mixed_model(), ms.RK4(dt=1e-3)
    ref = ms.simulate(model, 0.05, integ, output_dt=0.01)
    names = ref.names()
    assert "body/ball/position" in names and "energy/total" in names and len(names) > 30
    firsts = {
        "item": lambda r: r["joint/float/q"],
        "names": lambda r: r.names(),
        "pickle": lambda r: pickle.loads(pickle.dumps(r)),
        "repr": repr,
        "columns": lambda r: r.columns("q"),
        "file": lambda r: ms.load(r.save(tmp_path / "first.h5")),
    }
    for what, touch in firsts.items():
        r = ms.simulate(model, 0.05, integ, output_dt=0.01)
        assert "_signals" not in r.__dict__, what  # nothing laid out before the first use
        out = touch(r)
        got = out if isinstance(out, ms.Results) else r
        assert got.names() == names, what
        assert [got.unit(n) for n in names] == [ref.unit(n) for n in names], what
        np.testing.assert_array_equal(got["q"], ref["q"], err_msg=what)
        assert got.columns("u") == ref.columns("u"), what
    # a selective recording keeps only what it chose, however it is first read
    sel = ms.simulate(model, 0.05, integ, output_dt=0.01, sensors=["joint/hinge/*"])
    assert sel.names() == ["t", "joint/hinge/q", "joint/hinge/u", "joint/hinge/udot", "joint/hinge/reaction_force",
                           "joint/hinge/reaction_torque"]
    with pytest.raises(ms.ResultsError, match="unknown signal 'q'"):
        sel["q"]
    # (also when a file or a pickle is the first use)
    sel = ms.simulate(model, 0.05, integ, output_dt=0.01, sensors=["joint/hinge/*"])
    assert ms.load(sel.save(tmp_path / "sel.h5")).names()[:4] == ["t", "joint/hinge/q", "joint/hinge/u", "joint/hinge/udot"]
    sel = ms.simulate(model, 0.05, integ, output_dt=0.01, sensors=["joint/hinge/*"])
    assert "q" not in pickle.loads(pickle.dumps(sel)).names()
    # a missing attribute is still an AttributeError naming it
    with pytest.raises(AttributeError, match="no_such_thing"):
        ms.simulate(model, 0.05, integ, output_dt=0.01).no_such_thing


def test_a_layout_that_fails_fails_the_same_way_each_time():
    """A recording that cannot be laid out (here: no time column) raises on every use, not once
    and then an AttributeError about missing tables."""
    from mechsys.results import Results

    broken = Results.from_raw({}, [], [], {})
    for _ in range(2):
        with pytest.raises(KeyError, match="'t'"):
            broken.names()
