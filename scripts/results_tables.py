#!/usr/bin/python3
"""Markdown tables of docs/RESULTS.md from the outputs of scripts/results.sh.

  results_tables.py rmse DIR [DIR ...] [--window FIRST LAST]
      Pooled RMSE per parameter over the window's frames of every run directory (each with
      estimates.csv and reference.csv, as calibrate_simulation writes them), beside the
      paper's Table I; angles wrapped to +-180 deg.
  results_tables.py kitti LOG
      The last printed frame of each KITTI sequence of test_kitti's diagnostic, as a table.
  results_tables.py kitti_raw DIR
      evaluate --kitti-raw's output against KITTI's chain: the last pair's error and sigma, and
      the share of pairs from pair 30 on within 3 sigma with the truth's own sigma added.
  results_tables.py splice DOC DIR --stamp TEXT
      Puts each DIR/NAME.md into DOC between its <!-- results:NAME --> markers.
  results_tables.py ablation DIR VARIANT [VARIANT ...]
      scripts/ablation.sh's table: per variant (DIR/VARIANT/{drawn,phase0,po}) the campaigns'
      honest runs and frames beyond 5 sigma and paper_offroad's RMSE relative to `shipped`.
  results_tables.py campaign DIR
      A campaign's honesty (campaign.csv) beside what a perfectly consistent filter scores on
      the same number of frames, as the campaign printed it (summary.txt, perfect_filter.h).

The campaign table's columns: honest runs (all 12 errors within 3 sigma in >= 95 % of the
frames from frame 30 on and none beyond 5 sigma), runs with a frame beyond 5 sigma, those
frames (of them in an unseen change: a knock inside a blind stretch, nothing tracked since),
the mean share of frames within 3 sigma, and CONVERGED frames with some error beyond 3 sigma.
"""
import argparse
import csv
import math
import os
import sys

import numpy as np

NAMES = ["xl", "yl", "zl", "roll_l", "pitch_l", "yaw_l",
         "xr", "yr", "zr", "roll_r", "pitch_r", "yaw_r"]
ANGLE = [False] * 3 + [True] * 3 + [False] * 3 + [True] * 3
# Mueller & Wuensche 2016, Table I: RMSE (m, deg); the same values as
# src/tools/lib/evaluation.cpp paperTableRmse().
PAPER_RMSE = [0.0608, 0.0382, 0.0132, 0.2995, 0.7061, 0.2844,
              0.0044, 0.0048, 0.0037, 0.0236, 0.0174, 0.0193]


def read_frames(path):
    with open(path) as f:
        return {int(row["frame"]): row for row in csv.DictReader(f)}


def pooled_rmse(directories, first, last):
    """Per parameter (m, rad) over the window's frames of every run directory."""
    squares = np.zeros(12)
    count = 0
    for directory in directories:
        estimates = read_frames(os.path.join(directory, "estimates.csv"))
        reference = read_frames(os.path.join(directory, "reference.csv"))
        for frame in range(first, last + 1):
            if frame not in estimates or frame not in reference:
                sys.exit("results_tables: %s has no frame %d in estimates.csv and reference.csv"
                         % (directory, frame))
            for k, name in enumerate(NAMES):
                error = float(estimates[frame][name]) - float(reference[frame][name])
                if ANGLE[k]:
                    error = math.remainder(error, 2.0 * math.pi)
                squares[k] += error * error
            count += 1
    return np.sqrt(squares / count)


def rmse_table(directories, first, last):
    rmse = pooled_rmse(directories, first, last)
    units = ["mm" if not a else "deg" for a in ANGLE]
    head = "| | " + " | ".join("%s %s" % (n, u) for n, u in zip(NAMES, units)) + " |"
    print(head)
    print("|---|" + "---:|" * 12)

    def cells(values):
        out = []
        for k, v in enumerate(values):
            out.append("%.4f" % v if ANGLE[k] else "%.2f" % (v * 1e3))
        return " | ".join(out)

    ours = [rmse[k] * (180.0 / math.pi if ANGLE[k] else 1.0) for k in range(12)]
    print("| ours, %d runs x frames %d-%d | %s |" % (len(directories), first, last, cells(ours)))
    print("| paper, Table I | %s |" % cells(PAPER_RMSE))
    ratio = " | ".join("%.2f" % (ours[k] / PAPER_RMSE[k]) for k in range(12))
    print("| ours / paper | %s |" % ratio)


