"""The Contacts section of BENCHMARKS.md and its targets: the quadruped and
the Unitree Go1 (from its URDF, on a floating root) on four feet and the
five-bar loop against Pinocchio's `constraintDynamics`
and `lcaba` (benches/peers/run.sh writes <target>/benchmarks/contacts.json:
our times and Pinocchio's, in alternating rounds). Standard library only."""

import json
import os
import sys
from pathlib import Path

SYSTEMS = (("quadruped", 19, 18, "quadruped, 4 feet (19 coordinates, 13 rows; Pinocchio: nv 18, 12 rows)"),
           ("go1", 19, 18, "Unitree Go1 from its URDF, 4 feet (19 coordinates, 13 rows; Pinocchio: nv 18, 12 rows)"),
           ("five_bar", 4, 4, "five-bar loop (4 joints, 2 rows; Pinocchio: one 3D loop contact)"),
           ("g1_points", 36, 35, "Unitree G1 from its URDF on three points of each foot (36 coordinates, 19 rows of "
            "rank 13; Pinocchio: nv 35, 18 rows of rank 12)"),
           ("g1_flat", 36, 35, "Unitree G1 from its URDF on two flat feet (36 coordinates, 13 rows; Pinocchio: nv 35, "
            "two `CONTACT_6D`)"))
# The wanted ratio to `constraintDynamics` of each system's method: issue
# 27's q̈ ≥ 5×; issue 48's for the Go1 read from its URDF and for the G1 on
# three points of each foot (redundant) and on two flat feet.
TARGETS = {("quadruped", "acceleration"): 5, ("five_bar", "acceleration"): 5,
           ("go1", "acceleration"): 6, ("go1", "acceleration_and_multipliers"): 5,
           ("g1_points", "acceleration_and_multipliers"): 3,
           ("g1_flat", "acceleration"): 4, ("g1_flat", "acceleration_and_multipliers"): 4}
PEERS = ("constraintDynamics", "lcaba")
OURS = ("acceleration", "acceleration_and_multipliers")
# Issue 49's derivatives on contacts: our Jacobians of q̈ and λ
# (`acceleration_and_multiplier_jacobians_to`, into kept outputs)
# against `computeConstraintDynamicsDerivatives` (after the
# `constraintDynamics` it needs), and the ratio wanted.
DERIVATIVES = ("go1", "acceleration_and_multiplier_jacobians", "constraint_dynamics_derivatives", 3)
# Issue 48's redundant contacts: the G1 on three points of each foot
# (`benches/peers/robots/src/g1_standing.rs`): q̈ and λ (the minimum norm)
# at most this many times its own q̈.
REDUNDANT = ("g1_points", 1.5)
REDUNDANT_WAYS = (("acceleration", "`acceleration`"),
                  ("acceleration_and_multipliers", "`acceleration_and_multipliers`: the minimum-norm `λ` from the solve"),
                  ("acceleration_and_runtime_multipliers",
                   "`gauss`, then the runtime's minimum norm from its force (an SVD of `A`)"))


def _median(values):
    ordered = sorted(values)
    middle = len(ordered) // 2
    return ordered[middle] if len(ordered) % 2 else (ordered[middle - 1] + ordered[middle]) / 2


def at_least(text, r, wanted):
    """A target row: the median of the rounds' ratios `r` at least `wanted`."""
    return (text, _median(r), f"≥ {wanted}", lambda x, w=wanted: x >= w, "{:.2f}×")


def agrees(text, worst, tolerance=1e-12):
    """A target row: the worst relative difference at most `tolerance`."""
    return (text, worst, f"≤ {tolerance:.0e}", lambda x, t=tolerance: x <= t, "{:.1e}")


def json_lines(target, name):
    """The JSON objects of `benchmarks/<name>`, one a line (none without it)."""
    path = Path(target) / "benchmarks" / name
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.startswith("{")]


def load(target, name="contacts.json"):
    """(peer, what, system) → the list of its rounds' JSON lines, from
    `benchmarks/<name>` (the contacts', or the robots' `robots.json`)."""
    rows = {}
    for r in json_lines(target, name):
        rows.setdefault((r["peer"], r["what"], r["system"]), []).append(r)
    return rows


def ratios(rows, system, ours, theirs):
    """The rounds' ratios Pinocchio / ours (paired by round), or []."""
    a = {r["round"]: r["ns"] for r in rows.get(("constrained", ours, system), [])}
    b = {r["round"]: r["ns"] for r in rows.get(("pinocchio", theirs, system), []) if r["ok"] and r["ns"]}
    return [b[k] / a[k] for k in sorted(a) if k in b and a[k]]


