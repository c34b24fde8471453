/// @file drive_evaluation.cpp
/// @brief evaluateDrive: the loop over a drive's pairs (motion read where the estimator
/// believes the images were, as the node), then the files, Table I and the plots.
#include "online_stereo_calibration/tools/drive_evaluation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "online_stereo_calibration/core/pipeline/calibration_pipeline.h"
#include "online_stereo_calibration/tools/bag_evaluation.h"
#include "online_stereo_calibration/tools/calibration_file.h"
#include "online_stereo_calibration/tools/estimates_csv.h"
#include "online_stereo_calibration/tools/evaluation.h"
#include "online_stereo_calibration/tools/output_directory.h"
#include "online_stereo_calibration/tools/package_files.h"

namespace osc {
namespace {

std::string quote(const std::string& s) { return "'" + s + "'"; }

/// What the run gave: one row per processed pair, the reference rows, the times.
struct RunRecord {
  std::vector<EstimateRow> estimates;
  std::vector<ReferenceRow> reference;
  std::vector<double> times;
  int skipped = 0;
  double elapsed = 0.0;
  OdometryNoiseStatus odometry_noise;  ///< at the last pair
};

/// The pipeline over every pair of the source; estimates.csv written as it goes.
RunRecord runPairs(DriveSource& source, CalibrationPipeline& pipeline,
                   const DriveEvaluationOptions& options, std::ostream& log) {
  RunRecord run;
  EstimatesCsvWriter estimates_csv(options.out + "/estimates.csv");
  int total = source.pairCount();
  if (options.max_pairs > 0) total = std::min(total, options.max_pairs);
  const bool have_reference = source.hasReference();
  int frame = 0;
  // The estimator's events echoed to the progress output, each kind at most once every
  // kEventRepeatPairs pairs (a baseline guess that triangulates nothing says so every pair).
  struct EventEcho {
    int last_pair = -1;
    int suppressed = 0;
  };
  constexpr int kEventRepeatPairs = 50;
  std::map<FrameEvent, EventEcho> echoes;
  double previous_stamp = 0.0;
  bool have_previous = false;
  const auto start = std::chrono::steady_clock::now();
  auto last_report = start;
  // A terminal gets a progress bar redrawn twice a second; a log file a line every 10 s.
  const bool terminal = options.progress_bar;
  const auto report_every =
      terminal ? std::chrono::milliseconds(500) : std::chrono::milliseconds(10000);
  StereoPairInput pair;
  while (!(options.max_pairs > 0 && frame >= options.max_pairs) && source.next(&pair)) {
    const double stamp = pair.stamp;
    MotionIncrement motion;
    if (have_previous) {
      // Read where the estimator believes the images were (its time offset), as the node.
      const double shift = pipeline.estimator().odometryTimeShift();
      const auto increment = source.motionBetween(previous_stamp - shift, stamp - shift);
      if (increment) {
        motion = *increment;
        motion.time_shift = shift;
      } else {
        log << "\nevaluate: no odometry around pair " << frame << " (stamp " << stamp
            << "); tracking restarts\n";
        pipeline.resetTracking();
      }
    }
    const PipelineResult result = pipeline.process(pair.left, pair.right, motion);
    if (!result.processed) {
      log << "\nevaluate: pair " << frame << " not used: " << result.status << "\n";
      ++run.skipped;
      ++frame;
      continue;
    }
    previous_stamp = stamp;
    have_previous = true;
    // What the estimator's components did, and why it cannot learn (frame_event.h), in the
    // progress output: each kind at most once every kEventRepeatPairs pairs.
    for (const FrameEventLine& event : result.estimator.events) {
      EventEcho& echo = echoes[event.kind];
      if (echo.last_pair >= 0 && frame - echo.last_pair < kEventRepeatPairs) {
        ++echo.suppressed;
        continue;
      }
      log << "\nevaluate: pair " << frame << ": [" << frameEventName(event.kind) << "] "
          << event.text;
      if (echo.suppressed > 0) log << " (and " << echo.suppressed << " times before)";
      log << "\n";
      echo = EventEcho{frame, 0};
    }
    EstimateRow row;
    row.frame = frame;
    row.stamp = stamp;
    row.parameters = result.estimate.parameters;
    row.sigmas = result.estimate.sigmas();
    row.tracked_points = static_cast<int>(result.estimate.tracked_points);
    row.time_ms = 1000.0 * result.processing_time;
    row.time_offset = result.estimate.time_offset;
    row.time_offset_sigma = result.estimate.time_offset_sigma;
    run.odometry_noise = result.estimate.odometry_noise;
    estimates_csv.write(row);
    run.estimates.push_back(row);
    run.times.push_back(row.time_ms);
    if (have_reference) {
      if (const std::optional<Vector12d> reference = source.referenceAt(pair.stamp_ns)) {
        ReferenceRow ref;
        ref.frame = frame;
        ref.stamp = stamp;
        ref.parameters = *reference;
        run.reference.push_back(ref);
      }
    }
    ++frame;
    const auto now = std::chrono::steady_clock::now();
    if (frame == total || now - last_report > report_every) {
      last_report = now;
      log << (terminal ? "\r  " : "  ")
          << progressLine(frame, total, std::chrono::duration<double>(now - start).count())
          << "  points " << row.tracked_points << (terminal ? "" : "\n") << std::flush;
    }
  }
  if (terminal) log << "\n";
  estimates_csv.flush();
  run.elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

/// Table I over the window, the consistency and a step's convergence; the step's frame or -1.
int writeReferenceFigures(const DriveSource& source, const RunRecord& run,
                          const DriveEvaluationOptions& options, std::ostream& text) {
  ReferenceCsvWriter reference_csv(options.out + "/reference.csv");
  for (const ReferenceRow& r : run.reference) reference_csv.write(r);
  reference_csv.flush();
  const std::vector<EstimateRow>& estimates = run.estimates;
  const std::vector<ReferenceRow>& reference = run.reference;
  const int last_frame = estimates.back().frame;
  const int last = options.window_last >= 0 ? options.window_last : std::min(1150, last_frame);
  const int first =
      options.window_first >= 0 ? options.window_first : std::min(1000, std::max(0, last - 150));
  const EvaluationReport report = evaluateWindow(estimates, reference, first, last);
  text << source.name() << ", RMSE over frames " << first << "-" << last << " ("
       << report.frames_used << " frames used):\n"
       << formatTableI(report) << "\n";
  double within = 0;
  for (const auto& p : report.parameters) within += p.within_2sigma / 12.0;
  text << "Consistency: " << 100.0 * within << " % of errors within 2 sigma (95.4 % if "
       << "consistent), mean NEES " << report.mean_nees << " (1 if consistent)\n";
  const int step_frame = detectStepFrame(reference);
  if (step_frame >= 0) {
    int stepped = 0;
    double largest = 0;
    const auto& before = std::find_if(reference.begin(), reference.end(),
                                      [&](const ReferenceRow& r) { return r.frame == step_frame; });
    for (int p = 0; p < 12 && before != reference.begin(); ++p) {
      const double d = std::abs((before->parameters(p) - (before - 1)->parameters(p)) *
                                (isAngleParameter(p) ? 1.0 : 0.1));
      if (d > largest) largest = d, stepped = p;
    }
    const double tolerance = isAngleParameter(stepped) ? 0.3 * M_PI / 180.0 : 0.03;
    const int back = framesToConverge(estimates, reference, stepped, tolerance, step_frame);
    text << "Step at frame " << step_frame << " (largest in " << estimatesCsvColumns()[2 + stepped]
         << "): within " << (isAngleParameter(stepped) ? "0.3 deg" : "3 cm") << " from frame "
         << back << " on (" << (back >= 0 ? back - step_frame : -1) << " frames to converge)\n";
  }
  return step_frame;
}

/// The convergence plots (a failure only warns).
void drawPlots(const std::string& out, int step_frame, std::ostream& log) {
  const std::string script = findPackageFile("scripts/plot_convergence.py", "OSC_PLOT_SCRIPT");
  if (script.empty()) {
    log << "evaluate: warning: scripts/plot_convergence.py not found (set "
           "OSC_PLOT_SCRIPT); no plots\n";
    return;
  }
  std::string command = "/usr/bin/python3 " + quote(script) + " --out " + quote(out);
  if (step_frame >= 0) command += " --step-frame " + std::to_string(step_frame);
  if (std::system(command.c_str()) != 0) {
    log << "evaluate: warning: the plots failed (" << command << ")\n";
  }
}

}  // namespace

int evaluateDrive(DriveSource& source, const EstimatorConfig& config, const StereoExtrinsics& guess,
                  const DriveEvaluationOptions& options, std::ostream& out, std::ostream& log) {
  makeDirectories(options.out);
  CalibrationPipeline pipeline(config.filter, config.front_end, source.leftCamera(),
                               source.rightCamera(), guess);
  const RunRecord run = runPairs(source, pipeline, options, log);
  if (run.estimates.empty()) throw std::runtime_error("no stereo pair was processed");

  writeCalibrationFileAtomic(options.out + "/calibration.yaml",
                             calibrationFileOf(run.estimates.back()));

  const Percentiles timing = percentiles(run.times);
  std::ostringstream text;
  int step_frame = -1;
  if (!run.reference.empty()) {
    step_frame = writeReferenceFigures(source, run, options, text);
  } else {
    const EstimateRow& last = run.estimates.back();
    text << source.name() << " (no reference): final estimate and 1 sigma\n";
    for (int p = 0; p < 12; ++p) {
      text << "  " << estimatesCsvColumns()[2 + p] << " = " << last.parameters(p) << " +- "
           << last.sigmas(p) << "\n";
    }
  }
  text << "Pairs processed: " << run.estimates.size() << ", not used: " << run.skipped
       << "; time per frame: median " << timing.median << " ms, p95 " << timing.p95 << " ms; total "
       << run.elapsed << " s (" << run.estimates.size() / run.elapsed << " frames/s)\n";
  if (run.odometry_noise.enabled) {
    const std::string learned = run.odometry_noise.message();
    text << "Odometry noise at the last pair: "
         << (learned.empty() ? "as configured (odometry_noise_window_s)" : learned) << "\n";
  }
  for (const std::string& note : options.notes) text << note << "\n";
  out << text.str();
  std::ofstream(options.out + "/table.txt") << text.str();

  drawPlots(options.out, step_frame, log);
  out << "wrote " << options.out << "/estimates.csv, calibration.yaml, table.txt"
      << (run.reference.empty() ? "" : ", reference.csv") << "\n";
  return 0;
}

}  // namespace osc
