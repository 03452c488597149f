#!/usr/bin/env python3
"""Rewrites the tables of docs/benchmarks.md from the outputs tools/benchmarks.sh collected.

    benchmarks.py OUT_DIR docs/benchmarks.md

Every table sits between `<!-- table:NAME -->` and `<!-- /table:NAME -->`; a table is replaced
only when OUT_DIR holds what it is made from, and then starts with the command lines, the commit
and the date of the run. The machine line (`<!-- table:machine -->`) is rewritten on every run.
"""
import json
import os
import re
import subprocess
import sys

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def sh(*cmd):
    try:
        return subprocess.run(cmd, capture_output=True, text=True, check=True, cwd=REPO).stdout
    except (OSError, subprocess.CalledProcessError):
        return ""


def machine(out):
    info = {}
    for line in sh("lscpu").splitlines():
        key, _, value = line.partition(":")
        info[key.strip()] = value.strip()
    load = (read(out, "load", "") or "").strip() or f"{os.getloadavg()[0]:.1f}"
    return (f"{info.get('Model name', 'unknown CPU')}, {info.get('CPU(s)', '?')} cores "
            f"({info.get('Hypervisor vendor', 'no') + ' guest' if 'Hypervisor vendor' in info else 'bare metal'}), "
            f"L2 {info.get('L2 cache', '?')}; load average {load} when the run ended. "
            "The machine is shared with other builds and tests and is noisy: compare numbers "
            "within one table (measured side by side in one run), not across tables.")


def read(out, name, ext="txt"):
    path = os.path.join(out, f"{name}.{ext}" if ext else name)
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return f.read()


def command(out, name):
    cmd = read(out, name, "cmd").strip()
    build = os.path.dirname(os.path.abspath(out))
    cmd = cmd.replace(build + "/", os.path.relpath(build, REPO) + "/")
    cmd = cmd.replace(REPO + "/", "")
    cmd = re.sub(r"^env ", "", cmd)
    # The Siconos files as the glob that named them.
    cmd = re.sub(r"(\S+/lcp/\S+\.dat ?)+", "tests/data/siconos/lcp/*.dat ", cmd)
    return cmd.strip()


def stamp(out, names):
    cmds = "\n".join(command(out, n) for n in names)
    # tools/benchmarks.sh's record of the run: the commit, "+ uncommitted changes" when the
    # measured code differed from it, the date.
    run = (read(out, "run", "") or "unknown commit\n").strip().splitlines()
    code = " ".join(run[:-1]) or "unknown"
    date = run[-1] if len(run) > 1 else "date unknown"
    return f"```sh\n{cmds}\n```\n\nCommit {code}, run {date}.\n\n"


def markdown_tables(text):
    """The markdown table lines of a program's output (plus lines just above them)."""
    return "\n".join(l for l in text.splitlines() if l.startswith("|")) + "\n"


def program_output(out, name, indent="    "):
    text = read(out, name)
    if text is None:
        return None
    extra = [l for l in text.splitlines() if l and not l.startswith("|")]
    notes = "".join(f"{indent}{l}\n" for l in extra)
    body = markdown_tables(text)
    if notes:
        body += "\nThe program's other lines:\n\n" + notes
    return stamp(out, [name]) + body


def core(out):
    text = read(out, "core")
    if text is None:
        return None
    data = json.loads(text)
    rows = ["| benchmark | n | CPU ms per solve (per step) | residual (pyramids: worst) | "
            "iterations (last solve) | converged (pyramids: share of steps) |",
            "|---|---|---|---|---|---|"]
    for b in data["benchmarks"]:
        unit = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b.get("time_unit", "ns")]
        res = b.get("residual", b.get("worst_residual"))
        conv = b.get("converged", b.get("converged_fraction"))
        # Google Benchmark's own loop count shares the key "iterations" with the counter; the
        # counter comes last in the JSON, so json.loads keeps it.
        rows.append(f"| {b['name'].split('/iterations:')[0]} | {int(b.get('n', 0))} | "
                    f"{b['cpu_time'] * unit:.3g} | {'' if res is None else f'{res:.0e}'} | "
                    f"{int(b.get('iterations', 0))} | {'' if conv is None else f'{conv:g}'} |")
    return stamp(out, ["core"]) + "\n".join(rows) + "\n"


