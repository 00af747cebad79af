"""The summary that ends scripts/test.sh: what each stage ran, read from
its log in <target>/test-logs, with the stage's wall and CPU time.

    python3 scripts/test_summary.py LOG_DIR SUMMARY_FILE [START]

SUMMARY_FILE has one line per stage: name, wall seconds, CPU seconds
(tab-separated), written by test.sh as the stages finish. START (seconds
since the epoch) is when the run began: the total wall time is measured
from it, since stages that run side by side overlap."""

import re
import sys
import time
from pathlib import Path


def test_binaries(text):
    """(binary, passed, failed, ignored) per test binary of a `cargo test`
    log; criterion benches run once in test mode count their `Success`
    lines as passed."""
    rows, current, benches = [], None, 0
    for line in text.splitlines():
        running = re.match(r"\s+Running (.+?) \((.+)\)$", line)
        doc = re.match(r"\s+Doc-tests (\S+)", line)
        if running or doc:
            if current and benches:
                rows.append((current, benches, 0, 0))
            if running:
                stem = re.sub(r"-[0-9a-f]{16}$", "", Path(running.group(2)).name)
                current = f"{stem} ({running.group(1)})"
            else:
                current = f"doc tests of {doc.group(1)}"
            benches = 0
            continue
        if line.strip() == "Success":
            benches += 1
        result = re.match(
            r"test result: \w+\. (\d+) passed; (\d+) failed; (\d+) ignored", line
        )
        if result and current:
            counts = tuple(map(int, result.groups()))
            if any(counts):  # binaries without tests (the examples) are left out
                rows.append((current, *counts))
            current = None
    if current and benches:
        rows.append((current, benches, 0, 0))
    return rows


def describe(log_dir, stage):
    """A few words on what the stage ran, from its log."""
    logs = {
        "tests": "tests.log",
        "doc tests": "doctests.log",
        "std feature": "std-feature.log",
        "examples": "examples.log",
        "sympy": "sympy.log",
        "embedded": "embedded.log",
    }
    key = stage.split(":")[0]
    path = log_dir / logs.get(key, "")
    if key not in logs or not path.is_file():
        return []
    text = path.read_text(errors="replace")
    if key in ("tests", "doc tests", "std feature"):
        rows = test_binaries(text)
        lines = [f"    {p:5} passed {f:3} failed {i:3} ignored  {name}" for name, p, f, i in rows]
        total = [sum(r[k] for r in rows) for k in (1, 2, 3)]
        lines.append(
            f"    {total[0]:5} passed {total[1]:3} failed {total[2]:3} ignored  "
            f"in {len(rows)} binaries"
        )
        return lines
    if key == "examples":
        ran = re.findall(r"^-- (\S+)", text, re.M)
        return [f"    {len(ran)} examples ran: {', '.join(ran)}"]
    if key == "sympy":
        found = re.findall(r"^=* ?(\d+ passed.*?) ?=*$", text, re.M)
        return [f"    pytest: {found[-1]}" if found else "    pytest: no summary line"]
    found = [l for l in text.splitlines() if l.startswith("== ") and ":" in l]
    return ["    " + l for l in found]


def main():
    log_dir, summary = Path(sys.argv[1]), Path(sys.argv[2])
    stages = [l.split("\t") for l in summary.read_text().splitlines() if l.strip()]
    print()
    print("== summary (wall and CPU seconds per stage; logs in " + str(log_dir) + ")")
    wall = cpu = 0.0
    for name, w, c in stages:
        wall, cpu = wall + float(w), cpu + float(c)
        print(f"{name}: {w} s wall, {c} s CPU")
        for line in describe(log_dir, name):
            print(line)
    if len(sys.argv) > 3:  # stages side by side: the elapsed time, not their sum
        wall = time.time() - float(sys.argv[3])
    print(f"total: {wall:.0f} s wall ({wall / 60:.1f} min), {cpu:.0f} s CPU ({cpu / 60:.1f} min)")


main()
