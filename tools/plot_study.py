#!/usr/bin/env python3
"""Plots of the accuracy study (shellmpm study): for each reference problem a Pareto plot
(|error| against cost, log-log, every point labelled with its setting, the front
highlighted) and a convergence plot (|error| against the spacing h, with the fitted
order), plus one overview of every problem's Pareto plot.

Every sweep has one colour and marker, the same in every plot (the legends name them);
relative errors are plotted in percent, errors in metres in millimetres.

Usage: plot_study.py RESULTS_JSON OUTDIR
Needs matplotlib (Debian: python3-matplotlib). Prints the files it wrote.
"""
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.ticker import LogFormatter  # noqa: E402

MARKERS = "osD^v<>phP*XH"
# The study's sweeps in a fixed order, so that a sweep keeps its colour and marker from one
# problem, plot and study to the next; names not listed here follow in order of appearance.
KNOWN_SWEEPS = [
    "grid spacing",
    "mesh resolution",
    "quality preset",
    "CFL number",
    "particles per cell",
    "contact samples",
    "mesh / grid spacing",
    "in-plane quadrature",
    "layers through the thickness",
    "transfer",
    "integrator",
    "shell velocities",
    "contact distance",
]


def sweep_styles(problems):
    """Sweep name -> (colour, marker), for every sweep of every problem."""
    names = list(KNOWN_SWEEPS)
    for p in problems:
        for s in p["sweeps"]:
            if s["name"] not in names:
                names.append(s["name"])
    colours = plt.get_cmap("tab20").colors
    # Even entries of tab20 first (the saturated ones), then the light ones.
    order = list(colours[0::2]) + list(colours[1::2])
    return {n: (order[i % len(order)], MARKERS[i % len(MARKERS)]) for i, n in enumerate(names)}


def error_scale(problem):
    """(factor, axis label) turning an |error| into the plotted value."""
    if problem["error_kind"] == "relative":
        return 100.0, "|relative error| [%]"
    if problem["unit"] == "m":
        return 1000.0, "|error| [mm]"
    return 1.0, "|error| [%s]" % problem["unit"]


def cost_label(problem):
    if problem["cost_unit"] == "wall seconds":
        return "cost: wall time [s]"
    if problem["cost_unit"] == "wall seconds per simulated second":
        return "cost: wall time per simulated second [s/s]"
    return "cost [%s]" % problem["cost_unit"]


def abs_error(run):
    e = run.get("error")
    if e is None or run.get("status") != "ok":
        return None
    return max(abs(e), 1e-7)


def pareto_sweeps(problem):
    """The sweeps of a problem with at least one point on its Pareto plot."""
    runs = [r for r in problem["runs"] if "same_as_run" not in r]
    return [s["name"] for s in problem["sweeps"]
            if any(r["sweep"] == s["name"] and abs_error(r) is not None and r["cost"] > 0
                   for r in runs)]


def pareto_axes(ax, problem, styles, small=False):
    """Draws the Pareto plot; returns whether it has a front."""
    scale, ylabel = error_scale(problem)
    runs = [r for r in problem["runs"] if "same_as_run" not in r]
    for sweep in (s["name"] for s in problem["sweeps"]):
        pts = [(r["cost"], abs_error(r) * scale, r["label"]) for r in runs
               if r["sweep"] == sweep and abs_error(r) is not None and r["cost"] > 0]
        if not pts:
            continue
        colour, marker = styles[sweep]
        ax.scatter([p[0] for p in pts], [p[1] for p in pts], marker=marker, color=colour,
                   s=24 if small else 40, label=sweep, zorder=3)
        if not small:
            for c, e, lab in pts:
                ax.annotate(lab, (c, e), textcoords="offset points", xytext=(4, 4), fontsize=7)
    front = sorted((r["cost"], abs_error(r) * scale) for r in runs
                   if r.get("pareto") and abs_error(r) is not None and r["cost"] > 0)
    if front:
        ax.plot([p[0] for p in front], [p[1] for p in front], "-", color="black", lw=1.2,
                alpha=0.6, zorder=2)
        ax.scatter([p[0] for p in front], [p[1] for p in front], s=90 if not small else 50,
                   facecolors="none", edgecolors="black", zorder=4)
    log_axes(ax)
    ax.set_xlabel(cost_label(problem), fontsize=7 if small else 9)
    ax.set_ylabel(ylabel, fontsize=7 if small else 9)
    ax.grid(True, which="both", alpha=0.3)
    return bool(front)


class PlainLogFormatter(LogFormatter):
    """Labels the ticks matplotlib's log formatter labels, written plainly (0.3, 20)."""

    def __call__(self, x, pos=None):
        return "%g" % x if super().__call__(x, pos) else ""


