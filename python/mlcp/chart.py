"""Work-precision charts of sweeps and heat maps of stability grids, with matplotlib.

mlcp.chart.work_precision(df) and mlcp.chart.heatmap(df) draw DataFrames of mlcp.sweep and
mlcp.stability; tools/chart.py (`mlcp chart`) draws their CSV files with the same functions
(it loads this file by its path, so nothing here imports the rest of the package).
The columns each chart reads, and what its points, lines and colours mean: tools/chart.py.
"""

import csv
import importlib
import math
import os
import re
import statistics
from collections import OrderedDict, defaultdict

# matplotlib is imported by load_pyplot() once the input has been checked: it takes a second
# or two to load, which a bad file should not have to wait for; and tools/report.py imports
# this module's CSV reading with the standard library only.
plt = ListedColormap = Line2D = Patch = FuncFormatter = LogLocator = NullFormatter = None


def require(module, extra):
    """Imports an optional dependency of the package, or raises an ImportError that names the
    extra installing it (`pip install "mlcp[chart]"`; from a clone, `pip install ".[chart]"`)."""
    try:
        return importlib.import_module(module)
    except ImportError as e:
        raise ImportError(
            f"{module} is not installed; mlcp's '{extra}' extra installs it: "
            f"pip install \"mlcp[{extra}]\" (from a clone: pip install \".[{extra}]\")",
            name=module) from e


def load_pyplot():
    global plt, ListedColormap, Line2D, Patch, FuncFormatter, LogLocator, NullFormatter
    matplotlib = require("matplotlib", "chart")

    matplotlib.use("Agg")  # headless: CI has no display
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

SWEEP_COLUMNS = ["scene", "engine", "solver", "setting", "value", "step", "solver_ms",
                 "residual", "iterations", "status", "fallbacks", "max_penetration",
                 "joint_error"]
STABILITY_COLUMNS = ["engine", "solver", "x_name", "x_value", "y_name", "y_value", "outcome"]
FAILED = {"failed", "unsupported", "invalid-input", "numerical-issue"}
STATUSES = ["converged", "least-squares", "max-iterations", "time-limit"] + sorted(FAILED)
OUTCOMES = OrderedDict([  # outcome -> (colour, letter); colour-blind-safe-ish, lettered anyway
    ("stable", ("#1b7837", "S")),
    ("drifting", ("#e8c547", "D")),
    ("collapsed", ("#f4a261", "C")),
    ("exploded", ("#c0392b", "E")),
    ("solver-failure", ("#5e3c99", "F")),
])
ENGINE_STYLE = {"bullet": ("-", "o"), "bullet-multibody": ("-.", "P"), "ode": ("--", "s")}
OTHER_STYLES = [(":", "^"), ("-.", "D"), ((0, (5, 1)), "v")]
LOG_FLOOR = 1e-17  # where zeros go on a log axis
AXIS_NAMES = {  # setting name -> axis label with its unit (other names are shown as they are)
    "time_step": "time step [s]",
    "mass_ratio": "mass ratio (top / bottom box)",
    "height": "stack height [boxes]",
    "iterations": "iterations per solve",
    "tolerance": "tolerance (scaled residual)",
}


class InputError(Exception):
    pass


def read_rows(path, required):
    """The CSV's rows as dicts, after checking the header has every required column."""
    try:
        f = open(path, newline="")
    except OSError as e:
        raise InputError(f"{path}: cannot open ({e.strerror})")
    with f:
        reader = csv.DictReader(f)
        header = reader.fieldnames or []
        missing = [c for c in required if c not in header]
        if missing:
            raise InputError(f"{path}: missing column(s) {', '.join(missing)} "
                             f"(the header has: {', '.join(header) or 'nothing'})")
        rows = []
        for row in reader:
            if None in row or any(row[c] is None for c in required):
                raise InputError(f"{path}: line {reader.line_num}: expected "
                                 f"{len(header)} fields")
            row["_line"] = reader.line_num
            rows.append(row)
    if not rows:
        raise InputError(f"{path}: no data rows")
    return rows


