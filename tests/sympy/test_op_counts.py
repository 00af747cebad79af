"""Operation counts: the generated `acceleration` (counted on its expansion
by `op_count::acceleration`, exported by codegen's `op_counts` example)
against sympy's common-subexpression elimination of the same q̈, derived
here from the model's M, F and its constraints: a = M⁻¹F,
q̈ = a + M⁻¹Aᵀ (A M⁻¹ Aᵀ)⁻¹ (b − A a), by sympy's LU solves, then `cse`
(with and without its `basic` optimizations, the better of the two; on a
large q̈ `basic` runs in the benchmark run only, BASIC_UP_TO) and
`count_ops`. The generated code must not need more, except on the models
of KNOWN_GAPS, each held to its measured ratio so that it cannot grow
unnoticed (and flagged when it closes). Writes the table's numbers to
<target>/benchmarks/op_counts.json for BENCHMARKS.md.

A model with redundant constraints is counted twice on sympy's side: with
the rows that stay independent at a consistent state (chosen here, by
numbers; sympy's LU cannot solve the singular S of all of them there), and
with every row, the solve the generated code performs before its run-time
rank decision (generically nonsingular off the surface, so sympy's LU
goes through). The generated code must not need more than the latter.

sympy's LU of the eight-constraint four-bar's S takes minutes: models with
more than SLOW_CONSTRAINTS constraints are counted only when
CONSTRAINED_OP_COUNTS_ALL=1 (scripts/benchmarks.sh sets it)."""

import json
import os
import time
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from conftest import SYSTEMS, TARGET
from derivation import derive_constraint_equations, numeric, parse, symbols_for

GENERATED = Path(os.environ.get("CONSTRAINED_OP_COUNTS_JSON", TARGET / "sympy" / "op_counts.json"))
TABLE = TARGET / "benchmarks" / "op_counts.json"
COUNTS = json.loads(GENERATED.read_text()) if GENERATED.exists() else {}
SLOW_CONSTRAINTS = 4
EVERY = os.environ.get("CONSTRAINED_OP_COUNTS_ALL") == "1"
# Every exported model is counted (a model the export has and the counts
# lack fails below, rather than being skipped).
COUNTED = [s for s in SYSTEMS if EVERY or len(s["constraints"]) <= SLOW_CONSTRAINTS]
RESULTS = {}

# Models where the generated code needs more operations than sympy's cse,
# with the ratio it may not exceed and why the gap is there.
KNOWN_GAPS = {
    # The generated solve keeps all three rows and decides at run time
    # which one is redundant, which needs row 3 of S and r; sympy is given
    # the two independent rows (145 against 83; with all three, 180).
    "RedundantDoublePendulum": 1.76,
    # The same: φ₄ = y2·(x2² + 1) repeats φ₃ = y2 on the surface, so sympy
    # solves the three independent rows where the generated solve keeps
    # all four and decides at run time (126 against 105; with all four, 159).
    "SliderCrank": 1.21,
    # Since the addition theorems (cos(th1 − th2) in M, sin(th1 − th2) in
    # F), sympy's `basic` cse divides each row of M q̈ = F by what it has
    # in common (l1; m2·l2) before its LU: 35 operations against the
    # generated 39 (it was 45 against sympy's 50 before). The generated
    # LDLᵀ keeps M symmetric and checks the M the model reports. The
    # symmetric scaling D⁻¹ M D⁻¹ with D = diag(l1, l2) was measured
    # (35 as well) and not kept: with a length of 1e154 it answered
    # where M itself overflows, which tests/fault_matrix.rs rejects.
    "DoublePendulumAngles": 1.12,
}


def independent_rows(a_sym, s, state):
    """The rows of A that stay independent at a consistent state: the
    redundant constraints' rows are dropped (the generated code drops them
    at run time, by its rank decision)."""
    a = numeric(a_sym, s, state)
    kept = []
    for i in range(a.shape[0]):
        trial = a[kept + [i], :]
        if np.linalg.matrix_rank(trial, tol=1e-9 * max(1.0, np.abs(a).max())) == len(kept) + 1:
            kept.append(i)
    return kept


def redundant(system):
    """Whether some constraint's row depends on the others at a consistent
    state."""
    if not system["constraints"]:
        return False
    a_sym, _, _ = derive_constraint_equations(system)
    return len(independent_rows(a_sym, symbols_for(system), system["states"][0])) < a_sym.rows


def singular(m, s, state):
    """Whether M is numerically singular at a consistent state."""
    values = numeric(m, s, state)
    return np.linalg.matrix_rank(values, tol=1e-9 * max(1.0, np.abs(values).max())) < m.rows