def honest_runs(directory):
    """{run: honest?} of a campaign directory (a failed run is not honest)."""
    with open(os.path.join(directory, "campaign.csv")) as f:
        return {r["run"]: r["status"] == "ok" and float(r["share_within_3sigma"]) >= 0.95
                and int(r["frames_beyond_5sigma"]) == 0 for r in csv.DictReader(f)}


def campaign_counts(directory):
    """(honest runs, runs, frames beyond 5 sigma) of a campaign directory."""
    with open(os.path.join(directory, "campaign.csv")) as f:
        rows = list(csv.DictReader(f))
    honest = sum(honest_runs(directory).values())
    beyond = sum(int(r["frames_beyond_5sigma"]) for r in rows if r["status"] == "ok")
    return honest, len(rows), beyond


def ablation_table(directory, variants, first=1000, last=1150):
    """One row per variant of scripts/ablation.sh; RMSE relative to `shipped`. A variant on
    the same runs as `shipped` (not `noise`) also shows, paired, the runs it made dishonest
    and honest: both 0 when switching the mechanism off changes no run's verdict."""
    def seeds(variant):
        root = os.path.join(directory, variant, "po")
        return [os.path.join(root, d) for d in sorted(os.listdir(root))]

    shipped = pooled_rmse(seeds("shipped"), first, last)
    print("| switched off | drawn: honest (lost, gained) / frames > 5σ "
          "| phase-0: honest (lost, gained) / frames > 5σ "
          "| paper_offroad RMSE / shipped: largest (parameter) | pitch_l |")
    print("|---|---|---|---|---|")
    for variant in variants:
        cells = []
        for campaign in ("drawn", "phase0"):
            path = os.path.join(directory, variant, campaign)
            honest, runs, beyond = campaign_counts(path)
            paired = ""
            if variant not in ("shipped", "noise"):
                base = honest_runs(os.path.join(directory, "shipped", campaign))
                mine = honest_runs(path)
                lost = sum(1 for k, v in base.items() if v and not mine.get(k, False))
                gained = sum(1 for k, v in mine.items() if v and not base.get(k, False))
                paired = " (-%d, +%d)" % (lost, gained)
            cells.append("%d of %d%s / %d" % (honest, runs, paired, beyond))
        ratio = pooled_rmse(seeds(variant), first, last) / shipped
        largest = int(np.argmax(np.abs(np.log(ratio))))
        label = {"shipped": "nothing (shipped)",
                 "noise": "nothing, runs from seed 1001 (noise)"}.get(variant, variant)
        print("| %s | %s | %s | %.2f (%s) | %.2f |" % (label, cells[0], cells[1], ratio[largest],
                                                      NAMES[largest], ratio[4]))


def perfect_filter_line(directory):
    """What the campaign printed for a perfect filter on its runs' frames (summary.txt; the
    model of tools/perfect_filter.h): honest share range, share of runs beyond 5 sigma, mean
    share within 3 sigma, as printed."""
    import re
    path = os.path.join(directory, "summary.txt")
    text = open(path).read() if os.path.exists(path) else ""
    m = re.search(r"honest in (\d+)-(\d+) % of the runs, some frame beyond 5 sigma in "
                  r"([0-9.]+) %, mean share within 3 sigma ([0-9.]+)", text)
    if not m:
        sys.exit("results_tables: %s has no perfect-filter line (rerun the campaign)" % path)
    return m.groups()


