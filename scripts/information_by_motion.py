#!/usr/bin/python3
"""Where a KITTI raw drive's information on x_caml comes from, by the vehicle's motion.

    scripts/information_by_motion.py ESTIMATES.csv KITTI_RAW_DIR [--threshold-dps 3]
        [--stamp-offset S]

ESTIMATES.csv is `evaluate --kitti-raw KITTI_RAW_DIR ... --out OUT`'s OUT/estimates.csv, or
that of a simulated drive of the same motion (`kitti_raw_to_bag --tum`, a scenario with that
trajectory, `simulate`, `evaluate`) with --stamp-offset = its first pair's time in the drive's
clock minus its own first stamp. Each
pair's information gain on a parameter is how much 1/sigma^2 grew over the pair (the marginal
sigma: a first look, blind to correlations, and net of the drift noise the prediction added).
The pair is put in one class by the OXTS record nearest its stamp: "turning" (|yaw rate| above
the threshold), else "pitching/rolling" (|pitch| or |roll rate| above it), else "straight".
Prints, per x_caml parameter, the share of the drive's positive gain from each class beside
the share of pairs in it, and the five pairs of largest gain with their motion. A share of
information far above the class's share of pairs shows what motion the filter learns a
parameter from: on a car, zl from bumps' pitch and roll, xl and yl from the turns.
"""
import argparse
import bisect
import csv
import datetime
import math
import os
import sys

PARAMETERS = ["xl", "yl", "zl", "roll_l", "pitch_l", "yaw_l"]
CLASSES = ["turning", "pitching/rolling", "straight"]
# OXTS record fields (KITTI raw devkit): vf 8, wf 20, wl 21, wu 22 (roll, pitch, yaw rates).
VF, WF, WL, WU = 8, 20, 21, 22


def kitti_stamp(text):
    day, clock = text.strip().split(" ")
    whole, _, fraction = clock.partition(".")
    t = datetime.datetime.strptime(day + " " + whole, "%Y-%m-%d %H:%M:%S")
    return t.replace(tzinfo=datetime.timezone.utc).timestamp() + float("0." + (fraction or "0"))


def read_oxts(drive):
    """{stamp: record} of the OXTS records present in DRIVE/oxts/data."""
    stamps_path = os.path.join(drive, "oxts", "timestamps.txt")
    data = os.path.join(drive, "oxts", "data")
    if not os.path.isfile(stamps_path) or not os.path.isdir(data):
        sys.exit(f"information_by_motion.py: no oxts/timestamps.txt and oxts/data in {drive}")
    with open(stamps_path) as f:
        stamps = [kitti_stamp(line) for line in f if line.strip()]
    records = {}
    for name in sorted(os.listdir(data)):
        index = int(os.path.splitext(name)[0])
        if index >= len(stamps):
            continue
        with open(os.path.join(data, name)) as f:
            values = [float(v) for v in f.read().split()]
        if len(values) >= 25:
            records[stamps[index]] = values
    if not records:
        sys.exit(f"information_by_motion.py: no OXTS record in {data}")
    return records


def nearest(stamps, t):
    k = bisect.bisect_left(stamps, t)
    candidates = [c for c in (k - 1, k) if 0 <= c < len(stamps)]
    return min(candidates, key=lambda c: abs(stamps[c] - t))


def classify(record, threshold):
    roll, pitch, yaw = (math.degrees(record[i]) for i in (WF, WL, WU))
    if abs(yaw) > threshold:
        return "turning"
    if max(abs(roll), abs(pitch)) > threshold:
        return "pitching/rolling"
    return "straight"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("estimates")
    parser.add_argument("drive")
    parser.add_argument("--threshold-dps", type=float, default=3.0,
                        help="rotation rate (deg/s) above which a pair is turning or pitching")
    parser.add_argument("--stamp-offset", type=float, default=0.0,
                        help="s added to the estimates' stamps before the OXTS lookup")
    args = parser.parse_args()
    if not os.path.isfile(args.estimates):
        sys.exit(f"information_by_motion.py: {args.estimates} not found (evaluate's estimates.csv)")
    with open(args.estimates) as f:
        rows = list(csv.DictReader(f))
    missing = [f"sigma_{p}" for p in PARAMETERS if rows and f"sigma_{p}" not in rows[0]]
    if len(rows) < 2 or missing:
        sys.exit(f"information_by_motion.py: {args.estimates} holds no sigma columns {missing} "
                 "or fewer than 2 pairs")
    records = read_oxts(args.drive)
    stamps = sorted(records)
    pairs = {c: 0 for c in CLASSES}
    gain = {p: {c: 0.0 for c in CLASSES} for p in PARAMETERS}
    largest = {p: [] for p in PARAMETERS}
    for before, row in zip(rows, rows[1:]):
        record = records[stamps[nearest(stamps, float(row["stamp"]) + args.stamp_offset)]]
        kind = classify(record, args.threshold_dps)
        pairs[kind] += 1
        for p in PARAMETERS:
            g = float(row[f"sigma_{p}"]) ** -2 - float(before[f"sigma_{p}"]) ** -2
            if g > 0:
                gain[p][kind] += g
                largest[p].append((g, int(row["frame"]), record))
    total_pairs = sum(pairs.values())
    print(f"{total_pairs} pairs; rotation rate threshold {args.threshold_dps} deg/s\n")
    print("| parameter | " + " | ".join(f"{c} (pairs {100 * pairs[c] / total_pairs:.0f} %)"
                                        for c in CLASSES) + " |")
    print("|---|" + "---|" * len(CLASSES))
    for p in PARAMETERS:
        total = sum(gain[p].values())
        shares = [f"{100 * gain[p][c] / total:.0f} %" if total > 0 else "-" for c in CLASSES]
        print(f"| {p} | " + " | ".join(shares) + " |")
    print("\nShares of each parameter's positive information gain (1/sigma^2) by the pair's "
          "motion.\n")
    for p in PARAMETERS:
        top = sorted(largest[p], key=lambda x: -x[0])[:5]
        text = "; ".join(
            f"pair {frame}: speed {r[VF]:.1f} m/s, roll/pitch/yaw rate "
            f"{math.degrees(r[WF]):.1f}/{math.degrees(r[WL]):.1f}/{math.degrees(r[WU]):.1f} deg/s"
            for _, frame, r in top)
        print(f"- {p}: {text}")


if __name__ == "__main__":
    main()