def log_axes(ax):
    """Log-log axes with plain tick labels instead of powers of ten."""
    ax.set_xscale("log")
    ax.set_yscale("log")
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_formatter(PlainLogFormatter(labelOnlyBase=False))
        axis.set_minor_formatter(PlainLogFormatter(labelOnlyBase=False,
                                                   minor_thresholds=(2, 0.5)))


def front_handle():
    """The legend entry of the Pareto front: the circled points joined by a line."""
    return Line2D([], [], color="black", alpha=0.6, lw=1.2, marker="o", markersize=9,
                  markerfacecolor="none", markeredgecolor="black", label="Pareto front")


def convergence_axes(ax, problem, styles):
    scale, ylabel = error_scale(problem)
    drew = False
    fitted = False
    for sweep in problem["sweeps"]:
        if not sweep["refinement"]:
            continue
        pts = [(problem["runs"][i]["h"], abs_error(problem["runs"][i]))
               for i in sweep["runs"]]
        pts = [(h, e * scale) for h, e in pts if e is not None and h > 0]
        if not pts:
            continue
        hs = [p[0] for p in pts]
        es = [p[1] for p in pts]
        order = sweep.get("fitted_order")
        label = sweep["name"] + (" (fitted order %.2f)" % order if order is not None else "")
        colour, marker = styles[sweep["name"]]
        ax.plot(hs, es, "-", marker=marker, color=colour, label=label)
        if order is not None and len(pts) >= 2:
            # The fitted line through the geometric mean of the points.
            lh = sum(math.log(h) for h in hs) / len(hs)
            le = sum(math.log(e) for e in es) / len(es)
            xs = [min(hs), max(hs)]
            ax.plot(xs, [math.exp(le + order * (math.log(x) - lh)) for x in xs], ":",
                    color="gray", label=None if fitted else "fitted power law, |error| ~ h^order")
            fitted = True
        drew = True
    log_axes(ax)
    ax.set_xlabel("spacing h [m] (grid dx, or mesh edge length)")
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    return drew


def main():
    if len(sys.argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    with open(sys.argv[1]) as f:
        results = json.load(f)
    out = sys.argv[2]
    os.makedirs(out, exist_ok=True)
    written = []
    # Problems with no measured run (a --sweep its problem does not have) get no plots.
    problems = [p for p in results["problems"] if any(abs_error(r) is not None for r in p["runs"])]
    styles = sweep_styles(results["problems"])
    for p in problems:
        fig, ax = plt.subplots(figsize=(7, 5))
        has_front = pareto_axes(ax, p, styles)
        ax.set_title("%s\n%s" % (p["title"], p["reference_source"]), fontsize=9)
        handles, _ = ax.get_legend_handles_labels()
        if has_front:
            handles.append(front_handle())
        ax.legend(handles=handles, title="sweep", fontsize=7, title_fontsize=7)
        path = os.path.join(out, "pareto_%s.png" % p["name"])
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)

        fig, ax = plt.subplots(figsize=(6, 4.5))
        if convergence_axes(ax, p, styles):
            ax.set_title("%s: convergence" % p["title"], fontsize=9)
            ax.legend(title="refinement", fontsize=7, title_fontsize=7)
            path = os.path.join(out, "convergence_%s.png" % p["name"])
            fig.tight_layout()
            fig.savefig(path, dpi=110)
            written.append(path)
        plt.close(fig)

    if problems:
        cols = min(3, len(problems))
        rows = (len(problems) + cols - 1) // cols
        # One legend for all panels: the sweeps drawn in any of them, in the fixed order.
        shown = sorted({n for p in problems for n in pareto_sweeps(p)}, key=list(styles).index)
        ncol = 5
        legend_in = 0.35 + 0.22 * ((len(shown) + 1 + ncol - 1) // ncol)
        height = 3.6 * rows + legend_in
        fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, height), squeeze=False)
        for i, p in enumerate(problems):
            ax = axes[i // cols][i % cols]
            pareto_axes(ax, p, styles, small=True)
            ax.set_title(p["name"], fontsize=9)
        for j in range(len(problems), rows * cols):
            axes[j // cols][j % cols].axis("off")
        handles = [Line2D([], [], linestyle="none", marker=styles[n][1], color=styles[n][0],
                          markersize=6, label=n) for n in shown]
        handles.append(front_handle())
        fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), ncol), fontsize=8,
                   title="sweep", title_fontsize=8, frameon=False)
        fig.suptitle("Accuracy against cost (log-log; circled and joined: the Pareto front)",
                     fontsize=10)
        fig.tight_layout(rect=(0, legend_in / height, 1, 1))
        path = os.path.join(out, "study_overview.png")
        fig.savefig(path, dpi=100)
        plt.close(fig)
        written.append(path)
    print("wrote %d plots in %s" % (len(written), out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
