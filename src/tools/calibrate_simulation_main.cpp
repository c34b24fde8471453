// The README's demo: calibrates a simulated drive (measurement level: simulated pixel
// tracks and vehicle motion) and reports it against the truth in the seed's Table I layout.
//
//   calibrate_simulation [--scenario paper_offroad|urban_planar|drift] [--config PARAMS.yaml]
//                        [--out DIR] [--frames N] [--seed N] [--window FIRST LAST]
//                        [--baseline M] [--baseline-guess M]
//
// (the image-level counterpart, from rendered images through the front end, is `simulate` +
// `evaluate`, which scripts/demo.sh runs).
//
// Writes DIR/estimates.csv (interface.md columns), DIR/reference.csv (the truth),
// DIR/calibration.yaml (final estimate with sigmas, written atomically) and DIR/table.txt.
#include <sys/stat.h>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "online_stereo_calibration/core/sim/scenario_runner.h"
#include "online_stereo_calibration/tools/calibration_file.h"
#include "online_stereo_calibration/tools/campaign_score.h"
#include "online_stereo_calibration/tools/command_line.h"
#include "online_stereo_calibration/tools/estimates_csv.h"
#include "online_stereo_calibration/tools/evaluation.h"
#include "online_stereo_calibration/tools/filter_config_yaml.h"
#include "online_stereo_calibration/tools/output_directory.h"

namespace {

struct Options {
  std::string scenario = "paper_offroad";
  std::string config;
  std::string out = "out/calibrate_simulation";
  int frames = -1;
  int seed = -1;
  int window_first = 1000, window_last = 1150;
  double baseline = -1.0, baseline_guess = -1.0;  // m; negative: the scenario's
};

/// The command line (`--help` prints it).
osc::CommandLine commandLine(Options* o) {
  osc::CommandLine cli("calibrate_simulation",
                       "Calibrates a simulated drive at measurement level (simulated pixel tracks "
                       "and vehicle motion,\nno images; the image-level run is simulate + "
                       "evaluate, docs/evaluation.md) and prints\nthe RMSE beside the seed's "
                       "Table I. Writes DIR/estimates.csv, reference.csv, calibration.yaml,\n"
                       "table.txt.");
  cli.option("--scenario", &o->scenario, "NAME", "measurement-level scenario")
      .choices({"paper_offroad", "urban_planar", "drift"});
  cli.option("--config", &o->config, "PARAMS.yaml",
             "estimator parameters (config/default.yaml keys; a front_end: section is "
             "checked, not used)");
  cli.option("--out", &o->out, "DIR", "output directory");
  cli.option("--frames", &o->frames, "N", "frames (-1: the scenario's)").range(1, 1e7);
  cli.option("--seed", &o->seed, "N", "random seed (-1: the scenario's)").range(0, 2147483647);
  cli.option("--window", &o->window_first, &o->window_last, "FIRST LAST",
             "frames of the Table I RMSE (clipped to the drive)")
      .range(0, 1e7);
  cli.option("--baseline", &o->baseline, "M",
             "the rig's true baseline length along y (-1: the scenario's)")
      .range(-1.0, 10.0);
  cli.option("--baseline-guess", &o->baseline_guess, "M",
             "the initial guess of that length, its prior unchanged (-1: the scenario's start "
             "error)")
      .range(-1.0, 10.0);
  return cli;
}

osc::MeasurementScenario scenarioByName(const std::string& name) {
  if (name == "paper_offroad") return osc::paperOffroadScenario();
  if (name == "urban_planar") return osc::urbanPlanarScenario();
  if (name == "drift") return osc::driftScenario();
  throw std::invalid_argument("unknown scenario '" + name +
                              "' (paper_offroad, urban_planar, drift)");
}

}  // namespace