def number(path, row, column, allow_nonfinite=True):
    text = row[column].strip()
    try:
        v = float(text)
    except ValueError:
        raise InputError(f"{path}: line {row['_line']}: column {column}: "
                         f"expected a number, got {text!r}")
    if not allow_nonfinite and not math.isfinite(v):
        raise InputError(f"{path}: line {row['_line']}: column {column}: "
                         f"expected a finite number, got {text!r}")
    return v


def choice(path, row, column, known, what):
    text = row[column].strip()
    if text not in known:
        raise InputError(f"{path}: line {row['_line']}: column {column}: unknown {what} "
                         f"{text!r} (known: {', '.join(known)})")
    return text


def safe_name(text):
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_") or "chart"


def fmt_value(v):
    """Short tick text: 1/240 for time steps and the like, else 4 significant digits."""
    if 0 < abs(v) < 1:
        inverse = 1 / abs(v)
        if abs(inverse - round(inverse)) < 1e-4 * inverse and round(inverse) <= 100000:
            return f"{'-' if v < 0 else ''}1/{round(inverse)}"
    return format(v, ".4g")


def engine_style(engine, engines):
    if engine in ENGINE_STYLE:
        return ENGINE_STYLE[engine]
    others = [e for e in engines if e not in ENGINE_STYLE]
    return OTHER_STYLES[others.index(engine) % len(OTHER_STYLES)]


def tidy_log_axis(axis, lo, hi):
    """Readable ticks on a log axis: over less than 3 decades, plain numbers at 1, 2, 5 x 10^k
    (matplotlib would otherwise label crowded minor ticks); over more, powers of ten only."""
    axis.set_minor_formatter(NullFormatter())
    if hi / lo < 1e3:
        axis.set_major_locator(LogLocator(base=10, subs=(1, 2, 5)))
        axis.set_major_formatter(FuncFormatter(lambda v, _: format(v, "g")))


def save(figures, outdir):
    """Writes each figure as OUTDIR/stem.png and .svg, closes it; returns the paths."""
    os.makedirs(outdir, exist_ok=True)
    paths = []
    for stem, fig in figures.items():
        for ext in ("png", "svg"):
            p = os.path.join(outdir, f"{stem}.{ext}")
            fig.savefig(p, dpi=130 if ext == "png" else None, bbox_inches="tight")
            paths.append(p)
        plt.close(fig)
    return paths


# ----------------------------------------------------------------------------------------------
# Work-precision charts

METRICS = [  # (column, axis label, panel title)
    ("residual", "residual (scaled natural map, \u221e-norm)", "accuracy of the solves"),
    ("max_penetration", "max penetration [m]", "penetration"),
    ("joint_error", "joint error [m]", "joint drift"),
]


REDUCE = {"mean": statistics.fmean, "median": statistics.median, "max": max, "min": min}


def aggregate(path, rows, stat, time_stat):
    groups = defaultdict(list)
    for row in rows:
        choice(path, row, "status", STATUSES, "status")
        key = (row["scene"], row["engine"], row["solver"], row["setting"],
               number(path, row, "value", allow_nonfinite=False))
        groups[key].append(row)
    points = []
    for (scene, engine, solver, setting, value), members in groups.items():
        p = {"scene": scene, "engine": engine, "solver": solver, "setting": setting,
             "value": value, "steps": len(members),
             "applies": any(r.get("setting_applies", "1").strip() != "0" for r in members),
             "failed": sum(r["status"].strip() in FAILED for r in members)}
        for column in ["solver_ms"] + [m[0] for m in METRICS]:
            vals = [number(path, r, column) for r in members]
            vals = [v for v in vals if math.isfinite(v)]
            reduce = REDUCE[time_stat if column == "solver_ms" else stat]
            p[column] = reduce(vals) if vals else math.nan
        points.append(p)
    return points


def work_precision_figures(path, rows, stat="mean", time_stat="median"):
    """{file stem: figure}, one work-precision chart per scene of the sweep rows."""
    points = aggregate(path, rows, stat, time_stat)
    load_pyplot()
    return {safe_name(scene): work_precision_chart(
                scene, [p for p in points if p["scene"] == scene], stat, time_stat)
            for scene in sorted({p["scene"] for p in points})}


