"""Pinocchio traced into CasADi and emitted as C: the fastest Pinocchio.

Pinocchio's maintainers put its code generated through CasADi 5-10x ahead of
its library calls, so it is the bar the Robots rows are also measured
against. For each robot named on the command line, this reads our record of
it from the robots' reference file (written by `constrained-robots write`:
its URDF under example-robot-data's `robots` directory, the joints it holds
at zero, our coordinates' names and the states with our answers), builds
`CasadiKinDyn` of the same file as written (fixed base, the same joints held
at zero), and writes into OUT_DIR:

- `casadi_robots.c`, `casadi_robots.h`: CasADi's C for `aba(q, v, tau)`,
  `crba(q)` and `rnea(q, v, a)` of every robot, named `<robot>_aba` and so
  on, for `harness.c` to compile against;
- `casadi_registry.h`: the table of those functions the harness loops over;
- `casadi_states.txt`: every state mapped into CasADi's order by joint NAME
  (each of our coordinates a one-degree-of-freedom joint of its model, a
  continuous one as (cos, sin) in q, and no other joint moving), with our
  answers mapped the same way, for the harness to check its answers against
  before it times them.

Runs in its own virtual environment (`cmeel-casadi-kin-dyn` pulls an older
`pin` than the other peers'); `benches/peers/run.sh` sets it up.

Usage: generate.py ROBOTS_DIR REFERENCE_FILE OUT_DIR ROBOT...
"""

import math
import sys
from pathlib import Path

import casadi as cs
import casadi_kin_dyn as ckd


def records(path):
    """Our records: name → {n, urdf, locked, names, states}, each state a
    dict of its lines (q, v, tau, qdd, a, tau_id, M) in our order."""
    out = {}
    current = None
    for line in Path(path).read_text().splitlines():
        words = line.split()
        if not words:
            continue
        key, rest = words[0], words[1:]
        if key == "robot":
            current = {"n": int(rest[1]), "mimic": rest[2] == "1", "locked": [], "states": []}
            out[rest[0]] = current
        elif key == "urdf":
            current["urdf"] = rest[0]
        elif key == "locked":
            current["locked"] = rest
        elif key == "names":
            current["names"] = rest
        elif key == "state":
            current["states"].append({})
        else:
            current["states"][-1][key] = [float(x) for x in rest]
    return out


def model(robots_dir, record):
    """`CasadiKinDyn` of the record's URDF as written, fixed base, its
    locked joints held at zero."""
    text = (Path(robots_dir) / record["urdf"]).read_text()
    fixed = {name: 0.0 for name in record["locked"]}
    return ckd.CasadiKinDyn(text, ckd.CasadiKinDyn.JointType.OMIT, False, fixed)


def mapping(name, kin, record):
    """Where each of our coordinates sits in CasADi's q and v, by joint
    name: (iq, nq, iv) per coordinate. Every one must be a joint of one
    velocity there, and no other joint may move."""
    names = record["names"]
    moving = [j for j in kin.joint_names() if j != "universe" and kin.joint_nq(j) > 0]
    if sorted(moving) != sorted(names) or kin.nv() != record["n"]:
        sys.exit(f"{name}: CasADi's model moves {sorted(moving)} (nv {kin.nv()}), ours {sorted(names)}")
    out = []
    # Fixed base, one velocity a joint: a joint's place in v follows the
    # joints' order in q, counting one velocity per joint.
    order = sorted(names, key=kin.joint_iq)
    for joint in names:
        nq = kin.joint_nq(joint)
        if nq not in (1, 2):
            sys.exit(f"{name}: {joint} has {nq} coordinates in CasADi's model")
        out.append((kin.joint_iq(joint), nq, order.index(joint)))
    return out


def functions(name, kin):
    """The robot's three functions, renamed `<robot>_<what>` (the wheel
    names its `aba` `rnea`)."""
    out = []
    for what, make in (("aba", kin.aba), ("crba", kin.crba), ("rnea", kin.rnea)):
        f = make()
        inputs = [cs.SX.sym(f.name_in(i), f.sparsity_in(i)) for i in range(f.n_in())]
        # Dense outputs, so that the harness reads every entry in place
        # (a structural zero is an entry too).
        outputs = [cs.densify(o) for o in f.call(inputs)]
        out.append((what, cs.Function(f"{name}_{what}", inputs, outputs)))
    return out


def state_lines(record, where, nq):
    """The record's states in CasADi's order: q (a continuous joint as
    (cos, sin)), v, tau and a as inputs, our qdd, M (row-major) and tau_id
    as the answers to check against."""
    n = record["n"]

    def by_v(x):
        out = [0.0] * n
        for (_, _, iv), value in zip(where, x):
            out[iv] = value
        return out

    lines = []
    for s in record["states"]:
        q = [0.0] * nq
        for (iq, k, _), x in zip(where, s["q"]):
            if k == 2:
                q[iq], q[iq + 1] = math.cos(x), math.sin(x)
            else:
                q[iq] = x
        m = [[0.0] * n for _ in range(n)]
        for i, (_, _, vi) in enumerate(where):
            for j, (_, _, vj) in enumerate(where):
                m[vi][vj] = s["M"][i * n + j]
        lines.append("state")
        lines.append("q " + " ".join(repr(x) for x in q))
        for key in ("v", "tau", "a", "qdd", "tau_id"):
            lines.append(f"{key} " + " ".join(repr(x) for x in by_v(s[key])))
        lines.append("M " + " ".join(repr(x) for row in m for x in row))
    return lines


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__.strip().splitlines()[-1])
    robots_dir, reference, out_dir, names = sys.argv[1], sys.argv[2], Path(sys.argv[3]), sys.argv[4:]
    ours = records(reference)
    generator = cs.CodeGenerator("casadi_robots.c", {"with_header": True})
    registry, states = [], []
    for name in names:
        if name not in ours:
            sys.exit(f"{reference} has no robot {name}")
        record = ours[name]
        kin = model(robots_dir, record)
        where = mapping(name, kin, record)
        for _, f in functions(name, kin):
            generator.add(f)
        registry.append(f'  {{"{name}", {record["n"]}, {kin.nq()}, {name}_aba, {name}_aba_work, '
                        f'{name}_crba, {name}_crba_work, {name}_rnea, {name}_rnea_work}},')
        states.append(f"robot {name} {record['n']} {kin.nq()} {len(record['states'])}")
        states += state_lines(record, where, kin.nq())
    out_dir.mkdir(parents=True, exist_ok=True)
    generator.generate(str(out_dir) + "/")
    (out_dir / "casadi_registry.h").write_text(
        "/* Written by benches/peers/casadi/generate.py: the robots' CasADi functions. */\n"
        '#include "casadi_robots.h"\n'
        "static const casadi_robot casadi_robots[] = {\n" + "\n".join(registry) + "\n};\n")
    (out_dir / "casadi_states.txt").write_text("\n".join(states) + "\n")


if __name__ == "__main__":
    main()
