"""Box-on-box contact (separating axes, clipped face manifold, edge-edge point) under Moreau-Jean
time-stepping: resting boxes carry their weight with the expected number of contact points, the
closed-form gap of crossing edges, a box tipped over an edge falls the way its centre of mass says,
and a stack of ten equal boxes stays at rest."""

import math

import numpy as np
import pytest

import mechsys as ms

G = 9.81
# a tight contact solver: the stack's friction-contact problems are badly conditioned (4 points
# per interface, 10 bodies in series) and NSGS needs many sweeps from a cold start
TIGHT = ms.NSGS(tol=1e-12, max_iter=100_000)


def quat(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    return [math.cos(angle / 2), *(math.sin(angle / 2) * a)]


def free_box(m, name, half, mass, position, q=(1, 0, 0, 0)):
    b = m.add_body(name, mass, ms.inertia.box(mass, tuple(2 * h for h in half)))
    m.add_joint(ms.joints.Free(f"free_{name}", m.ground, b, q0=[*position, *q]))
    return b


def used(res, name, far=0.1):
    """Candidates in use at the last sample (unused ones carry a gap larger than the pair)."""
    return np.flatnonzero(res[f"contact/{name}/g_n"][-1] < far)


def stack_model(n, half=(0.1, 0.1, 0.05), mass=1.0, mu=0.5):
    m = ms.Model("stack", gravity=(0.0, 0.0, -G))
    boxes = [free_box(m, f"box{k}", half, mass, (0, 0, half[2] * (2 * k + 1))) for k in range(n)]
    shape = ms.contours.Box(half_extents=half)
    m.add_contact(ms.Contact("floor", boxes[0].contour(shape), m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             friction=ms.laws.Coulomb(mu)))
    for k in range(1, n):
        m.add_contact(ms.Contact(f"on{k}", boxes[k].contour(shape), boxes[k - 1].contour(shape), friction=ms.laws.Coulomb(mu)))
    return m


def test_a_box_on_an_equal_box_rests_on_four_points_and_carries_its_weight():
    """Two equal boxes face on face: the interface has four points (the corners), each closed,
    their normal forces add up to m g (1e-9) and diagonal corners carry equal loads (moment
    balance about the centre); the pair has 8 candidates, the other four never close."""
    mass, half = 2.0, (0.15, 0.1, 0.05)
    m = stack_model(2, half=half, mass=mass)
    res = ms.simulate(m, 0.5, ms.MoreauJean(1e-3, solver=TIGHT), output_dt=1e-2)
    g_n, lam = res["contact/on1/g_n"], res["contact/on1/lambda_n"]
    assert g_n.shape[1] == 8
    k = used(res, "on1")
    assert len(k) == 4
    assert np.abs(g_n[:, k]).max() < 1e-12
    assert g_n[:, [i for i in range(8) if i not in k]].min() > 0.1
    np.testing.assert_allclose(lam[-1].sum(), mass * G, rtol=1e-9)
    l4 = lam[-1, k]
    assert (l4 > 0).all()
    # the corners come in cyclic order: diagonal pairs (0, 2) and (1, 3)
    np.testing.assert_allclose([l4[0], l4[1]], [l4[2], l4[3]], rtol=1e-6)
    np.testing.assert_allclose(res["contact/floor/lambda_n"][-1].sum(), 2 * mass * G, rtol=1e-9)
    p = res["body/box1/position"]
    assert np.abs(p - p[0]).max() < 1e-10


def test_a_cube_turned_45_degrees_rests_on_the_octagon():
    """A cube turned by 45 degrees about the vertical on an equal cube (held by the ground): the
    contact region is the regular octagon, eight closed points carrying m g together, their
    resultant through the centre (how it is shared among them is not unique)."""
    h, mass = 0.1, 1.0
    m = ms.Model("octagon", gravity=(0.0, 0.0, -G))
    top = free_box(m, "top", (h, h, h), mass, (0, 0, 3 * h), quat((0, 0, 1), math.pi / 4))
    base = m.ground.contour(ms.contours.Box(half_extents=(h, h, h), center=(0, 0, h)))
    m.add_contact(ms.Contact("on", top.contour(ms.contours.Box(half_extents=(h, h, h))), base, friction=ms.laws.Coulomb(0.5)))
    res = ms.simulate(m, 0.3, ms.MoreauJean(1e-3, solver=TIGHT), output_dt=1e-2)
    g_n, lam = res["contact/on/g_n"], res["contact/on/lambda_n"]
    assert np.abs(g_n).max() < 1e-12  # all eight in use, closed
    assert (lam[-1] > 0).all()
    np.testing.assert_allclose(lam[-1].sum(), mass * G, rtol=1e-9)
    # moment balance about the centre: the vertices lie at 45-degree steps in cyclic order, so the
    # loads' resultant passes through the axis when sum(lambda_j exp(i pi j / 4)) = 0
    assert abs(np.sum(lam[-1] * np.exp(1j * np.pi * np.arange(8) / 4))) < 1e-6 * mass * G


def test_crossing_edges_close_at_the_closed_form_gap_and_carry_the_weight():
    """A cube turned 45 degrees about x above a fixed cube turned 45 degrees about y: their edges
    cross. Released 2 mm above the contact, the edge-edge gap is z - z_base - sqrt(2) (h1 + h2)
    (free fall, exact for the midpoint rule) until it closes at t = sqrt(2 gap / g); then the single
    point carries m g and the balanced cube stays put (after a penetration of less than one step's
    travel at impact, which time-stepping does not undo)."""
    h1, h2, mass, gap0 = 0.1, 0.15, 1.5, 2e-3
    z0 = math.sqrt(2) * (h1 + h2) + gap0
    m = ms.Model("edges", gravity=(0.0, 0.0, -G))
    top = free_box(m, "top", (h1, h1, h1), mass, (0, 0, z0), quat((1, 0, 0), math.pi / 4))
    base = m.ground.contour(ms.contours.Box(half_extents=(h2, h2, h2), cardan=(0, math.pi / 4, 0)))
    m.add_contact(ms.Contact("edge", top.contour(ms.contours.Box(half_extents=(h1, h1, h1))), base, friction=ms.laws.Coulomb(0.5)))
    res = ms.simulate(m, 0.25, ms.MoreauJean(1e-3, solver=TIGHT), output_dt=1e-3)
    g = res["contact/edge/g_n"]
    assert len(used(res, "edge")) == 1
    t = res.t
    before = t < math.sqrt(2 * gap0 / G) - 2e-3
    np.testing.assert_allclose(g[before, 0], gap0 - 0.5 * G * t[before] ** 2, atol=1e-12)
    np.testing.assert_allclose(g[before, 0], res["body/top/position"][before, 2] - math.sqrt(2) * (h1 + h2), atol=1e-12)
    assert g[:, 1:].min() > 0.1  # one point only
    np.testing.assert_allclose(res["contact/edge/lambda_n"][-1, 0], mass * G, rtol=1e-9)
    # time-stepping closes the contact within the impact step: the penetration is less than the
    # impact speed times the step, and then stays
    late = t > 0.1
    assert -math.sqrt(2 * G * gap0) * 1e-3 < g[late, 0].min() <= 0.0
    assert np.ptp(g[late, 0]) < 1e-9
    p = res["body/top/position"]
    assert np.abs(p[late] - p[-1]).max() < 1e-9


@pytest.mark.parametrize("beyond", [True, False])
def test_a_box_tipped_over_an_edge_falls_the_way_its_centre_of_mass_says(beyond):
    """A box tilted by 0.3 rad about y with its bottom face on the top edge x = 0.2 of a fixed box
    (its +x side down). With its centre of mass beyond the edge it turns further and falls off
    (+x, down); with it above the fixed box it turns back and lands flat on the top face, where it
    rests on four points carrying m g."""
    half, mass, theta = (0.1, 0.08, 0.04), 1.0, 0.3
    m = ms.Model("tip", gravity=(0.0, 0.0, -G))
    xi = -0.03 if beyond else 0.03  # where the edge touches, along the box's x from its centre
    c, s = math.cos(theta), math.sin(theta)
    # centre = edge point - R_y(theta) (xi, 0, -h_z)
    centre = (0.2 - (c * xi - s * half[2]), 0.0, 0.2 - (-s * xi - c * half[2]))
    box = free_box(m, "box", half, mass, centre, quat((0, 1, 0), theta))
    base = m.ground.contour(ms.contours.Box(half_extents=(0.2, 0.2, 0.1), center=(0, 0, 0.1)))
    m.add_contact(ms.Contact("on", box.contour(ms.contours.Box(half_extents=half)), base, friction=ms.laws.Coulomb(0.8)))
    res = ms.simulate(m, 0.8 if not beyond else 0.3, ms.MoreauJean(1e-3, solver=TIGHT), output_dt=1e-2)
    q = res["body/box/orientation"]  # quaternion (w, x, y, z)
    angle = 2 * np.arctan2(q[:, 2], q[:, 0])  # about y (the motion stays in the x-z plane)
    assert np.abs(q[:, [1, 3]]).max() < 1e-9
    x = res["body/box/position"]
    if beyond:
        assert angle[-1] > theta + 1.0 and x[-1, 0] > centre[0] + 0.02 and x[-1, 2] < centre[2] - 0.1
        assert np.all(np.diff(angle) > 0)
        # turning about the edge, the velocity-level scheme drifts into it by O(dt^2) per unit time
        assert res["contact/on/g_n"].min() > -2e-5
    else:
        # landing flat: an impact, closed within its step (penetration below the landing speed
        # times dt), which also leaves the box tilted by that penetration over its length
        assert res["contact/on/g_n"].min() > -3e-4
        assert abs(angle[-1]) < 5e-4 and abs(angle[0] - theta) < 1e-12
        np.testing.assert_allclose(x[-1, 2], 0.2 + half[2], atol=3e-4)
        assert len(used(res, "on")) == 4
        np.testing.assert_allclose(res["contact/on/lambda_n"][-1].sum(), mass * G, rtol=1e-9)
        v = np.gradient(x[:, 0], res.t)
        assert np.abs(v[-10:]).max() < 1e-9  # at rest


def test_a_stack_of_ten_equal_boxes_stays_at_rest():
    """Ten equal boxes face on face on the floor: after 1 s the top box has moved less than 1e-9 m,
    nothing penetrates by more than 1e-12 m, the floor carries 10 m g and the interface under box k
    (10 - k) m g, each on four points."""
    n, mass = 10, 1.0
    m = stack_model(n, mass=mass)
    res = ms.simulate(m, 1.0, ms.MoreauJean(1e-3, solver=TIGHT), output_dt=1e-2)
    for k in range(n):
        p = res[f"body/box{k}/position"]
        assert np.abs(p - p[0]).max() < 1e-9, k
    np.testing.assert_allclose(res["contact/floor/lambda_n"][-1].sum(), n * mass * G, rtol=1e-9)
    for k in range(1, n):
        assert len(used(res, f"on{k}")) == 4, k
        assert res[f"contact/on{k}/g_n"].min() > -1e-12, k
        np.testing.assert_allclose(res[f"contact/on{k}/lambda_n"][-1].sum(), (n - k) * mass * G, rtol=1e-9)


@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_the_auto_solver_holds_the_stack_at_its_static_weights_every_step(dt):
    """The auto solver (regularized Newton on the stack's singular Delassus problem): every step
    converges with residual <= 1e-12 (signals solver/residual, solver/converged), each interface
    carries the weight of the boxes above it to 1e-8 N in every step, and the top box stays put to
    1e-9 m over 2 s at dt = 1e-3 and 1e-2."""
    n, mass = 10, 1.0
    m = stack_model(n, mass=mass)
    res = ms.simulate(m, 2.0, ms.MoreauJean(dt, solver=ms.Auto(tol=1e-12)), output_dt=dt)
    assert res["solver/converged"][1:].all()
    assert res["solver/residual"].max() <= 1e-12
    assert (res["solver/contacts"][1:] == 4 * n).all() and (res["solver/islands"][1:] == 1).all()
    # the first steps start cold and settle; then a warm-started step takes one Gauss-Seidel
    # sweep, or the auto solver's 4 sweeps and a Newton step with the reused factorization
    it = res["solver/iterations"]
    assert it.max() <= 60 and np.median(it) <= 11
    top = res[f"body/box{n - 1}/position"]
    assert np.abs(top - top[0]).max() < 1e-9
    # lambda_n of a sample is the step's impulse over the step: every step's static weights
    floor = res["contact/floor/lambda_n"][1:].sum(axis=1)
    assert np.abs(floor - n * mass * G).max() < 1e-8
    for k in range(1, n):
        carried = res[f"contact/on{k}/lambda_n"][1:].sum(axis=1)
        assert np.abs(carried - (n - k) * mass * G).max() < 1e-8, k


@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_warm_started_steps_of_the_resting_stack_stay_with_gauss_seidel(dt):
    """At the default tolerance (1e-10) the auto solver leaves each step well inside it (its
    sweeps stop early only at a tenth of it, Newton takes a step past it), so the next warm
    start converges in a few sweeps: at most 5 % of the resting stack's steps go on to Newton
    (more than 4 iterations) and most take one sweep. (Leaving steps just under the tolerance
    sent every other step to Newton: 23 % of the steps at dt = 1e-2, 28 % at 1e-3.) Every step
    converges and the top box stays put."""
    n = 10
    m = stack_model(n)
    res = ms.simulate(m, 2.0, ms.MoreauJean(dt, solver=ms.Auto()), output_dt=dt)
    assert res["solver/converged"][1:].all() and res["solver/residual"].max() <= 1e-10
    it = res["solver/iterations"][1:]
    counts = np.unique(it, return_counts=True)
    assert (it > 4).mean() <= 0.05 and (it == 1).mean() >= 0.5, counts
    top = res[f"body/box{n - 1}/position"]
    assert np.abs(top - top[0]).max() < 1e-9


def test_an_unconverged_stack_warns_with_the_time_and_the_contacts():
    """A sweep budget the stack cannot meet: the run warns once, naming the count of
    unconverged steps, the first one's time and the contacts of its problem; the signals mark
    those samples."""
    m = stack_model(4)
    with pytest.warns(UserWarning, match=r"did not reach its tolerance in \d+ of 50 steps .*first at t = 0\.000500 s, "
                                         r"contacts \[\"floor\", \"on1\", \"on2\", \"on3\"\]"):
        res = ms.simulate(m, 0.05, ms.MoreauJean(1e-3, solver=ms.NSGS(tol=1e-12, max_iter=3)), output_dt=1e-3)
    assert res["solver/converged"][1] == 0 and res["solver/iterations"][1] == 3
    assert res["solver/residual"][1] > 1e-12
