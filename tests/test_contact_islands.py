"""Independent contact islands under Moreau-Jean: contacts that share no moving body form
separate friction-contact problems, solved apart and (``MoreauJean(parallel=True)``) on several
threads. The split changes nothing physical: two stacks side by side carry their weights, and the
runs with and without threads give the same numbers bit for bit."""

import numpy as np
import pytest

import mechsys as ms

G = 9.81
HALF = (0.1, 0.1, 0.05)


def stacks(count, n, gap=0.5):
    """``count`` stacks of ``n`` boxes, ``gap`` m apart along x: one island per stack."""
    m = ms.Model("stacks", gravity=(0.0, 0.0, -G))
    shape = ms.contours.Box(half_extents=HALF)
    floor = m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)))
    for s in range(count):
        boxes = []
        for k in range(n):
            b = m.add_body(f"b{s}_{k}", 1.0, ms.inertia.box(1.0, tuple(2 * h for h in HALF)))
            m.add_joint(ms.joints.Free(f"f{s}_{k}", m.ground, b, q0=[s * gap, 0.0, HALF[2] * (2 * k + 1), 1, 0, 0, 0]))
            boxes.append(b)
        m.add_contact(ms.Contact(f"floor{s}", boxes[0].contour(shape), floor, friction=ms.laws.Coulomb(0.5)))
        for k in range(1, n):
            m.add_contact(ms.Contact(f"on{s}_{k}", boxes[k].contour(shape), boxes[k - 1].contour(shape),
                                     friction=ms.laws.Coulomb(0.5)))
    return m


def test_two_stacks_are_two_islands_and_each_carries_its_weight():
    m = stacks(2, 5)
    res = ms.simulate(m, 0.3, ms.MoreauJean(1e-3, solver=ms.Auto(tol=1e-12)), output_dt=1e-3)
    # the floor is ground (not moving): it links nothing
    assert (res["solver/islands"][1:] == 2).all()
    assert (res["solver/contacts"][1:] == 2 * 5 * 4).all()
    assert res["solver/converged"][1:].all()
    for s in range(2):
        np.testing.assert_allclose(res[f"contact/floor{s}/lambda_n"][1:].sum(axis=1), 5 * G, rtol=0, atol=1e-8)
        for k in range(1, 5):
            np.testing.assert_allclose(res[f"contact/on{s}_{k}/lambda_n"][1:].sum(axis=1), (5 - k) * G, rtol=0, atol=1e-8)


@pytest.mark.parametrize("heights", [(5,), (5, 4)])
def test_islands_above_newtons_size_are_swept_whole_and_carry_their_weights(heights):
    """Auto sweeps the whole problem on the factored operator (no islands, no Delassus blocks)
    when the islands above Newton's size hold most contacts: a stack of 5 boxes (20 points, 60
    unknowns), or stacks of 5 and 4 boxes (neither alone holding three quarters of the points),
    beside a single box (4 points), Newton's size set to 30 unknowns. NSGS does so when its
    largest island holds three quarters of the points (the stack of 5 beside the box), and goes
    island by island otherwise. Each box still rests on what is below it with the weight above
    it, as in the split solve (to 1e-8 N at tol 1e-12, as the split stacks above). The signals do
    not tell which path ran: this checks the whole path's answer; `Islands::in_islands_above` and
    `Islands::largest`, which pick it, have their own Rust test."""
    m = ms.Model("stacks and box", gravity=(0.0, 0.0, -G))
    shape = ms.contours.Box(half_extents=HALF)
    floor = m.ground.contour(ms.contours.Plane(normal=(0, 0, 1)))
    weights = {}
    for s, n in enumerate((*heights, 1)):
        below = None
        for k in range(n):
            b = m.add_body(f"b{s}_{k}", 1.0, ms.inertia.box(1.0, tuple(2 * h for h in HALF)))
            m.add_joint(ms.joints.Free(f"f{s}_{k}", m.ground, b, q0=[0.5 * s, 0.0, HALF[2] * (2 * k + 1), 1, 0, 0, 0]))
            other = floor if k == 0 else below.contour(shape)
            m.add_contact(ms.Contact(f"c{s}_{k}", b.contour(shape), other, friction=ms.laws.Coulomb(0.5)))
            weights[f"c{s}_{k}"] = (n - k) * G
            below = b
    points = 4 * (sum(heights) + 1)
    # Auto swept whole, Auto split into islands with Newton on each; NSGS swept whole where one
    # island holds three quarters of the points (the stack of 5 beside the box), else by islands
    solvers = [ms.Auto(tol=1e-12, newton_max_unknowns=30), ms.Auto(tol=1e-12, newton_max_unknowns=480),
               ms.NSGS(tol=1e-12, max_iter=100_000)]
    for solver in solvers:
        res = ms.simulate(m, 0.2, ms.MoreauJean(1e-3, solver=solver), output_dt=1e-3)
        assert res["solver/converged"][1:].all()
        assert (res["solver/contacts"][1:] == points).all()
        for name, w in weights.items():
            np.testing.assert_allclose(res[f"contact/{name}/lambda_n"][1:].sum(axis=1), w, rtol=0, atol=1e-8,
                                       err_msg=f"{name}, {solver}")
        # the top boxes do not drift off their supports
        for s, n in enumerate(heights):
            assert abs(res[f"body/b{s}_{n - 1}/position"][-1, 2] - HALF[2] * (2 * n - 1)) < 1e-9


