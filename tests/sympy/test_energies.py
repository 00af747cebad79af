"""Systems given by their energies (`kinetic_energy`, `potential_energy`):
the macro's M and F are identically equal to what sympy's own
LagrangesMethod derives from the same T, V (as L = T − V) and generalized
forces Q, and q̈ at the exported states solves M q̈ = F + Aᵀλ by KKT."""

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import LagrangesMethod, dynamicsymbols, msubs

from conftest import SYSTEMS, record
from derivation import difference_vanishes, numeric, parse, symbols_for

ENERGY_SYSTEMS = [s for s in SYSTEMS if s.get("energies")]


def test_some_systems_are_given_by_energies():
    assert len(ENERGY_SYSTEMS) >= 2, [s["name"] for s in SYSTEMS]


def lagranges_method(system):
    """(M, F) from sympy.physics.mechanics, in the plain symbols of the export."""
    s = symbols_for(system)
    energies = system["energies"]
    q = dynamicsymbols(" ".join(system["coordinates"]), seq=True)
    qd = [c.diff(dynamicsymbols._t) for c in q]
    # The export's text with coordinates as functions of time, dot(q) as q̇.
    namespace = {c: f for c, f in zip(system["coordinates"], q)}
    namespace |= {str(p): p for p in s.parameters}
    namespace["t"] = dynamicsymbols._t
    velocity = dict(zip(system["coordinates"], qd))
    namespace["dot"] = lambda coordinate: velocity[str(coordinate.func)]
    read = lambda text: sp.sympify(text, locals=namespace)
    for name, text in system.get("definitions", []):
        namespace[name] = read(text)
    lagrangian = read(energies["kinetic"]) - read(energies["potential"])
    method = LagrangesMethod(lagrangian, q)
    method.form_lagranges_equations()
    forces = method.forcing + sp.Matrix([read(e) for e in energies["generalized_forces"]])
    # Back to plain symbols: q̇ first (msubs replaces derivatives before functions).
    plain = {d: v for d, v in zip(qd, s.velocities)} | {c: x for c, x in zip(q, s.coordinates)}
    plain[dynamicsymbols._t] = s.t
    return msubs(method.mass_matrix, plain), msubs(forces, plain), s


@pytest.mark.parametrize("system", ENERGY_SYSTEMS, ids=[s["name"] for s in ENERGY_SYSTEMS])
def test_mass_and_forces_equal_lagranges_method(system):
    m_sympy, f_sympy, s = lagranges_method(system)
    n = len(system["coordinates"])
    m_macro = sp.Matrix([[parse(e, s) for e in row] for row in system["mass"]])
    f_macro = sp.Matrix([parse(e, s) for e in system["forces"]])
    for i in range(n):
        assert difference_vanishes(f_macro[i], f_sympy[i]), f"F[{i}]: {f_macro[i]} vs {f_sympy[i]}"
        for j in range(n):
            assert difference_vanishes(m_macro[i, j], m_sympy[i, j]), f"M[{i},{j}]"
    # And numerically at the exported states, as a record of the agreement.
    for state in system["states"]:
        m = numeric(m_sympy, s, state)
        f = numeric(f_sympy, s, state).reshape(-1)
        qdd = np.array(state["qdd"])
        a = np.array(state["a"], dtype=float).reshape(-1, n)
        # M q̈ − F lies in the row space of A (it is Aᵀλ): zero without constraints.
        residual = m @ qdd - f
        if a.size:
            lam, *_ = np.linalg.lstsq(a.T, residual, rcond=None)
            residual = residual - a.T @ lam
        scale = 1.0 + np.abs(f).max() + np.abs(m @ qdd).max()
        record("M q̈ − F − Aᵀλ with LagrangesMethod's M, F", system["name"], np.abs(residual).max() / scale)
        assert np.abs(residual).max() < 1e-10 * scale
