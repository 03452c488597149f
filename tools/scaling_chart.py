#!/usr/bin/env python3
"""Chart and tables of tools/scaling_report.sh: time against island size, log-log.

Usage (tools/scaling_report.sh runs it):
  .venv/bin/python tools/scaling_chart.py --dir BUILD/scaling --png docs/scaling.png \
      --doc docs/benchmarks.md

Reads from --dir: scale_*.csv (tests/bench/scale_bench.sh: one row per scene, engine and solver),
islands.csv (build/bench/siconos_bench: one row per captured island, form and solver; optional),
machine.txt, load_start.txt, load_end.txt. Draws four panels into --png: the time per engine step
against the island's rows in the scenes of one island (one line per engine and solver), and the time per solve of the captured
islands against their rows in each form (findex, lcp, boxed; one line per solver). Marker shapes:
a circle where every step (every solve) met the tolerance by our residual, a cross where some did
not, a triangle where the solver reports no residual (Bullet's SI, ODE's QuickStep). Writes the
section between the markers below into --doc (appended when the markers are missing).
"""
import argparse
import csv
import glob
import math
import os
import re
import sys
import textwrap

BEGIN = "<!-- scaling_report.sh: begin (generated, edit tools/scaling_chart.py) -->"
END = "<!-- scaling_report.sh: end -->"
FORMS = ("findex", "lcp", "boxed")
OURS = ("pgs", "dantzig", "newton", "lemke", "auto")


def num(text):
    try:
        v = float(text)
    except (TypeError, ValueError):
        return math.nan
    return v


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def read_text(path, default=""):
    try:
        with open(path) as f:
            return f.read().strip()
    except OSError:
        return default


def step_points(rows):
    """(engine, solver) -> sorted [(rows, median_ms, marker)] of the one-island runs that reported
    steps."""
    lines = {}
    for r in rows:
        if int(r["steps_done"] or 0) == 0 or r["islands"] != "1":
            continue  # many small islands (stack_1000, boxes_3000): in the table only
        done, conv = int(r["steps_done"]), int(r["converged_steps"] or 0)
        if math.isnan(num(r["worst_residual"])):
            marker = "^"
        else:
            marker = "o" if conv == done else "X"
        lines.setdefault((r["engine"], r["solver"]), []).append(
            (int(r["rows"]), num(r["median_ms"]), marker))
    return {k: sorted(v) for k, v in lines.items()}


def island_points(rows, form):
    """solver -> sorted [(rows, ms, marker)] of the form's solves that returned an answer."""
    lines = {}
    for r in rows:
        if r["form"] != form or math.isnan(num(r["residual"])):
            continue  # no answer: skipped, unsupported, crashed, or stopped with none
        marker = "o" if r["status"] == "converged" else "X"
        lines.setdefault(r["solver"], []).append((int(r["rows"]), num(r["ms"]), marker))
    return {k: sorted(v) for k, v in lines.items()}


def draw_lines(ax, lines, label_of, style_of):
    for key, points in sorted(lines.items()):
        color, dash = style_of(key)
        xs = [p[0] for p in points]
        ys = [max(p[1], 1e-3) for p in points]
        ax.plot(xs, ys, dash, color=color, lw=1.2, label=label_of(key))
        for x, y, m in zip(xs, ys, [p[2] for p in points]):
            ax.plot([x], [y], m, color=color, ms=6 if m != "X" else 7,
                    mfc=color if m == "o" else "none", mew=1.4)
    from matplotlib.ticker import NullFormatter
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.grid(True, which="both", alpha=0.3)