def campaign_table(directory):
    with open(os.path.join(directory, "campaign.csv")) as f:
        rows = list(csv.DictReader(f))
    ok = [r for r in rows if r["status"] == "ok"]
    if not ok:
        sys.exit("results_tables: %s has no run that ran" % directory)
    frames = int(ok[0]["frames"])
    share = np.array([float(r["share_within_3sigma"]) for r in ok])
    beyond = np.array([int(r["frames_beyond_5sigma"]) for r in ok])
    unseen = np.array([int(r["frames_beyond_5sigma_unseen"]) for r in ok])
    converged = sum(int(r["frames_converged"]) for r in ok)
    converged_off = sum(int(r["frames_converged_beyond_3sigma"]) for r in ok)
    honest = int(np.sum((share >= 0.95) & (beyond == 0)))
    n = len(rows)

    perfect = perfect_filter_line(directory)
    print("| %d runs x %d frames | honest | runs beyond 5σ | frames beyond 5σ (unseen) "
          "| mean share within 3σ | CONVERGED frames beyond 3σ |" % (n, frames))
    print("|---|---|---|---|---|---|")
    print("| this estimator | %d of %d (%.1f %%) | %d (%.1f %%) | %d (%d) | %.3f | %d of %d (%.1f %%) |"
          % (honest, n, 100.0 * honest / n, int(np.sum(beyond > 0)), 100.0 * np.mean(beyond > 0),
             int(beyond.sum()), int(unseen.sum()), share.mean(), converged_off, converged,
             100.0 * converged_off / max(converged, 1)))
    print("| a perfect filter | %s-%s %% | %s %% | - | %s | ~3 %% |" % perfect)
    failed = n - len(ok)
    if failed:
        print("\n%d runs failed (status in campaign.csv)." % failed)


def kitti_table(log):
    """The last printed frame of each sequence of Kitti.DISABLED_Diagnostic's printout: error
    (1 sigma) against KITTI's calibration, as test_kitti prints them (m, deg, ms)."""
    import re
    last = {}
    for line in open(log):
        if re.match(r"^seq[12] ", line):
            last[line.split()[0]] = line
    if not last:
        sys.exit("results_tables: %s holds no 'seqN' line of the KITTI diagnostic" % log)
    number = r"([+-][0-9.]+)\(([0-9.]+)\)"

    def value(line, name):
        m = re.search(name + " " + number, line)
        return (float(m.group(1)), float(m.group(2))) if m else (float("nan"), float("nan"))

    print("| frame %s, error (1σ) | yr | roll_r | pitch_r | yaw_r | xl, yl, zl m | pitch_l | yaw_l "
          "| time offset |" % next(iter(last.values())).split()[1])
    print("|---|---|---|---|---|---|---|---|---|")
    for seq in sorted(last):
        line = last[seq]
        yr = value(line, "yr")
        angles = ["%+.3f° (%.3f)" % value(line, n) for n in ("roll_r", "pitch_r", "yaw_r")]
        xyz = ", ".join("%+.2f (%.2f)" % value(line, n) for n in ("xl", "yl", "zl"))
        left = ["%+.3f° (%.3f)" % value(line, n) for n in ("pitch_l", "yaw_l")]
        dt = value(line, "dt")
        print("| %s | %+.1f mm (%.1f) | %s | %s | %s | %+.1f ms (%.1f) |"
              % (seq, 1e3 * yr[0], 1e3 * yr[1], " | ".join(angles), xyz, " | ".join(left),
                 dt[0], dt[1]))


# How well the KITTI raw drive's truth is known, 1 sigma per parameter (m, rad): its README
# (xl 0.07 m, yl and zl 0.05 m, x_caml's angles 0.3-0.4 deg, taken 0.4; x_camr 2 mm, 0.03 deg).
KITTI_RAW_TRUTH_SIGMA = [0.07, 0.05, 0.05] + [math.radians(0.4)] * 3 + [0.002] * 3 + \
    [math.radians(0.03)] * 3


