"""Writes BENCHMARKS.md from one run of scripts/benchmarks.sh: criterion's
estimates (<target>/criterion), the lambdify timings and the expansion sizes
(<target>/benchmarks). Checks the performance targets and reports each ratio.
Standard library only."""

import json
import os
import platform
import subprocess
import sys
from datetime import datetime, timezone
from pathlib import Path

import report_build
import report_casadi
import report_contacts
import report_growth
import report_kinematics
import report_urdf_sweep

ROOT = Path(__file__).resolve().parents[1]
# Cargo's target directory (scripts/benchmarks.sh passes it: CARGO_TARGET_DIR
# when set).
TARGET = Path(os.environ.get("CONSTRAINED_TARGET_DIR", ROOT / "target"))
CRITERION = TARGET / "criterion"
STATES = 12  # Appell benches evaluate all shared states per iteration
XY_STATES = 1024  # the h = x·y + sin t group evaluates this many per iteration


def criterion_means():
    """full_id → mean time in ns, from every benchmark of the last run."""
    means = {}
    for bench in CRITERION.rglob("new/benchmark.json"):
        info = json.loads(bench.read_text())
        estimates = json.loads((bench.parent / "estimates.json").read_text())
        means[info["full_id"]] = estimates["mean"]["point_estimate"]
    return means


ROUNDS = 5  # paired rounds of each Appell comparison (benches/acceleration.rs)


def median(values):
    ordered = sorted(values)
    middle = len(ordered) // 2
    return ordered[middle] if len(ordered) % 2 else (ordered[middle - 1] + ordered[middle]) / 2


def paired(means, group):
    """The rounds of `group`'s generated/hand-written pair: each one's median
    time over the rounds, and the median and range of the rounds' ratios
    (generated / by hand). None when the group did not run."""
    rounds = [(means.get(f"{group}/generated/{r}"), means.get(f"{group}/hand_written_eq32/{r}"))
              for r in range(1, ROUNDS + 1)]
    if any(g is None or h is None for g, h in rounds):
        return None
    ratios = [g / h for g, h in rounds]
    return {
        "generated": median([g for g, _ in rounds]),
        "hand_written_eq32": median([h for _, h in rounds]),
        "ratio": median(ratios),
        "range": (min(ratios), max(ratios)),
    }


def ns(value):
    if value >= 1e6:
        return f"{value / 1e6:.2f} ms"
    if value >= 1e3:
        return f"{value / 1e3:.2f} µs"
    return f"{value:.2f} ns" if value < 100 else f"{value:.0f} ns"


def peers():
    """(peer, what, system, n) → the peer program's JSON result, from
    benches/peers/run.sh (absent when the peers were not run)."""
    path = TARGET / "benchmarks" / "peers.json"
    if not path.exists():
        return {}
    rows = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    return {(r["peer"], r["what"], r["system"], r["n"]): r for r in rows}


def machine():
    cpu = "unknown CPU"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    rustc = subprocess.run(["rustc", "--version"], capture_output=True, text=True).stdout.strip()
    return f"{cpu}, {os.cpu_count()} cores, {platform.system()}; {rustc}"


