"""The engine thread of ``mechsys.simulate``: one thread is kept between runs (a run while it is
busy gets a thread of its own, a forked child makes its own), and the answers do not depend on
which thread ran them; and the recorded body motion of the chain (the rigid-body fast path of the
record stage) against the chain's kinematics from its joint angles.
"""

from __future__ import annotations

import multiprocessing
import sys
import threading

import numpy as np
import pytest

import mechsys as ms
from mechsys import joints

L = 0.5
AXES = ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0))


def chain(n: int) -> ms.Model:
    """n uniform rods along x, revolute axes z, y, x, ..., gravity -z (the benchmark chain)."""
    m = ms.Model(f"chain-{n}", gravity=(0.0, 0.0, -9.81))
    parent = m.ground
    for i in range(n):
        body = m.add_body(f"link{i + 1}", mass=1.0, inertia=[2e-4, 0.0209, 0.0209], com=(0.5 * L, 0, 0))
        m.add_joint(joints.Revolute(f"j{i + 1}", parent, body, parent_frame=(0.0 if i == 0 else L, 0, 0),
                                    axis=AXES[i % 3], q0=0.1 + 0.05 * i, u0=0.3 - 0.2 * i))
        parent = body
    return m


def final_state(m: ms.Model) -> np.ndarray:
    res = ms.simulate(m, 0.2, integrator=ms.RK4(1e-3))
    return np.concatenate([res["q"][-1], res["u"][-1]])


def test_runs_from_several_threads_equal_the_serial_run_bit_for_bit():
    m = chain(5)
    m.build()
    reference = final_state(m)
    out: dict[int, np.ndarray] = {}
    errors: list[BaseException] = []

    def worker(k: int) -> None:
        try:
            out[k] = final_state(m)
        except BaseException as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=worker, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    assert len(out) == 4
    for k, y in out.items():
        np.testing.assert_array_equal(y, reference, err_msg=f"thread {k}")
    # the kept thread is free again afterwards: a further run gives the same answer
    np.testing.assert_array_equal(final_state(m), reference)


def test_an_engine_error_frees_the_kept_thread():
    m = chain(3)
    with pytest.raises(ms.errors.SolverError, match="max_steps"):
        ms.simulate(m, 1.0, integrator=ms.RK4(1e-3), max_steps=10)
    res = ms.simulate(m, 0.05, integrator=ms.RK4(1e-3))
    assert res["t"].shape == (51,) and abs(res["t"][-1] - 0.05) < 1e-12


def _child(conn) -> None:
    conn.send(final_state(chain(4)))
    conn.close()


@pytest.mark.skipif(sys.platform != "linux", reason="fork start method")
def test_a_forked_child_simulates_with_a_thread_of_its_own():
    m = chain(4)
    reference = final_state(m)  # the parent's kept thread exists before the fork
    ctx = multiprocessing.get_context("fork")
    parent_end, child_end = ctx.Pipe()
    p = ctx.Process(target=_child, args=(child_end,))
    p.start()
    assert parent_end.poll(60), "the forked child did not answer (its engine thread never ran)"
    got = parent_end.recv()
    p.join(10)
    assert p.exitcode == 0
    np.testing.assert_array_equal(got, reference)


def test_recorded_body_motion_matches_the_chain_kinematics():
    """Body origins (rigid bodies: r, v + ω × r, a + ω̇ × r + ω × v_O) from the recording against
    the positions of the joint chain computed here from the recorded angles, and their velocities
    and accelerations against central differences of those positions."""
    n, dt = 4, 1e-3
    m = chain(n)
    res = ms.simulate(m, 0.1, integrator=ms.RK4(dt))
    q = res["q"]

    def rot(axis: int, a: np.ndarray) -> np.ndarray:
        c, s = np.cos(a), np.sin(a)
        r = np.zeros(a.shape + (3, 3))
        i1, i2 = (axis + 1) % 3, (axis + 2) % 3
        r[..., axis, axis] = 1.0
        r[..., i1, i1], r[..., i1, i2], r[..., i2, i1], r[..., i2, i2] = c, -s, s, c
        return r

    A = np.broadcast_to(np.eye(3), (q.shape[0], 3, 3)).copy()
    r = np.zeros((q.shape[0], 3))
    for i in range(n):
        if i > 0:
            r = r + A @ np.array([L, 0.0, 0.0])
        A = A @ rot([2, 1, 0][i % 3], q[:, i])
        pos = res[f"body/link{i + 1}/position"]
        np.testing.assert_allclose(pos, r, rtol=0, atol=1e-13)
        vel = res[f"body/link{i + 1}/velocity"]
        acc = res[f"body/link{i + 1}/acceleration"]
        fd_v = (pos[2:] - pos[:-2]) / (2 * dt)
        fd_a = (pos[2:] - 2 * pos[1:-1] + pos[:-2]) / dt**2
        scale_v, scale_a = np.abs(vel).max(), np.abs(acc).max()
        assert np.abs(vel[1:-1] - fd_v).max() < 1e-5 * max(scale_v, 1.0), f"link{i + 1} velocity"
        assert np.abs(acc[1:-1] - fd_a).max() < 1e-3 * max(scale_a, 1.0), f"link{i + 1} acceleration"


def test_the_run_metadata_is_made_once_per_build_and_follows_a_changed_model():
    # the description and joint table every run's results carry are cached with the build: two
    # runs share them, and a model changed after a run gets them anew (a stale table would name
    # the wrong joints and q columns)
    m = chain(2)
    a = ms.simulate(m, 0.01, integrator=ms.RK4(1e-3))
    b = ms.simulate(m, 0.01, integrator=ms.RK4(1e-3))
    assert m.run_metadata() is m.run_metadata()
    assert a.attrs["model"] == b.attrs["model"] == m.build().description_json()
    assert a.names() == b.names()
    body = m.add_body("link3", mass=1.0, inertia=[2e-4, 0.0209, 0.0209], com=(0.5 * L, 0, 0))
    m.add_joint(joints.Revolute("j3", "link2", body, parent_frame=(L, 0, 0), axis=(0.0, 0.0, 1.0), q0=0.3))
    c = ms.simulate(m, 0.01, integrator=ms.RK4(1e-3))
    assert '"j3"' in c.attrs["model"] and '"j3"' not in a.attrs["model"]
    assert c["joint/j3/q"][0] == pytest.approx(0.3, abs=1e-12)
    assert c["q"].shape[1] == 3