def chart(step_rows, island_rows, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cmap = plt.get_cmap("tab20")
    solvers = sorted({r["solver"] for r in step_rows} | {r["solver"] for r in island_rows})
    color = {s: cmap(i % 20) for i, s in enumerate(solvers)}
    fig, axes = plt.subplots(2, 2, figsize=(15, 11))
    ax = axes[0][0]
    draw_lines(ax, step_points(step_rows), lambda k: "%s %s" % k,
               lambda k: (color[k[1]], "-" if k[0] == "bullet" else "--"))
    ax.set_title("Engine step, one-island scenes (solid Bullet, dashed ODE)")
    ax.set_xlabel("rows of the step's island")
    ax.set_ylabel("median ms per step")
    ax.legend(fontsize=7, ncol=2)
    for ax, form in zip((axes[0][1], axes[1][0], axes[1][1]), FORMS):
        draw_lines(ax, island_points(island_rows, form), lambda k: k,
                   lambda k: (color[k], "-" if k in OURS else ":"))
        ax.set_title({"findex": "Captured islands as engines hand them over (findex): ours",
                      "lcp": "Frictionless LCP of each island: ours (solid), Siconos (dotted)",
                      "boxed": "Friction bounds fixed at a reference's normals: ours, Siconos"}[form])
        ax.set_xlabel("rows of the island's problem")
        ax.set_ylabel("ms per solve")
        if ax.lines:
            ax.legend(fontsize=7, ncol=2)
    fig.suptitle("Time against island size at tolerance 1e-6 (circle: met it by our residual; "
                 "cross: did not; triangle: no residual reported)", fontsize=11)
    fig.tight_layout()
    fig.savefig(png, dpi=90)
    plt.close(fig)


def fmt_ms(v):
    if math.isnan(v):
        return "-"
    return "%.3g" % v if v < 100 else "%.0f" % v


def fmt_res(text):
    v = num(text)
    return "-" if math.isnan(v) else "%.2g" % v


LIMITED = {"1": "cut at the time limit", "2": "skipped: dense n x n above 12000 rows",
           "3": "failed (memory limit or crash)"}


def step_table(rows):
    out = ["| scene | engine | rows (islands, largest) | solver | steps | median ms/step "
           "(solver) | median ms/step (whole) | worst residual | converged | note |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        done = int(r["steps_done"] or 0)
        note = LIMITED.get(r["limited"], "")
        out.append("| %s | %s | %s (%s, %s) | %s | %d | %s | %s | %s | %s/%d | %s |" % (
            r["scene"], r["engine"], r["rows"], r["islands"], r["largest_island"], r["solver"],
            done, fmt_ms(num(r["median_ms"])), fmt_ms(num(r["median_step_ms"])),
            fmt_res(r["worst_residual"]), r["converged_steps"] or 0, done, note))
    return out


def cell(r):
    if r["status"] == "skipped":
        return "skipped"
    if r["status"] == "time-limit":
        return "> limit"
    if r["status"] == "crashed":
        return "crashed"
    if math.isnan(num(r["residual"])):
        return r["status"]
    mark = "" if r["status"] == "converged" else " **x**"
    return "%s ms, %s%s" % (fmt_ms(num(r["ms"])), fmt_res(r["residual"]), mark)


def island_table(rows, form):
    mine = [r for r in rows if r["form"] == form]
    solvers = []
    for r in mine:
        if r["solver"] not in solvers:
            solvers.append(r["solver"])
    islands = []
    for r in mine:
        if (r["island"], r["rows"]) not in islands:
            islands.append((r["island"], r["rows"]))
    islands.sort(key=lambda k: int(k[1]))
    by = {(r["island"], r["solver"]): r for r in mine}
    out = ["| island | rows | " + " | ".join(solvers) + " |",
           "|---|---|" + "---|" * len(solvers)]
    for island, n in islands:
        cells = [cell(by[(island, s)]) if (island, s) in by else "" for s in solvers]
        out.append("| %s | %s | %s |" % (island.replace("-island0", ""), n, " | ".join(cells)))
    return out


def section(d, step_rows, island_rows, png_name):
    machine = read_text(os.path.join(d, "machine.txt")).splitlines()
    load0 = read_text(os.path.join(d, "load_start.txt"))
    load1 = read_text(os.path.join(d, "load_end.txt"))
    load = lambda t: re.sub(r".*load average: ", "", t)
    settings = machine[2] if len(machine) > 2 else ""
    lines = [
        BEGIN,
        "## Scaling against the stock solvers and Siconos (`tools/scaling_report.sh`)",
        "",
        "One command regenerates this section and `docs/%s` (Release build in `build/`, "
        "Siconos numerics from `libsiconos-numerics-dev` for the island tables):" % png_name,
        "",
        "    tools/build.sh build && tools/scaling_report.sh",
        "",
        "%s; %s; %s. Load average (1, 5, 15 min) %s at the start, %s at the end: the machine is "
        "shared with other builds, so times are inflated and noisy; compare within one table." % (
            machine[0] if machine else "commit ?", machine[1] if len(machine) > 1 else "",
            settings, load(load0), load(load1)),
        "",
        "![time against island size](%s)" % png_name,
        "",
        "**Engine steps** (`tests/bench/scale_bench.sh`): each scene in each engine with each "
        "solver, tolerance 1e-6, no fallback; ours pgs, dantzig and newton without a time budget "
        "(each solve runs to the tolerance or the scene's 50 iterations), auto with its default "
        "per-step budget of 0.05 s. The stock solvers run as the engines ship them (SI 10 "
        "iterations, QuickStep 20; dWorldStep and btMLCPSolver exact pivoting); SI and QuickStep "
        "report no residual; dWorldStep's is measured against the exact friction bounds while "
        "it fixes them once from an intermediate normal, hence its residuals near 1. `rows` "
        "counts every island's rows at step 0. stack_1000 is 100 separate columns (islands) of "
        "10 cubes, and boxes_3000 100 columns of 30 cubes whose upper cubes fall onto the bottom "
        "layer during the 40 steps: these two are in the table only, the chart's first panel "
        "shows the scenes of one island. A run cut at the limit reports no step (`mlcp run` "
        "writes its CSV at the end); each run may use 8 GB of address space, and a run that "
        "ended otherwise (an allocation refused, a crash) is marked failed.",
        "",
    ]
    lines += step_table(step_rows)
    if island_rows:
        lines += [
            "",
            "**Captured islands** (`build/bench/siconos_bench`, the largest island of each scene "
            "at step 5 in each engine): each island solved by ours (pgs, dantzig, newton, lemke, "
            "auto from the registry) and by Siconos numerics 4.4 on the same rows, from zero, "
            "each solve cut at the limit above. Cells: time of the solve, our residual "
            "(`residual.hpp`, recomputed for every answer) and **x** where it misses 1e-6. Siconos "
            "has no friction coupling (findex), so it takes two forms of each island:",
            "",
            "- *lcp*: the frictionless LCP (the contact rows alone; Bullet's 1e10 upper bound "
            "taken as +inf), for lcp_newton_FB (Fischer-Burmeister), lcp_newton_min, "
            "lcp_newton_minFB, lcp_lexicolemke and lcp_pgs;",
            "- *boxed*: every row, with the **friction bounds fixed at the normals of a reference "
            "answer** (our lowest-residual answer of the findex form) and findex dropped, for "
            "Siconos' relay (box-constrained) solvers relay_pgs, relay_lexicolemke and "
            "relay_avi_caoferris. This is not the engine's problem: its answers solve the findex "
            "problem only where their normals equal the reference's (the CSV's findex_residual "
            "says how far that holds). Infinite bounds are capped at 10 (1 + |x_ref|_inf) for the "
            "relay solvers (relay Lemke doubles the box into an LCP with ub - lb).",
            "",
            "Siconos gets A dense (the storage these solvers take; islands above 6000 rows, or "
            "3000 for relay Lemke, are skipped), ours the captured sparse storage. Tolerances "
            "match: Siconos measures the same natural map in the 2-norm scaled by ||q||_2 (LCP) or "
            "1 + ||q||_2 (relay), ours in the infinity norm scaled by 1 + ||b||_inf; Siconos' "
            "tolerance is set to 1e-6 (1 + ||q||_inf) / ||q||_2 (or / (1 + ||q||_2)), so that an "
            "answer it accepts meets ours, and convergence is then judged by our residual alone. "
            "Limits: 1000 Newton steps or PGS sweeps; Lemke 50 n + 100 pivots; our dantzig 1000 "
            "friction passes. Each Siconos solve runs in a child process (killed at the limit), "
            "OpenBLAS on one thread.",
        ]
        for form, title in (("findex", "Islands as the engines hand them over (findex), ours"),
                            ("lcp", "Frictionless LCP"),
                            ("boxed", "Friction bounds fixed from the reference (relay)")):
            if any(r["form"] == form for r in island_rows):
                lines += ["", "*%s:*" % title, ""] + island_table(island_rows, form)
    lines += ["", END]
    return "\n".join(wrap(line) for line in lines) + "\n"


def wrap(line):
    """Prose at 100 columns as the rest of docs/ (tables, code, images and markers as they are)."""
    if not line or line.startswith(("|", "    ", "<!--", "![", "#")):
        return line
    indent = "  " if line.startswith("- ") else ""
    return textwrap.fill(line, width=100, subsequent_indent=indent, break_long_words=False,
                         break_on_hyphens=False)


def write_section(doc, text):
    old = read_text(doc, "") + "\n" if os.path.exists(doc) else ""
    if BEGIN in old and END in old:
        head, rest = old.split(BEGIN, 1)
        tail = rest.split(END, 1)[1].lstrip("\n")
        new = head + text + ("\n" + tail if tail.strip() else "")
    else:
        new = old.rstrip("\n") + "\n\n" + text if old.strip() else text
    with open(doc, "w") as f:
        f.write(new)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dir", required=True)
    ap.add_argument("--png", required=True)
    ap.add_argument("--doc", required=True)
    a = ap.parse_args()
    step_rows = []
    for path in sorted(glob.glob(os.path.join(a.dir, "scale_*.csv")),
                       key=lambda p: ("small" not in p, "large" not in p, p)):
        step_rows += read_csv(path)
    islands = os.path.join(a.dir, "islands.csv")
    island_rows = read_csv(islands) if os.path.exists(islands) else []
    if not step_rows and not island_rows:
        print("scaling_chart: no scale_*.csv or islands.csv in %s" % a.dir, file=sys.stderr)
        return 2
    chart(step_rows, island_rows, a.png)
    png_name = os.path.relpath(a.png, os.path.dirname(os.path.abspath(a.doc)))
    write_section(a.doc, section(a.dir, step_rows, island_rows, png_name))
    print("wrote %s and the section of %s" % (a.png, a.doc))
    return 0


if __name__ == "__main__":
    sys.exit(main())
