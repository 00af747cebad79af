"""The URDF sweep (scripts/urdf_sweep.sh): every URDF file of the
example-robot-data wheel that Pinocchio loads, read by `constrained` as
written, with a fixed base, and compared with Pinocchio by coordinate name.

For each file: Pinocchio's `buildModelFromUrdf` (a file it does not load is
left out); our expansion (`benches/urdf_sweep`: its time, the operations of
q̈, the sines of constants left, or the error naming the file's line); for
those that expand, a crate of their own built in release mode (its CPU
time), whose `acceleration` (τ = 0), `mass_matrix`, `inverse_dynamics` and
`gravity_forces` at 5 pseudo-random states are compared with `aba`, `crba`,
`rnea` and `computeGeneralizedGravity`, each vector and matrix by the
joints' names, relative to its largest entry. `<mimic>` is read as
Pinocchio reads it with `mimic=True` (the mimic joint follows the joint it
names and has no coordinate); `aba` refuses such models, so there the
reference q̈ solves `crba` q̈ = −`rnea`(q, v, 0). SWEEP_ONLY, if set, is a
substring of the files to sweep. Writes
<target>/benchmarks/urdf_sweep.json and prints the Markdown table.

Usage: urdf_sweep.py ROBOTS_DIR TARGET_DIR REPO_DIR
"""

import json
import math
import os
import resource
import subprocess
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin

import report_urdf_sweep

STATES = 5


def pinocchio_model(path):
    try:
        return pin.buildModelFromUrdf(str(path), mimic=True)
    except Exception as error:  # noqa: BLE001 - any refusal is reported
        return error


def is_mimic(joint):
    return joint.shortname() == "JointModelMimic"


def coordinates(model):
    """The joints with coordinates of their own, by name, in Pinocchio's order."""
    return [n for n, j in zip(list(model.names)[1:], list(model.joints)[1:]) if not is_mimic(j)]


def states(model):
    """Per state, each joint's (q, v, a) by name; pseudo-random, fixed."""
    names = coordinates(model)
    out = []
    for k in range(STATES):
        out.append({
            n: (0.9 * math.sin(1.7 * i + 0.9 * k + 0.3),
                0.5 * math.cos(1.1 * i + 0.4 * k),
                0.7 * math.sin(0.6 * i + 1.3 * k))
            for i, n in enumerate(names)
        })
    return out


def pinocchio_vectors(model, state):
    q, v, a = np.zeros(model.nq), np.zeros(model.nv), np.zeros(model.nv)
    for jid in range(1, model.njoints):
        joint, name = model.joints[jid], model.names[jid]
        if is_mimic(joint):  # follows its joint: Pinocchio fills it in
            continue
        angle, rate, acc = state[name]
        if joint.nq == 2:  # a continuous joint: (cos, sin)
            q[joint.idx_q], q[joint.idx_q + 1] = math.cos(angle), math.sin(angle)
        elif joint.nq == 1:
            q[joint.idx_q] = angle
        else:
            raise ValueError(f"joint {name} has {joint.nq} coordinates")
        v[joint.idx_v], a[joint.idx_v] = rate, acc
    return q, v, a


MAIN = """use constrained::nalgebra::{{SMatrix, SVector}};
use std::collections::HashMap;
use std::io::Write;

constrained::constrained_system! {{ pub struct Robot {{ urdf: {path}, }} }}

/// A method's answer, plain or `Result`.
trait Value<T> {{
    fn value(self) -> T;
}}
impl<T, E: std::fmt::Debug> Value<T> for Result<T, E> {{
    fn value(self) -> T {{
        self.expect("an answer")
    }}
}}
impl<const R: usize, const C: usize> Value<SMatrix<f64, R, C>> for SMatrix<f64, R, C> {{
    fn value(self) -> Self {{
        self
    }}
}}

fn main() {{
    let robot = Robot::<f64>::new();
    let names = Robot::<f64>::COORDINATES;
    let text = std::fs::read_to_string("states.txt").expect("the states");
    let mut states: Vec<HashMap<String, [f64; 3]>> = Vec::new();
    for line in text.lines() {{
        let p: Vec<&str> = line.split_whitespace().collect();
        let k: usize = p[0].parse().expect("an index");
        while states.len() <= k {{
            states.push(HashMap::new());
        }}
        let x: Vec<f64> = p[2..5].iter().map(|x| x.parse().expect("a number")).collect();
        states[k].insert(p[1].to_string(), [x[0], x[1], x[2]]);
    }}
    let mut out = std::fs::File::create("answers.txt").expect("writable");
    writeln!(out, "{{}}", names.join(" ")).expect("writable");
    let line = |x: &[f64]| x.iter().map(|v| format!("{{v:e}}")).collect::<Vec<_>>().join(" ");
    for s in &states {{
        let get = |j: usize| SVector::<f64, {n}>::from_fn(|i, _| s[names[i]][j]);
        let (q, v, a) = (get(0), get(1), get(2));
        let qdd: SVector<f64, {n}> = robot.acceleration(&q, &v, 0.0).value();
        let tau: SVector<f64, {n}> = robot.inverse_dynamics(&q, &v, &a, 0.0).value();
        let g: SVector<f64, {n}> = robot.gravity_forces(&q, 0.0).value();
        let m: SMatrix<f64, {n}, {n}> = robot.mass_matrix(&q, 0.0).value();
        for x in [qdd.as_slice(), tau.as_slice(), g.as_slice(), m.as_slice()] {{
            writeln!(out, "{{}}", line(x)).expect("writable");
        }}
    }}
}}
"""