def own_ratios(rows, system, what):
    """The rounds' ratios of `what` to `acceleration`, ours both (by round):
    the paired measure where the round has one (`paired`, batch against
    batch), else the two medians' ratio."""
    a = {r["round"]: r["ns"] for r in rows.get(("constrained", "acceleration", system), [])}
    b = {r["round"]: r for r in rows.get(("constrained", what, system), [])}
    out = []
    for k in sorted(a):
        if k not in b or not a[k]:
            continue
        paired = b[k].get("paired") if what == "acceleration_and_multipliers" else None
        out.append(paired if paired else b[k]["ns"] / a[k])
    return out


def targets(rows):
    """Each of `TARGETS`: our method ≥ its ratio × faster than `constraintDynamics`."""
    out = []
    system, wanted = REDUNDANT
    r = own_ratios(rows, system, "acceleration_and_multipliers")
    if r:
        out.append((f"Contacts: G1 on three points of each foot (redundant), q̈ and the minimum-norm λ ≤ {wanted} × "
                    f"its own q̈ (median of {len(r)} rounds, each the median of 31 paired batches)", _median(r),
                    f"≤ {wanted}",
                    lambda x, w=wanted: x <= w, "{:.2f}×"))
    for (system, ours), wanted in TARGETS.items():
        r = ratios(rows, system, ours, "constraintDynamics")
        if r:
            what = "q̈" if ours == "acceleration" else "q̈ and λ"
            out.append(at_least(f"Contacts: {system.replace('_', '-')} {what} ≥ {wanted} × faster than Pinocchio's "
                                f"`constraintDynamics` (median of {len(r)} alternating rounds)", r, wanted))
    system, ours, theirs, wanted = DERIVATIVES
    r = ratios(rows, system, ours, theirs)
    if r:
        out.append(at_least(f"Contacts: {system} ∂q̈ and ∂λ ≥ {wanted} × faster than Pinocchio's "
                            f"`computeConstraintDynamicsDerivatives` (median of {len(r)} alternating rounds)", r,
                            wanted))
    peer = rows.get(("pinocchio", theirs, system), [])
    if peer:
        out.append(agrees(f"Contacts: {system} ∂q̈ and ∂λ agree with `computeConstraintDynamicsDerivatives` at 20 "
                          "states (worst relative difference)", max(p["difference"] for p in peer)))
    return out


