#!/usr/bin/python3
"""Plots of a `campaign` (docs/campaign.md): DIR/campaign.png.

Reads DIR/campaign.csv and plots share_within_3sigma (top row) and max_z (bottom row, log
scale) of each run against the main drawn settings: the start errors of x_caml (largest
|error| per axis, m and deg), the baseline error (percent), the baseline (m), and the motion
kind, mounting and event (categories, runs spread sideways). Honest runs (share_within_3sigma
>= 0.95 and frames_beyond_5sigma = 0) are green, the others red; failed runs are left out
(summary.txt lists them). Dashed lines: share 0.95, z = 3 and z = 5.

Usage: plot_campaign.py --out DIR
"""

import argparse
import csv
import math
import os
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: E402  (after choosing the backend)
except ImportError as error:
    sys.exit("plot_campaign: %s for %s; run it with /usr/bin/python3 or install "
             "python3-matplotlib" % (error, sys.executable))

NUMERIC = [("start_caml_m", "x_caml start error (m, max axis)"),
           ("start_caml_deg", "x_caml start error (deg, max axis)"),
           ("start_baseline_percent", "baseline start error (%)"),
           ("baseline_m", "baseline (m)")]
CATEGORIES = [("motion", "motion"), ("mounting", "mounting"), ("event", "event")]


def number(text):
    try:
        return float(text)
    except ValueError:
        return float("nan")


def read_rows(path):
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        required = ["share_within_3sigma", "max_z", "frames_beyond_5sigma", "status"]
        missing = [c for c in required if c not in (reader.fieldnames or [])]
        if missing:
            sys.exit("plot_campaign: %s lacks the columns %s" % (path, ", ".join(missing)))
        return [row for row in reader if row["status"] == "ok"]


def honest(row):
    return number(row["share_within_3sigma"]) >= 0.95 and row["frames_beyond_5sigma"] == "0"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="campaign directory")
    args = parser.parse_args()
    path = os.path.join(args.out, "campaign.csv")
    if not os.path.isfile(path):
        sys.exit("plot_campaign: %s not found" % path)
    rows = read_rows(path)
    columns = [c for c in NUMERIC + CATEGORIES if rows and c[0] in rows[0]]
    if not rows or not columns:
        sys.exit("plot_campaign: no run that ran in %s" % path)
    colors = ["tab:green" if honest(r) else "tab:red" for r in rows]
    share = [number(r["share_within_3sigma"]) for r in rows]
    max_z = [max(number(r["max_z"]), 1e-3) if not math.isinf(number(r["max_z"])) else 1e6
             for r in rows]

    figure, axes = plt.subplots(2, len(columns), figsize=(3.2 * len(columns), 6.4),
                                squeeze=False, sharey="row")
    for column, (key, label) in enumerate(columns):
        if (key, label) in CATEGORIES:
            kinds = sorted(set(r[key] for r in rows))
            x = [kinds.index(r[key]) + 0.3 * (((i * 0.618) % 1.0) - 0.5)
                 for i, r in enumerate(rows)]
            ticks = (range(len(kinds)), kinds)
        else:
            x = [number(r[key]) for r in rows]
            ticks = None
        for row, (y, name) in enumerate([(share, "share_within_3sigma"), (max_z, "max_z")]):
            ax = axes[row][column]
            ax.scatter(x, y, c=colors, s=14, alpha=0.8)
            if ticks:
                ax.set_xticks(list(ticks[0]))
                ax.set_xticklabels(ticks[1], rotation=30, fontsize=8)
            if row == 1:
                ax.set_yscale("log")
                ax.axhline(3.0, color="grey", linestyle=":", linewidth=0.8)
                ax.axhline(5.0, color="grey", linestyle="--", linewidth=0.8)
                ax.set_xlabel(label, fontsize=9)
            else:
                ax.axhline(0.95, color="grey", linestyle="--", linewidth=0.8)
                ax.set_ylim(-0.05, 1.05)
            if column == 0:
                ax.set_ylabel(name)
            ax.grid(True, alpha=0.3)
    n_honest = sum(honest(r) for r in rows)
    figure.suptitle("campaign %s: %d runs, %d honest (green)" % (args.out, len(rows), n_honest))
    figure.tight_layout()
    out = os.path.join(args.out, "campaign.png")
    figure.savefig(out, dpi=90)
    print("wrote %s" % out)


if __name__ == "__main__":
    main()
