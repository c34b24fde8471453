#!/usr/bin/python3
"""Watches the calibration node for scripts/reliability/soak.sh and kill_resume.sh.

Sub-commands:
  soak      count ~calibration messages (and any non-finite value in them), /diagnostics
            calibration statuses and the node's RSS per loop of a bag played with
            `rosbag play -l --clock` (a loop ends when /clock jumps back); print a table,
            write a JSON summary; exit 1 on a failure (node gone, NaN, a loop without
            messages or statuses, timeout).
  first     wait for the first ~calibration message of a (re)started node and compare it
            with a calibration file: parameters to --tolerance (absolute), covariance to
            --cov-tolerance (relative to its largest entry); exit 1 when they differ.
  validate  check a calibration file as the package's reader (parseCalibrationYaml) and
            writer (formatCalibrationYaml) define it; exit 1 when it is not valid.

The message classes are built from the definition the publisher sends (rospy.AnyMsg +
genpy.dynamic), so the package's Python messages and geometry_msgs/diagnostic_msgs for
Python are not needed. Only the system python3 with rospy, genpy, yaml and numpy.
"""
import argparse
import json
import math
import os
import sys
import threading
import time

import numpy
import yaml

KEYS6 = ("vehicle_to_left", "left_to_right")
SIGMA_KEYS = ("sigma_vehicle_to_left", "sigma_left_to_right")
# Every key writeCalibrationFileAtomic writes for the node (the last one is the covariance:
# a file cut anywhere misses it or is not valid YAML).
WRITTEN_KEYS = KEYS6 + SIGMA_KEYS + ("stamp", "covariance")


# ---------------------------------------------------------------------------- files
def check_calibration_file(path):
    """(parameters[12], covariance[144] or None, error or None), as parseCalibrationYaml."""
    try:
        with open(path, "rb") as f:
            raw = f.read()
    except OSError as e:
        return None, None, "cannot open: %s" % e
    if not raw.endswith(b"\n"):
        return None, None, "does not end with a newline (truncated?)"
    try:
        root = yaml.safe_load(raw.decode("utf-8"))
    except (yaml.YAMLError, UnicodeDecodeError) as e:
        return None, None, "invalid YAML: %s" % str(e).replace("\n", " ")
    if not isinstance(root, dict):
        return None, None, "expected a map with keys vehicle_to_left, left_to_right"

    def vector(key, n):
        value = root.get(key)
        if not isinstance(value, list) or len(value) != n:
            raise ValueError("key '%s' must be a list of %d numbers" % (key, n))
        out = []
        for i, x in enumerate(value):
            if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
                raise ValueError("key '%s[%d]' is not a finite number" % (key, i))
            out.append(float(x))
        return out

    try:
        parameters = vector(KEYS6[0], 6) + vector(KEYS6[1], 6)
        missing = [k for k in WRITTEN_KEYS if k not in root]
        if missing:
            raise ValueError("keys the node writes are missing (truncated?): " + ", ".join(missing))
        sigmas = vector(SIGMA_KEYS[0], 6) + vector(SIGMA_KEYS[1], 6)
        if min(sigmas) < 0.0:
            raise ValueError("a sigma is negative")
        stamp = root["stamp"]
        if isinstance(stamp, bool) or not isinstance(stamp, (int, float)) or not math.isfinite(stamp):
            raise ValueError("key 'stamp' is not a finite number")
        covariance = vector("covariance", 144)
        c = numpy.array(covariance).reshape(12, 12)
        scale = numpy.abs(c).max()
        if numpy.abs(c - c.T).max() > 1e-9 * scale:
            raise ValueError("key 'covariance' is not symmetric")
        if scale == 0.0:
            raise ValueError("key 'covariance' is not positive definite")
        try:
            numpy.linalg.cholesky(c)
        except numpy.linalg.LinAlgError:
            raise ValueError("key 'covariance' is not positive definite")
        for i in range(12):
            variance = sigmas[i] ** 2
            if abs(c[i, i] - variance) > 1e-6 * max(variance, c[i, i]):
                raise ValueError("covariance[%d] disagrees with the square of its sigma" % (13 * i))
    except ValueError as e:
        return None, None, str(e)
    return parameters, covariance, None


def cmd_validate(args):
    parameters, _, error = check_calibration_file(args.file)
    print(json.dumps({"file": args.file, "valid": error is None, "error": error,
                      "parameters": parameters}))
    return 0 if error is None else 1


