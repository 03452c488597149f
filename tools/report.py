#!/usr/bin/env python3
"""The report folder's summary.md and index.html, from what tools/report.sh put there.

Usage: python3 tools/report.py REPORT_DIR [--note TEXT]...   (standard library only)

Reads from REPORT_DIR:
  sweep.csv           `mlcp sweep` rows (columns: see tools/chart.py); required
  charts/*.png|svg    work-precision charts (`mlcp chart work-precision`), one per scene
  stability.csv       `mlcp stability` cells, and stability/*.png|svg heat maps; optional
  table.md            `mlcp table --markdown` on the worked examples and Siconos problems; optional
Writes summary.md (Markdown) and index.html (charts and tables), and prints their paths.

summary.md has one table per scene, one row per engine + solver, taken at the sweep's most
accurate value (the largest iteration count or the smallest tolerance; a stock solver that
ignores the setting has its one run): mean solver time per step, worst residual, max
penetration and joint error, fallbacks, steps by status, and which solvers answered. A run
that blew up (non-finite state) at any value of the sweep is flagged.

Above them, one table says per scene and engine whether `auto` is on the Pareto front of all
(solver, setting value) points with a measured residual, with the charts' statistics (median
solver ms per step, mean residual); residuals below EXACT count as equal. Each scene's section
lists its fronts.
"""

import argparse
import html
import math
import os
import re
import sys
from collections import Counter, OrderedDict, defaultdict

from chart import SWEEP_COLUMNS, InputError, aggregate, read_rows, safe_name, solver_order

STATUS_SHORT = OrderedDict([("converged", "conv"), ("max-iterations", "max-it"),
                            ("time-limit", "time"), ("least-squares", "lsq"), ("failed", "FAILED"),
                            ("numerical-issue", "NUMERICAL"), ("unsupported", "UNSUPPORTED"),
                            ("invalid-input", "INVALID")])


def num(text):
    try:
        return float(text)
    except ValueError:
        return math.nan


def fmt(v, digits=2):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "—"
    if v == 0:
        return "0"
    if abs(v) >= 1000 or abs(v) < 0.01:
        return f"{v:.{digits - 1}e}".replace("e-0", "e-").replace("e+0", "e")
    return f"{v:.{digits + 1}g}"


def finite_max(values):
    vals = [v for v in values if math.isfinite(v)]
    return max(vals) if vals else math.nan


def summarise(rows):
    """scene -> list of row dicts for the summary tables, and the sweep's setting text."""
    runs = defaultdict(list)  # (scene, engine, solver, value) -> rows
    for r in rows:
        runs[(r["scene"], r["engine"], r["solver"], num(r["value"]))].append(r)
    settings = sorted({r["setting"] for r in rows})
    setting = settings[0] if len(settings) == 1 else "/".join(settings)
    smaller_is_accurate = setting == "tolerance"
    max_steps = defaultdict(int)
    for (scene, _, _, _), members in runs.items():
        max_steps[scene] = max(max_steps[scene], len(members))

    by_solver = defaultdict(dict)  # (scene, engine, solver) -> value -> rows
    for (scene, engine, solver, value), members in runs.items():
        by_solver[(scene, engine, solver)][value] = members
    # Scenes in the sweep's order; per scene, engines alphabetical, our solvers before stock.
    scenes = list(OrderedDict.fromkeys(r["scene"] for r in rows))
    order = solver_order({k[2] for k in by_solver})
    tables = OrderedDict((scene, []) for scene in scenes)
    for (scene, engine, solver), per_value in sorted(
            by_solver.items(), key=lambda kv: (scenes.index(kv[0][0]), kv[0][1],
                                               order.index(kv[0][2]))):
        values = sorted(per_value)
        ref = values[0] if smaller_is_accurate else values[-1]
        members = per_value[ref]
        applies = members[0].get("setting_applies", "1").strip() != "0"
        statuses = Counter(r["status"].strip() for r in members)
        answered = Counter()
        for r in members:
            for token in (r.get("choice") or "").split():
                name, _, count = token.rpartition(":")
                if name and name != "none":
                    answered[name] += int(num(count)) if math.isfinite(num(count)) else 1
        blew = []
        for v in values:
            ms = per_value[v]
            bad = any(not math.isfinite(num(r.get("max_speed", "0"))) for r in ms)
            if bad or len(ms) < max_steps[scene]:
                blew.append(f"{fmt_value(v)} (step {len(ms) - 1})")
        residuals = [num(r["residual"]) for r in members]
        tables[scene].append({
            "engine": engine, "solver": solver,
            "value": fmt_value(ref) if applies else "ignored",
            "steps": len(members),
            "ms": sum(num(r["solver_ms"]) for r in members) / len(members),
            "residual": (math.nan if all(math.isnan(x) for x in residuals)
                         else max((x for x in residuals if not math.isnan(x)))),
            "penetration": finite_max(num(r["max_penetration"]) for r in members),
            "joint": finite_max(num(r["joint_error"]) for r in members),
            "fallbacks": sum(int(num(r["fallbacks"])) for r in members
                             if math.isfinite(num(r["fallbacks"]))),
            "statuses": ", ".join(f"{STATUS_SHORT.get(s, s)} {n}"
                                  for s, n in sorted(statuses.items(),
                                                     key=lambda kv: list(STATUS_SHORT).index(kv[0])
                                                     if kv[0] in STATUS_SHORT else 99)),
            "answered": ", ".join(f"{n} {c}" for n, c in answered.most_common(3)),
            "blew_up": ", ".join(blew),
        })
    return tables, setting