def peer_sections(peer, timed, chain, rk4, get, mq):
    """The side-by-side tables against Pinocchio and MuJoCo."""
    links = [1, 2, 4, 8, 16, 32]
    agree = max((r["difference"] for r in peer.values() if r["ok"] and r["system"] == "chain"), default=float("nan"))
    failed = [f"{r['peer']} {r['what']} ({r['system']}, N = {r['n']}: {r['difference']:.1e})"
              for r in peer.values() if not r["ok"]]
    ratio = lambda theirs, ours: f"{theirs / ours:.0f}×" if theirs and ours else "–"  # noqa: E731
    show = lambda v: ns(v) if v else "–"  # noqa: E731
    lines = [
        "",
        "## Against Pinocchio and MuJoCo",
        "",
        "Pinocchio 4.1 (C++) and MuJoCo 4.0 (C), compiled against the headers and",
        "libraries of their Python wheels by `benches/peers/run.sh` (`-O3`, no",
        "`-march=native`, like the Rust side), on the same systems and states, pinned",
        "to one core like the criterion runs. Each peer's answer is checked against the",
        "generated code's before it is timed; a disagreeing answer gets no time. Peer",
        "times are the median of 31 batches of about 5 ms; ours are criterion means.",
        f"On the chains every peer answer agreed to {agree:.1e} (MuJoCo needs a small",
        "positive inertia, 1e-12, on each point mass; that is most of its difference).",
        "",
    ]
    if failed:
        lines += ["**Answers that disagreed (not timed):** " + "; ".join(failed), ""]
    lines += [
        "### Planar N-link chain: one q̈",
        "",
        "Ours in Cartesian coordinates (2N coordinates, N constraints, generalized",
        "inverse); the peers in joint angles (N revolute joints, no constraints):",
        "Pinocchio's articulated-body algorithm `aba`, MuJoCo's `mj_forward` (its",
        "whole pipeline, which is what a user calls for q̈).",
        "",
        "| N | ours | Pinocchio `aba` | MuJoCo `mj_forward` | `aba` / ours | `mj_forward` / ours |",
        "|---|---|---|---|---|---|",
    ]
    for n in links:
        a, p, j = chain[n], timed(("pinocchio", "aba", "chain", n)), timed(("mujoco", "mj_forward", "chain", n))
        lines.append(f"| {n} | {show(a)} | {show(p)} | {show(j)} | {ratio(p, a)} | {ratio(j, a)} |")
    angles8 = mq.get("pendulum_angles_8/acceleration")
    p8 = timed(("pinocchio", "aba", "chain", 8))
    if angles8 and p8:
        lines += [
            "",
            f"In joint angles, as the peers see it (`PendulumAngles8`, dense M(q) from the energies,",
            f"no constraints), ours takes {ns(angles8)} at N = 8: {angles8 / p8:.2f}× Pinocchio's `aba`. The",
            "generated code solves a dense 8 × 8 `M(q)` (O(N³), with every entry's trigonometry",
            "expanded) where `aba` is O(N).",
        ]
    baumgarte = {n: get(f"chain_rk4_step_baumgarte/{n}") for n in links}
    projection = {n: get(f"chain_rk4_step_projection/{n}") for n in links}
    lines += [
        "",
        "### Planar N-link chain: one RK4 step (h = 1 ms)",
        "",
        "Ours plain, with Baumgarte's correction (rate 10/s) and with projection onto",
        "the constraints to 1e-12 after the step; MuJoCo's `mj_step` with its RK4",
        "integrator (joint angles: its joint constraints hold exactly, ours drift without",
        "stabilization). MuJoCo's step agreed with ours to the digits RK4 leaves.",
        "",
        "| N | ours plain | ours Baumgarte | ours projection | MuJoCo `mj_step` RK4 | `mj_step` / ours (plain, Baumgarte, projection) |",
        "|---|---|---|---|---|---|",
    ]
    for n in links:
        j = timed(("mujoco", "mj_step_rk4", "chain", n))
        ours = (rk4[n], baumgarte[n], projection[n])
        ratios = ", ".join(ratio(j, o) for o in ours)
        lines.append(f"| {n} | {show(ours[0])} | {show(ours[1])} | {show(ours[2])} | {show(j)} | {ratios} |")
    fb_cart, fb_angles = get("models/four_bar_cartesian/acceleration"), mq.get("four_bar_angles/acceleration")
    lines += [
        "",
        "### Parallelogram four-bar (closed loop, 1 degree of freedom): one q̈",
        "",
        "Ours in body coordinates (9 coordinates, 8 constraints, constant M) and in link",
        "angles (3 coordinates, 2 constraints, M(q)); the peers on a tree of 3 revolute",
        "joints with a point constraint closing the loop: Pinocchio's `constraintDynamics`",
        "(proximal KKT, damping 1e-10) and `lcaba` (loop-constrained ABA, damping 1e-6),",
        "MuJoCo's `mj_forward` with an `equality/connect` as stiff as it allows.",
        "",
        "| implementation | time | / ours in body coordinates | / ours in link angles | answer vs ours |",
        "|---|---|---|---|---|",
        f"| ours, body coordinates | {show(fb_cart)} | 1× | – | – |",
        f"| ours, link angles, M(q) | {show(fb_angles)} | – | 1× | – |",
    ]
    for who, what, label in (("pinocchio", "constraintDynamics", "Pinocchio `constraintDynamics`"),
                             ("pinocchio", "lcaba", "Pinocchio `lcaba`"),
                             ("mujoco", "mj_forward", "MuJoCo `mj_forward`")):
        r = peer.get((who, what, "four_bar", 3))
        if r:
            t = r["ns"] if r["ok"] else None
            lines.append(f"| {label} | {show(t)} | {ratio(t, fb_cart)} | {ratio(t, fb_angles)} | {r['difference']:.1e} |")
    lines += [
        "",
        "MuJoCo's four-bar answer is checked at rest: its constraints are soft (it leaves",
        "about 2e-4 of the exact q̈ at the stiffest `solimp`) and it drops the `J̇ q̇` term.",
        "",
        "### What makes the comparison unfair",
        "",
        "- **For us:** the generated code is specialised at compile time to one planar",
        "  model: no joint-type dispatch, 2-D kinematics only, sparsity and constant",
        "  masses folded in. Pinocchio and MuJoCo are general 3-D engines that read their",
        "  model at run time: 6-D spatial algebra, a variant per joint, every quantity in",
        "  3-D. `mj_forward` runs MuJoCo's whole pipeline (kinematics, inertia, collision",
        "  detection with nothing to collide, the constraint solver, actuation, sensors);",
        "  `mj_step` adds four of those per RK4 step.",
        "- **For them:** in joint angles the peers solve N unknowns where our Cartesian",
        "  chain solves 2N plus N multipliers, and their joint constraints hold exactly,",
        "  while the Cartesian chain drifts unless stabilized (the Baumgarte and",
        "  projection columns are the honest comparison for long runs). MuJoCo's soft",
        "  constraints buy robustness (contacts, redundancy) that exact constraints do not",
        "  have. Pinocchio also computes quantities (spatial forces, frame placements)",
        "  that a user may want and our q̈ does not give.",
        "- **Neither:** both sides are compiled for generic x86-64 at full optimisation;",
        "  the peers' times are medians of a C loop, ours criterion means, so ratios within",
        "  10 % should not be read closely.",
    ]
    return lines


# The robots of benches/peers/robots/build.rs's table: (system, label, the
# speed targets the issues name (ours → wanted Pinocchio / ours), whether
# agreement to 1e-12 is a target of its own). Issue 26 set the Panda's and
# the UR5's speed; issue 47 the G1's `mass_matrix` with its arms locked and
# the agreement of the robots read as users bring them; issue 48 the whole
# G1's and TALOS's.
ISSUE_26 = {"acceleration": 3, "mass_matrix": 2, "inverse_dynamics": 3}
ISSUE_48 = {"acceleration": 4, "mass_matrix": 3, "inverse_dynamics": 4}
ROBOTS = (
    ("panda", "Panda (7 joints, fingers locked)", ISSUE_26, False),
    ("ur5", "UR5 (6 joints)", ISSUE_26, False),
    ("talos", "TALOS (`talos_reduced`, 32 joints)", ISSUE_48, True),
    ("xarm7", "xArm7 (7 joints)", {}, True),
    ("kinova", "Kinova Jaco 2 j2s6s200 (6 joints)", {}, True),
    ("g1_arms_locked", "G1, 14 arm joints locked (15 joints)", {"mass_matrix": 3}, False),
    ("g1", "G1 (29 joints)", ISSUE_48, False),
    ("icub", "iCub (`icub_reduced`, 29 joints)", {}, True),
    ("panda_mimic", "Panda, finger `<mimic>` (8 joints)", {}, False),
)
ROBOT_PAIRS = (("acceleration", "aba", "q̈"), ("mass_matrix", "crba", "M(q)"),
               ("inverse_dynamics", "rnea", "inverse dynamics"))
