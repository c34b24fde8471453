#!/usr/bin/python3
"""What a perfectly consistent filter scores on the campaign's honesty criterion.

The campaign (docs/campaign.md) calls a run honest when, from frame 30 on, all 12 errors are
within 3 sigma in >= 95 % of the frames and none is beyond 5 sigma. Even a filter whose
reported sigmas are exactly right misses that in some runs: 12 parameters each within 3
sigma 99.73 % of the time gives 96.8 % of the frames, and a calibration error changes
slowly, so a run spends long stretches on the same side. This script draws runs of such a
filter, with normalised errors z = error / sigma that are exactly N(0, 1) in every frame, for
two models of how z moves in time:

  constant  the recursive estimate of a constant from independent measurements:
            z_t = (sum of t N(0,1)) / sqrt(t), correlation sqrt(s / t) between frames s < t;
  ar TAU    a first-order process with a correlation time of TAU frames (a calibration
            with a random walk settles into this).

It prints the share of honest runs and of runs beyond the bounds for each, and with
--campaign DIR the same figures of a campaign beside them. Usage:

  scripts/honest_by_chance.py [--campaign DIR] [--runs N] [--frames F] [--tau T ...]
"""
import argparse
import csv
import os
import sys

import numpy as np

FIRST_SCORED_FRAME = 30
PARAMETERS = 12


def constant_model(rng, runs, frames):
    """z of a recursive estimate of a constant (the error is the running mean's)."""
    sums = np.cumsum(rng.standard_normal((runs, PARAMETERS, frames)), axis=2)
    return sums / np.sqrt(np.arange(1, frames + 1))


def ar_model(rng, runs, frames, tau):
    """z of a stationary first-order process with correlation time tau frames."""
    a = np.exp(-1.0 / tau)
    z = np.empty((runs, PARAMETERS, frames))
    z[:, :, 0] = rng.standard_normal((runs, PARAMETERS))
    for t in range(1, frames):
        z[:, :, t] = a * z[:, :, t - 1] + np.sqrt(1 - a * a) * rng.standard_normal((runs, PARAMETERS))
    return z


def scores(z):
    """Per run: share of frames with all 12 |z| <= 3 and the largest |z|, from frame 30 on."""
    z = np.abs(z[:, :, FIRST_SCORED_FRAME:])
    share = 1.0 - (z > 3.0).any(axis=1).mean(axis=1)
    return share, z.max(axis=(1, 2))


def campaign_scores(directory):
    path = os.path.join(directory, "campaign.csv")
    with open(path) as f:
        rows = [r for r in csv.DictReader(f) if r["status"] == "ok"]
    share = np.array([float(r["share_within_3sigma"]) for r in rows])
    beyond5 = np.array([int(r["frames_beyond_5sigma"]) for r in rows])
    max_z = np.array([float(r["max_z"]) for r in rows])
    return share, max_z, beyond5


def line(name, share, max_z, beyond5=None):
    if beyond5 is None:
        beyond5 = (max_z > 5.0).astype(int)
    honest = np.mean((share >= 0.95) & (beyond5 == 0))
    cells = [honest, np.mean(share < 0.95), np.mean(share < 0.9), np.mean(share < 0.8),
             np.mean(max_z > 4.0), np.mean(beyond5 > 0), share.mean()]
    return "| %s | %d | " % (name, len(share)) + " | ".join("%.3f" % c for c in cells) + " |"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--campaign", action="append", default=[],
                        help="a campaign directory (with campaign.csv); may repeat")
    parser.add_argument("--runs", type=int, default=4000, help="drawn runs per model (4000)")
    parser.add_argument("--frames", type=int, default=600, help="frames per run (600)")
    parser.add_argument("--tau", type=float, nargs="*", default=[30.0, 100.0, 300.0],
                        help="correlation times of the ar model, frames (30 100 300)")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    if args.frames <= FIRST_SCORED_FRAME:
        sys.exit("honest_by_chance: --frames must be above %d" % FIRST_SCORED_FRAME)
    rng = np.random.default_rng(args.seed)

    print("| runs of | runs | honest | share < 0.95 | share < 0.9 | share < 0.8 | max_z > 4 "
          "| beyond 5 sigma | mean share |")
    print("|---|---|---|---|---|---|---|---|---|")
    print(line("consistent, constant", *scores(constant_model(rng, args.runs, args.frames))))
    for tau in args.tau:
        print(line("consistent, ar %g frames" % tau,
                   *scores(ar_model(rng, args.runs, args.frames, tau))))
    for directory in args.campaign:
        print(line("campaign " + directory, *campaign_scores(directory)))


if __name__ == "__main__":
    main()
