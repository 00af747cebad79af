"""An independent derivation with sympy: parse the macro's expressions, derive
A and b with sympy's own differentiation, solve Gauss's principle as a KKT
system, and map Cartesian accelerations to minimal coordinates."""

from dataclasses import dataclass, field

import numpy as np
import sympy as sp


@dataclass
class Symbols:
    """The variables of one system, as sympy symbols."""

    coordinates: list
    velocities: list
    accelerations: list
    parameters: list
    t: sp.Symbol
    namespace: dict = field(default_factory=dict)


def symbols_for(system):
    q = [sp.Symbol(c) for c in system["coordinates"]]
    qd = [sp.Symbol(f"{c}_dot") for c in system["coordinates"]]
    qdd = [sp.Symbol(f"{c}_ddot") for c in system["coordinates"]]
    params = [sp.Symbol(p) for p in system["parameters"]]
    t = sp.Symbol("t")
    velocity = {str(c): v for c, v in zip(q, qd)}
    namespace = {str(s): s for s in q + params}
    namespace["t"] = t
    # `dot(x)` in the macro's syntax is the velocity of coordinate x.
    namespace["dot"] = lambda coordinate: velocity[str(coordinate)]
    # The macro's shared subexpressions, substituted wherever they are named.
    for name, text in system.get("definitions", []):
        namespace[name] = sp.sympify(text, locals=namespace)
    return Symbols(q, qd, qdd, params, t, namespace)


def parse(text, s):
    return sp.sympify(text, locals=s.namespace)


def total_derivative(e, s):
    """D e = Σ ∂e/∂qᵢ q̇ᵢ + Σ ∂e/∂q̇ᵢ q̈ᵢ + ∂e/∂t."""
    return (
        sum(sp.diff(e, q) * qd for q, qd in zip(s.coordinates, s.velocities))
        + sum(sp.diff(e, qd) * qdd for qd, qdd in zip(s.velocities, s.accelerations))
        + sp.diff(e, s.t)
    )


def is_velocity_level(phi, s):
    return any(phi.has(v) for v in s.velocities)


def derive_constraint_equations(system):
    """(A, b, levels) from the constraints φ alone, with sympy."""
    s = symbols_for(system)
    a_rows, b, levels = [], [], []
    zero = {qdd: 0 for qdd in s.accelerations}
    for text in system["constraints"]:
        phi = parse(text, s)
        velocity = is_velocity_level(phi, s)
        psi = total_derivative(phi, s) if velocity else total_derivative(total_derivative(phi, s), s)
        a_rows.append([sp.diff(psi, qdd) for qdd in s.accelerations])
        b.append(-psi.subs(zero))
        levels.append("velocity" if velocity else "position")
    return sp.Matrix(a_rows), sp.Matrix(b), levels


def difference_vanishes(lhs, rhs):
    """Whether lhs − rhs is identically zero: expanded, then simplified."""
    d = sp.expand(lhs - rhs)
    return d == 0 or sp.simplify(d) == 0


def numeric(expr_matrix, s, state):
    """A sympy matrix evaluated at an exported state (float64)."""
    values = {}
    for sym, v in zip(s.coordinates, state["q"]):
        values[sym] = v
    for sym, v in zip(s.velocities, state["qd"]):
        values[sym] = v
    for sym, v in zip(s.parameters, state["params"]):
        values[sym] = v
    values[s.t] = state["t"]
    args = s.coordinates + s.velocities + s.parameters + [s.t]
    f = sp.lambdify(args, expr_matrix, modules="numpy")
    return np.array(f(*[values[a] for a in args]), dtype=float)


def gauss_by_kkt(m, f, a, b):
    """q̈ minimising ½(q̈ − a)ᵀM(q̈ − a) subject to A q̈ = b, from the KKT
    system [[M, Aᵀ], [A, 0]] [q̈; μ] = [F; b]: solved directly when the
    constraints are independent, by least squares when they are redundant
    (then μ is not unique but q̈ is)."""
    n, k = m.shape[0], a.shape[0]
    kkt = np.block([[m, a.T], [a, np.zeros((k, k))]])
    rhs = np.concatenate([f, b])
    if np.linalg.matrix_rank(a, tol=1e-9 * max(1.0, np.abs(a).max())) == k:
        x = np.linalg.solve(kkt, rhs)
    else:
        x = np.linalg.lstsq(kkt, rhs, rcond=1e-10)[0]
    return x[:n]


def second_derivative(expr, s, qdd_values, state):
    """d²/dt² of expr(q, t) along the motion, with q̈ given."""
    dd = total_derivative(total_derivative(expr, s), s)
    subs = {qdd: v for qdd, v in zip(s.accelerations, qdd_values)}
    return float(numeric(sp.Matrix([dd.subs(subs)]), s, state)[0][0])


def first_derivative(expr, s, state):
    d = total_derivative(expr, s)
    return float(numeric(sp.Matrix([d]), s, state)[0][0])