# A model with mimic joints: `aba` refuses it, so its q̈ is compared with
# the solution of `crba` q̈ = τ − `rnea`(q, v, 0), and nothing is timed.
MIMIC_PAIRS = (("acceleration", "crba_solve", "q̈"), ("mass_matrix", "crba", "M(q)"),
               ("inverse_dynamics", "rnea", "inverse dynamics"))
AGREEMENT = 1e-12


def robot_ratios(rows, system, ours, theirs):
    """The rounds' ratios Pinocchio / ours, paired by round."""
    return report_contacts.ratios(rows, system, ours, theirs)


def robot_difference(rows, system):
    """The worst relative difference of Pinocchio's answers from ours over
    every round (q̈, M and τ), or None if the robot did not run."""
    peer = [r for (who, _, name), rs in rows.items() if who == "pinocchio" and name == system for r in rs]
    return max(r["difference"] for r in peer) if peer else None


def robot_targets(rows):
    """Issue 26's and issue 47's targets against Pinocchio on the robots
    read from URDF."""
    targets = []
    for system, _, speed, agreement in ROBOTS:
        for ours, theirs, label in ROBOT_PAIRS:
            wanted = speed.get(ours)
            r = robot_ratios(rows, system, ours, theirs) if wanted else None
            if r:
                targets.append(report_contacts.at_least(
                    f"Robots: {system} {label} ≥ {wanted} × faster than Pinocchio's `{theirs}` "
                    f"(median of {len(r)} alternating rounds)", r, wanted))
        worst = robot_difference(rows, system) if agreement else None
        if worst is not None:
            targets.append(report_contacts.agrees(
                f"Robots: {system} from URDF as written agrees with Pinocchio (worst relative "
                "difference of q̈, M, τ)", worst, AGREEMENT))
    return targets


def robot_section(rows):
    """The Robots table: robots read from example-robot-data's URDFs as
    written, the generated code against Pinocchio on the same files."""
    table = []
    for system, name, _, _ in ROBOTS:
        mimic = any(who == "pinocchio" and what == "crba_solve" and s == system for who, what, s in rows)
        for ours, theirs, label in MIMIC_PAIRS if mimic else ROBOT_PAIRS:
            mine, peer = rows.get(("constrained", ours, system), []), rows.get(("pinocchio", theirs, system), [])
            if not peer:
                continue
            worst = max(x["difference"] for x in peer)
            if mimic:
                against = "`crba` q̈ = τ − `rnea`(q, v, 0)" if theirs == "crba_solve" else f"`{theirs}`"
                table.append(f"| {name} | {label}: `{ours}` / {against} (answers only) | – | – | – | {worst:.1e} |")
                continue
            if not mine:
                continue
            r = robot_ratios(rows, system, ours, theirs)
            table.append(report_contacts.ratio_row(name, f"{label}: `{ours}` / `{theirs}`", mine, peer, r, worst, ns))
    if not table:
        return []
    return [
        "",
        "## Robots from URDF as written, against Pinocchio",
        "",
        "Both sides read the same files of the `example-robot-data` wheel, as written, with a",
        "fixed base: ours with `urdf:` in `constrained_system!` (`benches/peers/robots`,",
        "release build for plain x86-64; its `build.rs` holds the table of robots and",
        "writes each with `dispatch: [avx]`, so that its large methods run as AVX code where",
        "the CPU has it, a copy chosen at run time that Pinocchio's wheel does not have), Pinocchio with",
        "`urdf::buildModel` without a root joint and `buildReducedModel` for locked joints",
        "(`benches/peers/robots.cpp`). The files: `panda_description/urdf/panda.urdf` (the",
        "two finger joints locked; and again with no lock, the second finger following the",
        "first by its `<mimic>`, against `buildModel(.., mimic=true)`),",
        "`ur_description/urdf/ur5_robot.urdf` (its `1.57079632679` read as that angle, not π/2,",
        "on both sides), `talos_data/robots/talos_reduced.urdf`",
        "(nothing locked: its grippers' `<mimic>` joints are fixed joints, so each gripper",
        "is one revolute joint on both sides), `xarm_description/urdf/xarm7.urdf`,",
        "`kinova_description/robots/kinova.urdf` (the Jaco 2 j2s6s200; its three",
        "`continuous` joints are one angle on our side, (cos, sin) in Pinocchio's q) and",
        "`g1_description/urdf/g1_29dof_rev_1_0.urdf` (whole, and with its 14 shoulder,",
        "elbow and wrist joints locked at 0; its `floating_base_joint` is commented out in",
        "the file, so as written the pelvis is fixed on both sides) and",
        "`icub_description/robots/icub_reduced.urdf` (every frame turned by `1.5708`, not",
        "π/2, and axes with `6e-17` leftovers, read as written on both sides: no placement",
        "is sparse, and our `M` is formed in world axes, as `crba` forms it). Before timing,",
        "Pinocchio's model is matched to ours by joint NAME (each of our `COORDINATES` a",
        "one-degree-of-freedom joint of Pinocchio's, and no other joint moving), and at 20",
        "pseudo-random states per robot its answers are checked against ours, in every",
        "round, relative to the largest entry (`crba` symmetrised), to within",
        f"{AGREEMENT:.0e}; the last column is the worst difference seen. `aba` refuses a model with mimic",
        "joints: there q̈ is compared with the solution of `crba` q̈ = τ − `rnea`(q, v, 0),",
        "and nothing is timed. Times are per state, the median of 31 batches over the 20",
        "states, the same loop on both sides, pinned to one core, on the thread's CPU",
        "clock (`CLOCK_THREAD_CPUTIME_ID`), in 5 alternating rounds (ours, then",
        "Pinocchio's), each side's program a fresh copy in each round (a new file's",
        "pages: where the code outgrows the L1 instruction cache, identical copies of",
        "one binary differ by up to a fifth); each side's time is the median of its",
        "rounds, the ratio the median of the rounds' ratios (their range in brackets).",
        "`crba` computes the upper",
        "triangle only; our `mass_matrix` returns the full matrix.",
        "",
        "| robot | what | ours | Pinocchio | Pinocchio / ours | worst relative difference |",
        "|---|---|---|---|---|---|",
    ] + table


