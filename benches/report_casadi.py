"""The section of BENCHMARKS.md against Pinocchio generated through CasADi,
and its targets (issue 48): `aba`, `crba` and `rnea` of the Panda, the UR5
and the G1 traced into CasADi and emitted as C (benches/peers/casadi), on
the Robots rows' states, in the same alternating rounds
(benches/peers/run.sh appends CasADi's lines, `"peer": "casadi"`, to
<target>/benchmarks/robots.json). Standard library only.

Run alone (`python3 benches/report_casadi.py`), it rewrites this section and
its targets' rows in BENCHMARKS.md from the last run of the peers, leaving
the rest of the file as the last full run wrote it."""

import sys

import report_contacts

# (system, label): issue 48's robots; each quantity's target is 2×.
SYSTEMS = (
    ("panda", "Panda (7 joints, fingers locked)"),
    ("ur5", "UR5 (6 joints)"),
    ("g1", "G1 (29 joints, fixed base)"),
)
PAIRS = (("acceleration", "aba", "q̈"), ("mass_matrix", "crba", "M(q)"),
         ("inverse_dynamics", "rnea", "inverse dynamics"))
WANTED = 2
AGREEMENT = 1e-12
HEADING = "## Against Pinocchio generated through CasADi"
TARGET_PREFIX = "CasADi: "


def load(target):
    return report_contacts.load(target, "robots.json")


def ratios(rows, system, ours, theirs):
    """The rounds' ratios CasADi's / ours, paired by round."""
    a = {r["round"]: r["ns"] for r in rows.get(("constrained", ours, system), [])}
    b = {r["round"]: r["ns"] for r in rows.get(("casadi", theirs, system), []) if r["ok"] and r["ns"]}
    return [b[k] / a[k] for k in sorted(a) if k in b and a[k]]


def targets(rows):
    """Each quantity of each robot ≥ 2× faster than CasADi's, and the
    agreement of every answer."""
    out = []
    for system, _ in SYSTEMS:
        for ours, theirs, label in PAIRS:
            r = ratios(rows, system, ours, theirs)
            if r:
                out.append(report_contacts.at_least(
                    f"{TARGET_PREFIX}{system} {label} ≥ {WANTED} × faster than Pinocchio's `{theirs}` generated "
                    f"through CasADi (median of {len(r)} alternating rounds)", r, WANTED))
    peer = [x for (who, _, _), xs in rows.items() if who == "casadi" for x in xs]
    if peer:
        out.append(report_contacts.agrees(
            f"{TARGET_PREFIX}Pinocchio generated through CasADi agrees with ours on every robot at 20 states "
            "(worst relative difference of q̈, M, τ)", max(x["difference"] for x in peer), AGREEMENT))
    return out


def section(rows, ns):
    """The table: per robot and quantity, both times, the ratios and the
    worst difference seen."""
    table = []
    for system, name in SYSTEMS:
        for ours, theirs, label in PAIRS:
            mine, peer = rows.get(("constrained", ours, system), []), rows.get(("casadi", theirs, system), [])
            if not mine or not peer:
                continue
            worst = max(x["difference"] for x in peer)
            r = ratios(rows, system, ours, theirs)
            table.append(report_contacts.ratio_row(name, f"{label}: `{ours}` / `{theirs}`", mine, peer, r, worst, ns))
    if not table:
        return []
    return [
        "",
        HEADING,
        "",
        "Pinocchio's maintainers put its code generated through CasADi 5–10× ahead of its",
        "library calls, which makes it the fastest Pinocchio. `benches/peers/casadi/generate.py`",
        "builds `CasadiKinDyn` (the `cmeel-casadi-kin-dyn` wheel, Pinocchio 2.6 inside, in a",
        "virtual environment of its own: `benches/peers/.venv-casadi`) of the Robots rows'",
        "URDFs as written, fixed base, the Panda's fingers held at zero, and emits its `aba`,",
        "`crba` and `rnea` as C with CasADi's code generator; `benches/peers/casadi/harness.c`",
        "compiles them at `-O3` (no `-march`, as both other sides) and runs them on the Robots",
        "rows' 20 states, mapped into CasADi's order by joint NAME, in the same alternating",
        "rounds (ours, Pinocchio's, CasADi's), on the thread's CPU clock, the same statistic.",
        "Every answer is checked against ours before it is timed (`crba`'s upper triangle",
        f"mirrored), relative to the largest entry, to {AGREEMENT:.0e}.",
        "",
        "| robot | what | ours | CasADi's | CasADi's / ours | worst relative difference |",
        "|---|---|---|---|---|---|",
    ] + table


JSON, NAME = "robots.json", "report_casadi.py"


if __name__ == "__main__":
    report_contacts.run_alone(sys.modules[__name__], "CasADi")
