"""The holonomic systems derived again in minimal coordinates with
sympy.physics.mechanics (LagrangesMethod): the macro's Cartesian q̈, mapped
to the generalized coordinates, gives the same generalized accelerations.
The two-link arm, already in joint angles, has its M and F checked against
LagrangesMethod instead."""

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import LagrangesMethod, dynamicsymbols, msubs

from conftest import SYSTEMS, record
from derivation import first_derivative, parse, second_derivative, symbols_for

t = dynamicsymbols._t


def kinetic(m, *position):
    return m / 2 * sum(sp.diff(c, t) ** 2 for c in position)


def spherical(s):
    m, g, l = (s.namespace[n] for n in ("m", "g", "l"))
    x, y, z = s.coordinates
    th, ph = dynamicsymbols("th ph")
    p = (l * sp.sin(th) * sp.cos(ph), l * sp.sin(th) * sp.sin(ph), -l * sp.cos(th))
    lagrangian = kinetic(m, *p) - m * g * p[2]
    minimal = [sp.atan2(sp.sqrt(x**2 + y**2), -z), sp.atan2(y, x)]
    return lagrangian, [th, ph], minimal


def double(s):
    m1, m2, l1, l2, g = (s.namespace[n] for n in ("m1", "m2", "l1", "l2", "g"))
    x1, y1, x2, y2 = s.coordinates
    th1, th2 = dynamicsymbols("th1 th2")
    p1 = (l1 * sp.sin(th1), -l1 * sp.cos(th1))
    p2 = (p1[0] + l2 * sp.sin(th2), p1[1] - l2 * sp.cos(th2))
    lagrangian = kinetic(m1, *p1) + kinetic(m2, *p2) - g * (m1 * p1[1] + m2 * p2[1])
    minimal = [sp.atan2(x1, -y1), sp.atan2(x2 - x1, -(y2 - y1))]
    return lagrangian, [th1, th2], minimal


def bead(s):
    m, g, r, w = (s.namespace[n] for n in ("m", "g", "r", "omega"))
    x, y, z = s.coordinates
    psi = dynamicsymbols("psi")
    p = (r * sp.sin(psi) * sp.cos(w * t), r * sp.sin(psi) * sp.sin(w * t), -r * sp.cos(psi))
    lagrangian = kinetic(m, *p) - m * g * p[2]
    # The signed position along the hoop's plane, so that ψ covers a full turn.
    along = x * sp.cos(w * s.t) + y * sp.sin(w * s.t)
    return lagrangian, [psi], [sp.atan2(along, -z)]


MINIMAL = {
    "SphericalPendulum": spherical,
    "DoublePendulum": double,
    "RedundantDoublePendulum": double,
    "BeadOnRotatingHoop": bead,
}


@pytest.mark.parametrize("name", sorted(MINIMAL))
def test_generalized_accelerations(name):
    system = next(sys for sys in SYSTEMS if sys["name"] == name)
    s = symbols_for(system)
    lagrangian, coords, minimal = MINIMAL[name](s)
    method = LagrangesMethod(lagrangian, coords)
    method.form_lagranges_equations()
    rhs = method.rhs()
    n = len(coords)
    for state in system["states"]:
        point = dict(zip(s.coordinates, state["q"])) | dict(zip(s.parameters, state["params"])) | {s.t: state["t"]}
        values = [float(e.subs(point)) for e in minimal]
        rates = [first_derivative(e, s, state) for e in minimal]
        from_macro = np.array([second_derivative(e, s, state["qdd"], state) for e in minimal])
        subs = {sp.diff(c, t): v for c, v in zip(coords, rates)}
        subs |= dict(zip(coords, values))
        subs |= dict(zip(s.parameters, state["params"]))
        lagrange = np.array([float(msubs(rhs[n + i], subs).subs(t, state["t"])) for i in range(n)])
        diff = np.abs(from_macro - lagrange).max() / (1.0 + np.abs(lagrange).max())
        record("generalized q̈ vs LagrangesMethod", name, diff)
        assert diff < 1e-9, f"{name}: from the macro {from_macro} vs Lagrange {lagrange}"


def test_two_link_arm_mass_and_forces():
    system = next(sys for sys in SYSTEMS if sys["name"] == "TwoLinkArmOnLine")
    s = symbols_for(system)
    m1, m2, l1, l2, g = (s.namespace[n] for n in ("m1", "m2", "l1", "l2", "g"))
    th1, th2 = dynamicsymbols("th1 th2")
    p1 = (l1 * sp.cos(th1), l1 * sp.sin(th1))
    p2 = (p1[0] + l2 * sp.cos(th1 + th2), p1[1] + l2 * sp.sin(th1 + th2))
    lagrangian = kinetic(m1, *p1) + kinetic(m2, *p2) - g * (m1 * p1[1] + m2 * p2[1])
    method = LagrangesMethod(lagrangian, [th1, th2])
    method.form_lagranges_equations()
    plain = {sp.diff(th1, t): s.velocities[0], sp.diff(th2, t): s.velocities[1], th1: s.coordinates[0], th2: s.coordinates[1]}
    mass = msubs(method.mass_matrix, plain)
    forcing = msubs(method.forcing, plain)
    for i in range(2):
        for j in range(2):
            model = parse(system["mass"][i][j], s)
            assert sp.simplify(sp.trigsimp(sp.expand(mass[i, j] - model))) == 0, f"M[{i},{j}]: {mass[i, j]} vs {model}"
        model = parse(system["forces"][i], s)
        assert sp.simplify(sp.trigsimp(sp.expand_trig(sp.expand(forcing[i] - model)))) == 0, f"F[{i}]: {forcing[i]} vs {model}"
