"""The checks can fail: a deliberately wrong derivative (one entry of A with
its sign flipped, one term of b dropped) and a slightly wrong acceleration
are caught for every system."""

import copy

import numpy as np
import sympy as sp

from conftest import CONSTRAINED
from derivation import derive_constraint_equations, difference_vanishes, gauss_by_kkt, numeric, parse, symbols_for


def test_a_flipped_sign_in_a_is_caught():
    for system in CONSTRAINED:
        s = symbols_for(system)
        a, _, _ = derive_constraint_equations(system)
        mutated = copy.deepcopy(system)
        i, j = next((i, j) for i, row in enumerate(a.tolist()) for j, e in enumerate(row) if e != 0)
        mutated["a_matrix"][i][j] = f"-({system['a_matrix'][i][j]})"
        assert not difference_vanishes(a[i, j], parse(mutated["a_matrix"][i][j], s)), system["name"]


def test_a_dropped_term_in_b_is_caught():
    for system in CONSTRAINED:
        s = symbols_for(system)
        _, b, _ = derive_constraint_equations(system)
        macro = parse(system["b_vector"][0], s)
        terms = sp.Add.make_args(sp.expand(macro))
        mutated = sp.Add(*terms[1:]) if len(terms) > 1 else 2 * macro
        assert not difference_vanishes(b[0], mutated), system["name"]


def test_a_wrong_acceleration_is_caught():
    for system in CONSTRAINED:
        s = symbols_for(system)
        a_sym, b_sym, _ = derive_constraint_equations(system)
        m_sym = sp.Matrix([[parse(e, s) for e in row] for row in system["mass"]])
        f_sym = sp.Matrix([parse(e, s) for e in system["forces"]])
        state = system["states"][0]
        qdd = gauss_by_kkt(
            numeric(m_sym, s, state), numeric(f_sym, s, state).ravel(), numeric(a_sym, s, state), numeric(b_sym, s, state).ravel()
        )
        wrong = np.array(state["qdd"]) * (1 + 1e-7)
        assert np.abs(wrong - qdd).max() / (1 + np.abs(qdd).max()) > 1e-9, system["name"]


def test_a_wrong_force_from_energies_is_caught():
    from test_energies import ENERGY_SYSTEMS, lagranges_method

    for system in ENERGY_SYSTEMS:
        _, f_sympy, s = lagranges_method(system)
        wrong = parse(f"-({system['forces'][-1]}) + 1", s)
        assert not difference_vanishes(f_sympy[-1], wrong), system["name"]
