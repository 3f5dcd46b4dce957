#!/usr/bin/env python3
"""Plots of the accuracy study (shellmpm study): for each reference problem a Pareto plot
(|error| against cost, log-log, every point labelled with its setting, the front
highlighted) and a convergence plot (|error| against the spacing h, with the fitted
order), plus one overview of every problem's Pareto plot.

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

MARKERS = "osD^v<>ph*"


def abs_error(run):
    e = run.get("error")
    if e is None or run.get("status") != "ok":
        return None
    return max(abs(e), 1e-7)


def error_label(problem):
    if problem["error_kind"] == "relative":
        return "|relative error|"
    return "|error| [%s]" % problem["unit"]


def pareto_axes(ax, problem, small=False):
    runs = [r for r in problem["runs"] if "same_as_run" not in r]
    sweeps = [s["name"] for s in problem["sweeps"]]
    for k, sweep in enumerate(sweeps):
        pts = [(r["cost"], abs_error(r), r["label"]) for r in runs
               if r["sweep"] == sweep and abs_error(r) is not None and r["cost"] > 0]
        if not pts:
            continue
        ax.scatter([p[0] for p in pts], [p[1] for p in pts], marker=MARKERS[k % len(MARKERS)],
                   s=24 if small else 40, label=sweep, zorder=3)
        if not small:
            for c, e, lab in pts:
                ax.annotate(lab, (c, e), textcoords="offset points", xytext=(4, 4), fontsize=7)
    front = sorted((r["cost"], abs_error(r)) for r in runs
                   if r.get("pareto") and abs_error(r) is not None and r["cost"] > 0)
    if front:
        ax.plot([p[0] for p in front], [p[1] for p in front], "-", color="black", lw=1.2,
                alpha=0.6, label="Pareto front", zorder=2)
        ax.scatter([p[0] for p in front], [p[1] for p in front], s=90 if not small else 50,
                   facecolors="none", edgecolors="black", zorder=4)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(problem["cost_unit"], fontsize=7 if small else 9)
    ax.set_ylabel(error_label(problem), fontsize=7 if small else 9)
    ax.grid(True, which="both", alpha=0.3)


def convergence_axes(ax, problem):
    drew = False
    for k, sweep in enumerate(problem["sweeps"]):
        if not sweep["refinement"]:
            continue
        pts = [(problem["runs"][i]["h"], abs_error(problem["runs"][i]))
               for i in sweep["runs"]]
        pts = [p for p in pts if p[1] is not None and p[0] > 0]
        if not pts:
            continue
        hs = [p[0] for p in pts]
        es = [p[1] for p in pts]
        order = sweep.get("fitted_order")
        label = sweep["name"] + (" (fitted order %.2f)" % order if order is not None else "")
        ax.plot(hs, es, MARKERS[k % len(MARKERS)] + "-", label=label)
        if order is not None and len(pts) >= 2:
            # The fitted line through the geometric mean of the points.
            lh = sum(math.log(h) for h in hs) / len(hs)
            le = sum(math.log(e) for e in es) / len(es)
            xs = [min(hs), max(hs)]
            ax.plot(xs, [math.exp(le + order * (math.log(x) - lh)) for x in xs], ":",
                    color="gray")
        drew = True
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("spacing h [m]")
    ax.set_ylabel(error_label(problem))
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
    for p in problems:
        fig, ax = plt.subplots(figsize=(7, 5))
        pareto_axes(ax, p)
        ax.set_title("%s\n%s" % (p["title"], p["reference_source"]), fontsize=9)
        ax.legend(fontsize=7)
        path = os.path.join(out, "pareto_%s.png" % p["name"])
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)

        fig, ax = plt.subplots(figsize=(6, 4.5))
        if convergence_axes(ax, p):
            ax.set_title("%s: convergence" % p["title"], fontsize=9)
            ax.legend(fontsize=7)
            path = os.path.join(out, "convergence_%s.png" % p["name"])
            fig.tight_layout()
            fig.savefig(path, dpi=110)
            written.append(path)
        plt.close(fig)

    if problems:
        cols = min(3, len(problems))
        rows = (len(problems) + cols - 1) // cols
        fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.6 * rows), squeeze=False)
        for i, p in enumerate(problems):
            ax = axes[i // cols][i % cols]
            pareto_axes(ax, p, small=True)
            ax.set_title(p["name"], fontsize=9)
        for j in range(len(problems), rows * cols):
            axes[j // cols][j % cols].axis("off")
        fig.suptitle("Accuracy against cost (log-log; circled: the Pareto front)", fontsize=10)
        fig.tight_layout()
        path = os.path.join(out, "study_overview.png")
        fig.savefig(path, dpi=100)
        plt.close(fig)
        written.append(path)
    print("wrote %d plots in %s" % (len(written), out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
