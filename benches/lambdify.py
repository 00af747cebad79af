"""sympy's lambdify on Appell's particle, on the same 12 states as the Rust
benches: what a Python user would write instead. q̈ is derived here with
sympy (tests/sympy/derivation.py, from φ alone) in closed form, eq. 32, then
compiled by lambdify twice: with numpy (the common choice) and with the
math module and common-subexpression elimination (the fastest variant for
scalar calls). Writes the time per call, in ns, as JSON."""

import os
import json
import sys
import timeit
from pathlib import Path

import sympy as sp

ROOT = Path(__file__).resolve().parents[1]
# Cargo's target directory (scripts/benchmarks.sh passes it: CARGO_TARGET_DIR
# when set).
TARGET = Path(os.environ.get("CONSTRAINED_TARGET_DIR", ROOT / "target"))
sys.path.insert(0, str(ROOT / "tests" / "sympy"))
from derivation import derive_constraint_equations, symbols_for  # noqa: E402

system = {
    "coordinates": ["x", "y", "z"],
    "parameters": ["g", "alpha"],
    # Appell's particle as the macro's models::Appell writes it (h = z).
    "constraints": ["dot(x)**2/2 + dot(y)**2/2 - dot(z)**2/2 - alpha*z"],
}
s = symbols_for(system)
g, alpha = s.parameters
a_row, b, _ = derive_constraint_equations(system)
a_vec = sp.Matrix([0, 0, -g])  # M = I, F = [0, 0, −g]
A = a_row  # 1 × 3
qdd = a_vec + A.T * ((b - A * a_vec) / (A * A.T)[0])  # eq. 32
args = s.coordinates + s.velocities + [s.t, g, alpha]

data = json.loads((ROOT / "benches" / "data" / "appell_states.json").read_text())
states = [st["q"] + st["qd"] + [st["t"], data["g"], data["alpha"]] for st in data["states"]]

variants = {
    "lambdify_numpy": sp.lambdify(args, list(qdd), modules="numpy"),
    "lambdify_math_cse": sp.lambdify(args, list(qdd), modules="math", cse=True),
}
results = {}
for name, f in variants.items():
    def run(f=f):
        for st in states:
            f(*st)
    timer = timeit.Timer(run)
    loops, _ = timer.autorange()
    best = min(timer.repeat(repeat=7, number=loops)) / loops
    results[name] = best / len(states) * 1e9
    print(f"{name}: {results[name]:.0f} ns per call")

out = TARGET / "benchmarks" / "lambdify.json"
out.parent.mkdir(parents=True, exist_ok=True)
out.write_text(json.dumps(results, indent=1))