# ---------------------------------------------------------------------------- ROS
class Decoder:
    """rospy.AnyMsg -> message object, class generated from the connection header."""

    def __init__(self):
        self.classes = {}

    def __call__(self, raw):
        import genpy.dynamic
        header = raw._connection_header
        key = (header["type"], header.get("md5sum"))
        if key not in self.classes:
            generated = genpy.dynamic.generate_dynamic(header["type"], header["message_definition"])
            self.classes[key] = generated[header["type"]]
        msg = self.classes[key]()
        msg.deserialize(raw._buff)
        return msg


def non_finite(msg):
    """Names of the fields of a StereoCalibration message holding NaN or Inf."""
    bad = []
    for name in ("parameters", "covariance", "sigma"):
        if not all(math.isfinite(x) for x in getattr(msg, name)):
            bad.append(name)
    for name in ("vehicle_to_left", "left_to_right"):
        t = getattr(msg, name)
        values = (t.translation.x, t.translation.y, t.translation.z,
                  t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w)
        if not all(math.isfinite(x) for x in values):
            bad.append(name)
    if not math.isfinite(msg.processing_time):
        bad.append("processing_time")
    return bad


def rss_kib(pid):
    """Resident set size of @p pid in KiB, None when the process is gone (or a zombie)."""
    try:
        with open("/proc/%d/status" % pid) as f:
            text = f.read()
    except OSError:
        return None
    fields = dict(line.split(":", 1) for line in text.splitlines() if ":" in line)
    if fields.get("State", "").strip().startswith("Z"):
        return None
    return int(fields["VmRSS"].split()[0]) if "VmRSS" in fields else None


def init_ros(name):
    import rospy
    rospy.init_node(name, anonymous=True, disable_signals=True)
    return rospy


def touch(path):
    if path:
        with open(path, "w") as f:
            f.write("%d\n" % os.getpid())


STATE_NAMES = {0: "INITIALIZING", 1: "CONVERGING", 2: "CONVERGED", 3: "DIVERGED"}
LEVEL_NAMES = {0: "OK", 1: "WARN", 2: "ERROR", 3: "STALE"}


