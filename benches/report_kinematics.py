"""The Kinematics and derivatives section of BENCHMARKS.md and its targets
(issue 49): the Panda, the Unitree G1 and the Unitree Go1 read from
example-robot-data's URDFs with named frames, the generated placements,
frame Jacobians, classical accelerations, centre of mass, centroidal
momentum, ∂τ and ∂q̈ against Pinocchio's (benches/peers/run.sh writes <target>/benchmarks/kinematics.json:
our times and Pinocchio's, in alternating rounds, Pinocchio's lines with its
agreement with ours). Standard library only.

Run alone (`python3 benches/report_kinematics.py`), it rewrites this section
and its targets' rows in BENCHMARKS.md from the last run of the peers,
leaving the rest of the file as the last full run wrote it."""

import sys

import report_contacts

# (system, label, the targets of issue 49 by quantity: Pinocchio / ours ≥).
SYSTEMS = (
    ("panda", "Panda (7 joints, fingers locked), `tool` on `panda_hand`",
     {"frame_jacobian": 3, "center_of_mass_and_jacobian": 3, "centroidal_map": 3,
      "inverse_dynamics_jacobian": 3, "acceleration_jacobian": 3}),
    ("g1", "G1 (29 joints, fixed base), `left_sole` on `left_ankle_roll_link`",
     {"frame_jacobian": 3, "center_of_mass_and_jacobian": 3, "centroidal_map": 3,
      "inverse_dynamics_jacobian": 3, "acceleration_jacobian": 3}),
    ("go1", "Go1 (12 joints, fixed trunk), `fl_sole` on `FL_foot`",
     {"frame_jacobian": 3, "center_of_mass_and_jacobian": 3, "centroidal_map": 3}),
)
# A row: Pinocchio's line (the JSON's `what`), our method it is timed
# against (ours' `what`; the same name but for a second counterpart of one
# of ours) and what it is.
QUANTITIES = (
    ("frame_placement", "frame_placement", "placement `(R, p)`"),
    ("frame_jacobian", "frame_jacobian", "frame Jacobian (6 × n)"),
    ("frame_velocity", "frame_velocity", "frame velocity `J q̇`"),
    ("frame_acceleration_bias", "frame_acceleration_bias", "acceleration bias `J̇ q̇`"),
    ("center_of_mass_and_jacobian", "center_of_mass_and_jacobian", "centre of mass and its Jacobian"),
    ("center_of_mass_velocity", "center_of_mass_velocity", "centre of mass velocity `ċ`"),
    ("centroidal_map", "centroidal_map", "centroidal map `A_G` (6 × n)"),
    ("centroidal_map_bias", "centroidal_map_bias", "centroidal bias `Ȧ_G q̇`"),
    ("centroidal_momentum_time_variation", "centroidal_map_bias", "centroidal bias `Ȧ_G q̇`"),
    ("inverse_dynamics_jacobian", "inverse_dynamics_jacobian", "`∂τ/∂q`, `∂τ/∂q̇`"),
    ("acceleration_jacobian", "acceleration_jacobian", "`∂q̈/∂q`, `∂q̈/∂q̇`, `∂q̈/∂τ`"),
)
AGREEMENT = 1e-12
HEADING = ("## Kinematics and derivatives: frames, centre of mass, centroidal momentum, ∂τ and ∂q̈, "
           "against Pinocchio")
TARGET_PREFIX = "Kinematics: "


def load(target):
    return report_contacts.load(target, "kinematics.json")


def _theirs(rows, system, what):
    return rows.get(("pinocchio", what, system), [])


def targets(rows):
    """Issue 49's speed targets, and its agreement to 1e-12 per robot."""
    out = []
    for system, _, speed in SYSTEMS:
        for what, wanted in speed.items():
            r = report_contacts.ratios(rows, system, what, what)
            peer = _theirs(rows, system, what)
            if r and peer:
                out.append(report_contacts.at_least(
                    f"{TARGET_PREFIX}{system} {what} ≥ {wanted} × faster than Pinocchio's "
                    f"`{peer[0]['pinocchio']}` (median of {len(r)} alternating rounds)", r, wanted))
        peer = [x for (who, _, s), xs in rows.items() if who == "pinocchio" and s == system for x in xs]
        if peer:
            out.append(report_contacts.agrees(
                f"{TARGET_PREFIX}{system}: every quantity agrees with Pinocchio's at 20 states "
                "(worst relative difference)", max(x["difference"] for x in peer), AGREEMENT))
    return out