def sympy_acceleration(system, all_rows=False):
    """q̈ by sympy, with the independent rows of A q̈ = b, or every row."""
    s = symbols_for(system)
    m = sp.Matrix([[parse(e, s) for e in row] for row in system["mass"]])
    f = sp.Matrix([parse(e, s) for e in system["forces"]])
    if system["constraints"] and singular(m, s, system["states"][0]):
        # A singular M (quaternion rates): sympy's LU would divide by a pivot
        # that is identically zero but not simplified to 0, a formula that
        # cannot be evaluated, so its count bounds nothing. The generated
        # code solves Udwadia & Schutte's auxiliary system M + s AᵀA,
        # F + s Aᵀb with s = tr M / tr AᵀA; sympy is given the same.
        # The scale is a symbol in the solve, as the generated code
        # computes it once (`__saux`) and uses it; its own expression is
        # returned with q̈ so that cse counts it once, sharing M's and A's
        # subexpressions (LU with the quotient inside took minutes).
        a_all, b_all, _ = derive_constraint_equations(system)
        normal = a_all.T * a_all
        scale = sp.Symbol("s_aux")
        scale_value = m.trace() / normal.trace()
        m, f = m + scale * normal, f + scale * a_all.T * b_all
    else:
        scale, scale_value = None, None
    if m.is_diagonal():
        solve = lambda x: sp.Matrix(x.rows, x.cols, lambda i, j: x[i, j] / m[i, i])  # noqa: E731
    else:
        solve = m.LUsolve
    acc = solve(f)
    scale_part = [] if scale is None else [scale_value]
    if not system["constraints"]:
        return scale_part + list(acc)
    a_sym, b_sym, _ = derive_constraint_equations(system)
    rows = list(range(a_sym.rows)) if all_rows else independent_rows(a_sym, s, system["states"][0])
    a_mat = a_sym.extract(rows, list(range(a_sym.cols)))
    b_vec = b_sym.extract(rows, [0])
    minv_at = solve(a_mat.T)
    lam = (a_mat * minv_at).LUsolve(b_vec - a_mat * acc)
    return scale_part + list(acc + minv_at * lam)


def cse_ops(exprs, **options):
    replacements, reduced = sp.cse(exprs, **options)
    return sum(sp.count_ops(e) for _, e in replacements) + sum(sp.count_ops(e) for e in reduced)


# cse's `basic` optimizations cost most of the suite's time on large q̈
# (42 s for the heavy top's, 50 for the free body's) and have never won
# there (525 and 493 against plain cse's 395 and 404): above this many
# operations of plain cse they run in the benchmark run only
# (CONSTRAINED_OP_COUNTS_ALL=1), where BENCHMARKS.md's column needs them.
BASIC_UP_TO = 300


def basic_cse_ops(exprs, plain):
    """cse with `basic` optimizations, or None where skipped (above)."""
    if plain > BASIC_UP_TO and not EVERY:
        return None
    return cse_ops(exprs, optimizations="basic")


def best_cse_ops(exprs):
    """sympy's cse with and without its `basic` optimizations: the better."""
    plain = cse_ops(exprs)
    basic = basic_cse_ops(exprs, plain)
    return plain if basic is None else min(plain, basic)


@pytest.mark.skipif(not COUNTS, reason=f"{GENERATED} is missing: scripts/sympy.sh writes it")
@pytest.mark.parametrize("system", COUNTED, ids=[s["name"] for s in COUNTED])
def test_generated_needs_no_more_operations_than_sympy_cse(system):
    start = time.perf_counter()
    qdd = sympy_acceleration(system)
    plain = cse_ops(qdd)
    basic = basic_cse_ops(qdd, plain)
    elapsed = time.perf_counter() - start
    ours = COUNTS.get(system["name"])
    assert ours, f"no generated count for {system['name']} in {GENERATED}"
    RESULTS[system["name"]] = {"generated": ours, "sympy_cse": plain, "sympy_cse_basic": basic, "sympy_seconds": elapsed}
    best = plain if basic is None else min(plain, basic)
    if redundant(system):
        every_row = best_cse_ops(sympy_acceleration(system, all_rows=True))
        RESULTS[system["name"]]["sympy_cse_all_rows"] = every_row
        assert ours["total"] <= every_row, (
            f"generated {ours['total']} operations, sympy's cse over every row {every_row}")
    bound = KNOWN_GAPS.get(system["name"])
    if bound is None:
        assert ours["total"] <= best, f"generated {ours['total']} operations, sympy's cse {best}"
    else:
        ratio = ours["total"] / best
        assert ratio <= bound, f"generated {ours['total']} operations, {ratio:.2f}× sympy's cse {best} (held to {bound})"
        assert ours["total"] > best, f"the gap closed ({ours['total']} ≤ {best}): remove it from KNOWN_GAPS"


def teardown_module(module):
    if RESULTS:
        TABLE.parent.mkdir(parents=True, exist_ok=True)
        TABLE.write_text(json.dumps(RESULTS, indent=1, sort_keys=True))