def fmt_value(v):
    return format(v, "g")


# ----------------------------------------------------------------------------------------------
# Pareto front: is `auto` as accurate as the best single solver at no more time?

EXACT = 1e-12  # residuals below this are "exact": equal to each other on the front
TIME_STAT, RESIDUAL_STAT = "median", "mean"  # as on the charts (chart.py's defaults)
# Auto behind its own sole choice by at most this factor counts as that solver ("yes, as"): the
# same computation plus the classification; repeated runs put the two within 0-3% of each other.
SAME_SOLVER_MARGIN = 1.05


def accuracy_key(residual):
    """The residual as the front compares it: rounding noise (1e-15 against 3e-15) is no
    difference in accuracy."""
    return 0.0 if residual < EXACT else residual


def dominates(q, p):
    """q is at least as fast and as accurate as p, and strictly better in one of the two."""
    qa, pa = accuracy_key(q["residual"]), accuracy_key(p["residual"])
    return (q["solver_ms"] <= p["solver_ms"] and qa <= pa
            and (q["solver_ms"] < p["solver_ms"] or qa < pa))


def best_by_accuracy(points):
    """The most accurate point; among equally accurate ones the fastest."""
    return min(points, key=lambda p: (accuracy_key(p["residual"]), p["solver_ms"]),
               default=None)


def sole_choice(rows, scene, engine):
    """The solver auto handed every island with rows to in this scene and engine (the run
    CSV's `choice` column, e.g. "dantzig:3 none:1"), or None when it chose more than one."""
    names = set()
    for r in rows:
        if r["scene"] == scene and r["engine"] == engine and r["solver"] == "auto":
            names.update(t.split(":")[0] for t in str(r["choice"]).split() if t)
    names.discard("none")
    return names.pop() if len(names) == 1 else None


def fronts(path, rows):
    """One dict per scene x engine (sweep order, engines alphabetical): the Pareto front of its
    points with a measured residual, auto's most accurate point, the most accurate point
    of any other solver, whether auto is on the front and, if not, the best point dominating
    it."""
    scenes = list(OrderedDict.fromkeys(r["scene"] for r in rows))
    groups = defaultdict(list)
    for p in aggregate(path, rows, RESIDUAL_STAT, TIME_STAT):
        if math.isfinite(p["solver_ms"]) and math.isfinite(p["residual"]):
            groups[(p["scene"], p["engine"])].append(p)
    out = []
    for (scene, engine), points in sorted(groups.items(),
                                          key=lambda kv: (scenes.index(kv[0][0]), kv[0][1])):
        values = Counter(p["solver"] for p in points)
        for p in points:  # the setting value is part of the name only when the solver swept it
            p["label"] = values[p["solver"]] > 1 and p["applies"]
            p["name"] = p["solver"] + (f" ({p['setting']} {fmt_value(p['value'])})"
                                       if p["label"] else "")
        front = [p for p in points if not any(dominates(q, p) for q in points if q is not p)]
        auto = best_by_accuracy([p for p in points if p["solver"] == "auto"])
        dominating = [q for q in points if auto and dominates(q, auto)]
        choice = sole_choice(rows, scene, engine)
        # Dominated only by its own choice, with the same accuracy: the same computation plus
        # auto's classification, and a time difference within the noise of repeated runs.
        by_itself = bool(dominating) and choice is not None and all(
            q["solver"] == choice and accuracy_key(q["residual"]) == accuracy_key(auto["residual"])
            and auto["solver_ms"] <= SAME_SOLVER_MARGIN * q["solver_ms"] for q in dominating)
        out.append({"scene": scene, "engine": engine, "front": front,
                    "auto": auto, "choice": choice, "by_itself": by_itself,
                    "best": best_by_accuracy([p for p in points if p["solver"] != "auto"]),
                    "by": best_by_accuracy(dominating)})
    return out