def section(rows, ns):
    """The Contacts table, with each peer's damping, iterations and agreement."""
    if not rows:
        return []
    table, notes = [], []
    for system, n, nv, name in SYSTEMS:
        for theirs in PEERS:
            peer = rows.get(("pinocchio", theirs, system), [])
            if not peer:
                continue
            p = peer[0]
            lam = f", λ {p['lambda_difference']:.1e}" if p.get("lambda_difference") not in (None, "null") else ""
            # A redundant set is checked to tolerances of its own, its
            # proximal loop capped (see contacts.cpp).
            own = theirs == "constraintDynamics" and p.get("lambda_tolerance", p["tolerance"]) != p["tolerance"]
            checked = f"{p['tolerance']:.0e} and {p['lambda_tolerance']:.0e}" if own else f"{p['tolerance']:.0e}"
            cap = f", at most {p['max_iter']} iterations" if own else ""
            notes.append(f"- {system.replace('_', '-')}, `{theirs}`: ProximalSettings(accuracy {p['accuracy']:.0e}, "
                         f"mu {p['mu']:.0e}{cap}), {p['iterations']} iteration(s); agreement with ours: q̈ "
                         f"{p['difference']:.1e}{lam} (relative to the largest entry; checked to {checked})"
                         + ("" if p["ok"] else " — disagreed, not timed"))
            theirs_ns = _median([r["ns"] for r in peer if r["ok"] and r["ns"]]) if any(r["ok"] and r["ns"] for r in peer) else None
            for ours in OURS:
                mine = rows.get(("constrained", ours, system), [])
                if not mine:
                    continue
                ours_ns = _median([r["ns"] for r in mine])
                r = ratios(rows, system, ours, theirs)
                ratio = f"{_median(r):.2f}× ({min(r):.2f}–{max(r):.2f})" if r else "–"
                their = ns(theirs_ns) if theirs_ns else "disagreed"
                table.append(f"| {name} | `{ours}` / `{theirs}` | {ns(ours_ns)} | {their} | {ratio} |")
    system, ours, theirs, _ = DERIVATIVES
    peer = rows.get(("pinocchio", theirs, system), [])
    mine = rows.get(("constrained", ours, system), [])
    if peer and mine:
        p = peer[0]
        notes.append(f"- {system}, `computeConstraintDynamicsDerivatives` (after `constraintDynamics`, same settings): "
                     f"agreement with ours: {max(x['difference'] for x in peer):.1e} (each of ∂a/∂q, ∂a/∂v, ∂a/∂τ, "
                     "∂λ/∂q, ∂λ/∂v, ∂λ/∂τ relative to its largest entry; checked to "
                     f"{p['tolerance']:.0e})" + ("" if all(x["ok"] for x in peer) else " — disagreed, not timed"))
        timed = [x["ns"] for x in peer if x["ok"] and x["ns"]]
        r = ratios(rows, system, ours, theirs)
        ratio = f"{_median(r):.2f}× ({min(r):.2f}–{max(r):.2f})" if r else "–"
        name = dict((x[0], x[3]) for x in SYSTEMS)[system]
        table.append(f"| {name} | `acceleration_and_multiplier_jacobians_to` / "
                     f"`constraintDynamics` + `computeConstraintDynamicsDerivatives` | "
                     f"{ns(_median([x['ns'] for x in mine]))} | {ns(_median(timed)) if timed else 'disagreed'} | "
                     f"{ratio} |")
    parts = {what: _median([r["ns"] for r in rows.get(("constrained", what, "quadruped"), [])] or [0.0])
             for what in ("acceleration", "mass_matrix", "forces", "constraint_matrices")}
    profile = []
    if parts["acceleration"] and parts["mass_matrix"]:
        profile = [
            "",
            f"For scale, our quadruped's `acceleration` ({ns(parts['acceleration'])}) against the model's",
            f"own pieces each called alone: `M` {ns(parts['mass_matrix'])}, `F` {ns(parts['forces'])}, `A` and `b` "
            f"{ns(parts['constraint_matrices'])}. `acceleration` builds",
            "none of them: in one straight-line body it forms the system in the base's own",
            "axes (docs/math.md): the quaternion's accelerations `q̈ = ½ (q α + Gᵀ β)` and the",
            "base position's `p̈ = R̂ z` (`R̂ = R(q/|q|)`, a rotation for every `q ≠ 0`, so",
            "nothing is approximated off the unit sphere), `TᵀMT` and `TᵀF` from the",
            "recursions with the base's columns in its own frame, each foot's three rows",
            "premultiplied by `R̂ᵀ` in closed form, `[I, −r̃, J]` (`λ = R̂ λ'`): none of it",
            "holds the attitude but gravity. The norm's row fixes `α` alone; each leg is",
            "eliminated through its foot's rows, `θ̈ = J⁻¹ (b − E u)` (its cofactors over",
            "`det J`; a straight leg hands the solve to the runtime's dense one), and the",
            "base's six unknowns `u` come from its 6 × 6 inertia with the feet held.",
            "`acceleration` never forms the constraint force; `acceleration_and_multipliers`",
            "returns the solve's own `λ = J⁻ᵀ (f − M_lb u − M_ll θ̈)`, turned back into the",
            "world's axes.",
            "",
            "The instruction-cache table below measures the other half of these ratios: the",
            "quadruped's and the Go1's calls each run more distinct 64-byte lines of code than",
            "a 32 KiB L1i holds (its code run), so the whole hot path streams from L2 at",
            "every call.",
            "On a loaded machine both sides' times grow, not in proportion: compare the",
            "ratios of one run's rounds, and their range. The same binary's quadruped",
            "`acceleration` also moves between runs, 0.93 to 1.11 µs on one afternoon",
            "(`gauss_acceleration` is 67.4 KB of code, byte for byte the same in",
            "binaries built from commits whose generated code is the same, at the same",
            "address; the runs differ in where the rest lands).",
        ]
    return [
        "",
        "## Contacts and loops: the quadruped, the Go1 and the five-bar, against Pinocchio",
        "",
        "Pinocchio's constrained dynamics (`constraintDynamics`, and `lcaba` where it runs) in",
        "C++ (`benches/peers/contacts.cpp`) on models built from the same figures as ours",
        "(`examples/support/quadruped.rs`: a free flyer, 12 revolute joints, each foot a 3D",
        "point contact with the world in world-aligned axes; the Unitree Go1 of",
        "example-robot-data's `go1.urdf` read by both sides, ours with a `floating` root",
        "joint from a `world` link, Pinocchio's with `JointModelFreeFlyer`, its joints",
        "matched by name and its four foot links' origins 3D point contacts; the five-bar of",
        "`examples/five_bar.rs` closed by one 3D contact between the distal tips, whose",
        "`y` row is identically zero — ours writes the two rows `x`, `z`; and the Unitree G1",
        "of `g1_29dof_rev_1_0.urdf` on a floating root standing on two flat feet",
        "(`benches/peers/robots/src/g1_flat.rs`: each foot's sole, `(0.035, 0, −0.035)` in",
        "its ankle roll link, held by `position(..) == [x, y, z]` and",
        "`orientation(..) == [roll, pitch, yaw]`, six independent rows a foot; Pinocchio's",
        "a `CONTACT_6D` at the same sole in `LOCAL` axes, to which our world-axes force",
        "and torque are turned; the generated solve answers every state, one with a knee at",
        "0.028 rad included, since its order takes every coordinate before any row,",
        "docs/math.md), at 20 consistent",
        "states each (`benches/peers/robots/src/bin/contacts.rs`: the legs placed by",
        "inverse kinematics with the base moving (the Go1's by Newton's method), the",
        "five-bar by projection; `A q̈ = b`",
        "checked to 1e-12 at every state). Our `q̈` is turned into Pinocchio's free-flyer",
        "acceleration (the base's spatial acceleration in its own axes) and our `λ` (the",
        "force on each foot, world axes, `Q_c = Aᵀλ`) compared with `lambda_c`. Each peer",
        "ran with the smallest damping `mu` (0, then 1e-14, 1e-12, …) whose answers agree",
        "with ours (to 1e-12; `lcaba` to 1e-8, as close as it comes at any damping; the",
        "G1 on three points of each foot as its subsection below says), and",
        "was timed only then. The Go1's derivatives: our",
        "`acceleration_and_multiplier_jacobians` (by `q` and `q̇`, the quaternion's four coordinates and",
        "rates) are turned into Pinocchio's (a displacement `q ⊕ δ` with the base's",
        "velocity in its own axes held; `benches/peers/robots/src/go1_derivatives.rs`),",
        "checked against central differences of our `q̈` and `λ` so turned (to 1e-6), and",
        "compared with `computeConstraintDynamicsDerivatives`; the conversion is not",
        "timed, and the timed calls write into outputs the harness keeps from call to",
        "call (`acceleration_and_multiplier_jacobians_to`), as Pinocchio keeps its `Data`:",
        "",
    ] + notes + [
        "",
        "Times are per state (the median of 31 batches over the 20 states), both sides",
        "pinned to one core, in 5 alternating rounds (ours, then Pinocchio's), each a",
        "fresh copy of each side's program (as the Robots rows' are); the",
        "ratio is the median of the rounds' ratios (their range in brackets). Unlike the",
        "other peers' rows these are the thread's CPU time (`CLOCK_THREAD_CPUTIME_ID` on",
        "both sides): on the shared machine the wall time of the same call moved 10×",
        "between rounds.",
        "",
        "| system | what | ours | Pinocchio | Pinocchio / ours |",
        "|---|---|---|---|---|",
    ] + table + profile + icache(load_icache()) + redundant(rows, ns)


