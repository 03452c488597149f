#!/usr/bin/env python3
"""Reads run.sh's per-run records (RUNS/<demo>.<solver>.{json,meta}), compares every library run
with the stock run of the same demo, writes the CSV, prints the table and, last, the geometric
mean of step_vs_stock per library solver. Exit 0 only if no library run crashed or produced NaN
where stock did not.

usage: report.py RUNS_DIR CSV_OUT SOLVER...   (the first solver is the baseline, "stock")
"""
import csv
import json
import math
import os
import sys


def read(runs, demo, solver):
    rec, meta = None, {}
    path = os.path.join(runs, "%s.%s.json" % (demo, solver))
    if os.path.exists(path):
        with open(path) as f:
            rec = json.loads(f.read())
    mpath = os.path.join(runs, "%s.%s.meta" % (demo, solver))
    if os.path.exists(mpath):
        with open(mpath) as f:
            for line in f:
                if "=" in line:
                    k, v = line.rstrip("\n").split("=", 1)
                    meta[k] = v
    return rec, meta


def status(rec, meta):
    rc = int(meta.get("rc", "-1"))
    if rc == 124:
        return "timeout"
    if rec is None:
        return "crash" if rc != 0 else "missing"
    if rec["nan_steps"] > 0:
        return "nan"
    # A record is written when the frames are done: a crash after it is in the demo's teardown
    # (demo_chain2's C++ wrappers outlive dCloseODE).
    return "ok" if rc == 0 else "ok, exit rc=%d" % rc


def main():
    runs, csv_out, solvers = sys.argv[1], sys.argv[2], sys.argv[3:]
    base, libs = solvers[0], solvers[1:]
    demos = sorted({f.split(".")[0] for f in os.listdir(runs) if f.endswith(".meta")})
    rows = []
    for demo in demos:
        srec, smeta = read(runs, demo, base)
        sstat = status(srec, smeta)
        for solver in solvers:
            rec, meta = read(runs, demo, solver)
            row = {"demo": demo, "solver": solver, "status": status(rec, meta),
                   "keys": meta.get("keys", ""), "instructions": meta.get("instructions", "")}
            if rec:
                row.update(rec)
            if rec and srec and srec["median_step_ms"] > 0 and (sstat.startswith("ok") or sstat == "nan"):
                row["step_vs_stock"] = rec["median_step_ms"] / srec["median_step_ms"]
                row["speed_vs_stock"] = rec["max_speed"] / srec["max_speed"] if srec["max_speed"] > 0 else None
            if row["instructions"] and smeta.get("instructions"):
                row["instructions_vs_stock"] = int(row["instructions"]) / int(smeta["instructions"])
            rows.append(row)

    cols = ["demo", "solver", "status", "called", "frames", "steps", "median_step_ms", "step_vs_stock",
            "instructions", "instructions_vs_stock", "total_step_ms", "nan_steps", "first_nan_frame", "max_speed", "speed_vs_stock",
            "frames_unconverged", "steps_unconverged", "steps_fallback", "steps_rejected", "islands",
            "islands_unconverged", "rows", "max_rows", "worst_residual", "choices", "worst_message", "keys"]
    with open(csv_out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in cols})

    def fmt(v, spec):
        return "-" if v is None or v == "" else spec % v

    hdr = "| demo | stock calls | solver | status | steps | median step ms | step_vs_stock | frames unconverged | fallback steps | max speed vs stock | rows/step | largest island | choices |"
    print(hdr)
    print("|" + "---|" * (hdr.count("|") - 1))
    for r in rows:
        rows_per_step = r["rows"] / r["steps"] if r.get("steps") else None
        print("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            r["demo"], r.get("called", "-"), r["solver"], r["status"], r.get("steps", "-"),
            fmt(r.get("median_step_ms"), "%.4f"), fmt(r.get("step_vs_stock"), "%.2f"),
            fmt(r.get("frames_unconverged") if r["solver"] != base else None, "%d"),
            fmt(r.get("steps_fallback") if r["solver"] != base else None, "%d"),
            fmt(r.get("speed_vs_stock"), "%.3f"),
            fmt(rows_per_step if r["solver"] != base else None, "%.0f"),
            fmt(r.get("max_rows") if r["solver"] != base else None, "%d"),
            (r.get("choices", "") if r["solver"] != base else "")[:60]))

    bad = 0
    print()
    for solver in libs:
        ratios = [r["step_vs_stock"] for r in rows if r["solver"] == solver and r.get("step_vs_stock")
                  and r["status"].startswith("ok")]
        worst = sorted(((r["step_vs_stock"], r["demo"]) for r in rows if r["solver"] == solver
                        and r.get("step_vs_stock")), reverse=True)[:5]
        unconv = sum(r.get("frames_unconverged", 0) for r in rows if r["solver"] == solver)
        failed = [r for r in rows if r["solver"] == solver and not r["status"].startswith("ok")
                  and status(*read(runs, r["demo"], base)).startswith("ok")]
        bad += len(failed)
        gm = math.exp(sum(math.log(x) for x in ratios) / len(ratios)) if ratios else float("nan")
        instr = [r["instructions_vs_stock"] for r in rows if r["solver"] == solver
                 and r.get("instructions_vs_stock") and r["status"].startswith("ok")]
        if instr:
            gi = math.exp(sum(math.log(x) for x in instr) / len(instr))
            worst_i = sorted(((r["instructions_vs_stock"], r["demo"]) for r in rows if r["solver"] == solver
                              and r.get("instructions_vs_stock")), reverse=True)[:5]
            print("%s: geometric mean of instructions in the step calls against stock %.2fx over %d demos; "
                  "above 3x: %d; most: %s" % (solver, gi, len(instr), sum(1 for x in instr if x > 3),
                                               ", ".join("%s %.1fx" % (d, x) for x, d in worst_i)))
        print("%s: geometric mean step_vs_stock %.2fx over %d demos; above 3x: %d; worst: %s; "
              "frames unconverged (all demos): %d; crashed/NaN/timeout where stock was fine: %s" % (
                  solver, gm, len(ratios), sum(1 for x in ratios if x > 3),
                  ", ".join("%s %.1fx" % (d, x) for x, d in worst), unconv,
                  ", ".join("%s (%s)" % (r["demo"], r["status"]) for r in failed) or "none"))
    skipped = os.path.join(runs, "skipped.txt")
    if os.path.exists(skipped):
        print("not run: " + open(skipped).read().strip())
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