def fmt_residual(r):
    return f"{fmt(r)} (exact)" if r < EXACT else fmt(r)


def fmt_ms(ms):
    return fmt(ms, 3)


def front_names(front):
    """"pgs (iterations 5, 10), dantzig": the front fastest first, a solver's neighbouring
    points in one group."""
    groups = []
    for p in sorted(front, key=lambda p: p["solver_ms"]):
        if groups and groups[-1][0]["solver"] == p["solver"] and p["label"]:
            groups[-1].append(p)
        else:
            groups.append([p])
    return ", ".join(g[0]["solver"] + (f" ({g[0]['setting']} "
                                       + ", ".join(fmt_value(p["value"]) for p in g) + ")"
                                       if g[0]["label"] else "") for g in groups)


def verdict(entry):
    auto, by = entry["auto"], entry["by"]
    if auto is None:
        return "— (auto not run)"
    if by is None:
        return "yes"
    if entry["by_itself"]:
        return (f"yes, as {by['name']} (its only choice: the same answers; "
                f"{auto['solver_ms'] / by['solver_ms']:.2f}x its time)")
    exact = ", exact" if by["residual"] < EXACT else ""
    return (f"no, dominated by {by['name']} ({fmt_ms(by['solver_ms'])} ms, residual "
            f"{fmt(by['residual'])}{exact})")


FRONT_COLUMNS = ["scene", "engine", "auto ms/step", "auto residual", "most accurate other",
                 "its ms/step", "its residual", "auto time / its", "auto on the front"]


def front_row(entry):
    auto, best = entry["auto"], entry["best"]
    row = [entry["scene"], entry["engine"]]
    row += ([fmt_ms(auto["solver_ms"]), fmt_residual(auto["residual"])] if auto
            else ["—", "—"])
    row += ([best["name"], fmt_ms(best["solver_ms"]), fmt_residual(best["residual"])] if best
            else ["—", "—", "—"])
    row.append(f"{auto['solver_ms'] / best['solver_ms']:.2f}"
               if auto and best and best["solver_ms"] > 0 else "—")
    row.append(verdict(entry))
    return row


FRONT_INTRO = ("Is `auto` as accurate as the best single solver at no more time? Per scene and "
               "engine, every ({setting} value, solver) point with a measured residual, with the "
               "charts' statistics: " + TIME_STAT + " solver ms per step and " + RESIDUAL_STAT
               + " residual over the run's steps. A point is on the Pareto front when no other "
               "point has both lower-or-equal time and lower-or-equal residual, one of them "
               f"strictly lower. Residuals below {EXACT:g} count as equal (\"exact\"): 1e-15 "
               "against 3e-15 is rounding, not accuracy. Times are compared as measured, "
               "without a margin: *most accurate other* is the point of another solver with "
               "the lowest residual (the fastest among equals), *auto time / its* is auto's time "
               "over its time, and *auto on the front* names the best point that dominates auto, "
               "if one does. Where auto hands every island to one solver and only that "
               "solver's point dominates it, with the same residual and at most "
               f"{SAME_SOLVER_MARGIN:g} times less time, the two are the same computation plus "
               "auto's classification, and their times differ by that and by run-to-run noise "
               "(each run is repeated and each step keeps its shortest time; 0-3% remain): the "
               "verdict says *yes, as* that solver, with the time ratio.")


def front_lines(entries):
    """Per engine: auto against the most accurate other solver, and the front."""
    lines = []
    for e in entries:
        text = f"- {e['engine']}: {front_names(e['front'])}"
        if e["auto"]:
            text += f"; auto on it: {verdict(e)}"
        lines.append(text + ".")
    return lines


COLUMNS = [  # (key, header, formatter)
    ("engine", "engine", str),
    ("solver", "solver", str),
    ("value", "{setting}", str),
    ("steps", "steps", str),
    ("ms", "solver ms/step (mean)", fmt),
    ("residual", "worst residual", fmt),
    ("penetration", "max penetration [m]", fmt),
    ("joint", "max joint error [m]", fmt),
    ("fallbacks", "fallbacks", str),
    ("statuses", "steps by status", str),
    ("answered", "islands answered by", str),
    ("blew_up", "blew up at", str),
]

INTRO = ("Each row: one scene run in one engine with one solver at the sweep's most accurate "
         "{setting} (largest iteration count / smallest tolerance; `ignored`: a stock solver "
         "that does not use it, run once). Residual: scaled natural-map residual of the "
         "step's MLCP (— : not measured, stock iterative solvers do not expose their "
         "impulses). *blew up at* (only when something did): {setting} values at which the state "
         "became non-finite, and the step.")


