"""A space-truss boom: the elastic body that mechsys and Exudyn's reduced-order floating-frame
body can both take without approximation (3 translational DOFs per node, no rotations).

The boom runs along body x from the root section at x = 0 to the tip at x = ``length``; each of
its ``n_bays + 1`` sections is a square of side ``width`` centred on the x axis with 4 corner
nodes. Bars (pin-jointed, axial stiffness E A / l each):

* chords: the 4 longitudinal bars per bay,
* section edges: the 4 sides of every section square,
* face diagonals: one per side face per bay,
* section diagonals: one across every section square (keeps the section from shearing).

Mass is lumped: half of every bar's mass ρ A l at each of its end nodes, plus ``node_mass`` at
every node and ``tip_mass`` spread over the 4 tip nodes. The matrices are 3 DOFs per node in the
order (ux, uy, uz) of node 0, node 1, ...; node ``4 s + c`` is corner c of section s, so the root
nodes are 0..3 and the tip nodes the last four.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

STEEL = dict(E=210e9, rho=7850.0)


@dataclass
class TrussBoom:
    """Nodes (n, 3), bars (b, 2), lumped node masses (n,), and the 3n x 3n matrices."""

    nodes: np.ndarray
    bars: np.ndarray
    node_masses: np.ndarray
    M: np.ndarray
    K: np.ndarray
    root: list
    tip: list

    @property
    def n_nodes(self) -> int:
        return len(self.nodes)

    @property
    def mass(self) -> float:
        return float(self.node_masses.sum())

    def free_dofs(self) -> np.ndarray:
        """The 3-DOF indices left when the root nodes are clamped."""
        held = {3 * i + d for i in self.root for d in range(3)}
        return np.array([k for k in range(3 * self.n_nodes) if k not in held])

    def six_dof(self):
        """M and K embedded in 6 DOFs per node (ux, uy, uz, rx, ry, rz), the rotations empty —
        the layout of :func:`mechsys.elastic.fe_model`."""
        n = self.n_nodes
        idx = np.array([6 * i + d for i in range(n) for d in range(3)])
        M6, K6 = np.zeros((6 * n, 6 * n)), np.zeros((6 * n, 6 * n))
        M6[np.ix_(idx, idx)] = self.M
        K6[np.ix_(idx, idx)] = self.K
        return M6, K6

    def clamped_modes(self, n_modes: int):
        """The ``n_modes`` lowest modes with the root nodes clamped, mass-normalized: (ω² (q,),
        shapes (3n, q)) — the independent reference (dense SciPy on the full matrices)."""
        from scipy.linalg import eigh

        f = self.free_dofs()
        w2, v = eigh(self.K[np.ix_(f, f)], self.M[np.ix_(f, f)], subset_by_index=[0, n_modes - 1])
        phi = np.zeros((3 * self.n_nodes, n_modes))
        phi[f] = v
        return w2, phi

    def static(self, load):
        """The full FE static displacement (3n,) under the nodal ``load`` (3n,), root clamped."""
        f = self.free_dofs()
        u = np.zeros(3 * self.n_nodes)
        u[f] = np.linalg.solve(self.K[np.ix_(f, f)], np.asarray(load, float)[f])
        return u


def truss_boom(length: float = 1.0, width: float = 0.05, n_bays: int = 20, *, bar_area: float = 2e-5,
               E: float = STEEL["E"], rho: float = STEEL["rho"], node_mass: float = 0.0,
               tip_mass: float = 0.0) -> TrussBoom:
    """The boom of the module docstring (SI units; defaults: a 1 m steel boom 5 cm wide, 20 bays,
    84 nodes, bars of 20 mm² section)."""
    h = 0.5 * width
    corners = np.array([[-h, -h], [h, -h], [h, h], [-h, h]])  # (y, z), counter-clockwise about x
    xs = np.linspace(0.0, length, n_bays + 1)
    nodes = np.array([[x, y, z] for x in xs for y, z in corners])
    bars = []
    for s in range(n_bays + 1):
        a = 4 * s
        bars += [(a + c, a + (c + 1) % 4) for c in range(4)]  # section edges
        bars.append((a, a + 2))  # section diagonal
        if s < n_bays:
            b = a + 4
            bars += [(a + c, b + c) for c in range(4)]  # chords
            bars += [(a + c, b + (c + 1) % 4) for c in range(4)]  # face diagonals
    bars = np.array(bars)
    n = len(nodes)
    K = np.zeros((3 * n, 3 * n))
    masses = np.full(n, float(node_mass))
    for i, j in bars:
        d = nodes[j] - nodes[i]
        le = np.linalg.norm(d)
        e = d / le
        k = E * bar_area / le * np.outer(e, e)  # bar stiffness: EA/l along its axis
        for p, q, s in ((i, i, 1.0), (j, j, 1.0), (i, j, -1.0), (j, i, -1.0)):
            K[3 * p : 3 * p + 3, 3 * q : 3 * q + 3] += s * k
        masses[[i, j]] += 0.5 * rho * bar_area * le
    tip = list(range(n - 4, n))
    masses[tip] += tip_mass / 4.0
    M = np.diag(np.repeat(masses, 3))
    return TrussBoom(nodes=nodes, bars=bars, node_masses=masses, M=M, K=K, root=[0, 1, 2, 3], tip=tip)


def mechsys_body(boom: TrussBoom, n_modes: int, name: str = "boom", craig_bampton_nodes=None):
    """The boom as a mechsys reduced body: its matrices through ``fe_model`` (6 DOFs per node,
    rotations fixed everywhere, the root nodes clamped — the body frame is the root section), the
    ``n_modes`` lowest clamped modes, or a Craig–Bampton basis with ``craig_bampton_nodes`` as the
    interface."""
    from mechsys import elastic as el

    M6, K6 = boom.six_dof()
    fe = el.fe_model(boom.nodes, M6, K6, node_masses=boom.node_masses, name=name)
    fixed = {i: ["rx", "ry", "rz"] for i in range(boom.n_nodes)}
    fixed.update({i: "clamped" for i in boom.root})
    if craig_bampton_nodes is None:
        return el.modal_reduction(fe, n_modes, fixed=fixed, name=name)
    return el.craig_bampton(fe, n_modes, craig_bampton_nodes, fixed=fixed, name=name)