def kitti_raw_table(directory, first=30):
    """evaluate --kitti-raw's estimates.csv against its reference.csv (KITTI's chain): the last
    pair's error and 1 sigma per parameter, and from pair @p first on the share of pairs within
    3 and beyond 5 of the sigma with the truth's own added."""
    names = ["xl", "yl", "zl", "roll_l", "pitch_l", "yaw_l", "xr", "yr", "zr", "roll_r",
             "pitch_r", "yaw_r"]
    with open(os.path.join(directory, "estimates.csv")) as f:
        estimates = {int(r["frame"]): r for r in csv.DictReader(f)}
    with open(os.path.join(directory, "reference.csv")) as f:
        reference = {int(r["frame"]): r for r in csv.DictReader(f)}
    frames = sorted(k for k in estimates if k in reference)
    if not frames:
        sys.exit("results_tables: %s has no pair with a reference" % directory)
    judged = [k for k in frames if k >= first]
    last = frames[-1]

    def shown(p, value):  # mm / deg / m as the interface reads them
        if p in (6, 7, 8):
            return "%+.1f mm" % (1e3 * value), "%.1f" % (1e3 * value)
        if p < 3:
            return "%+.3f m" % value, "%.3f" % value
        return "%+.3f°" % math.degrees(value), "%.3f" % math.degrees(value)

    print("| at the last pair (%d) | error ± 1σ | within 3σ from pair %d (truth's σ added) | "
          "beyond 5σ |" % (last, first))
    print("|---|---|---|---|")
    every_within, every_beyond = 0, 0
    within_all = [True] * len(judged)
    for p, name in enumerate(names):
        error = float(estimates[last][name]) - float(reference[last][name])
        sigma = float(estimates[last]["sigma_" + name])
        within = beyond = 0
        for i, k in enumerate(judged):
            e = float(estimates[k][name]) - float(reference[k][name])
            s = math.hypot(float(estimates[k]["sigma_" + name]), KITTI_RAW_TRUTH_SIGMA[p])
            within += abs(e) <= 3 * s
            beyond += abs(e) > 5 * s
            within_all[i] = within_all[i] and abs(e) <= 3 * s
        e_text = shown(p, error)[0]
        s_text = shown(p, sigma)[1]
        print("| %s | %s ± %s | %.0f %% | %d |" % (name, e_text, s_text,
                                                 100.0 * within / max(1, len(judged)), beyond))
        every_beyond += beyond
    print("\nAll 12 within 3σ (truth's σ added) in %d of %d pairs from pair %d on (%.0f %%); "
          "%d parameter-pairs beyond 5σ." % (sum(within_all), len(judged), first,
                                             100.0 * sum(within_all) / max(1, len(judged)),
                                             every_beyond))


def splice(document, directory, stamp):
    """Replaces the text between each <!-- results:NAME --> and <!-- /results:NAME --> of
    @p document with DIRECTORY/NAME.md, under a line saying where it was measured."""
    with open(document) as f:
        text = f.read()
    replaced = []
    for name in sorted(os.listdir(directory)):
        if not name.endswith(".md"):
            continue
        key = name[:-3]
        begin, end = "<!-- results:%s -->" % key, "<!-- /results:%s -->" % key
        if begin not in text or end not in text:
            continue
        with open(os.path.join(directory, name)) as f:
            table = f.read().strip()
        head, rest = text.split(begin, 1)
        _, tail = rest.split(end, 1)
        text = "%s%s\n%s\n\n%s\n%s%s" % (head, begin, stamp, table, end, tail)
        replaced.append(key)
    if not replaced:
        sys.exit("results_tables: no table of %s has a marker in %s" % (directory, document))
    tmp = document + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, document)
    print("results_tables: replaced %s in %s" % (", ".join(replaced), document))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    rmse = sub.add_parser("rmse")
    rmse.add_argument("directories", nargs="+")
    rmse.add_argument("--window", type=int, nargs=2, default=[1000, 1150])
    camp = sub.add_parser("campaign")
    camp.add_argument("directory")
    kit = sub.add_parser("kitti")
    kit.add_argument("log")
    raw = sub.add_parser("kitti_raw")
    raw.add_argument("directory")
    spl = sub.add_parser("splice")
    spl.add_argument("document")
    spl.add_argument("directory")
    spl.add_argument("--stamp", required=True, help="the line above each table")
    abl = sub.add_parser("ablation")
    abl.add_argument("directory")
    abl.add_argument("variants", nargs="+")
    args = parser.parse_args()
    if args.command == "rmse":
        rmse_table(args.directories, args.window[0], args.window[1])
    elif args.command == "kitti":
        kitti_table(args.log)
    elif args.command == "kitti_raw":
        kitti_raw_table(args.directory)
    elif args.command == "splice":
        splice(args.document, args.directory, args.stamp)
    elif args.command == "ablation":
        ablation_table(args.directory, args.variants)
    else:
        campaign_table(args.directory)


if __name__ == "__main__":
    main()