def op_count_section():
    """The generated accelerations' operation counts against sympy's cse
    (tests/sympy/test_op_counts.py writes them)."""
    path = TARGET / "benchmarks" / "op_counts.json"
    if not path.exists():
        return []
    counts = json.loads(path.read_text())
    lines = [
        "",
        "## Operations per `acceleration`, against sympy's common-subexpression elimination",
        "",
        "The arithmetic of each generated `acceleration` (`op_count::acceleration` on",
        "the expansion: `+ − × ÷`, negations and elementary functions, only what `q̈`",
        "reads), against sympy's `cse` + `count_ops` of the same q̈ derived by sympy",
        "from the model's M, F and constraints (`a = M⁻¹F`, `q̈ = a + M⁻¹Aᵀ(AM⁻¹Aᵀ)⁻¹(b − Aa)`",
        "by LU), with and without `optimizations=\"basic\"`. Models whose solve calls the",
        "runtime (a singular `M`) have no straight-line count. sympy is given the rows",
        "of `A q̈ = b` that stay independent at a consistent state; for the two models",
        "with a redundant constraint the last column also counts sympy's solve over",
        "every row, which is the solve the generated code performs before its run-time",
        "rank decision drops the redundant row (sympy cannot take that decision: on the",
        "surface its `S` is singular).",
        "",
        "| model | generated | sympy `cse` | sympy `cse`, basic | generated / best sympy | sympy `cse`, every row |",
        "|---|---|---|---|---|---|",
    ]
    for name in sorted(counts):
        c = counts[name]
        ours, plain, basic = c["generated"]["total"], c["sympy_cse"], c["sympy_cse_basic"]
        # `basic` is None where it was skipped (a large q̈ outside the
        # benchmark run: tests/sympy/test_op_counts.py, BASIC_UP_TO).
        best = plain if basic is None else min(plain, basic)
        mark = "" if ours <= best else " ✗"
        every = c.get("sympy_cse_all_rows")
        every = f"{every} ({ours / every:.2f})" if every else "—"
        shown = "—" if basic is None else basic
        lines.append(f"| {name} | {ours} | {plain} | {shown} | {ours / best:.2f}{mark} | {every} |")
    lines += [
        "",
        "Where the generated code needs more (✗), `tests/sympy/test_op_counts.py` names",
        "the reason and holds the ratio where it is. Both are redundant models: their",
        "fast path needs the redundant row of `S` and `r` to decide, at run time, that",
        "the row is redundant.",
    ]
    return lines


def egg_section():
    """egg's equality saturation against the rule-based factoring
    (scripts/egg_compare.sh writes the table)."""
    path = TARGET / "benchmarks" / "egg.md"
    if not path.exists():
        return []
    return [
        "",
        "## Factoring: rules against an e-graph",
        "",
        "Each reference model's raw `M`, `F`, `A` and `b` (lowered and differentiated,",
        "nothing factored) factored by `constrained_codegen::factor::Factorer`, as the",
        "macro does, and saturated by `egg` 0.10 (commutativity, associativity,",
        "distribution and factoring both ways, squares, signs; 30 iterations, 50,000",
        "e-nodes, 5 s) then extracted by the same cost: operations of the expression",
        "tree, as `count_ops` counts them (`benches/egg`, `scripts/egg_compare.sh`).",
        "",
        *path.read_text().strip().splitlines(),
    ]


EVENT_RUNS = (
    "dp45_double_pendulum_5s/plain", "dp45_double_pendulum_5s/untriggered",
    "dp45_double_pendulum_5s/untriggered_unscreened", "rk4_double_pendulum_1s/plain",
    "rk4_double_pendulum_1s/untriggered", "rk4_double_pendulum_1s/untriggered_unscreened",
    "rk4_chain32_0.1s/plain", "rk4_chain32_0.1s/untriggered", "rk4_chain32_0.1s/untriggered_unscreened",
)
EVENT_CASES = (("double pendulum, DP45, 5 s", "dp45_double_pendulum_5s"),
               ("double pendulum, RK4 h = 1 ms, 1 s", "rk4_double_pendulum_1s"),
               ("32-link chain, RK4 h = 1 ms, 0.1 s", "rk4_chain32_0.1s"))
EVENT_ROUNDS = 3  # rounds of benches/events.rs, the runs of a case alternating in each


def event_runs(means):
    """run → (median time over the rounds, median over the rounds of its
    ratio to the same round's run without events), or None when missing."""
    runs = {}
    for key in EVENT_RUNS:
        case = key.rsplit("/", 1)[0]
        rounds = range(1, EVENT_ROUNDS + 1)
        times = [means.get(f"events/{key}/{r}") for r in rounds]
        plains = [means.get(f"events/{case}/plain/{r}") for r in rounds]
        if any(t is None for t in times + plains):
            runs[key] = None
            continue
        runs[key] = (median(times), median([t / p for t, p in zip(times, plains)]))
    return runs


