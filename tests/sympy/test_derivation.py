"""A and b of every system, re-derived from φ with sympy's own
differentiation, equal the macro's expressions identically; the exported
numbers equal sympy's at every consistent state."""

import numpy as np
import sympy as sp

from conftest import record
from derivation import derive_constraint_equations, difference_vanishes, numeric, parse, symbols_for


def test_levels_match(system):
    _, _, levels = derive_constraint_equations(system)
    assert levels == system["levels"]


def test_a_and_b_equal_sympys_derivation(system):
    s = symbols_for(system)
    a, b, _ = derive_constraint_equations(system)
    for i, row in enumerate(system["a_matrix"]):
        for j, text in enumerate(row):
            macro = parse(text, s)
            assert difference_vanishes(a[i, j], macro), f"A[{i},{j}]: sympy {a[i, j]} vs macro {macro}"
    for i, text in enumerate(system["b_vector"]):
        macro = parse(text, s)
        assert difference_vanishes(b[i], macro), f"b[{i}]: sympy {sp.expand(b[i])} vs macro {macro}"


def test_exported_numbers_equal_sympy(system):
    s = symbols_for(system)
    a_sym, b_sym, _ = derive_constraint_equations(system)
    for state in system["states"]:
        a = numeric(a_sym, s, state)
        b = numeric(b_sym, s, state).ravel()
        scale = 1.0 + np.abs(a).max() + np.abs(b).max()
        da = np.abs(a - np.array(state["a"])).max() / scale
        db = np.abs(b - np.array(state["b"])).max() / scale
        record("A, b numbers vs sympy", system["name"], max(da, db))
        assert da < 1e-12 and db < 1e-12, f"A off by {da:.2e}, b off by {db:.2e}"
        # The states are consistent: φ vanishes there.
        assert np.abs(state["residual"]).max() < 1e-9
