#!/usr/bin/env python3
"""Charts from mlcp CSV files: work-precision charts of a sweep, heat maps of a stability grid.

Usage (from the repository, after tools/setup.sh has built .venv):
  .venv/bin/python tools/chart.py work-precision SWEEP.csv -o OUTDIR [--stat mean|median|max]
                                  [--time-stat median|mean|min]
  .venv/bin/python tools/chart.py heatmap STABILITY.csv -o OUTDIR

Both write one PNG and one SVG per scene into OUTDIR and print their paths. A bad file stops
with a message naming the file, the line and what is wrong (exit code 2).

Sweep CSV (`mlcp sweep`, tidy: one row per scene x engine x solver x setting value x step;
columns in any order, extra columns ignored):
  scene            scene name
  engine           bullet | ode | ...
  solver           solver name (registry name or fallback chain)
  setting          name of the swept setting, e.g. iterations, tolerance
  value            its value in this row (a number)
  step             step index, 0-based
  solver_ms        wall time of the MLCP solve(s) in this step, milliseconds
  residual         scaled natural-map residual of the step's MLCP (dimensionless)
  iterations       iterations (or pivots) the solver used
  status           converged | least-squares | max-iterations | time-limit | failed | unsupported |
                   invalid-input | numerical-issue
  fallbacks        number of fallbacks taken in this step
  max_penetration  deepest contact penetration after the step, m
  joint_error      largest joint position error after the step, m
  setting_applies  optional: 0 when the solver ignores the setting (a stock solver run once)
Each point of a chart is one (scene, engine, solver, setting, value): over its steps, the
--time-stat (default median: robust to the odd preempted step on a busy machine) of solver_ms
(x) and the --stat (default mean) of residual (y), max_penetration and joint_error (side
panels). One line per engine + solver (+ setting) runs through the setting's values, labelled
with them (the ends only when there are many lines; a one-point line has its value in the
legend). Hollow markers: some steps failed (failed, unsupported, invalid-input or
numerical-issue). Non-finite values are left out; zeros are drawn at the bottom of the log axis.

Stability CSV (`mlcp stability`; one row per cell):
  engine, solver   as above
  x_name, x_value  the setting along the horizontal axis and its value (a number)
  y_name, y_value  the setting along the vertical axis and its value (a number)
  outcome          stable | drifting | collapsed | exploded | solver-failure
  scene            optional: one chart per scene when present
One panel per engine + solver, cells coloured (and lettered) by outcome.
"""


import argparse
import importlib.util
import os
import sys

# The drawing is the Python package's mlcp.chart (python/mlcp/chart.py), loaded by its path so
# that neither the package's extension module nor a build is needed here.
_spec = importlib.util.spec_from_file_location(
    "mlcp_chart", os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "python",
                               "mlcp", "chart.py"))
_chart = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_chart)
SWEEP_COLUMNS, STABILITY_COLUMNS = _chart.SWEEP_COLUMNS, _chart.STABILITY_COLUMNS
InputError, aggregate, read_rows = _chart.InputError, _chart.aggregate, _chart.read_rows
safe_name, solver_order = _chart.safe_name, _chart.solver_order


def work_precision(args):
    rows = read_rows(args.csv, SWEEP_COLUMNS)
    return _chart.save(_chart.work_precision_figures(args.csv, rows, args.stat, args.time_stat),
                       args.out)


def heatmap(args):
    rows = read_rows(args.csv, STABILITY_COLUMNS)
    return _chart.save(_chart.heatmap_figures(args.csv, rows), args.out)


def main(argv=None):
    parser = argparse.ArgumentParser(
        description="Charts from mlcp CSV files (see the top of this script for the columns).")
    sub = parser.add_subparsers(dest="mode", required=True)
    wp = sub.add_parser("work-precision", help="solver time against residual, per scene")
    wp.add_argument("csv", help="tidy sweep CSV (mlcp sweep)")
    wp.add_argument("-o", "--out", required=True, help="folder for the PNG and SVG files")
    wp.add_argument("--stat", choices=["mean", "median", "max"], default="mean",
                    help="statistic over the steps of each point's residual, penetration and "
                         "joint error (default: mean)")
    wp.add_argument("--time-stat", choices=["median", "mean", "min"], default="median",
                    help="statistic over the steps of each point's solver time (default: "
                         "median)")
    hm = sub.add_parser("heatmap", help="stability grid outcomes")
    hm.add_argument("csv", help="stability CSV (mlcp stability)")
    hm.add_argument("-o", "--out", required=True, help="folder for the PNG and SVG files")
    args = parser.parse_args(argv)
    try:
        written = work_precision(args) if args.mode == "work-precision" else heatmap(args)
    except InputError as e:
        print(f"chart.py: {e}", file=sys.stderr)
        return 2
    for p in written:
        print(p)
    return 0


if __name__ == "__main__":
    sys.exit(main())