ICACHE_NAMES = {"quadruped": "quadruped", "go1": "Unitree Go1 from its URDF", "five_bar": "five-bar loop",
                "g1_points": "G1 on three points of each foot", "g1_flat": "G1 on two flat feet", "panda": "Panda (fixed base, Robots table)",
                "ur5": "UR5 (fixed base)", "talos": "TALOS (fixed base)", "xarm7": "xArm7 (fixed base)",
                "kinova": "Kinova Jaco 2 (fixed base)", "g1_arms_locked": "G1, arms locked (fixed base)",
                "g1": "G1, 29 joints (fixed base)"}
# The Kinematics table's robots (`kinematics spin`), where a name differs.
ICACHE_KINEMATICS_NAMES = {"panda": "Panda (Kinematics table)", "g1": "G1, 29 joints (fixed base)",
                           "go1": "Go1, 12 joints (fixed trunk)"}
# The Go1's Jacobians, `contacts spin go1 jacobians`, by the method's name.
ICACHE_CALLS = {"jacobians": "acceleration_and_multiplier_jacobians_to"}


def load_icache(name="icache.json"):
    """The lines of `benchmarks/icache.json` (benches/peers/icache.sh), or []."""
    import report

    path = Path(report.TARGET) / "benchmarks" / name
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.startswith("{")]