def bullet_rows(text):
    """label -> (cpu ms, residual, note) from bullet_bench's plain table."""
    rows, n = {}, None
    for line in text.splitlines():
        m = re.match(r"rows per step: (\d+)", line)
        if m:
            n = int(m.group(1))
        if len(line) < 23 or line.startswith(("solver ", "pyramid", "ratio", "speed", "same")):
            continue
        label, rest = line[:22].strip(), line[22:].split()
        if len(rest) < 7:
            continue
        try:
            cpu, residual = float(rest[6]), float(rest[2])
        except ValueError:
            continue
        rows[label] = (cpu, residual, " ".join(rest[7:]))
    return rows, n


BULLET_STATES = [
    ("bullet-switch-15", "15 boxes, after the switch"),
    ("bullet-switch-55", "55 boxes, after the switch"),
    ("bullet-rest-55", "55, at rest after SI"),
    ("bullet-demo-55", "55, a demo's first 300 steps"),
    ("bullet-steady-55", "55, the demo's steady state"),
    ("bullet-switch-210", "210 boxes, after the switch"),
]
BULLET_SOLVERS = ["SI (stock)", "ours pgs", "MLCP-PGS (stock)", "ours dantzig", "ours newton",
                  "MLCP-Dantzig (stock)", "ours lemke", "MLCP-Lemke (stock)"]


def bullet(out):
    states = [(n, t, read(out, n)) for n, t in BULLET_STATES]
    states = [(n, t, x) for n, t, x in states if x is not None]
    if not states:
        return None
    parsed = []
    for name, title, text in states:
        rows, n = bullet_rows(text)
        parsed.append((name, f"{title} (n = {n})" if n else title, rows))
    head = "| solver | " + " | ".join(t for _, t, _ in parsed) + " |"
    lines = [head, "|---" * (len(parsed) + 1) + "|"]

    def cell(rows, label):
        if label not in rows:
            return ""
        cpu, res, note = rows[label]
        if note.startswith("skipped"):
            return note
        return f"{cpu:.3g} ({res:.1e}{'; ' + note if note else ''})"

    for label in BULLET_SOLVERS:
        if any(label in rows for _, _, rows in parsed):
            lines.append(f"| {label} | " + " | ".join(cell(r, label) for _, _, r in parsed) + " |")
    for ours in ("dantzig", "newton"):
        ratios = []
        for _, _, rows in parsed:
            a, b = rows.get("MLCP-Dantzig (stock)"), rows.get("ours " + ours)
            ratios.append(f"**{a[0] / b[0]:.1f}x**" if a and b and b[0] > 0 else "")
        lines.append(f"| {ours} speed-up (stock Dantzig / ours) | " + " | ".join(ratios) + " |")
    return stamp(out, [n for n, _, _ in states]) + "\n".join(lines) + "\n"


def pgs_vs_si(out):
    text = read(out, "pgs-vs-si")
    if text is None:
        return None
    body = program_output(out, "pgs-vs-si")
    base = read(out, "pgs-vs-si-baseline")
    if base is not None:
        body += "\nWith the baseline machine code:\n\n" + program_output(out, "pgs-vs-si-baseline")
    return body


def replace(doc, name, content):
    pattern = re.compile(rf"(<!-- table:{re.escape(name)} -->\n)(.*?)(<!-- /table:{re.escape(name)} -->)",
                         re.S)
    if not pattern.search(doc):
        sys.exit(f"benchmarks.py: no <!-- table:{name} --> block in the document")
    return pattern.sub(lambda m: m.group(1) + content + m.group(3), doc)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    out, path = sys.argv[1], sys.argv[2]
    with open(path) as f:
        doc = f.read()
    doc = replace(doc, "machine", machine(out) + "\n")
    for name, make in [("core", core), ("bullet", bullet), ("pgs-vs-si", pgs_vs_si),
                       ("ode-dantzig", lambda o: program_output(o, "ode-dantzig")),
                       ("ode-pgs", lambda o: program_output(o, "ode-pgs")),
                       ("siconos", lambda o: program_output(o, "siconos", indent=""))]:
        content = make(out)
        if content is not None:
            doc = replace(doc, name, content)
    with open(path, "w") as f:
        f.write(doc)


if __name__ == "__main__":
    main()