def events_section(events):
    """Event location (benches/events.rs): untriggered runs against plain
    ones, and the evaluations per crossing (<target>/benchmarks/events.json)."""
    if not all(events.values()):
        return []
    lines = [
        "",
        "## Event location (`benches/events.rs`)",
        "",
        "Whole runs with two event functions that never cross zero against the same",
        "runs without events: the same steps and evaluations of the system; what is",
        "added is the search of each step (the event closure at the step's end, and at",
        "`samples` interior points of its continuous extension, default 4, unless",
        "screening skips them: a step whose functions stay far from zero for the",
        "curvature of their values at the ends of the last two steps; `every grid` turns",
        "screening off, `with_screening(false)`) and the stepper's bookkeeping. A step with",
        "no crossing is searched where its data lie and not kept. Times are the medians of",
        f"{EVENT_ROUNDS} rounds in which the runs of a case alternate, ratios the medians of",
        "the rounds' ratios (the machine's load drifts between benchmarks).",
        "",
        "| run | without events | events (default) | / without | events, every grid | / without |",
        "|---|---|---|---|---|---|",
    ]
    for label, key in EVENT_CASES:
        (plain, _), (grid, grid_ratio) = events[f"{key}/plain"], events[f"{key}/untriggered"]
        ends = events.get(f"{key}/untriggered_unscreened")
        lines.append(f"| {label} | {ns(plain)} | {ns(grid)} | {grid_ratio:.2f}× | "
                     f"{ns(ends[0]) if ends else '–'} | {f'{ends[1]:.2f}×' if ends else '–'} |")
    path = TARGET / "benchmarks" / "events.json"
    if path.exists():
        counts = json.loads(path.read_text())
        b, u = counts["bounces"], counts["untriggered"]
        lines += [
            "",
            f"Evaluations per located crossing (a ball bouncing {b['crossings']} times, e = 0.8, DP45 at",
            "rtol 1e-10, default time tolerance 4 ε (|t| + h)): each is one evaluation of the",
            "step's continuous extension and one call of the event closure, none of the system.",
            "",
            "| crossings | root-finder iterations | per crossing | grid points | steps | evaluations of q̈ |",
            "|---|---|---|---|---|---|",
            f"| {b['crossings']} | {b['refinements']} | {b['refinements'] / b['crossings']:.1f} | "
            f"{b['samples']} | {b['steps']} | {b['evaluations']} |",
            "",
            f"The untriggered DP45 run: {u['steps']} steps, {u.get('screened', 0)} of them screened, "
            f"{u['samples']} grid points ({u['samples'] / u['steps']:.2f} per step), "
            f"{u['evaluations']} evaluations of q̈, as without events.",
        ]
    return lines


IMPACT_MODELS = (("pendulum on a wall, Cartesian", "pendulum_wall", "2, 1, 1"),
                 ("rimless wheel at heel strike", "rimless_wheel", "3, 2, 1"),
                 ("compass gait at heel strike, from energies", "compass_gait", "4, 2, 1"))


def impact_section(get):
    """The impact map per impact (benches/impact.rs)."""
    times = {key: get(f"impact/{key}") for _, key, _ in IMPACT_MODELS}
    if not all(times.values()):
        return []
    lines = [
        "",
        "## Impact maps (`benches/impact.rs`)",
        "",
        "One call of the generated `impact` at a contact: the model's `M(q)`, constraint",
        "rows and their velocity residual, the gaps' gradients, then the runtime's",
        "solve of the impulsive Gauss principle (`impact_with_gaps`). Each answer is",
        "checked against its closed form before it is timed (the rebound `−e ω`,",
        "McGeer's ratio, the angular momentum about the new foot).",
        "",
        "| model | coordinates, constraints, gaps | per impact |",
        "|---|---|---|",
    ]
    for label, key, shape in IMPACT_MODELS:
        lines.append(f"| {label} | {shape} | {ns(times[key])} |")
    return lines


