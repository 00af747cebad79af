"""The generated linearizations against sympy.physics.mechanics, derived here
from the physics alone (frames, points, particles, loads), not from the
macro's export:

- the cart-pole in generalized coordinates: `LagrangesMethod`, q̈ solved
  symbolically and differentiated exactly (`acceleration_jacobian`), and its
  `Linearizer` (`linearize`), at random states and at the upright
  equilibrium, where the eigenvalues are also compared with the closed form;
- the Cartesian cart-pole (the rod a constraint): the eigenvalues of
  `linearize_reduced` at the upright state are those of the generalized form;
- the Chaplygin sleigh with a torque, a nonholonomic system with an input:
  `KanesMethod` with the dependent speed the generated code chose, and its
  `linearize`, against `linearize_reduced` (state: every coordinate and the
  independent speeds), matrices and eigenvalues.
"""

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import (
    KanesMethod,
    LagrangesMethod,
    Lagrangian,
    Particle,
    Point,
    ReferenceFrame,
    RigidBody,
    dynamicsymbols,
    inertia,
    msubs,
)

from conftest import LINEARIZATIONS, record

TIME = dynamicsymbols._t


def states_of(name):
    [model] = [m for m in LINEARIZATIONS if m["name"] == name]
    assert model["states"], name
    return model["states"]


def relative(ours, theirs):
    ours, theirs = np.asarray(ours, dtype=float), np.asarray(theirs, dtype=float)
    assert ours.shape == theirs.shape, (ours.shape, theirs.shape)
    return np.abs(ours - theirs).max() / (1.0 + np.abs(theirs).max())


def matching_eigenvalues(ours, theirs):
    """The largest distance from each of our eigenvalues to sympy's nearest
    unmatched one (both lists have the same length)."""
    theirs = list(theirs)
    worst = 0.0
    for value in sorted(ours, key=lambda z: (z.real, z.imag)):
        distances = [abs(value - other) for other in theirs]
        k = int(np.argmin(distances))
        worst = max(worst, distances[k])
        theirs.pop(k)
    return worst


# ---------------------------------------------------------------- cart-pole

class CartPole:
    """The cart-pole from its particles: the cart of mass mc at s pushed
    along the rail, the bob of mass mp at the end of a rod of length l at
    angle θ from hanging down, gravity g."""

    def __init__(self):
        self.s, self.th = dynamicsymbols("s theta")
        self.push = dynamicsymbols("push")
        self.mc, self.mp, self.l, self.g = sp.symbols("m_c m_p l g", positive=True)
        frame = ReferenceFrame("N")
        origin = Point("O")
        origin.set_vel(frame, 0)
        cart = origin.locatenew("C", self.s * frame.x)
        cart.set_vel(frame, self.s.diff(TIME) * frame.x)
        tip = cart.locatenew("P", self.l * sp.sin(self.th) * frame.x - self.l * sp.cos(self.th) * frame.y)
        tip.set_vel(frame, tip.pos_from(origin).dt(frame))
        cart_particle = Particle("cart", cart, self.mc)
        bob = Particle("bob", tip, self.mp)
        bob.potential_energy = self.mp * self.g * tip.pos_from(origin).dot(frame.y)
        lagrangian = Lagrangian(frame, cart_particle, bob)
        self.q = [self.s, self.th]
        self.qd = [c.diff(TIME) for c in self.q]
        self.qdd = [c.diff(TIME) for c in self.qd]
        self.method = LagrangesMethod(lagrangian, self.q, forcelist=[(cart, self.push * frame.x)], frame=frame)
        self.method.form_lagranges_equations()
        # q̈ in closed form, then its exact derivatives.
        self.acceleration = self.method.mass_matrix.LUsolve(self.method.forcing)
        self.jacobians = (
            self.acceleration.jacobian(self.q),
            self.acceleration.jacobian(self.qd),
            self.acceleration.jacobian([self.push]),
        )

    def values(self, state):
        mc, mp, l, g, push = state["params"]
        values = {self.mc: mc, self.mp: mp, self.l: l, self.g: g, self.push: push}
        values |= dict(zip(self.q, state["q"])) | dict(zip(self.qd, state["qd"]))
        return values

    def evaluate(self, expression, values):
        # Derivatives before the functions they are derivatives of.
        return np.array(msubs(expression, values).evalf(), dtype=float)

    def linearizer(self, state):
        """Sympy's Linearizer at the state: (A, B) for x = (s, θ, ṡ, θ̇)."""
        values = self.values(state)
        qdd = self.evaluate(self.acceleration, values).ravel()
        op_point = values | dict(zip(self.qdd, qdd))
        parameters = {k: v for k, v in values.items() if k in (self.mc, self.mp, self.l, self.g)}
        a, b, inputs = self.method.linearize(
            q_ind=self.q, qd_ind=self.qd, A_and_B=True, op_point=op_point
        )
        assert list(inputs) == [self.push], inputs
        return self.evaluate(msubs(a, parameters), op_point), self.evaluate(msubs(b, parameters), op_point)