def test_islands_give_the_same_result_serial_and_parallel_bit_for_bit():
    """Two pyramids of 55 spheres, each in its own box, dropped onto their floors (impacts, then
    slip and stick while they settle): two islands, together above the size from which islands
    go to threads (400 contact points). Serial and threaded runs agree exactly."""
    from test_contact_groups import square_pyramid

    m, _ = square_pyramid(gap=3e-3, mu=0.3, base=5, at=(0.0, 1.0))
    runs = []
    for parallel in (False, True):
        # (NSGS: `auto` would sweep two islands of this size whole)
        integ = ms.MoreauJean(1e-3, solver=ms.NSGS(tol=1e-6, max_iter=3000, anderson=4), parallel=parallel)
        runs.append(ms.simulate(m, 0.1, integ, output_dt=1e-3, progress=False))
    serial, threaded = runs
    assert serial["solver/islands"].max() >= 2
    assert serial["solver/contacts"].max() >= 400  # PARALLEL_MIN_CONTACTS: the threads were used
    for name in ("q", "u", "solver/residual", "solver/iterations", "contact/pile/force_against",
                 "contact/pile1/force_against"):
        assert np.array_equal(serial[name], threaded[name]), name


def test_a_large_pile_swept_in_two_domains_on_two_threads_is_the_serial_run_bit_for_bit():
    """A square pyramid of 140 spheres (7×7 ... 1) settling in a box that holds its base: one
    island of about 640 contact points, swept whole (Newton's size set below it), so that each
    Gauss–Seidel sweep runs in two domains of the contact graph, on two threads
    (``MoreauJean(parallel=True)``) after a solve's first 16 sweeps, and then over the contacts
    between them. Serial and threaded runs agree exactly and once settled the container carries
    the weight (momentum balance, to the solver's tolerance). (Gauss–Seidel crawls on a resting
    pyramid, whose forces are statically indeterminate: a step or two while it settles may end at
    the sweep budget; the settled steps converge.)"""
    from test_contact_groups import MASS, square_pyramid

    m, n = square_pyramid(base=7)
    runs = []
    for parallel in (False, True):
        solver = ms.Auto(tol=1e-5, newton_max_unknowns=30)
        runs.append(ms.simulate(m, 0.15, ms.MoreauJean(1e-3, solver=solver, parallel=parallel), output_dt=1e-3,
                                progress=False))
    serial, threaded = runs
    for name in ("q", "u", "contact/pile/force_against", "solver/iterations", "solver/residual"):
        assert np.array_equal(serial[name], threaded[name]), name
    assert serial["solver/converged"][-50:].all() and serial["solver/converged"][1:].mean() >= 0.98
    # one island above the size from which the halves go to threads, solves beyond the serial sweeps
    assert (serial["solver/islands"][-50:] == 1).all() and serial["solver/contacts"][-50:].min() >= 400
    assert serial["solver/iterations"][-50:].max() > 16
    f = serial["contact/pile/force_against"][-30:, 2]
    np.testing.assert_allclose(f, n * MASS * G, rtol=1e-5)
