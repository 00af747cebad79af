"""The Growth section of BENCHMARKS.md and its target: the operations of
the generated `acceleration`, `mass_matrix` and `inverse_dynamics` over the
Unitree G1's truncations, its joints locked from the last in Pinocchio's
order until six are left (benches/growth.py writes
<target>/benchmarks/growth.json, one line per truncation). The exponent is
the least-squares slope of log(operations) on log(n). Standard library
only."""

import json
import math
import sys
from datetime import datetime, timezone
from pathlib import Path

import report_contacts

HEADING = "## Growth: operations over the G1's truncations"
TARGET_PREFIX = "Growth: "
JSON, NAME = "growth.json", "report_growth.py"
# Issue 48: operations per q̈ over the G1 with joints removed (6 → 29)
# grow at most as n^1.1.
WANTED = 1.1
COLUMNS = (("ops", "q̈ (`acceleration`)"), ("mass_matrix_ops", "`mass_matrix`"),
           ("inverse_dynamics_ops", "`inverse_dynamics`"))


def load(target):
    """The truncations' rows, by joint count, or [] where growth.py has not run."""
    path = Path(target) / "benchmarks" / JSON
    if not path.exists():
        return []
    rows = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    return sorted((r for r in rows if r.get("ok")), key=lambda r: r["n"])


def exponent(rows, key):
    """The least-squares slope of log(rows' `key`) on log(n)."""
    xs = [math.log(r["n"]) for r in rows]
    ys = [math.log(r[key]) for r in rows]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def endpoints(rows, key):
    """The exponent between the smallest and the largest truncation."""
    first, last = rows[0], rows[-1]
    return math.log(last[key] / first[key]) / math.log(last["n"] / first["n"])


def per_joint(row):
    """`inverse_dynamics`' operations per joint."""
    return round(row["inverse_dynamics_ops"] / row["n"])


def section(rows, _ns=None):
    """The section's lines: what was counted, the exponents, the table."""
    if len(rows) < 2:
        return []
    lines = [
        "",
        HEADING,
        "",
        "The Unitree G1 of example-robot-data's `g1_29dof_rev_1_0.urdf` (fixed base), its joints",
        "`locked:` from the last in Pinocchio's order (right arm, left arm, waist, right leg) until",
        f"{rows[0]['n']} are left, each truncation expanded by `benches/urdf_sweep` and its generated",
        "functions' operations counted (`constrained_codegen::tools::op_count`: the arithmetic of the",
        "code as emitted). The exponent is the least-squares slope of log(operations) on log(n) over",
        f"the {len(rows)} truncations; in brackets, the one between the first and the last.",
        "",
        "| function | exponent | first → last |",
        "|---|---|---|",
    ]
    for key, label in COLUMNS:
        lines.append(f"| {label} | n^{exponent(rows, key):.2f} (n^{endpoints(rows, key):.2f}) | "
                     f"{rows[0][key]:,} → {rows[-1][key]:,} |")
    lines += [
        "",
        "`M` by the composite-rigid-body algorithm costs one force transform per joint and",
        "ancestor, O(n d) for depth d, and its `L D Lᵀ` within the tree's branches O(n d²):",
        "the arms, added last, sit deepest (ten joints from the pelvis), so each adds more",
        "than a leg's joint did. Recursive Newton–Euler is O(n) in the bodies; its exponent",
        f"is above 1 where the joints added last cost more each ({per_joint(rows[0])} operations a",
        f"joint at {rows[0]['n']} joints, {per_joint(rows[-1])} at {rows[-1]['n']}).",
        "",
        "| joints | q̈ | per joint | `mass_matrix` | `inverse_dynamics` |",
        "|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(f"| {r['n']} | {r['ops']:,} | {r['ops'] / r['n']:.0f} | {r['mass_matrix_ops']:,} | "
                     f"{r['inverse_dynamics_ops']:,} |")
    return lines


def targets(rows):
    """The growth target's row, where growth.py has run."""
    if len(rows) < 2:
        return []
    text = (f"{TARGET_PREFIX}operations per q̈ over the G1's truncations ({rows[0]['n']} → {rows[-1]['n']} "
            "joints) grow at most as n^1.1 (least-squares exponent)")
    return [(text, exponent(rows, "ops"), f"≤ n^{WANTED}", lambda x: x <= WANTED, "n^{:.2f}")]


def splice(target, root):
    """Rewrites the Growth section and its target's row of `root`/BENCHMARKS.md."""
    rows = load(target)
    if len(rows) < 2:
        sys.exit(f"no {JSON}: run scripts/urdf_sweep.sh")
    run = Path(target) / "benchmarks" / JSON
    when = datetime.fromtimestamp(run.stat().st_mtime, timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    provenance = [f"From the sweep of {when} (this section alone: `python3 benches/{NAME}`)."]
    report_contacts.replace_section(Path(root) / "BENCHMARKS.md", HEADING, section(rows), targets(rows),
                                    TARGET_PREFIX, provenance)


if __name__ == "__main__":
    import report

    splice(report.TARGET, report.ROOT)
    print(f"wrote the growth section of {report.ROOT / 'BENCHMARKS.md'}")