def cmd_soak(args):
    rospy = init_ros("reliability_soak_monitor")
    from rosgraph_msgs.msg import Clock
    decode = Decoder()
    lock = threading.Lock()
    done = threading.Event()     # /clock ended the last loop
    stopped = threading.Event()  # 1 s later: counting stops (late messages still count)
    n = args.loops
    loops = [{"messages": 0, "nan": 0, "statuses": 0, "levels": {}, "states": {},
              "status_stamps": [],
              "rss_end_kib": None, "wall_end_s": None, "stamps": [None, None]}
             for _ in range(n)]
    state = {"loop": 0, "clock": None, "rss_max": 0, "rss_samples": [], "failure": None,
             "nan_examples": [], "started": None, "last_message_wall": None, "seq_gaps": 0,
             "last_seq": None}

    rss0 = rss_kib(args.pid)
    if rss0 is None:
        print("monitor: node pid %d not running" % args.pid, file=sys.stderr)
        return 1
    state["rss_start"] = rss0
    state["rss_max"] = rss0

    def finish_loop():
        k = state["loop"]
        loops[k]["rss_end_kib"] = rss_kib(args.pid)
        loops[k]["wall_end_s"] = time.time() - (state["started"] or time.time())
        state["loop"] = k + 1
        if state["loop"] >= n:
            done.set()

    def on_clock(msg):
        t = msg.clock.to_sec()
        with lock:
            if done.is_set():
                return
            if state["started"] is None:
                state["started"] = time.time()
            if state["clock"] is not None and t < state["clock"] - args.jump:
                finish_loop()
            state["clock"] = t

    # Messages and statuses count for the loop their own stamps say (a stamp jumping back
    # starts the next loop), so that one published just before /clock's jump arrives is
    # not counted in the wrong loop; those after the last loop are not counted.
    stream_loop = {}

    def loop_of(stream, stamp):
        last, k = stream_loop.get(stream, (None, 0))
        if last is not None and stamp < last - args.jump:
            k += 1
        stream_loop[stream] = (stamp, k)
        return k

    def on_calibration(raw):
        msg = decode(raw)
        with lock:
            if stopped.is_set() or state["started"] is None:
                return
            stamp = msg.header.stamp.to_sec()
            k = loop_of("calibration", stamp)
            if k >= n:
                return
            entry = loops[k]
            entry["messages"] += 1
            if entry["stamps"][0] is None:
                entry["stamps"][0] = stamp
            entry["stamps"][1] = stamp
            s = STATE_NAMES.get(msg.state, str(msg.state))
            entry["states"][s] = entry["states"].get(s, 0) + 1
            bad = non_finite(msg)
            if bad:
                entry["nan"] += 1
                if len(state["nan_examples"]) < 5:
                    state["nan_examples"].append({"stamp": stamp, "fields": bad})
            state["last_message_wall"] = time.time()

    def on_diagnostics(raw):
        msg = decode(raw)
        with lock:
            if stopped.is_set() or state["started"] is None:
                return
            k = loop_of("diagnostics", msg.header.stamp.to_sec())
            if k >= n:
                return
            entry = loops[k]
            for status in msg.status:
                if status.name.endswith(": calibration"):
                    entry["statuses"] += 1
                    entry["status_stamps"].append(round(msg.header.stamp.to_sec(), 3))
                    level = LEVEL_NAMES.get(ord(status.level) if isinstance(status.level, bytes)
                                            else status.level, str(status.level))
                    entry["levels"][level] = entry["levels"].get(level, 0) + 1

    rospy.Subscriber("/clock", Clock, on_clock, queue_size=100)
    rospy.Subscriber(args.topic, rospy.AnyMsg, on_calibration, queue_size=1000)
    rospy.Subscriber("/diagnostics", rospy.AnyMsg, on_diagnostics, queue_size=100)
    time.sleep(1.0)  # connections to the node's publishers before playback starts
    touch(args.ready_file)

    deadline = time.time() + args.timeout
    next_sample = time.time()
    while not done.is_set():
        now = time.time()
        if now >= next_sample:
            rss = rss_kib(args.pid)
            if rss is None:
                state["failure"] = "node (pid %d) is gone" % args.pid
                break
            with lock:
                state["rss_max"] = max(state["rss_max"], rss)
                state["rss_samples"].append([round(now - (state["started"] or now), 1),
                                             state["loop"], rss])
            next_sample = now + args.rss_period
        if now > deadline:
            state["failure"] = "timeout after %.0f s: %d of %d loops done" % (
                args.timeout, state["loop"], n)
            break
        done.wait(0.2)
    if done.is_set():
        time.sleep(1.0)  # messages of the last loop still on their way
    stopped.set()

    alive = rss_kib(args.pid) is not None
    wall = time.time() - (state["started"] or time.time())
    failures = []
    if state["failure"]:
        failures.append(state["failure"])
    if not alive and not state["failure"]:
        failures.append("node (pid %d) is gone at the end" % args.pid)
    for k, entry in enumerate(loops[:state["loop"]]):
        if entry["messages"] == 0:
            failures.append("loop %d: no ~calibration message" % (k + 1))
        if entry["statuses"] == 0:
            failures.append("loop %d: no /diagnostics calibration status" % (k + 1))
        if entry["nan"]:
            failures.append("loop %d: %d messages with NaN/Inf" % (k + 1, entry["nan"]))

    mib = lambda kib: "%.1f" % (kib / 1024.0) if kib is not None else "-"
    def max_gap(stamps):
        gaps = [b - a for a, b in zip(stamps, stamps[1:])]
        return "%.1f" % max(gaps) if gaps else "-"

    lines = ["soak: %d loop(s) of the drive, %.1f s wall, node pid %d %s" % (
        n, wall, args.pid, "alive" if alive else "GONE"),
        "%-6s %9s %9s %5s %9s %8s %9s  %s" % ("loop", "wall_s", "messages", "NaN", "statuses",
                                             "max_gap", "RSS_MiB", "states / status levels")]
    lines.append("%-6s %9s %9s %5s %9s %8s %9s" % ("start", "0.0", "-", "-", "-", "-", mib(rss0)))
    for k, e in enumerate(loops):
        lines.append("%-6d %9s %9d %5d %9d %8s %9s  %s / %s" % (
            k + 1, "%.1f" % e["wall_end_s"] if e["wall_end_s"] is not None else "-",
            e["messages"], e["nan"], e["statuses"], max_gap(e["status_stamps"]),
            mib(e["rss_end_kib"]),
            " ".join("%s %d" % kv for kv in sorted(e["states"].items())) or "-",
            " ".join("%s %d" % kv for kv in sorted(e["levels"].items())) or "-"))
    total_msgs = sum(e["messages"] for e in loops)
    total_nan = sum(e["nan"] for e in loops)
    lines.append("%-6s %9s %9d %5d %9d %8s %9s" % ("total", "%.1f" % wall, total_msgs, total_nan,
                                                   sum(e["statuses"] for e in loops), "",
                                               "max " + mib(state["rss_max"])))
    print("\n".join(lines))
    for f in failures:
        print("FAIL: " + f)
    if args.out:
        with open(args.out, "w") as f:
            json.dump({"loops": loops, "wall_s": wall, "alive": alive, "failures": failures,
                       "rss_start_kib": rss0, "rss_max_kib": state["rss_max"],
                       "rss_samples": state["rss_samples"], "nan_examples": state["nan_examples"]},
                      f, indent=1)
    rospy.signal_shutdown("done")
    return 1 if failures else 0