def section(rows, ns):
    """The table: per robot and quantity, both times, the ratios and the
    worst difference seen."""
    if not rows:
        return []
    median = report_contacts._median
    table = []
    for system, label, _ in SYSTEMS:
        for what, ours, name in QUANTITIES:
            peer = _theirs(rows, system, what)
            if not peer:
                continue
            worst = max(x["difference"] for x in peer)
            mine = rows.get(("constrained", ours, system), [])
            timed = [x["ns"] for x in peer if x["ok"] and x["ns"]]
            r = report_contacts.ratios(rows, system, ours, what)
            if not timed or not mine:
                why = "disagreed" if not all(x["ok"] for x in peer) else "answers only"
                table.append(f"| {label} | {name} | `{peer[0]['pinocchio']}` | – | – | {why} | {worst:.1e} |")
                continue
            table.append(f"| {label} | {name} | `{peer[0]['pinocchio']}` | {ns(median([x['ns'] for x in mine]))} | "
                         f"{ns(median(timed))} | {median(r):.2f}× ({min(r):.2f}–{max(r):.2f}) | {worst:.1e} |")
    return [
        "",
        HEADING,
        "",
        "What a robot controller calls (issue 49), generated with a `frames:` section next to",
        "`urdf:` (`benches/peers/robots/src/bin/kinematics.rs`; build.rs's `FRAMED` table),",
        "against Pinocchio in C++ on the same files and states (`benches/peers/kinematics.cpp`):",
        "the Panda (`panda_description/urdf/panda.urdf`, its fingers locked) with a tool point",
        "on `panda_hand` (a link merged into `panda_link7` by two fixed joints, turned −π/4)",
        "at `xyz [0.01, -0.02, 0.1034]`, `rpy [0.1, -0.2, 0.3]`; the G1",
        "(`g1_description/urdf/g1_29dof_rev_1_0.urdf`) with a sole under `left_ankle_roll_link`",
        "and a palm on `right_rubber_hand`; the Go1 (`go1_description/urdf/go1.urdf`) with a",
        "frame under each foot. All three fixed base as written (the Go1's `floating_base`",
        "joint is `fixed` in its file, the G1's floating joint commented out); the Go1 on",
        "its four feet is the Contacts section's business. Each frame is added to Pinocchio's",
        "model as an `OP_FRAME` on the link's `BODY` frame with the same placement. At 20",
        "pseudo-random states per robot, in every round, Pinocchio's answers are checked",
        "against ours by joint name, relative to the largest entry, to within",
        f"{AGREEMENT:.0e} (the last column: the worst difference seen, over every frame): `oMf`",
        "after `forwardKinematics` + `updateFramePlacements` (rotation and translation);",
        "`computeFrameJacobian` and `getFrameJacobian`, `getFrameVelocity` and",
        "`getFrameClassicalAcceleration` at `a = 0` against our `J̇ q̇`, all",
        "`LOCAL_WORLD_ALIGNED`; `centerOfMass` and `jacobianCenterOfMass`; `centerOfMass(q, v)`'s",
        "`vcom[0]` against `center_of_mass_velocity`; `computeCentroidalMap`'s `Ag` against",
        "`centroidal_map` (rows `[P; L_G]`, world axes, about the centre of mass);",
        "`dccrba`'s `dAg · v` (and its `Ag`), `computeCentroidalMapTimeVariation`'s `dAg · v`",
        "right after it and `computeCentroidalMomentumTimeVariation(q, v, 0)`'s `dhg` against",
        "`centroidal_map_bias`;",
        "`computeRNEADerivatives` at a random `q̈` against `inverse_dynamics_jacobian`; and",
        "`computeABADerivatives` (its `M⁻¹` symmetrised) against `acceleration_jacobian`",
        "(`v` is `q̇` on these revolute joints, so a column per rate is a column per `v`:",
        "no quaternion to map). The first frame is timed, each side's call",
        "over the same 20 states (per state: the median of 31 batches), pinned to one",
        "core, on the thread's CPU clock, in 5 alternating rounds (ours, then Pinocchio's),",
        "each a fresh copy of each side's program (as the Robots rows' are);",
        "each side's time is the median of its rounds, the ratio the median of the rounds'",
        "ratios (their range in brackets). Ours is one generated method per quantity",
        "(`center_of_mass_and_jacobian` for the centre and its Jacobian), each computing",
        "only the joints it depends on, the centre of mass and its Jacobian from the",
        "subtrees' first moments summed in each body's own axes (no body's carried to the",
        "world); Pinocchio's placement and acceleration run",
        "`forwardKinematics` over every joint (its way to one frame's placement or",
        "classical acceleration), `computeFrameJacobian` over the frame's chain only, and",
        "`jacobianCenterOfMass` (without the subtrees' centres) computes both the centre",
        "and its Jacobian in one pass, as `centerOfMass(q, v)` does the centre and its",
        "velocity. `centroidal_map_bias` has two rows: `dccrba` (which forms `Ag`, `dAg`, `hg`",
        "and `vcom`, then `dAg · v`) and `computeCentroidalMomentumTimeVariation` at `a = 0` (a",
        "Newton–Euler pass straight to `dhg = dAg · v`, Pinocchio's cheaper way to the same",
        "vector). `computeCentroidalMapTimeVariation`, the same pass as `dccrba`, is not timed:",
        "in Pinocchio 4.1 it reads `data.vcom[0]` without computing it, which adds",
        "`(m ċ) × vcom[0]` to `dAg · v`; after another state's `centerOfMass(q, v)` on the same",
        "`Data` it was off by 4e-2 (Go1) to 0.39 (Panda) of the largest entry, and it agrees",
        "once `vcom[0]` is the state's `ċ`, as `dccrba` leaves it. `computeRNEADerivatives`",
        "forms `∂τ/∂q̈ = M` as well as the two of ours. Our `inverse_dynamics_jacobian` is",
        "straight-line code, built at compile time two ways and kept the one with fewer",
        "operations: by the recursions of `computeRNEADerivatives`, each subtree on the",
        "world in the cheapest of its candidate frames (the world's, or that of one of the",
        "first four bodies down its chain: each of the fixed Go1's legs takes its hip's), or by the",
        "partials of `τ`'s own expressions; here the recursions win on all three. Our",
        "`acceleration_jacobian` is that `∂τ` at the solved `q̈` (`tangent_rhs`) multiplied,",
        "as `computeABADerivatives` does, by `M⁻¹`:",
        "formed from the generated `L D Lᵀ` of `M` by Takahashi's recurrence within each",
        "block of `M` (the fixed-base G1's three: each leg, and the waist with both arms; the",
        "fixed Go1's four), `∂q̈/∂τ` is its columns, and each column of `∂τ/∂q`, `∂τ/∂q̇`",
        "is a product with it over the column's structural nonzeros (an arm joint's column",
        "has none in the other arm's rows), in a loop over the `2n` columns, one copy of the",
        "product per pattern of columns (a structurally zero column, a first joint about",
        "the vertical by `q`, is written as zeros). Both end in one check that every entry is finite, branch-free over the",
        "matrices' storage (`all_finite`), where an exit per entry would branch at every one.",
        "Both are timed through their `_to` forms (`inverse_dynamics_jacobian_to`,",
        "`acceleration_jacobian_to`), into one output the harness keeps from call to call, as",
        "Pinocchio's write into its `Data`: a `Result` returned by value is a copy of its",
        "entries (13 KB for the G1's `∂τ`, 20 KB for its `∂q̈`). For the G1 and the Go1 the",
        "`_to` form of `∂τ` zeroes the output and writes the structural nonzeros into it, and",
        "that of `∂q̈` writes every column, zeros included, without clearing it first; for the",
        "Panda (7 joints) `∂τ` is one literal stored into it.",
        "How much code each call runs, and how much of it misses the instruction cache, is",
        "in the instruction-cache table below: the G1's `∂τ` and `∂q̈` run several times the",
        "code a 32 KiB L1i holds, so every call reads it again from L2.",
        "",
        "| robot, frame | quantity | Pinocchio | ours | Pinocchio's | Pinocchio / ours | worst relative difference |",
        "|---|---|---|---|---|---|---|",
    ] + table


JSON, NAME = "kinematics.json", "report_kinematics.py"


if __name__ == "__main__":
    report_contacts.run_alone(sys.modules[__name__], "kinematics")