@pytest.fixture(scope="module")
def cart_pole():
    return CartPole()


def test_cart_pole_jacobians_are_sympys_exact_ones(cart_pole):
    for state in states_of("CartPole"):
        values = cart_pole.values(state)
        for key, exact in zip(("dq", "dqd", "du"), cart_pole.jacobians):
            diff = relative(state[key], cart_pole.evaluate(exact, values))
            record(f"cart-pole ∂q̈/∂{key[1:]} vs sympy", "CartPole", diff)
            assert diff < 1e-9, f"{key} at {state['q']}, {state['qd']}: {state[key]} (relative {diff:.2e})"


def test_cart_pole_linearization_is_sympys_linearizer(cart_pole):
    for state in states_of("CartPole"):
        a, b = cart_pole.linearizer(state)
        for key, theirs in (("a", a), ("b", b)):
            diff = relative(state[key], theirs)
            record(f"cart-pole linearize {key.upper()} vs Linearizer", "CartPole", diff)
            assert diff < 1e-9, f"{key}: {state[key]} vs {theirs.tolist()} (relative {diff:.2e})"


def test_upright_cart_pole_has_the_closed_form_eigenvalues(cart_pole):
    upright = states_of("CartPole")[0]
    assert upright["q"][1] == pytest.approx(np.pi) and upright["qd"] == [0.0, 0.0]
    mc, mp, l, g, _ = upright["params"]
    rate = np.sqrt(g * (mc + mp) / (mc * l))
    closed_form = [0.0, 0.0, rate, -rate]
    a, _ = cart_pole.linearizer(upright)
    for name, matrix, tolerance in (("generated", upright["a"], 1e-9), ("sympy", a, 1e-9)):
        diff = matching_eigenvalues(np.linalg.eigvals(np.array(matrix)), closed_form)
        record(f"upright cart-pole eigenvalues ({name})", "CartPole", diff)
        assert diff < tolerance, (name, np.linalg.eigvals(np.array(matrix)), closed_form)


def test_cartesian_cart_pole_reduces_to_the_generalized_eigenvalues(cart_pole):
    [cartesian] = states_of("CartPoleCartesian")
    upright = states_of("CartPole")[0]
    assert cartesian["params"][:4] == upright["params"][:4]
    reduced = np.array(cartesian["reduced"]["a"])
    assert reduced.shape == (4, 4), "two coordinates and two speeds stay free"
    a, _ = cart_pole.linearizer(upright)
    # The double zero is a Jordan block: rounding splits it by about √ε.
    diff = matching_eigenvalues(np.linalg.eigvals(reduced), np.linalg.eigvals(a))
    record("Cartesian cart-pole reduced eigenvalues", "CartPoleCartesian", diff)
    assert diff < 1e-6, (np.linalg.eigvals(reduced), np.linalg.eigvals(a))
    # The full Cartesian linearization has six, two of them along the rod.
    assert np.array(cartesian["a"]).shape == (6, 6)


# ---------------------------------------------------------- Chaplygin sleigh