def cmd_first(args):
    expected = None
    if args.file:
        parameters, covariance, error = check_calibration_file(args.file)
        if error:
            print(json.dumps({"ok": False, "error": "expected file invalid: " + error}))
            return 1
        expected = (parameters, covariance)
    rospy = init_ros("reliability_first_monitor")
    decode = Decoder()
    got = []
    event = threading.Event()

    def on_calibration(raw):
        if event.is_set():
            return
        got.append((decode(raw), raw._connection_header.get("callerid", "")))
        event.set()

    rospy.Subscriber(args.topic, rospy.AnyMsg, on_calibration, queue_size=10)
    touch(args.ready_file)
    if not event.wait(args.timeout):
        print(json.dumps({"ok": False, "error": "no ~calibration within %.0f s" % args.timeout}))
        rospy.signal_shutdown("done")
        return 1
    msg, caller = got[0]
    result = {"seq": msg.header.seq, "stamp": msg.header.stamp.to_sec(), "callerid": caller,
              "parameters": list(msg.parameters), "non_finite": non_finite(msg)}
    ok = not result["non_finite"]
    if expected:
        dp = max(abs(a - b) for a, b in zip(msg.parameters, expected[0]))
        scale = max(abs(x) for x in expected[1])
        dc = max(abs(a - b) for a, b in zip(msg.covariance, expected[1])) / scale
        result.update({"max_abs_parameter_diff": dp, "max_rel_covariance_diff": dc,
                       "parameters_exact": dp <= args.tolerance,
                       "covariance_exact": dc <= args.cov_tolerance})
        ok = ok and result["parameters_exact"] and result["covariance_exact"]
    result["ok"] = ok
    print(json.dumps(result))
    rospy.signal_shutdown("done")
    return 0 if ok else 1


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    topic = "/stereo/online_stereo_calibration/calibration"

    p = sub.add_parser("soak", help="per-loop counts and RSS while a bag loops")
    p.add_argument("--pid", type=int, required=True, help="the calibration node's pid")
    p.add_argument("--loops", type=int, default=3)
    p.add_argument("--topic", default=topic)
    p.add_argument("--rss-period", type=float, default=2.0, help="s between RSS samples")
    p.add_argument("--jump", type=float, default=1.0, help="s of /clock going back = a new loop")
    p.add_argument("--timeout", type=float, default=600.0, help="wall s")
    p.add_argument("--ready-file", default="", help="touched once subscribed")
    p.add_argument("--out", default="", help="JSON summary")
    p.set_defaults(func=cmd_soak)

    p = sub.add_parser("first", help="first ~calibration vs a calibration file")
    p.add_argument("--file", default="", help="expected calibration (none: only wait)")
    p.add_argument("--topic", default=topic)
    p.add_argument("--tolerance", type=float, default=1e-9, help="parameters, absolute")
    p.add_argument("--cov-tolerance", type=float, default=1e-9, help="covariance, relative")
    p.add_argument("--timeout", type=float, default=60.0, help="wall s")
    p.add_argument("--ready-file", default="", help="touched once subscribed")
    p.set_defaults(func=cmd_first)

    p = sub.add_parser("validate", help="check a calibration file")
    p.add_argument("file")
    p.set_defaults(func=cmd_validate)

    args = parser.parse_args()
    sys.exit(args.func(args))


if __name__ == "__main__":
    main()