def icache(rows):
    """The instruction-cache table: per call, instructions, the code run and L1i misses."""
    if not rows:
        return []
    r = rows[0]
    out = [
        "",
        "### Instruction cache, per call",
        "",
        "`bash benches/peers/icache.sh`: cachegrind on `contacts spin SYSTEM WHAT PASSES` and, for",
        "the Robots and Kinematics tables' robots, `constrained-robots` and `kinematics spin ROBOT",
        "WHAT PASSES` (the states, then only calls), each figure the difference of a run with calls and",
        "one without. The code run is the distinct lines of code the calls touch that the",
        "states' set-up did not (a 1 MiB L1i, where only first touches miss: a lower",
        f"bound); the misses are this machine's L1i's ({r['i1_bytes'] // 1024} KiB, {r['i1_ways']}-way, "
        f"{r['line']}-byte lines, from sysfs),",
        "over 1,000 calls. Where the code run is larger than the L1i, every line of it",
        "misses at every call. Cachegrind counts every byte a `rep movsb` copies or `rep stosb`",
        "clears as an instruction: a call that returns large matrices by value (the",
        "derivatives) shows their copies among its instructions.",
        "",
        "| system | call | instructions | code run | L1i misses |",
        "|---|---|---|---|---|",
    ]
    for r in rows:
        kb = r["lines"] * r["line"] / 1024
        names = ICACHE_KINEMATICS_NAMES if r.get("binary") == "kinematics" else ICACHE_NAMES
        what = ICACHE_CALLS.get(r["what"], r["what"])
        out.append(f"| {names.get(r['system'], r['system'])} | `{what}` | {r['instructions']:,.0f} | "
                   f"{kb:.1f} KiB ({r['lines']:,} lines) | {r['i1_misses']:,.0f} |")
    return out


def redundant(rows, ns):
    """The G1 on three points of each foot: our three ways to `q̈` (and `λ`)."""
    system, _ = REDUNDANT
    mine = {what: rows.get(("constrained", what, system), []) for what, _ in REDUNDANT_WAYS}
    if not all(mine.values()):
        return []
    worst = max(r.get("worst", 0.0) for r in mine["acceleration"])
    residual = max(r.get("residual", 0.0) for r in mine["acceleration"])
    dense = max(r.get("dense", 0.0) for r in mine["acceleration"])
    peer = rows.get(("pinocchio", "constraintDynamics", system), [])
    agreement = []
    if peer:
        p = peer[0]
        agreement = [
            "Pinocchio's `constraintDynamics` (the table above) never reaches its accuracy on",
            "these rows: at every damping its proximal loop stops at its cap, and its `λ`",
            "drifts along the rows' null space as it iterates. The first setting whose",
            "answers agree with ours to 1e-12 (`q̈`) and 1e-7 (`λ`) is timed: mu",
            f"{p['mu']:.0e}, at most {p.get('max_iter', 100)} iterations, `q̈` within {p['difference']:.1e} of ours "
            f"and `λ` within {p['lambda_difference']:.1e}.",
        ]
    out = [
        "",
        "### Redundant contacts: the G1 on three points of each foot",
        "",
        "The Unitree G1 of example-robot-data's `g1_29dof_rev_1_0.urdf` (29 joints) on a",
        "`floating` root joint, unpowered, each foot held at three of the points its file",
        "gives as contact spheres (`benches/peers/robots/src/g1_standing.rs`): 36",
        "coordinates and 19 rows (the six points' 18 and the quaternion's norm) of rank 13,",
        "so six rows are dependent and `λ` is not unique: the minimum-norm one is",
        "returned. Each foot's three points are not on one line, so they fix it: the solve",
        "takes the foot's own six rows (its first point's and its angular acceleration),",
        "decided at compile time, in the velocity form's saddle-point solve, and each point's",
        "`λ` is the least that exerts the foot's wrench, through compile-time constants",
        "(docs/math.md, \"A body held at three or more points\"). The third row is the",
        "runtime's SVD of `A` from the solve's force instead, timed in the same run (the",
        "second row's ratio is the median of 31 back-to-back pairs of batches, `q̈` then `q̈`",
        "and `λ`, and of the rounds). At 20 states (the base turned and",
        "moving, the joints within ±0.3 rad, the rates on the rows' null space) each `λ`",
        f"agrees with the SVD's to {worst:.1e} (relative to the largest entry; checked to",
        f"1e-10), `A q̈ = b` holds to {residual:.1e} (relative, as above; checked to 1e-12)",
        f"and `q̈` is within {dense:.1e} of the runtime's dense Moore–Penrose solve (an SVD,",
        "which satisfies every row to rounding; checked to 1e-12).",
    ] + agreement + [
        "",
        "| how | ours | / own `q̈` |",
        "|---|---|---|",
    ]
    for what, name in REDUNDANT_WAYS:
        t = _median([r["ns"] for r in mine[what]])
        r = own_ratios(rows, system, what)
        ratio = f"{_median(r):.2f}× ({min(r):.2f}–{max(r):.2f})" if r else "–"
        out.append(f"| {name} | {ns(t)} | {ratio} |")
    return out


