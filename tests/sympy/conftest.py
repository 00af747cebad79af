"""Loads the macro's export (tests/sympy/export.rs) and reports the
largest discrepancy each check saw."""

import json
import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
# Cargo's target directory (scripts/sympy.sh passes it: CARGO_TARGET_DIR
# when set), where the inputs are read and the outputs written.
TARGET = Path(os.environ.get("CONSTRAINED_TARGET_DIR", ROOT / "target"))
EXPORT = Path(os.environ.get("CONSTRAINED_SYSTEMS_JSON", TARGET / "sympy" / "systems.json"))

DISCREPANCIES = {}


def record(check, system, value):
    """Keeps the largest discrepancy seen by `check` on `system`."""
    key = (check, system)
    DISCREPANCIES[key] = max(DISCREPANCIES.get(key, 0.0), float(value))


def load_export():
    if not EXPORT.exists():
        raise FileNotFoundError(
            f"{EXPORT} is missing: run `cargo run -p constrained-tests --example sympy_export -- {EXPORT}` first "
            "(scripts/sympy.sh does)"
        )
    return json.loads(EXPORT.read_text())


_EXPORT = load_export()
SYSTEMS = _EXPORT["systems"]
# The input-driven models' generated linearizations (test_linearization.py).
LINEARIZATIONS = _EXPORT["linearizations"]
# The systems with constraints: the checks of A, b and Gauss's principle.
CONSTRAINED = [s for s in SYSTEMS if s["constraints"]]

# CONSTRAINED_SYMPY_MUTATE=1 flips the sign of each system's b₁ as exported
# by the macro, a deliberately wrong derivative: the suite must then fail
# (scripts/sympy.sh --mutate shows it).
if os.environ.get("CONSTRAINED_SYMPY_MUTATE") == "1":
    for _system in CONSTRAINED:
        _system["b_vector"][0] = f"-({_system['b_vector'][0]})"


@pytest.fixture(params=CONSTRAINED, ids=[s["name"] for s in CONSTRAINED])
def system(request):
    return request.param


def pytest_terminal_summary(terminalreporter):
    if not DISCREPANCIES:
        return
    terminalreporter.section("largest discrepancies (relative)")
    for (check, name), value in sorted(DISCREPANCIES.items()):
        terminalreporter.write_line(f"{check:<42} {name:<26} {value:.2e}")
    worst = max(DISCREPANCIES.values())
    terminalreporter.write_line(f"largest over all checks: {worst:.2e}")