def cpu_of_children():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def build_and_run(name, path, n, names, model, sweep, repo):
    """Builds the robot's crate, runs it on the states (our order, by
    name) and returns (build CPU seconds, worst relative difference)."""
    crate = sweep / "robots" / name
    (crate / "src").mkdir(parents=True, exist_ok=True)
    (crate / "Cargo.toml").write_text(
        f'[package]\nname = "sweep-{name}"\nversion = "0.1.0"\nedition = "2021"\n\n'
        f'[dependencies]\nconstrained = {{ path = {json.dumps(str(repo))}, default-features = false }}\n\n'
        '[workspace]\n')
    main = MAIN.format(path=json.dumps(str(path)), n=n)
    (crate / "src" / "main.rs").write_text(main)
    env = dict(os.environ, CARGO_TARGET_DIR=str(sweep / "target"))
    before = cpu_of_children()
    built = subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=crate, env=env,
                           capture_output=True, text=True)
    cpu = cpu_of_children() - before
    if built.returncode != 0:
        return cpu, None, built.stderr.strip().splitlines()[-1:]
    ss = states(model)
    with open(crate / "states.txt", "w") as f:
        for k, s in enumerate(ss):
            for c, (q, v, a) in s.items():
                f.write(f"{k} {c} {q!r} {v!r} {a!r}\n")
    binary = sweep / "target" / "release" / f"sweep-{name}"
    ran = subprocess.run([str(binary)], cwd=crate, capture_output=True, text=True)
    if ran.returncode != 0:
        return cpu, None, ran.stderr.strip().splitlines()[-1:]
    lines = (crate / "answers.txt").read_text().splitlines()
    ours = lines[0].split()
    if sorted(ours) != sorted(names):
        return cpu, None, [f"coordinates {ours} are not Pinocchio's {names}"]
    data = pin.Data(model)
    index = {c: model.joints[model.getJointId(c)].idx_v for c in ours}
    order = [index[c] for c in ours]
    worst = {"q̈": 0.0, "M": 0.0, "τ": 0.0, "g": 0.0}
    for k, s in enumerate(ss):
        q, v, a = pinocchio_vectors(model, s)
        qdd, tau, g, m = (np.array([float(x) for x in lines[1 + 4 * k + i].split()]) for i in range(4))
        m = m.reshape((n, n), order="F")
        if any(is_mimic(j) for j in model.joints):
            full = pin.crba(model, data, q)
            full = np.triu(full) + np.triu(full, 1).T
            p_qdd = np.linalg.solve(full, -pin.rnea(model, data, q, v, np.zeros(model.nv)))[order]
        else:
            p_qdd = pin.aba(model, data, q, v, np.zeros(model.nv))[order]
        p_tau = pin.rnea(model, data, q, v, a)[order]
        p_g = pin.computeGeneralizedGravity(model, data, q)[order]
        p_m = pin.crba(model, data, q)
        p_m = (np.triu(p_m) + np.triu(p_m, 1).T)[np.ix_(order, order)]
        for what, ours_, theirs in (("q̈", qdd, p_qdd), ("τ", tau, p_tau), ("g", g, p_g), ("M", m, p_m)):
            scale = max(abs(theirs).max(), 1e-300)
            worst[what] = max(worst[what], abs(ours_ - theirs).max() / scale)
        # Where M is ill-conditioned two correct q̈ differ by up to its
        # condition number times ε: both residuals say whether each solves it.
        bias = pin.rnea(model, data, q, v, np.zeros(model.nv))[order]
        worst["residual"] = max(worst.get("residual", 0.0),
                                abs(m @ qdd + bias).max() / max(abs(bias).max(), 1e-300))
        worst["condition"] = max(worst.get("condition", 0.0), float(np.linalg.cond(p_m)))
    return cpu, worst, None if ours == names else ["not in Pinocchio's order"]


def main():
    robots, target, repo = (Path(p) for p in sys.argv[1:4])
    sweep = target / "urdf-sweep"
    tool = sweep / "tool" / "release" / "urdf-sweep"
    rows = []
    only = os.environ.get("SWEEP_ONLY", "")
    for path in sorted(p for p in robots.rglob("*.urdf") if only in str(p)):
        name = path.stem.replace("-", "_").replace(".", "_")
        label = str(path.relative_to(robots))
        model = pinocchio_model(path)
        if isinstance(model, Exception):
            rows.append({"file": label, "pinocchio": False, "refusal": str(model).strip().splitlines()[0].replace(str(robots) + "/", "")})
            continue
        run = subprocess.run([str(tool), str(path)], capture_output=True, text=True, timeout=900)
        if run.returncode != 0 or not run.stdout.strip():
            # The macro must never panic: say so in the table.
            tail = (run.stderr.strip().splitlines() or ["no output"])
            expanded = {"ok": False, "error": "the expansion panicked: " + " ".join(tail[:2])}
        else:
            expanded = json.loads(run.stdout)
        row = {"file": label, "pinocchio": True, "n": model.nv, **expanded}
        row["file"] = label
        if expanded.get("ok"):
            names = None
            cpu, worst, failure = None, None, None
            try:
                names = coordinates(model)
                cpu, worst, failure = build_and_run(name, path, expanded["n"], names, model, sweep, repo)
            except Exception as error:  # noqa: BLE001 - reported in the table
                failure = [f"{type(error).__name__}: {error}"]
            row.update(build_cpu=cpu, worst=worst, failure=failure)
        else:
            row["error"] = expanded.get("error", "").replace(str(robots) + "/", "")
        rows.append(row)
        print(json.dumps(row), file=sys.stderr, flush=True)
    (target / "benchmarks").mkdir(parents=True, exist_ok=True)
    (target / "benchmarks" / "urdf_sweep.json").write_text("\n".join(json.dumps(r) for r in rows) + "\n")
    print("\n".join(report_urdf_sweep.section(rows)))


if __name__ == "__main__":
    main()