class Sleigh:
    """The Chaplygin sleigh by Kane's method: a rigid body of mass m and
    moment of inertia I about its centre of mass P = (x, y), heading θ,
    on a blade at C, a distance a behind P, that cannot slide sideways:
    v_C · b_y = 0. A torque turns it."""

    def __init__(self, dependent):
        self.q = list(dynamicsymbols("x y theta"))
        self.u = list(dynamicsymbols("u_x u_y u_theta"))
        self.torque = dynamicsymbols("torque")
        self.m, self.inertia, self.a = sp.symbols("m I a", positive=True)
        x, y, theta = self.q
        frame = ReferenceFrame("N")
        body_frame = frame.orientnew("B", "Axis", [theta, frame.z])
        body_frame.set_ang_vel(frame, self.u[2] * frame.z)
        origin = Point("O")
        centre = origin.locatenew("P", x * frame.x + y * frame.y)
        centre.set_vel(frame, self.u[0] * frame.x + self.u[1] * frame.y)
        contact = centre.locatenew("C", -self.a * body_frame.x)
        contact.v2pt_theory(centre, frame, body_frame)
        body = RigidBody(
            "sleigh", centre, body_frame, self.m, (inertia(body_frame, 0, 0, self.inertia), centre)
        )
        self.independent = [u for i, u in enumerate(self.u) if i != dependent]
        self.method = KanesMethod(
            frame,
            q_ind=self.q,
            u_ind=self.independent,
            kd_eqs=[c.diff(TIME) - u for c, u in zip(self.q, self.u)],
            u_dependent=[self.u[dependent]],
            velocity_constraints=[contact.vel(frame).dot(body_frame.y)],
        )
        self.method.kanes_equations([body], [(body_frame, self.torque * frame.z)])

    def linearize(self, state):
        m, inertia_value, a, torque = state["params"]
        parameters = {self.m: m, self.inertia: inertia_value, self.a: a}
        values = parameters | {self.torque: torque}
        values |= dict(zip(self.q, state["q"])) | dict(zip(self.u, state["qd"]))
        values |= {c.diff(TIME): v for c, v in zip(self.q, state["qd"])}
        # Every speed's derivative at the state, from Kane's own equations
        # (the dynamic ones and the derivative of the velocity constraint).
        mass = np.array(msubs(self.method.mass_matrix, values).evalf(), dtype=float)
        forcing = np.array(msubs(self.method.forcing, values).evalf(), dtype=float).ravel()
        ud = np.linalg.solve(mass, forcing)
        order = self.independent + [u for u in self.u if u not in self.independent]
        op_point = values | {u.diff(TIME): v for u, v in zip(order, ud)}
        a_matrix, b_matrix, inputs = self.method.linearize(A_and_B=True, op_point=op_point)
        assert list(inputs) == [self.torque], inputs
        evaluate = lambda e: np.array(msubs(msubs(e, parameters), op_point).evalf(), dtype=float)
        return evaluate(a_matrix), evaluate(b_matrix)


def test_sleigh_reduced_linearization_is_kanes():
    kanes = {}
    for state in states_of("ChaplyginSleigh"):
        reduced = state["reduced"]
        assert reduced["coordinates"] == [0, 1, 2], "no holonomic constraint: every coordinate stays"
        [dependent] = [i for i in range(3) if i not in reduced["speeds"]]
        sleigh = kanes.setdefault(dependent, Sleigh(dependent))
        a, b = sleigh.linearize(state)
        for key, theirs in (("a", a), ("b", b)):
            diff = relative(reduced[key], theirs)
            record(f"sleigh reduced {key.upper()} vs KanesMethod.linearize", "ChaplyginSleigh", diff)
            assert diff < 1e-9, f"{key} at {state['q']}, {state['qd']}: {reduced[key]} vs {theirs.tolist()}"
        diff = matching_eigenvalues(np.linalg.eigvals(np.array(reduced["a"])), np.linalg.eigvals(a))
        record("sleigh reduced eigenvalues vs Kane", "ChaplyginSleigh", diff)
        assert diff < 1e-8, (np.linalg.eigvals(np.array(reduced["a"])), np.linalg.eigvals(a))


def test_straight_sleigh_turns_towards_its_heading_at_the_closed_form_rate():
    """Straight-line motion at speed v (no spin, no torque): a small spin
    decays as exp(−m a v t / (I + m a²)); every other direction is neutral."""
    straight = states_of("ChaplyginSleigh")[0]
    m, inertia_value, a, torque = straight["params"]
    assert torque == 0.0 and straight["qd"][2] == 0.0
    speed = np.hypot(straight["qd"][0], straight["qd"][1])
    closed_form = [0.0, 0.0, 0.0, 0.0, -m * a * speed / (inertia_value + m * a * a)]
    eigenvalues = np.linalg.eigvals(np.array(straight["reduced"]["a"]))
    diff = matching_eigenvalues(eigenvalues, closed_form)
    record("straight sleigh eigenvalues vs closed form", "ChaplyginSleigh", diff)
    assert diff < 1e-9, (eigenvalues, closed_form)