def columns(rows):
    """COLUMNS, without "blew up at" when nothing blew up."""
    return [c for c in COLUMNS if c[0] != "blew_up" or any(r["blew_up"] for r in rows)]


def markdown_summary(tables, setting, notes, pareto):
    lines = ["# mlcp comparison: summary", ""]
    lines += [f"- {n}" for n in notes] + ([""] if notes else [])
    lines += ["## auto on the Pareto front", "", FRONT_INTRO.format(setting=setting), ""]
    lines.append("| " + " | ".join(FRONT_COLUMNS) + " |")
    lines.append("|" + "---|" * len(FRONT_COLUMNS))
    lines += ["| " + " | ".join(front_row(e)) + " |" for e in pareto]
    lines += ["", INTRO.format(setting=setting), ""]
    for scene, rows in tables.items():
        lines += [f"## {scene}", ""]
        entries = [e for e in pareto if e["scene"] == scene]
        if entries:
            lines += ["Pareto front, fastest first (" + TIME_STAT + " ms, " + RESIDUAL_STAT
                      + " residual; see the top):"] + front_lines(entries) + [""]
        cols = columns(rows)
        lines.append("| " + " | ".join(h.format(setting=setting) for _, h, _ in cols) + " |")
        lines.append("|" + "---|" * len(cols))
        for row in rows:
            lines.append("| " + " | ".join(f(row[k]) for k, _, f in cols) + " |")
        lines.append("")
    return "\n".join(lines)


# ----------------------------------------------------------------------------------------------
# HTML


def html_table(header, rows, numeric=()):
    out = ["<table>", "<thead><tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in header)
           + "</tr></thead>", "<tbody>"]
    for row in rows:
        cells = []
        for i, c in enumerate(row):
            cls = ' class="num"' if i in numeric else ""
            text = html.escape(c)
            text = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", text)
            if re.search(r"FAILED|NUMERICAL|UNSUPPORTED|INVALID", c) or (
                    header[i] == "blew up at" and c):
                cls = ' class="bad"'
            cells.append(f"<td{cls}>{text}</td>")
        out.append("<tr>" + "".join(cells) + "</tr>")
    out += ["</tbody>", "</table>"]
    return "\n".join(out)


def markdown_to_html(text):
    """The pipe tables, bullet lists and paragraphs `mlcp table --markdown` prints."""
    out, table, items = [], [], []

    def flush():
        if table:
            header = [c.strip() for c in table[0].strip("|").split("|")]
            body = [[c.strip() for c in line.strip().strip("|").split("|")]
                    for line in table[2:]]
            out.append(html_table(header, body, numeric=range(1, len(header))))
            table.clear()
        if items:
            out.append("<ul>" + "".join(f"<li>{html.escape(i)}</li>" for i in items) + "</ul>")
            items.clear()

    for line in text.splitlines():
        if line.startswith("|"):
            table.append(line)
        elif line.startswith("- "):
            items.append(line[2:])
        else:
            flush()
            if line.strip():
                out.append(f"<p>{html.escape(line)}</p>")
    flush()
    return "\n".join(out)


CSS = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 1400px; color: #222;
       padding: 0 1em; }
