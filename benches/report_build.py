"""The build-time rows of BENCHMARKS.md's targets: the CPU time of building
a binary that calls the standing G1's `acceleration`, its dependencies
built (benches/peers/build_time.sh writes <target>/benchmarks/build_time.json:
three builds in each of two release profiles). Standard library only."""

import report_contacts

# Issue 48's build target: at most this many seconds of CPU.
WANTED = 15.0
PROFILES = (("advised", "the generator at opt-level 3, as docs/dsl.md advises for large models"),
            ("default", "cargo's default release profile, proc macros unoptimized"))


def load(target):
    """profile → its builds' JSON lines, from `benchmarks/build_time.json`."""
    rows = {}
    for r in report_contacts.json_lines(target, JSON):
        rows.setdefault(r["profile"], []).append(r)
    return rows


def targets(rows):
    """A target row per profile measured: the median CPU (user + system)."""
    out = []
    for profile, text in PROFILES:
        builds = rows.get(profile)
        if not builds:
            continue
        cpu = report_contacts._median([b["user"] + b["sys"] for b in builds])
        wall = report_contacts._median([b["wall"] for b in builds])
        out.append((f"Build: a binary calling the standing G1's `acceleration` (36 coordinates, 19 rows), "
                    f"its dependencies built, {text}: CPU seconds, user + system (median of {len(builds)} "
                    f"builds; {wall:.1f} s wall)",
                    cpu, f"≤ {WANTED:.0f} s", lambda x: x <= WANTED, "{:.1f} s"))
    return out


HEADING = "## Build time: the standing G1"
TARGET_PREFIX = "Build: "
JSON, NAME = "build_time.json", "report_build.py"


def section(rows, ns=None):
    """The Build time section: each profile's builds."""
    if not rows:
        return []
    lines = [
        "",
        HEADING,
        "",
        "A binary that calls the standing G1's `acceleration` (the Unitree G1 of",
        "example-robot-data's `g1_29dof_rev_1_0.urdf` on a floating root, three points",
        "of each foot held: 36 coordinates, 19 rows), in a crate of its own with its",
        "dependencies built, its main file touched and rebuilt three times",
        "(`benches/peers/build_time.sh`): the seconds of cargo and the compiler,",
        "release profile, with the `jacobians` feature (the default).",
        "",
        "| profile | CPU (user + system), median (range) | user | system | wall |",
        "|---|---|---|---|---|",
    ]
    for profile, text in PROFILES:
        builds = rows.get(profile)
        if not builds:
            continue
        cpu = [b["user"] + b["sys"] for b in builds]
        lines.append(f"| {text} | {report_contacts._median(cpu):.1f} s ({min(cpu):.1f}–{max(cpu):.1f}) | "
                     f"{report_contacts._median([b['user'] for b in builds]):.1f} s | "
                     f"{report_contacts._median([b['sys'] for b in builds]):.1f} s | "
                     f"{report_contacts._median([b['wall'] for b in builds]):.1f} s |")
    return lines


if __name__ == "__main__":
    import sys

    report_contacts.run_alone(sys.modules[__name__], "build time")