def solver_order(solvers):
    """Ours first (registry names), then the stock ones (bullet-*, ode-*), each alphabetical."""
    return sorted(solvers, key=lambda s: (s.startswith(("bullet-", "ode-")), s))


def value_labels(xy, every):
    """(x, y, text) labels for a line's points: points that would overprint one another (within
    ~6% on both log axes) share one label such as "5, 10"; with `every` False only the first
    and last label of the line are kept."""
    groups = []
    for x, y, p in xy:
        if groups and abs(math.log10(x / groups[-1][0])) < 0.025 and \
                abs(math.log10(y / groups[-1][1])) < 0.025:
            groups[-1][2].append(p["value"])
        else:
            groups.append([x, y, [p["value"]]])
    if not every and len(groups) > 2:
        groups = [groups[0], groups[-1]]
    return [(x, y, ", ".join(fmt_value(v) for v in vals)) for x, y, vals in groups]


def work_precision_chart(scene, points, stat, time_stat):
    engines = sorted({p["engine"] for p in points})
    solvers = solver_order({p["solver"] for p in points})
    several_settings = len({p["setting"] for p in points}) > 1
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    # The residual panel always; a side panel for each other metric that has something to show.
    metrics = [m for m in METRICS
               if m[0] == "residual" or any(math.isfinite(p[m[0]]) and p[m[0]] > 0
                                            for p in points)]
    fig, axes = plt.subplots(1, len(metrics), figsize=(6.2 * len(metrics), 4.9), squeeze=False)
    axes = axes[0]
    lines = defaultdict(list)
    for p in points:
        lines[(p["engine"], p["solver"], p["setting"])].append(p)
    every_label = len(lines) <= 6
    clipped = False
    legend = OrderedDict()  # label -> handle, over every panel (a line may miss some panels)
    no_residual = set()
    order = sorted(lines, key=lambda k: (solvers.index(k[1]), k[0], k[2]))
    for rank, (engine, solver, setting) in enumerate(order):
        pts = sorted(lines[(engine, solver, setting)], key=lambda p: p["value"])
        style, marker = engine_style(engine, engines)
        colour = colours[solvers.index(solver) % len(colours)]
        # Earlier lines get bigger markers, so that points on top of one another (auto choosing
        # dantzig, say) show as rings instead of hiding each other.
        size = 9 - 4 * rank / max(len(order) - 1, 1)
        fixed = all(not p["applies"] for p in pts)
        label = f"{engine} / {solver}"
        if fixed:
            label += f" (ignores {setting})"
        elif len(pts) == 1:  # one point: its value goes in the legend, not next to it
            label += f" ({setting} {fmt_value(pts[0]['value'])})"
        elif several_settings:
            label += f" ({setting})"
        for ax, (column, _, _) in zip(axes, metrics):
            xy = [(p["solver_ms"], p[column], p) for p in pts
                  if math.isfinite(p["solver_ms"]) and math.isfinite(p[column])]
            if not xy:
                if column == "residual":
                    no_residual.add(solver)
                continue
            clipped |= any(x <= 0 or y <= 0 for x, y, _ in xy)
            xs = [max(x, LOG_FLOOR) for x, _, _ in xy]
            ys = [max(y, LOG_FLOOR) for _, y, _ in xy]
            (handle,) = ax.plot(xs, ys, linestyle=style, color=colour, linewidth=1.4,
                                marker=marker, markersize=size, label=label, zorder=2 + rank)
            legend.setdefault(label, handle)
            for x, y, (_, _, p) in zip(xs, ys, xy):
                if p["failed"]:
                    ax.plot([x], [y], marker=marker, color=colour, markersize=size,
                            markerfacecolor="white", linestyle="none", zorder=2 + rank)
            if fixed or len(pts) == 1:
                continue
            for x, y, text in value_labels(list(zip(xs, ys, (p for _, _, p in xy))),
                                           every_label):
                ax.annotate(text, (x, y), textcoords="offset points", xytext=(5, 4),
                            fontsize=7, color=colour, zorder=30)
    steps = sorted({p["steps"] for p in points})
    for ax, (column, ylabel, title) in zip(axes, metrics):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(f"solver time per step [ms], {time_stat}")
        ax.set_ylabel(f"{ylabel}, {stat}")
        ax.set_title(title, fontsize=10)
        tidy_log_axis(ax.xaxis, *ax.get_xlim())
        tidy_log_axis(ax.yaxis, *ax.get_ylim())
        ax.grid(True, which="major", alpha=0.35)
        ax.grid(True, which="minor", alpha=0.12)
    handles, labels = list(legend.values()), list(legend)
    if any(p["failed"] for p in points):
        handles.append(Line2D([], [], marker="o", color="grey", markerfacecolor="white",
                              linestyle="none"))
        labels.append("hollow: some steps failed")
    axes[-1].legend(handles, labels, fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1),
                    borderaxespad=0, title="engine / solver", title_fontsize=8, frameon=False)
    settings = sorted({p["setting"] for p in points})
    note = (f"{time_stat} time and {stat} measures over "
            f"{steps[0] if len(steps) == 1 else f'{steps[0]}-{steps[-1]}'} steps; "
            f"points labelled with {', '.join(settings)}; lower left is better")
    if no_residual:
        note += (f"\nno residual for {', '.join(solver_order(no_residual))} (stock iterative "
                 "solvers do not expose their impulses): right-hand panels only")
    if clipped:
        note += f"; zeros drawn at {LOG_FLOOR:g}"
    fig.suptitle(f"{scene}: solver time against accuracy", fontsize=13, fontweight="bold")
    fig.text(0.5, 0.005, note, ha="center", va="bottom", fontsize=8, color="dimgrey")
    fig.tight_layout(rect=(0, 0.06 if no_residual else 0.035, 1, 0.97))
    return fig