HEADING = "## Contacts and loops: the quadruped, the Go1 and the five-bar, against Pinocchio"
TARGET_PREFIX = "Contacts: "


def machine():
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return f"{line.split(':', 1)[1].strip()}, {os.cpu_count()} cores"
    return "unknown CPU"


def replace_section(path, heading, lines, new_targets, prefix, provenance):
    """Rewrites the section `heading` of `path` (BENCHMARKS.md) with `lines`
    (as a `section` returns them, `provenance` inserted after the heading)
    and the targets' rows whose names start with `prefix` with
    `new_targets`, leaving the rest as the last full run wrote it."""
    text = path.read_text()
    lines[3:3] = provenance + [""]
    body = "\n".join(lines[1:]) + "\n"
    start = text.find(heading)
    if start >= 0:
        end = text.find("\n## ", start + len(heading))
        text = text[:start] + body + (text[end:] if end >= 0 else "")
    else:
        at = text.find("\n## Contacts and loops")
        at = at + 1 if at >= 0 and heading != HEADING else len(text)
        text = text[:at] + body + "\n" + text[at:]
    kept = [line for line in text.split("\n") if not line.startswith(f"| {prefix}")]
    end = next(i for i, line in enumerate(kept) if line.startswith("## Targets"))
    end = next(i for i in range(end + 4, len(kept)) if not kept[i].startswith("|"))
    new = [f"| {name} | {fmt.format(value)} | {wanted} | {'✓' if check(value) else '✗'} |"
           for name, value, wanted, check, fmt in new_targets]
    path.write_text("\n".join(kept[:end] + new + kept[end:]))


def splice_report(path, lines, new_targets, when, report):
    """Rewrites the section `report` (its `HEADING`, `TARGET_PREFIX`, `JSON` and
    script `NAME`) and its targets' rows of `path` (BENCHMARKS.md)."""
    if not lines:
        sys.exit(f"no {report.JSON}: run benches/peers/run.sh")
    provenance = [f"From the peers' run of {when} on {machine()} (this section alone:",
                  f"`python3 benches/{report.NAME}`)."]
    replace_section(path, report.HEADING, lines, new_targets, report.TARGET_PREFIX, provenance)


def ratio_row(name, what, mine, peer, r, worst, ns):
    """A table row of ours against a peer: both times (medians of the rounds),
    the peer's / ours (median and range of the rounds' ratios) and the worst
    difference; `disagreed` where the peer timed nothing."""
    ours_ns = _median([x["ns"] for x in mine])
    if not r:
        return f"| {name} | {what} | {ns(ours_ns)} | disagreed | – | {worst:.1e} |"
    theirs_ns = _median([x["ns"] for x in peer if x["ok"] and x["ns"]])
    return (f"| {name} | {what} | {ns(ours_ns)} | {ns(theirs_ns)} | "
            f"{_median(r):.2f}× ({min(r):.2f}–{max(r):.2f}) | {worst:.1e} |")


def run_alone(module, what):
    """A report module run alone (`python3 benches/<its NAME>`): rewrites its
    section (`section`) and targets' rows (`targets`) of BENCHMARKS.md from
    the last run of the peers (its `JSON`, by `load`), dated by that file."""
    from datetime import datetime, timezone

    import report

    run = report.TARGET / "benchmarks" / module.JSON
    when = datetime.fromtimestamp(run.stat().st_mtime, timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    rows = module.load(report.TARGET)
    splice_report(report.ROOT / "BENCHMARKS.md", module.section(rows, report.ns), module.targets(rows), when, module)
    print(f"wrote the {what} section of {report.ROOT / 'BENCHMARKS.md'}")


JSON, NAME = "contacts.json", "report_contacts.py"


if __name__ == "__main__":
    run_alone(sys.modules[__name__], "contacts")
