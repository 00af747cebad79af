"""The URDF sweep's section of BENCHMARKS.md, from
<target>/benchmarks/urdf_sweep.json (written by scripts/urdf_sweep.sh):
shared by benches/urdf_sweep.py, which prints it, and benches/report.py."""

import json


def load(path):
    """The sweep's rows, or None where it has not been run."""
    if not path.exists():
        return None
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def worst(row):
    """The largest relative difference of the four answers."""
    w = row.get("worst")
    if w is None:
        return None
    return max(w[k] for k in ("q̈", "M", "τ", "g"))


def agrees(row):
    return worst(row) is not None and worst(row) <= 1e-12 and not row.get("failure")


def section(rows):
    """The section's lines: what was done, the count that agrees, the table."""
    if not rows:
        return []
    loaded = [r for r in rows if r["pinocchio"]]
    agree = [r for r in loaded if agrees(r)]
    refused = [r for r in loaded if not r.get("ok")]
    lines = [
        "",
        "## Every URDF of example-robot-data, against Pinocchio (`scripts/urdf_sweep.sh`)",
        "",
        "Each URDF file of the `example-robot-data` wheel, with a fixed base, read as written",
        "by Pinocchio (`buildModelFromUrdf(.., mimic=True)`: a `<mimic>` joint follows the joint it",
        "names) and by `constrained_system! { urdf: .. }`. For each",
        "file that expands, a crate of its own is built in release mode and its `acceleration`",
        "(τ = 0), `mass_matrix`, `inverse_dynamics` and `gravity_forces` at 5 pseudo-random",
        "states are compared with `aba`, `crba`, `rnea` and `computeGeneralizedGravity`, by",
        "joint name, each relative to its largest entry; the worst of the four is shown.",
        "Expansion is the macro's own time (release build of the generator); build CPU is",
        "the robot's crate alone, its dependencies already built; operations per q̈ are",
        "those of the generated `acceleration`; the last column counts sines and cosines of",
        "constants left in the generated code.",
        "",
        f"{len(rows)} files; Pinocchio loads {len(loaded)}; {len(agree)} of them "
        f"({100 * len(agree) / max(len(loaded), 1):.0f} %) agree to ≤ 1e-12 and "
        f"{len(refused)} are refused with the file, line and element.",
        "",
        "| file | joints | expansion | build CPU | operations per q̈ | worst relative difference | sines of constants |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if not r["pinocchio"]:
            why = f": {r['refusal']}" if r.get("refusal") else ""
            lines.append(f"| `{r['file']}` | – | not loaded by Pinocchio{why} | | | | |")
        elif not r.get("ok"):
            lines.append(f"| `{r['file']}` | {r['n']} | refused: {r['error']} | | | | |")
        elif worst(r) is None:
            lines.append(f"| `{r['file']}` | {r['n']} | {r['seconds']:.2f} s | failed: "
                         f"{r['failure']} | {r['ops']:,} | | |")
        else:
            w = r["worst"]
            note = f" ({r['failure'][0]})" if r.get("failure") else ""
            if worst(r) > 1e-12:
                note += (f" (q̈; `M`'s condition number {w['condition']:.0e}, our q̈ solves "
                         f"`M q̈ = −c` to {w['residual']:.0e}; `M` {w['M']:.0e}, τ {w['τ']:.0e})")
            lines.append(f"| `{r['file']}` | {r['n']} | {r['seconds']:.2f} s | {r['build_cpu']:.1f} s | "
                         f"{r['ops']:,} | {worst(r):.1e}{note} | {r['constant_trig']} |")
    return lines