# ----------------------------------------------------------------------------------------------
# Stability heat maps


def heatmap_figures(path, rows):
    """{file stem: figure}, one heat map per scene and pair of axes of the stability rows."""
    charts = defaultdict(list)
    for row in rows:
        choice(path, row, "outcome", list(OUTCOMES), "outcome")
        row["x"] = number(path, row, "x_value", allow_nonfinite=False)
        row["y"] = number(path, row, "y_value", allow_nonfinite=False)
        charts[(row.get("scene") or "", row["x_name"], row["y_name"])].append(row)
    load_pyplot()
    several = len({k[1:] for k in charts}) > 1
    figures = {}
    for (scene, x_name, y_name), cells in sorted(charts.items()):
        stem = "stability" + (f"_{scene}" if scene else "") + (
            f"_{y_name}_vs_{x_name}" if several else "")
        figures[safe_name(stem)] = heatmap_chart(scene, x_name, y_name, cells)
    return figures


def heatmap_chart(scene, x_name, y_name, cells):
    xs = sorted({c["x"] for c in cells})
    ys = sorted({c["y"] for c in cells})
    engines = sorted({c["engine"] for c in cells})
    per_engine = [solver_order({c["solver"] for c in cells if c["engine"] == e}) for e in engines]
    # One row per engine, its solvers across (ours first, in the same order in every row, so a
    # solver's panels line up); a square grid when an engine has too many solvers for a row.
    if max(len(s) for s in per_engine) <= 5:
        nrows, ncols = len(engines), max(len(s) for s in per_engine)
        slots = {(e, s): r * ncols + k for r, (e, ss) in enumerate(zip(engines, per_engine))
                 for k, s in enumerate(ss)}
    else:
        flat = [(e, s) for e, ss in zip(engines, per_engine) for s in ss]
        ncols = math.ceil(math.sqrt(len(flat)))
        nrows = math.ceil(len(flat) / ncols)
        slots = {panel: i for i, panel in enumerate(flat)}
    panels = sorted(slots, key=slots.get)
    cw = max(3.2, 0.55 * len(xs) + 1.6)
    ch = max(2.6, 0.42 * len(ys) + 1.3)
    fig, axes = plt.subplots(nrows, ncols, figsize=(cw * ncols, ch * nrows + 0.9),
                             squeeze=False)
    names = list(OUTCOMES)
    cmap = ListedColormap([OUTCOMES[n][0] for n in names])
    cmap.set_bad("#eeeeee")
    used = set(slots.values())
    for i, ax in enumerate(axes.flat):
        ax.set_visible(i in used)
    for engine, solver in panels:
        ax = axes.flat[slots[(engine, solver)]]
        grid = [[math.nan] * len(xs) for _ in ys]
        for c in cells:
            if (c["engine"], c["solver"]) == (engine, solver):
                grid[ys.index(c["y"])][xs.index(c["x"])] = names.index(c["outcome"].strip())
        ax.imshow(grid, cmap=cmap, vmin=-0.5, vmax=len(names) - 0.5, origin="lower",
                  aspect="auto", interpolation="nearest")
        for i, row in enumerate(grid):
            for j, v in enumerate(row):
                if not math.isnan(v):
                    name = names[int(v)]
                    ax.text(j, i, OUTCOMES[name][1], ha="center", va="center", fontsize=8,
                            color="black" if name in ("drifting", "collapsed") else "white")
        ax.set_xticks(range(len(xs)), [fmt_value(x) for x in xs], rotation=45 if len(xs) > 6
                      else 0, fontsize=8)
        ax.set_yticks(range(len(ys)), [fmt_value(y) for y in ys], fontsize=8)
        ax.set_xlabel(AXIS_NAMES.get(x_name, x_name))
        ax.set_ylabel(AXIS_NAMES.get(y_name, y_name))
        ax.set_title(f"{engine} / {solver}", fontsize=10)
    legend = [Patch(facecolor=OUTCOMES[n][0], label=f"{OUTCOMES[n][1]}  {n}") for n in names]
    legend.append(Patch(facecolor="#eeeeee", label="   not run"))
    fig.legend(handles=legend, loc="lower center", ncol=len(legend), fontsize=8,
               frameon=False)
    title = f"{scene}: stability map" if scene else "Stability map"
    fig.suptitle(f"{title}, {AXIS_NAMES.get(y_name, y_name).split(' [')[0]} against "
                 f"{AXIS_NAMES.get(x_name, x_name).split(' [')[0]}", fontsize=13,
                 fontweight="bold")
    fig.tight_layout(rect=(0, 0.07, 1, 0.95))
    return fig


