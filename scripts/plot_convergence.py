#!/usr/bin/python3
"""Convergence plots of an online_stereo_calibration run, like Fig. 5 and 6 of the seed paper.

Reads DIR/estimates.csv (the per-frame CSV of docs interface: frame, stamp, 12 parameters,
12 sigmas, tracked_points, time_ms; metres and radians) and, if present, DIR/reference.csv
(frame, stamp, 12 parameters). Writes
  DIR/vehicle_to_left.png  x_caml: estimate (black), 1-sigma band (grey), reference (yellow)
  DIR/left_to_right.png    x_camr: the same
  DIR/errors.png           estimate - reference with the +-2-sigma band (needs the reference)
Units on the plots: m and deg.

Usage: plot_convergence.py --out DIR [--step-frame N] [--first-frame N] [--last-frame N]
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
    import numpy as np  # noqa: E402
except ImportError as error:
    sys.exit("plot_convergence: %s for %s; run it with /usr/bin/python3 or install "
             "python3-matplotlib" % (error, sys.executable))

PARAMETERS = ["xl", "yl", "zl", "roll_l", "pitch_l", "yaw_l",
              "xr", "yr", "zr", "roll_r", "pitch_r", "yaw_r"]
ESTIMATE_COLUMNS = (["frame", "stamp"] + PARAMETERS + ["sigma_" + p for p in PARAMETERS]
                    + ["tracked_points", "time_ms"])
REFERENCE_COLUMNS = ["frame", "stamp"] + PARAMETERS
LABELS = ["x", "y", "z", "roll", "pitch", "yaw"]


class InputError(Exception):
    """A missing or malformed input file."""


def is_angle(index):
    return index % 6 >= 3


def read_csv(path, columns):
    """Returns {column: np.array} for the listed columns; raises InputError with the reason."""
    if not os.path.isfile(path):
        raise InputError("%s: file not found" % path)
    with open(path, newline="") as handle:
        reader = csv.reader(handle)
        header = next(reader, None)
        if header is None:
            raise InputError("%s: empty file" % path)
        header = [name.strip() for name in header]
        if header[:len(columns)] != columns:
            missing = [c for c in columns if c not in header]
            detail = ("missing columns: " + ", ".join(missing)) if missing else "wrong column order"
            raise InputError("%s: header must start with\n  %s\n%s\nfound\n  %s"
                             % (path, ",".join(columns), detail, ",".join(header)))
        rows = []
        for line_number, row in enumerate(reader, start=2):
            if not row or all(not field.strip() for field in row):
                continue
            if len(row) < len(columns):
                raise InputError("%s, line %d: %d fields, expected %d"
                                 % (path, line_number, len(row), len(columns)))
            try:
                rows.append([float(field) for field in row[:len(columns)]])
            except ValueError as error:
                raise InputError("%s, line %d: %s" % (path, line_number, error))
    if not rows:
        raise InputError("%s: no data rows" % path)
    data = np.array(rows, dtype=float)
    table = {name: data[:, i] for i, name in enumerate(columns)}
    order = np.argsort(table["frame"], kind="stable")
    return {name: values[order] for name, values in table.items()}


def wrap(angle):
    """Wraps radians to (-pi, pi]."""
    return -((-angle + math.pi) % (2.0 * math.pi) - math.pi)


def match_reference(estimates, reference):
    """Reference parameters at the estimate frames (NaN where the reference has no such frame)."""
    index = {int(frame): i for i, frame in enumerate(reference["frame"])}
    rows = [index.get(int(frame), -1) for frame in estimates["frame"]]
    matched = {}
    for name in PARAMETERS:
        values = np.full(len(rows), np.nan)
        for k, row in enumerate(rows):
            if row >= 0:
                values[k] = reference[name][row]
        matched[name] = values
    return matched


def display(values, index):
    """m stays m; angles in deg, unwrapped so a track across +-180 deg does not jump."""
    if not is_angle(index):
        return values
    unwrapped = values.copy()
    finite = np.isfinite(values)
    unwrapped[finite] = np.unwrap(values[finite])
    return np.degrees(unwrapped)


def near(values, target):
    """Shifts angle values (deg) by multiples of 360 to lie closest to target on average."""
    both = np.isfinite(values) & np.isfinite(target)
    if not both.any():
        return values
    turns = np.round(np.mean(target[both] - values[both]) / 360.0)
    return values + 360.0 * turns


def unit(index):
    return "deg" if is_angle(index) else "m"


def mark_step(axis, step_frame):
    if step_frame is not None:
        axis.axvline(step_frame, color="tab:red", linestyle="--", linewidth=1.0)


def plot_block(estimates, reference, block, title, path, step_frame):
    """One figure with the six parameters of a block (0: vehicle_to_left, 1: left_to_right)."""
    figure, axes = plt.subplots(3, 2, figsize=(11, 8.5), sharex=True)
    frames = estimates["frame"]
    for j in range(6):
        k = 6 * block + j
        name = PARAMETERS[k]
        axis = axes[j % 3, j // 3]  # left column: x, y, z; right column: roll, pitch, yaw
        estimate = display(estimates[name], k)
        scale = math.degrees(1.0) if is_angle(k) else 1.0
        sigma = estimates["sigma_" + name] * scale
        if reference is not None:
            truth = display(reference[name], k)
            if is_angle(k):
                truth = near(truth, estimate)
            axis.plot(frames, truth, color="gold", linewidth=3.5, label="reference", zorder=1)
        axis.fill_between(frames, estimate - sigma, estimate + sigma, color="0.75",
                          linewidth=0, label="1 sigma", zorder=2)
        axis.plot(frames, estimate, color="black", linewidth=1.0, label="estimate", zorder=3)
        mark_step(axis, step_frame)
        axis.set_ylabel("%s [%s]" % (LABELS[j], unit(k)))
        axis.grid(True, linewidth=0.3)
    for axis in axes[-1, :]:
        axis.set_xlabel("frame")
    axes[0, 0].legend(loc="best", fontsize="small")
    figure.suptitle(title)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def plot_errors(estimates, reference, path, step_frame):
    """Error (estimate - reference, angles wrapped) with the +-2-sigma band, 12 subplots."""
    figure, axes = plt.subplots(6, 2, figsize=(11, 13), sharex=True)
    frames = estimates["frame"]
    for k, name in enumerate(PARAMETERS):
        axis = axes[k % 6, k // 6]  # left column: vehicle_to_left, right: left_to_right
        error = estimates[name] - reference[name]
        if is_angle(k):
            error = wrap(error)
        scale = math.degrees(1.0) if is_angle(k) else 1.0
        error = error * scale
        two_sigma = 2.0 * estimates["sigma_" + name] * scale
        axis.fill_between(frames, -two_sigma, two_sigma, color="0.8", linewidth=0,
                          label="+-2 sigma")
        axis.plot(frames, error, color="black", linewidth=0.8, label="error")
        axis.axhline(0.0, color="gold", linewidth=1.5)
        mark_step(axis, step_frame)
        axis.set_ylabel("%s [%s]" % (name, unit(k)))
        axis.grid(True, linewidth=0.3)
    for axis in axes[-1, :]:
        axis.set_xlabel("frame")
    axes[0, 0].legend(loc="best", fontsize="small")
    figure.suptitle("Error = estimate - reference (left: vehicle_to_left, right: left_to_right)")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def select_frames(table, first, last):
    keep = np.ones(len(table["frame"]), dtype=bool)
    if first is not None:
        keep &= table["frame"] >= first
    if last is not None:
        keep &= table["frame"] <= last
    if not keep.any():
        raise InputError("no frames in the chosen range")
    return {name: values[keep] for name, values in table.items()}


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", required=True, metavar="DIR",
                        help="directory with estimates.csv (and reference.csv); plots go here")
    parser.add_argument("--step-frame", type=int, default=None, metavar="N",
                        help="draw a dashed vertical line at this frame (e.g. a known step)")
    parser.add_argument("--first-frame", type=int, default=None, metavar="N")
    parser.add_argument("--last-frame", type=int, default=None, metavar="N")
    args = parser.parse_args(argv)

    try:
        estimates = read_csv(os.path.join(args.out, "estimates.csv"), ESTIMATE_COLUMNS)
        estimates = select_frames(estimates, args.first_frame, args.last_frame)
        reference_path = os.path.join(args.out, "reference.csv")
        reference = None
        if os.path.exists(reference_path):
            reference = match_reference(estimates, read_csv(reference_path, REFERENCE_COLUMNS))
        else:
            print("plot_convergence: no %s; plotting without reference" % reference_path)
    except InputError as error:
        print("plot_convergence: error: %s" % error, file=sys.stderr)
        return 2

    written = []
    path = os.path.join(args.out, "vehicle_to_left.png")
    plot_block(estimates, reference, 0,
               "vehicle_to_left (x_caml): left camera body frame in the vehicle frame", path,
               args.step_frame)
    written.append(path)
    path = os.path.join(args.out, "left_to_right.png")
    plot_block(estimates, reference, 1,
               "left_to_right (x_camr): right camera body frame in the left camera body frame",
               path, args.step_frame)
    written.append(path)
    if reference is not None:
        path = os.path.join(args.out, "errors.png")
        plot_errors(estimates, reference, path, args.step_frame)
        written.append(path)
    for path in written:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
