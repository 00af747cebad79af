"""sympy's LagrangesMethod on the planar N-link pendulum in joint angles —
the model `constrained_codegen::fixtures::joint_angle_pendulum` gives the
macro (same masses 1 + 0.1 i, lengths 1 + 0.05 i, symbolic g): what a user
ran before the macro took energies. Times the derivation of M and F
(`form_lagranges_equations`, `mass_matrix`, `forcing`) once per N, and
stops trying larger N once one takes longer than the budget. Writes
seconds per N as JSON."""

import os
import json
import multiprocessing
import sys
import time
from pathlib import Path

import sympy as sp
from sympy.physics.mechanics import LagrangesMethod, dynamicsymbols

ROOT = Path(__file__).resolve().parents[1]
# Cargo's target directory (scripts/benchmarks.sh passes it: CARGO_TARGET_DIR
# when set).
TARGET = Path(os.environ.get("CONSTRAINED_TARGET_DIR", ROOT / "target"))
BUDGET = float(sys.argv[1]) if len(sys.argv) > 1 else 120.0


def derive(links):
    t = dynamicsymbols._t
    g = sp.Symbol("g")
    th = dynamicsymbols(" ".join(f"th{i}" for i in range(1, links + 1)), seq=True)
    x = y = sp.Integer(0)
    angle = sp.Integer(0)
    kinetic = potential = sp.Integer(0)
    for i in range(1, links + 1):
        m = sp.Float(1 + 0.1 * i)
        l = sp.Float(1 + 0.05 * i)
        angle = angle + th[i - 1]
        x = x + l * sp.sin(angle)
        y = y - l * sp.cos(angle)
        kinetic += m * (sp.diff(x, t) ** 2 + sp.diff(y, t) ** 2) / 2
        potential += m * g * y
    start = time.perf_counter()
    method = LagrangesMethod(kinetic - potential, th)
    method.form_lagranges_equations()
    _ = (method.mass_matrix, method.forcing)
    return time.perf_counter() - start


def timed(links, queue):
    queue.put(derive(links))


def main():
    results = {}
    for links in (2, 4, 8, 16):
        queue = multiprocessing.Queue()
        worker = multiprocessing.Process(target=timed, args=(links, queue))
        worker.start()
        worker.join(BUDGET)
        if worker.is_alive():
            worker.terminate()
            results[links] = None
            print(f"N = {links}: sympy LagrangesMethod did not finish within {BUDGET:.0f} s")
            break
        seconds = queue.get()
        results[links] = seconds
        print(f"N = {links}: sympy LagrangesMethod {seconds:.3f} s")
    out = TARGET / "benchmarks" / "lagrange_sympy.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"budget": BUDGET, "seconds": results}))


if __name__ == "__main__":
    main()