h1 { margin-bottom: 0.2em; } h2 { margin-top: 2em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; font-size: 0.85em; margin: 0.5em 0 1.5em; }
th, td { border: 1px solid #ddd; padding: 3px 8px; text-align: left; }
th { background: #f3f3f3; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
td.bad { background: #fde2e1; } tr:hover td { background: #f7f9ff; }
img { max-width: 100%; border: 1px solid #eee; margin: 0.5em 0 1.5em; }
.note { color: #555; font-size: 0.9em; } nav a { margin-right: 1em; }
"""


def figures(out_dir, sub):
    folder = os.path.join(out_dir, sub)
    if not os.path.isdir(folder):
        return []
    return sorted(f[:-4] for f in os.listdir(folder) if f.endswith(".png"))


def index_html(out_dir, tables, setting, notes, pareto):
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>mlcp comparison</title>"
             f"<style>{CSS}</style></head><body>", "<h1>mlcp comparison report</h1>"]
    parts += [f"<p class='note'>{html.escape(n)}</p>" for n in notes]
    found = figures(out_dir, "charts")
    charts = [safe_name(s) for s in tables if safe_name(s) in found]
    charts += [c for c in found if c not in charts]
    stability = figures(out_dir, "stability")
    has_table = os.path.exists(os.path.join(out_dir, "table.md"))
    nav = [("pareto", "auto on the Pareto front"), ("summary", "Summary"),
           ("charts", "Work-precision charts")]
    nav += [("stability", "Stability map")] + ([("siconos", "Siconos table")] if has_table else [])
    parts.append("<nav>" + "".join(f"<a href='#{a}'>{t}</a>" for a, t in nav) + "</nav>")

    parts.append("<h2 id='pareto'>auto on the Pareto front</h2>")
    parts.append(f"<p class='note'>{html.escape(FRONT_INTRO.format(setting=setting))}</p>")
    parts.append(html_table(FRONT_COLUMNS, [front_row(e) for e in pareto],
                            numeric=(2, 3, 5, 6, 7)))

    parts.append("<h2 id='summary'>Summary</h2>")
    parts.append(f"<p class='note'>{html.escape(INTRO.format(setting=setting))} "
                 "Also as <a href='summary.md'>summary.md</a>; every step is in "
                 "<a href='sweep.csv'>sweep.csv</a>.</p>")
    for scene, rows in tables.items():
        cols = columns(rows)
        header = [h.format(setting=setting) for _, h, _ in cols]
        numeric = [i for i, (k, _, _) in enumerate(cols)
                   if k in ("steps", "ms", "residual", "penetration", "joint", "fallbacks")]
        parts.append(f"<h3>{html.escape(scene)}</h3>")
        entries = [e for e in pareto if e["scene"] == scene]
        if entries:
            parts.append("<p class='note'>Pareto front, fastest first:</p><ul class='note'>"
                         + "".join(f"<li>{html.escape(line[2:])}</li>"
                                   for line in front_lines(entries)) + "</ul>")
        parts.append(html_table(header, [[f(r[k]) for k, _, f in cols] for r in rows],
                                numeric))

    parts.append("<h2 id='charts'>Work-precision charts</h2>")
    parts.append("<p class='note'>One chart per scene: x = mean solver time per step, "
                 "y = mean residual (left) and penetration / joint drift (right); one line per "
                 f"engine + solver through the {html.escape(setting)} values; lower left is "
                 "better. Click a chart for its SVG.</p>")
    for stem in charts:
        parts.append(f"<h3>{html.escape(stem)}</h3><a href='charts/{stem}.svg'>"
                     f"<img src='charts/{stem}.png' alt='{html.escape(stem)}'></a>")

    parts.append("<h2 id='stability'>Stability map</h2>")
    if stability:
        parts.append("<p class='note'>Cells in <a href='stability.csv'>stability.csv</a>; "
                     "thresholds in <code>mlcp stability --help</code>.</p>")
        for stem in stability:
            parts.append(f"<a href='stability/{stem}.svg'><img src='stability/{stem}.png' "
                         f"alt='{html.escape(stem)}'></a>")
    else:
        parts.append("<p class='note'>Not in this report (no stability.csv: "
                     "<code>mlcp stability</code> was not run).</p>")

    if has_table:
        parts.append("<h2 id='siconos'>Seed and Siconos problems</h2>")
        parts.append("<p class='note'><code>mlcp table --markdown</code>: each solver on the "
                     "the worked examples and the Siconos LCP corpus; a cell is the residual "
                     "reached (tolerance 1e-10) or the status, with the reasons below. Also as "
                     "<a href='table.md'>table.md</a>.</p>")
        with open(os.path.join(out_dir, "table.md")) as f:
            parts.append(markdown_to_html(f.read()))
    parts.append("</body></html>")
    return "\n".join(parts)


def main(argv=None):
    parser = argparse.ArgumentParser(description="summary.md and index.html of a report folder")
    parser.add_argument("dir", help="report folder (holds sweep.csv, charts/, ...)")
    parser.add_argument("--note", action="append", default=[],
                        help="a line for the top of the report (repeatable)")
    args = parser.parse_args(argv)
    csv_path = os.path.join(args.dir, "sweep.csv")
    try:
        rows = read_rows(csv_path, SWEEP_COLUMNS)
        tables, setting = summarise(rows)
        pareto = fronts(csv_path, rows)
    except InputError as e:
        print(f"report.py: {e}", file=sys.stderr)
        return 2
    written = []
    for name, text in (("summary.md", markdown_summary(tables, setting, args.note, pareto)),
                       ("index.html", index_html(args.dir, tables, setting, args.note,
                                                 pareto))):
        path = os.path.join(args.dir, name)
        with open(path, "w") as f:
            f.write(text + "\n")
        written.append(path)
    for p in written:
        print(p)
    return 0


if __name__ == "__main__":
    sys.exit(main())