int main(int argc, char** argv) {
  Options parsed;
  osc::CommandLine cli = commandLine(&parsed);
  return osc::runTool(
      "calibrate_simulation", [&] { return cli.usage(); },
      [&] {
        if (!cli.parse(argc, argv)) return 0;
        if (parsed.window_last < parsed.window_first) {
          throw osc::CommandLineError("--window wants FIRST <= LAST");
        }
        const Options& options = parsed;
        osc::MeasurementScenario scenario = scenarioByName(options.scenario);
        if (options.frames > 0) scenario.frames = options.frames;
        if (options.seed >= 0) scenario.seed = static_cast<unsigned>(options.seed);
        constexpr int kYr = 7;  // the right camera sits at -baseline along the left's y
        if (options.baseline > 0.0) scenario.truth(kYr) = -options.baseline;  // start error kept
        if (options.baseline_guess > 0.0) {
          scenario.initial_error(kYr) = -options.baseline_guess - scenario.truth(kYr);
        }
        const osc::FilterConfig config = options.config.empty()
                                             ? osc::FilterConfig()
                                             : osc::readFilterConfigFile(options.config);
        osc::makeDirectories(options.out);

        osc::EstimatesCsvWriter estimates(options.out + "/estimates.csv");
        osc::ReferenceCsvWriter reference(options.out + "/reference.csv");
        std::vector<osc::EstimateRow> estimate_rows;
        std::vector<osc::ReferenceRow> reference_rows;
        std::vector<double> times;
        std::vector<osc::ScenarioFrameResult> results;
        int jumps = 0;
        const auto start = std::chrono::steady_clock::now();
        std::cerr << "calibrating simulated drive '" << scenario.name << "': " << scenario.frames
                  << " frames at " << scenario.rate_hz << " Hz, seed " << scenario.seed << "\n";

        const auto on_frame = [&](const osc::ScenarioFrameResult& r) {
          estimate_rows.push_back(osc::estimateRowOf(r));
          estimates.write(estimate_rows.back());
          reference_rows.push_back(osc::referenceRowOf(r));
          reference.write(reference_rows.back());
          times.push_back(r.time_ms);
          results.push_back(r);
          if (r.jump_detected) {
            ++jumps;
            std::cerr << "  frame " << r.frame
                      << ": sudden calibration change detected, re-converging\n";
          }
          if ((r.frame + 1) % 100 == 0 || r.frame + 1 == scenario.frames) {
            const double elapsed =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            const double rate = (r.frame + 1) / std::max(elapsed, 1e-9);
            std::fprintf(stderr, "  frame %5d/%d  %6.0f frames/s  ETA %4.0f s  points %3d\n",
                         r.frame + 1, scenario.frames, rate, (scenario.frames - r.frame - 1) / rate,
                         r.tracked_points);
          }
        };
        osc::runMeasurementScenario(scenario, config, on_frame);
        estimates.flush();
        reference.flush();

        osc::writeCalibrationFileAtomic(options.out + "/calibration.yaml",
                                        osc::calibrationFileOf(estimate_rows.back()));

        std::sort(times.begin(), times.end());
        const double median = times[times.size() / 2];
        const double p95 = times[std::min(times.size() - 1, times.size() * 95 / 100)];
        std::ostringstream text;
        const int last = std::min(options.window_last, scenario.frames - 1);
        const int first = std::min(options.window_first, std::max(0, last - 150));
        const osc::EvaluationReport report =
            osc::evaluateWindow(estimate_rows, reference_rows, first, last);
        text << "Scenario " << scenario.name << " (measurement level, seed " << scenario.seed
             << "), RMSE over frames " << first << "-" << last << ":\n"
             << osc::formatTableI(report) << "\n";
        if (scenario.step_frame >= 0 && scenario.step_frame < scenario.frames) {
          const int back = osc::framesToConverge(estimate_rows, reference_rows, 5,
                                                 0.3 * M_PI / 180.0, scenario.step_frame);
          text << "Step of x_caml at frame " << scenario.step_frame
               << ": yaw_l within 0.3 deg from frame " << back << " on ("
               << (back >= 0 ? back - scenario.step_frame : -1) << " frames)\n";
        }
        if (scenario.frames > osc::kCampaignFirstScoredFrame) {
          const osc::CampaignScore honesty = osc::scoreCampaignRun(results);
          text << "Honesty from frame " << osc::kCampaignFirstScoredFrame
               << ": all 12 errors within 3 sigma in " << honesty.share_within_3sigma
               << " of the frames (>= 0.95 honest), " << honesty.frames_beyond_5sigma
               << " frames beyond 5 sigma, largest |error| / sigma " << honesty.max_z << " ("
               << honesty.max_z_parameter << ")\n";
        }
        text << "Sudden changes detected: " << jumps << "\n"
             << "Estimator time per frame: median " << median << " ms, p95 " << p95 << " ms\n";
        std::cout << text.str();
        std::ofstream(options.out + "/table.txt") << text.str();
        std::cout << "wrote " << options.out
                  << "/estimates.csv, reference.csv, calibration.yaml, table.txt\n";
        return 0;
      });
}