# ----------------------------------------------------------------------------------------------
# From pandas DataFrames (mlcp.sweep, mlcp.stability): the same rows as from their CSV files


def frame_rows(df, required, what):
    """The DataFrame's rows as the CSV reader's dicts of text (after the same column check)."""
    missing = [c for c in required if c not in df.columns]
    if missing:
        raise InputError(f"{what}: missing column(s) {', '.join(missing)} "
                         f"(the frame has: {', '.join(map(str, df.columns)) or 'nothing'})")
    if len(df) == 0:
        raise InputError(f"{what}: no data rows")
    columns = [str(c) for c in df.columns]
    rows = []
    for line, values in enumerate(df.itertuples(index=False, name=None), start=2):
        row = {c: "" if v is None else str(v) for c, v in zip(columns, values)}
        row["_line"] = line
        rows.append(row)
    return rows


def work_precision(df, out=None, stat="mean", time_stat="median"):
    """Work-precision charts of a sweep DataFrame (mlcp.sweep), one per scene, as
    `tools/chart.py work-precision` draws them: {scene file stem: matplotlib Figure}, or with
    `out` a folder, the PNG and SVG files written there (their paths; figures closed).
    stat: mean, median or max over each point's steps (residual, penetration, joint error);
    time_stat: median, mean or min of its solver_ms. Raises ValueError for a frame that is not
    a sweep's."""
    try:
        figures = work_precision_figures("frame", frame_rows(df, SWEEP_COLUMNS, "frame"), stat,
                                         time_stat)
    except InputError as e:
        raise ValueError(str(e)) from None
    return figures if out is None else save(figures, os.fspath(out))


def heatmap(df, out=None):
    """Stability heat maps of a stability DataFrame (mlcp.stability), as `tools/chart.py
    heatmap` draws them: {file stem: Figure}, or with `out` the files written there."""
    try:
        figures = heatmap_figures("frame", frame_rows(df, STABILITY_COLUMNS, "frame"))
    except InputError as e:
        raise ValueError(str(e)) from None
    return figures if out is None else save(figures, os.fspath(out))