def main():
    m = criterion_means()
    lam = json.loads((TARGET / "benchmarks" / "lambdify.json").read_text())
    sizes = json.loads((TARGET / "benchmarks" / "expansion.json").read_text())
    get = lambda key: m.get(key)  # noqa: E731

    pair = paired(m, "appell_acceleration_12_states")
    dynamic = get("appell_acceleration_12_states/dynamic_nalgebra_svd")
    if pair is None or dynamic is None:
        sys.exit("missing criterion results for appell_acceleration_12_states: run scripts/benchmarks.sh")
    per_call = {
        "generated": pair["generated"] / STATES,
        "hand_written_eq32": pair["hand_written_eq32"] / STATES,
        "dynamic_nalgebra_svd": dynamic / STATES,
    }
    generated = per_call["generated"]
    links = [1, 2, 4, 8, 16, 32]
    chain = {n: get(f"chain_acceleration/{n}") for n in links}
    chain_ga = {n: get(f"chain_acceleration_gibbs_appell/{n}") for n in links}
    rk4 = {n: get(f"chain_rk4_step/{n}") for n in links}
    expand = {n: get(f"expand_planar_chain/{n}") for n in links}
    size = {row["links"]: row for row in sizes}
    lagrange = json.loads((TARGET / "benchmarks" / "lagrange_sympy.json").read_text())
    pendulum_links = [2, 4, 8, 16]
    from_energies = {n: get(f"expand_joint_angle_pendulum/{n}") for n in pendulum_links}

    xy = paired(m, "appell_xy_sin_t_1024_states")
    targets = [
        ("Appell: generated ≤ 1.2 × hand-written eq. 32 (median of 5 paired rounds)", pair["ratio"], "≤ 1.2", lambda r: r <= 1.2, "{:.2f}×"),
        ("Appell: ≥ 20 × faster than dynamic nalgebra (SVD)", per_call["dynamic_nalgebra_svd"] / generated, "≥ 20", lambda r: r >= 20, "{:.0f}×"),
        ("Appell: ≥ 50 × faster than the fastest lambdify", lam["lambdify_math_cse"] / generated, "≥ 50", lambda r: r >= 50, "{:.0f}×"),
        ("Chain q̈: cost N = 32 / N = 4 ≤ 12 (dense ~128)", chain[32] / chain[4], "≤ 12", lambda r: r <= 12, "{:.1f}×"),
        ("Energies: N = 8 pendulum expands in < 0.1 s", from_energies[8] / 1e9, "< 0.1 s", lambda r: r < 0.1, "{:.3f} s"),
        ("Energies: N = 16 pendulum expands in < 2 s", from_energies[16] / 1e9, "< 2 s", lambda r: r < 2.0, "{:.3f} s"),
    ]
    if xy:
        targets.insert(1, ("Appell, h = x·y + sin t, 1024 states: generated ≤ 1.05 × hand-written eq. 32 (median of 5 paired rounds)",
                           xy["ratio"], "≤ 1.05", lambda r: r <= 1.05, "{:.2f}×"))
    rk4_projection = {n: get(f"chain_rk4_step_projection/{n}") for n in links}
    projection_alone = {n: get(f"chain_projection/{n}") for n in links}
    if rk4_projection[32] and rk4[32]:
        targets.append(("Projection: RK4 step with projection ≤ 2 × plain (N = 32)",
                        rk4_projection[32] / rk4[32], "≤ 2", lambda r: r <= 2, "{:.2f}×"))
    mq = {key: get(f"models/{key}") for key in (
        "four_bar_angles/acceleration", "four_bar_angles/gibbs_appell", "four_bar_angles/dense_kkt",
        "four_bar_cartesian/acceleration", "rolling_disk/acceleration", "rolling_disk/gibbs_appell",
        "rolling_disk/dense_kkt", "pendulum_angles_8/acceleration", "pendulum_angles_8/dense_kkt",
        "two_link_arm/acceleration")}
    if mq["four_bar_angles/acceleration"] and mq["rolling_disk/acceleration"]:
        targets += [
            ("M(q): four-bar in link angles ≤ 60 ns", mq["four_bar_angles/acceleration"], "≤ 60 ns", lambda r: r <= 60, "{:.1f} ns"),
            ("M(q): rolling disk ≤ 150 ns", mq["rolling_disk/acceleration"], "≤ 150 ns", lambda r: r <= 150, "{:.1f} ns"),
            ("M(q): rolling disk ≥ 3 × faster than a dense KKT solve",
             mq["rolling_disk/dense_kkt"] / mq["rolling_disk/acceleration"], "≥ 3", lambda r: r >= 3, "{:.1f}×"),
        ]
    peer = peers()
    timed = lambda key: peer[key]["ns"] if key in peer and peer[key]["ok"] else None  # noqa: E731
    pin8 = timed(("pinocchio", "aba", "chain", 8))
    if pin8 and mq["pendulum_angles_8/acceleration"]:
        targets.append(("M(q): 8-link pendulum in joint angles within 3 × Pinocchio's `aba`",
                        mq["pendulum_angles_8/acceleration"] / pin8, "≤ 3", lambda r: r <= 3, "{:.2f}×"))
    robots = report_contacts.load(TARGET, "robots.json")
    targets += robot_targets(robots)
    targets += report_casadi.targets(robots)
    kinematics = report_kinematics.load(TARGET)
    targets += report_kinematics.targets(kinematics)
    contacts = report_contacts.load(TARGET)
    targets += report_contacts.targets(contacts)
    targets += report_build.targets(report_build.load(TARGET))
    # Present where scripts/urdf_sweep.sh has been run.
    targets += report_growth.targets(report_growth.load(TARGET))
    jac = {(model, way): get(f"jacobian/{model}/{way}") for model in ("cart_pole", "chain_8", "chain_32")
           for way in ("acceleration", "generated", "central_differences", "dual_numbers")}
    if jac[("cart_pole", "generated")]:
        targets.append(("Jacobian: cart-pole ≤ 4 × one `acceleration`",
                        jac[("cart_pole", "generated")] / jac[("cart_pole", "acceleration")], "≤ 4", lambda r: r <= 4, "{:.1f}×"))
        for model in ("cart_pole", "chain_8", "chain_32"):
            targets.append((f"Jacobian: {model.replace('_', ' ')} ≥ 5 × faster than central differences",
                            jac[(model, "central_differences")] / jac[(model, "generated")], "≥ 5", lambda r: r >= 5, "{:.2f}×"))
    events = event_runs(m)
    for label, key in EVENT_CASES:
        if events[f"{key}/untriggered"]:
            targets.append((f"Events: a run with two events never triggered ≤ 1.1 × the run without ({label}; "
                            f"median of {EVENT_ROUNDS} paired rounds)",
                            events[f"{key}/untriggered"][1], "≤ 1.1", lambda r: r <= 1.1, "{:.2f}×"))
    lines = [
        "# Benchmarks",
        "",
        f"Produced by `bash scripts/benchmarks.sh` in one run on {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC,",
        f"{machine()}.",
        "Criterion means (Rust), `timeit` best of 7 (Python), same machine, same run.",
        "The machine is shared and noisy: ratios move by some percent between runs.",
        "The Rust benchmarks are built with every function and loop aligned to 64 bytes",
        "(`-C llvm-args=-align-all-functions=6 -C llvm-args=-align-loops=64`), so that",
        "a ratio does not depend on where the linker placed the two functions: without",
        "it, the same Appell comparison can read 0.82× in one build and 1.50× in the next.",
        "",
        "To reproduce: `bash scripts/benchmarks.sh` (pinned to one core; about half an",
        "hour, the peers' stage the longest while Pinocchio's C++ compiles). It needs",
        "`python3` with `venv` and `g++`: it uses the sympy suite's virtual environment,",
        "creates one for Pinocchio and MuJoCo (`benches/peers/`), compiles the peers",
        "against their wheels' headers, checks each answer against ours before timing it,",
        "and rewrites this file. Earlier runs are in the history of this file in git.",
        "The URDF sweep's section comes from `bash scripts/urdf_sweep.sh`, run before it",
        "(about six minutes; the same environment).",
        "",
        "## Targets",
        "",
        "| target | measured | wanted | met |",
        "|---|---|---|---|",
    ]
    all_met = True
    for name, value, wanted, check, fmt in targets:
        met = check(value)
        all_met &= met
        lines.append(f"| {name} | {fmt.format(value)} | {wanted} | {'✓' if met else '✗'} |")
    lines += [
        "",
        "## Appell's particle: one `acceleration` (eq. 32)",
        "",
        "Per call over the 12 states of `benches/data/appell_states.json`. The",
        "generated and hand-written functions are timed alternately in 5 rounds;",
        "their rows are the median round, the ratio the median of the rounds'",
        f"ratios (range {pair['range'][0]:.2f}–{pair['range'][1]:.2f}×).",
        "",
        "| implementation | time per call | time relative to generated |",
        "|---|---|---|",
    ]
    rows = [
        ("`constrained_system!` (generated)", generated),
        ("eq. 32 written by hand", per_call["hand_written_eq32"]),
        ("dynamic nalgebra: A, b into `DMatrix`, SVD pseudo-inverse", per_call["dynamic_nalgebra_svd"]),
        ("sympy `lambdify`, numpy", lam["lambdify_numpy"]),
        ("sympy `lambdify`, math module, `cse=True`", lam["lambdify_math_cse"]),
    ]
    for name, value in rows:
        lines.append(f"| {name} | {ns(value)} | {value / generated:.2f}× |")
    if xy:
        lines += [
            "",
            "With the time-dependent `h = x·y + sin t` (`AppellTimeDependent`), over 1024",
            "varied states (`benches/acceleration.rs`, `appell_xy`), `g` and `α` behind",
            "`black_box` on both sides so that neither is constant-folded, in 5 paired",
            f"rounds (generated / by hand: median {xy['ratio']:.3f}×, range "
            f"{xy['range'][0]:.3f}–{xy['range'][1]:.3f}×):",
            "",
            "| implementation | time per call | time relative to generated |",
            "|---|---|---|",
            f"| `constrained_system!` (generated) | {ns(xy['generated'] / XY_STATES)} | 1.00× |",
            f"| eq. 32 written by hand | {ns(xy['hand_written_eq32'] / XY_STATES)} | "
            f"{xy['hand_written_eq32'] / xy['generated']:.2f}× |",
        ]
    lines += op_count_section()
    lines += egg_section()
    lines += [
        "",
        "## Planar N-link chain (2N coordinates, N constraints)",
        "",
        "| N | q̈, generalized inverse | q̈, Gibbs–Appell | RK4 step | RK4 steps/s | `expand` | generated lines | solver lines |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for n in links:
        steps = 1e9 / rk4[n] if rk4[n] else float("nan")
        lines.append(
            f"| {n} | {ns(chain[n])} | {ns(chain_ga[n])} | {ns(rk4[n])} | {steps:,.0f} | {ns(expand[n])} | "
            f"{size[n]['lines']} | {size[n]['solver_lines']} |"
        )
    lines += [
        "",
        "The generalized-inverse q̈ and its solver grow about linearly in N (the",
        "factorization follows the chain's tridiagonal `A M⁻¹ Aᵀ`, eliminated from",
        "both ends). The Gibbs–Appell form builds a dense reduced system at every",
        "call: O(N³). The whole expansion grows quadratically only because",
        "`mass_matrix`, `constraint_matrices` and `SYMBOLIC` return dense n × n and",
        "k × n data.",
        "",
        "## Projection onto the constraints (`Stabilization::projection`)",
        "",
        "Newton steps through the generated factorizations of `acceleration` (`W S⁺ r`,",
        "O(N) for the chain). An RK4 step with projection to 1e-12 after it, from the",
        "same consistent state as the plain step; and the projection alone from a state",
        "knocked 1e-6 off the constraints in q and q̇ (several Newton steps each).",
        "(`benches/projection.rs`, a binary of its own.)",
        "",
        "| N | RK4 step | RK4 step + projection | ratio | projection from 1e-6 off |",
        "|---|---|---|---|---|",
    ]
    for n in links:
        plain, projected, alone = rk4[n], rk4_projection[n], projection_alone[n]
        if plain and projected and alone:
            lines.append(f"| {n} | {ns(plain)} | {ns(projected)} | {projected / plain:.2f}× | {ns(alone)} |")
    lines += [
        "",
        "## Lagrange's equations from energies: N-link pendulum in joint angles",
        "",
        "`kinetic_energy` and `potential_energy` of the planar N-link pendulum in",
        "joint angles (`fixtures::joint_angle_pendulum`: dense `M(q)`, O(N²)",
        "velocity products in `F`), expanded by the macro, against sympy's",
        "`LagrangesMethod` deriving M and F from the same T and V",
        f"(`benches/lagrange_sympy.py`, one run each, stopped after {lagrange['budget']:.0f} s).",
        "",
        "| N | macro expansion (all of it) | sympy LagrangesMethod (M and F only) | ratio |",
        "|---|---|---|---|",
    ]
    for n in pendulum_links:
        sympy_s = lagrange["seconds"].get(str(n))
        ours = from_energies[n]
        if sympy_s is None:
            lines.append(f"| {n} | {ns(ours)} | > {lagrange['budget']:.0f} s (not finished) | > {lagrange['budget'] * 1e9 / ours:,.0f}× |")
        else:
            lines.append(f"| {n} | {ns(ours)} | {sympy_s:.2f} s | {sympy_s * 1e9 / ours:,.0f}× |")
    lines += [
        "",
        "## Both equations of motion on the reference models",
        "",
        "| system | `acceleration` | `acceleration_gibbs_appell` |",
        "|---|---|---|",
    ]
    for system in ("appell", "double_pendulum", "redundant_double_pendulum", "chaplygin_sleigh", "two_link_arm"):
        a, b = get(f"models/{system}/acceleration"), get(f"models/{system}/gibbs_appell")
        if a and b:
            lines.append(f"| {system.replace('_', ' ')} | {ns(a)} | {ns(b)} |")
    if mq["four_bar_angles/acceleration"]:
        lines += [
            "",
            "## Configuration-dependent M(q)",
            "",
            "`M(q)` factored in generated code on its compile-time pattern (then `S = A M⁻¹ Aᵀ`",
            "as for a constant `M`), against a dense KKT solve `[[M, Aᵀ], [A, 0]]` by LU on",
            "the heap of the same generated `M`, `F`, `A`, `b`. Rows marked M(q).",
            "",
            "| system | coordinates, constraints | `acceleration` | `acceleration_gibbs_appell` | dense KKT | KKT / ours |",
            "|---|---|---|---|---|---|",
        ]
        for key, label, shape in (
            ("four_bar_angles", "four-bar in link angles, M(q)", "3, 2"),
            ("rolling_disk", "rolling disk, M(q)", "5, 2 (nonholonomic)"),
            ("pendulum_angles_8", "8-link pendulum in joint angles, M(q)", "8, 0"),
            ("two_link_arm", "two-link arm on a line, M(q)", "2, 1"),
            ("four_bar_cartesian", "four-bar in body coordinates, constant M", "9, 8"),
        ):
            acc = mq.get(f"{key}/acceleration") or get(f"models/{key}/acceleration")
            ga = get(f"models/{key}/gibbs_appell")
            kkt = mq.get(f"{key}/dense_kkt")
            ratio = f"{kkt / acc:.1f}×" if kkt and acc else "–"
            lines.append(f"| {label} | {shape} | {ns(acc) if acc else '–'} | {ns(ga) if ga else '–'} | {ns(kkt) if kkt else '–'} | {ratio} |")
    if jac[("cart_pole", "generated")]:
        lines += [
            "",
            "## The Jacobian of q̈ (`acceleration_jacobian`)",
            "",
            "Against central differences (2·2N evaluations of `acceleration`) and dual",
            "numbers (`num_dual::Dual64` through the same generated code, 2N evaluations),",
            "with one `acceleration` for scale. The tangent systems are solved through the",
            "generated factorizations of `acceleration`: the chains' `S` (sparse, each",
            "column's right-hand side straight-line over its nonzeros), the cart-pole's `M(q)`",
            "(its derivatives bound in the same body as `M`, `F`, `A`, `b`, so that its",
            "sine and cosine are computed once, and each column that is not identically",
            "zero solved straight-line). Central differences gain from inlining: the",
            "compiler shares `M(q)` between the evaluations at the same `q`.",
            "",
            "| model | `acceleration` | `acceleration_jacobian` | central differences | dual numbers |",
            "|---|---|---|---|---|",
        ]
        for model in ("cart_pole", "chain_8", "chain_32"):
            a, g_, c_, d_ = (jac[(model, w)] for w in ("acceleration", "generated", "central_differences", "dual_numbers"))
            lines.append(f"| {model.replace('_', ' ')} | {ns(a)} | {ns(g_)} ({g_ / a:.1f}×) | {ns(c_)} ({c_ / g_:.2f}× ours) | {ns(d_)} ({d_ / g_:.2f}× ours) |")
    lines += events_section(events)
    lines += impact_section(get)
    if peer:
        lines += peer_sections(peer, timed, chain, rk4, get, mq)
    lines += robot_section(robots)
    lines += report_casadi.section(robots, ns)
    # Present where scripts/urdf_sweep.sh has been run.
    lines += report_urdf_sweep.section(report_urdf_sweep.load(TARGET / "benchmarks" / "urdf_sweep.json"))
    lines += report_kinematics.section(kinematics, ns)
    lines += report_growth.section(report_growth.load(TARGET))
    lines += report_contacts.section(contacts, ns)
    lines += report_build.section(report_build.load(TARGET))
    lines.append("")
    (ROOT / "BENCHMARKS.md").write_text("\n".join(lines))
    print("\n".join(lines[7:14]))
    print(f"wrote {ROOT / 'BENCHMARKS.md'}")
    if not all_met:
        print("note: not every target is met on this run (see ✗ above)")


def splice_robots():
    """Rewrites the Robots section and the Robots rows of the targets in
    BENCHMARKS.md from the last run of the peers (`benches/peers/run.sh`),
    leaving the rest as the last full run wrote it."""
    from types import SimpleNamespace

    robots = SimpleNamespace(HEADING="## Robots from URDF as written, against Pinocchio", TARGET_PREFIX="Robots: ",
                             JSON="robots.json", NAME="report.py robots",
                             load=lambda target: report_contacts.load(target, "robots.json"),
                             section=lambda rows, _ns: robot_section(rows), targets=robot_targets)
    report_contacts.run_alone(robots, "Robots")

if __name__ == "__main__":
    if sys.argv[1:] == ["robots"]:
        splice_robots()
    else:
        main()
