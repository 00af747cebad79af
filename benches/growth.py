"""The G1's truncations (scripts/urdf_sweep.sh, after the sweep): the
Unitree G1 of example-robot-data's `g1_29dof_rev_1_0.urdf` expanded with
its joints locked from the last in Pinocchio's order until six are left,
each by `benches/urdf_sweep` (`LOCKED=`), which counts the operations of
the generated `acceleration`, `mass_matrix` and `inverse_dynamics`. Writes
<target>/benchmarks/growth.json and the Growth section of BENCHMARKS.md
(benches/report_growth.py).

Usage: growth.py ROBOTS_DIR TARGET_DIR REPO_DIR
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import pinocchio as pin

import report_growth

URDF = "g1_description/urdf/g1_29dof_rev_1_0.urdf"
SMALLEST = 6


def main():
    robots, target, repo = (Path(p) for p in sys.argv[1:4])
    tool = target / "urdf-sweep" / "tool" / "release" / "urdf-sweep"
    path = robots / URDF
    model = pin.buildModelFromUrdf(str(path))
    names = list(model.names)[1:]
    rows = []
    for n in range(SMALLEST, len(names) + 1):
        env = dict(os.environ, LOCKED=",".join(names[n:]))
        run = subprocess.run([str(tool), str(path)], env=env, capture_output=True, text=True,
                             timeout=900, check=True)
        row = json.loads(run.stdout)
        row["file"] = URDF
        if row.get("ok") and row["n"] != n:
            sys.exit(f"{n} joints asked, {row['n']} expanded")
        rows.append(row)
        print(json.dumps(row), file=sys.stderr, flush=True)
    (target / "benchmarks").mkdir(parents=True, exist_ok=True)
    (target / "benchmarks" / report_growth.JSON).write_text("\n".join(json.dumps(r) for r in rows) + "\n")
    report_growth.splice(target, repo)
    print("\n".join(report_growth.section(report_growth.load(target))))


if __name__ == "__main__":
    main()
