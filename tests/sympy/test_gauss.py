"""Gauss's principle solved independently: the KKT system from sympy's A and
b and the model's M and F gives the same q̈ as both of the macro's equations
of motion, and the same constraint force M q̈ − F."""

import numpy as np
import sympy as sp

from conftest import record
from derivation import derive_constraint_equations, gauss_by_kkt, numeric, parse, symbols_for


def test_accelerations_and_forces(system):
    s = symbols_for(system)
    a_sym, b_sym, _ = derive_constraint_equations(system)
    m_sym = sp.Matrix([[parse(e, s) for e in row] for row in system["mass"]])
    f_sym = sp.Matrix([parse(e, s) for e in system["forces"]])
    for state in system["states"]:
        m = numeric(m_sym, s, state)
        f = numeric(f_sym, s, state).ravel()
        a = numeric(a_sym, s, state)
        b = numeric(b_sym, s, state).ravel()
        qdd = gauss_by_kkt(m, f, a, b)
        scale = 1.0 + np.abs(qdd).max()
        # Near a coordinate singularity (the rolling disk lying almost flat,
        # where its Euler angles φ and ψ turn about one axis) M is
        # ill-conditioned and no method gets q̈ better than about κ(M)·ε:
        # the bound grows with the condition number there, not elsewhere.
        conditioning = np.linalg.cond(m)
        tolerance = max(1e-9, 100 * np.finfo(float).eps * conditioning) if np.isfinite(conditioning) else 1e-9
        for key, check in [("qdd", "q̈ generalized inverse vs KKT"), ("qdd_gibbs_appell", "q̈ Gibbs–Appell vs KKT")]:
            assert state[key] is not None, f"{key} missing: the Gibbs–Appell form failed at a generic state"
            diff = np.abs(np.array(state[key]) - qdd).max() / scale
            record(check, system["name"], diff)
            assert diff < tolerance, f"{key}: {state[key]} vs KKT {qdd} (relative {diff:.2e}, κ(M) {conditioning:.1e})"
        force = m @ qdd - f
        diff = np.abs(np.array(state["constraint_force"]) - force).max() / (1.0 + np.abs(f).max() + np.abs(force).max())
        record("constraint force vs KKT", system["name"], diff)
        assert diff < 1e-9, f"constraint force {state['constraint_force']} vs {force}"
