#include "online_stereo_calibration/tools/campaign.h"

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>
#include <opencv2/core/utility.hpp>

#include "online_stereo_calibration/core/sim/image_scenario_runner.h"
#include "online_stereo_calibration/core/sim/scenario_runner.h"
#include "online_stereo_calibration/tools/campaign_summary.h"
#include "online_stereo_calibration/tools/output_directory.h"
#include "online_stereo_calibration/tools/package_files.h"

namespace osc {

namespace {

/// The status of a run whose process died (killed, crashed) starts so; such runs are retried.
const std::string kProcessFailure = "failed: process ";

/// The title of DIR/inputs/config.yaml.
constexpr const char* kConfigTitle = "estimator configuration of the campaign";

bool exists(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0;
}

std::string runFile(const std::string& dir, int run) {
  char name[32];
  std::snprintf(name, sizeof(name), "/runs/run_%04d.csv", run);
  return dir + name;
}

std::string quote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string inputsText(const CampaignInputs& inputs) {
  std::ostringstream text;
  text << "frames: " << inputs.frames << "\nseed: " << inputs.seed
       << "\nimages: " << (inputs.images ? "true" : "false") << "\n";
  return text.str();
}

std::string duration(double seconds) {
  char text[32];
  if (!(seconds >= 0.0) || seconds > 1e7) return "?";
  const long s = static_cast<long>(seconds + 0.5);
  if (s >= 3600) {
    std::snprintf(text, sizeof(text), "%ldh%02ldm", s / 3600, s / 60 % 60);
  } else {
    std::snprintf(text, sizeof(text), "%ldm%02lds", s / 60, s % 60);
  }
  return text;
}

/// Runs one run in this (child) process and writes its row file; never returns.
[[noreturn]] void runChild(const CampaignInputs& inputs, const std::string& dir, int run,
                           int jobs) {
  int code = 0;
  if (jobs > 1) cv::setNumThreads(1);  // J processes share the cores; no thread pool each
  try {
    const std::vector<std::string> names = campaignSettingNames(inputs.images);
    CampaignRow row;
    try {
      row = runCampaignRun(drawCampaignRun(inputs, run), inputs.config, inputs.images);
    } catch (const std::exception& e) {  // the draw itself failed
      row = failedCampaignRow(run, inputs.seed + run, inputs.frames, {}, e.what());
    }
    writeTextFileAtomic(runFile(dir, run),
                        campaignCsvHeader(names) + "\n" + formatCampaignCsvLine(row, names) + "\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "campaign: run %d: %s\n", run, e.what());
    code = 1;
  }
  std::fflush(stderr);
  _exit(code);
}

}  // namespace

CampaignRunSpec drawCampaignRun(const CampaignInputs& inputs, int run) {
  return drawCampaignRun(inputs.ranges, run, inputs.seed + static_cast<unsigned>(run),
                         inputs.frames, inputs.images);
}

std::vector<ScenarioFrameResult> simulateCampaignRun(
    const CampaignRunSpec& spec, const EstimatorConfig& config, bool images,
    const std::function<void(const ScenarioFrameResult&)>& on_frame) {
  if (!spec.error.empty()) throw std::runtime_error(spec.error);
  const std::vector<std::string> problems = spec.scenario.validate();
  if (!problems.empty()) {
    std::string message = "invalid scenario:";
    for (const std::string& p : problems) message += " " + p + ";";
    throw std::invalid_argument(message);
  }
  // The declared pixel noise is the configuration's (pixel_noise_px), as a front end declares
  // its own; the simulator adds the scenario's (0.5 px).
  if (!images) return runMeasurementScenario(spec.scenario, config.filter, on_frame, true);
  std::vector<ScenarioFrameResult> results;
  for (const ImageFrameResult& r :
       runImageScenario(spec.scenario, config.filter, config.front_end, spec.image_options)) {
    if (!r.processed) continue;
    results.push_back(r.filter);
    if (on_frame) on_frame(r.filter);
  }
  return results;
}

CampaignRow runCampaignRun(const CampaignRunSpec& spec, const EstimatorConfig& config,
                           bool images) {
  const auto start = std::chrono::steady_clock::now();
  CampaignRow row;
  try {
    const std::vector<ScenarioFrameResult> results = simulateCampaignRun(spec, config, images);
    row.score = scoreCampaignRun(results, unseenChangeSpans(spec.scenario));
  } catch (const std::exception& e) {
    row = failedCampaignRow(spec.run, spec.seed, spec.scenario.frames, spec.settings, e.what());
  }
  row.run = spec.run;
  row.seed = spec.seed;
  row.frames = spec.scenario.frames;
  row.settings = spec.settings;
  row.run_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return row;
}

namespace {

/// A configuration file's keys and values as written ("front_end.KEY" for its map's).
std::map<std::string, std::string> configScalars(const std::string& text) {
  std::map<std::string, std::string> scalars;
  const YAML::Node root = YAML::Load(text);
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    if (!entry.second.IsMap()) {
      scalars[key] = entry.second.Scalar();
      continue;
    }
    for (const auto& inner : entry.second) {
      scalars[key + "." + inner.first.as<std::string>()] = inner.second.Scalar();
    }
  }
  return scalars;
}

/// Whether a stored DIR/inputs/config.yaml holds what @p config_text holds: the same keys
/// with the same values as written, in any order and with any comments, so that a file of an
/// older layout of formatEstimatorConfigYaml (the keys not yet grouped in sections) matches.
bool sameConfigFile(const std::string& stored, const std::string& config_text) {
  if (stored == config_text) return true;
  try {
    return configScalars(stored) == configScalars(config_text);
  } catch (const YAML::Exception&) {
    return false;
  }
}

}  // namespace

void storeOrCheckCampaignInputs(const std::string& dir, const CampaignInputs& inputs) {
  const std::string in = dir + "/inputs";
  const std::string config_text = formatEstimatorConfigYaml(inputs.config, kConfigTitle);
  const std::string campaign_text = inputsText(inputs);
  if (!exists(in + "/campaign.txt")) {
    makeDirectories(in);
    writeTextFileAtomic(in + "/ranges.yaml", inputs.ranges_text);
    writeTextFileAtomic(in + "/config.yaml", config_text);
    writeTextFileAtomic(in + "/campaign.txt", campaign_text);  // last: marks the inputs complete
    return;
  }
  std::vector<std::string> differences;
  const std::string stored = readTextFile(in + "/campaign.txt");
  if (stored != campaign_text) {
    differences.push_back("--frames/--seed/--images (there: " + stored + "here: " + campaign_text +
                          ")");
  }
  if (readTextFile(in + "/ranges.yaml") != inputs.ranges_text) {
    differences.push_back("the ranges (compare with " + in + "/ranges.yaml)");
  }
  if (!sameConfigFile(readTextFile(in + "/config.yaml"), config_text)) {
    differences.push_back("the estimator configuration --config (compare with " + in +
                          "/config.yaml)");
  }
  if (!differences.empty()) {
    std::string message = "'" + dir + "' holds a campaign made with other inputs; differing:";
    for (const std::string& d : differences) message += "\n  " + d;
    throw std::runtime_error(message + "\n(use another --out DIR, or the same inputs to resume)");
  }
}

std::vector<CampaignRow> runCampaign(const CampaignInputs& inputs, const CampaignOptions& options) {
  if (options.runs < 1) throw std::invalid_argument("--runs must be >= 1");
  if (options.jobs < 1) throw std::invalid_argument("--jobs must be >= 1");
  makeDirectories(options.out);
  storeOrCheckCampaignInputs(options.out, inputs);
  makeDirectories(options.out + "/runs");
  const std::vector<std::string> names = campaignSettingNames(inputs.images);

  std::vector<int> pending;
  int done = 0, honest = 0;
  for (int run = 0; run < options.runs; ++run) {
    const std::string file = runFile(options.out, run);
    // A run whose process was killed or crashed is run again; any other row stays.
    const std::vector<CampaignRow> rows =
        exists(file) ? readCampaignCsv(file) : std::vector<CampaignRow>();
    if (rows.empty() || rows.front().status.rfind(kProcessFailure, 0) == 0) {
      pending.push_back(run);
      continue;
    }
    ++done;
    honest += rows.front().honest();
  }
  const int skipped = done;
  const bool tty = isatty(2);
  const auto start = std::chrono::steady_clock::now();
  const auto show = [&] {
    if (!options.progress) return;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const int new_done = done - skipped;
    const double eta = new_done > 0 ? elapsed / new_done * (options.runs - done) : -1.0;
    const int width = 30, filled = width * done / options.runs;
    std::fprintf(stderr, "%s[%s%s] %d/%d runs  ETA %s  honest %d/%d (%.0f %%)%s", tty ? "\r" : "",
                 std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), done,
                 options.runs,
                 done == options.runs ? "0m00s" : (new_done ? duration(eta).c_str() : "?"), honest,
                 done, done ? 100.0 * honest / done : 0.0, tty ? "" : "\n");
    std::fflush(stderr);
  };
  if (skipped > 0 && options.progress) {
    std::fprintf(stderr, "campaign: %d of %d runs already in %s/runs, skipped\n", skipped,
                 options.runs, options.out.c_str());
  }
  show();

  std::map<pid_t, int> running;
  size_t next = 0;
  while (next < pending.size() || !running.empty()) {
    while (next < pending.size() && static_cast<int>(running.size()) < options.jobs) {
      const int run = pending[next++];
      std::cout.flush();
      std::cerr.flush();
      std::fflush(nullptr);
      const pid_t pid = fork();
      if (pid < 0) throw std::runtime_error("fork failed");
      if (pid == 0) runChild(inputs, options.out, run, options.jobs);
      running[pid] = run;
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) throw std::runtime_error("waitpid failed");
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const int run = it->second;
    running.erase(it);
    const std::string file = runFile(options.out, run);
    if (!exists(file)) {  // crashed: record it
      std::string reason = WIFSIGNALED(status)
                               ? "process killed by signal " + std::to_string(WTERMSIG(status))
                               : "process exited with code " + std::to_string(WEXITSTATUS(status));
      CampaignSettings settings;
      try {
        settings = drawCampaignRun(inputs, run).settings;
      } catch (const std::exception&) {
      }
      const CampaignRow row =
          failedCampaignRow(run, inputs.seed + run, inputs.frames, settings, reason);
      writeTextFileAtomic(
          file, campaignCsvHeader(names) + "\n" + formatCampaignCsvLine(row, names) + "\n");
    }
    ++done;
    for (const CampaignRow& row : readCampaignCsv(file)) honest += row.honest();
    show();
  }
  if (options.progress && tty) std::fprintf(stderr, "\n");

  std::vector<CampaignRow> rows;
  std::string csv = campaignCsvHeader(names) + "\n";
  for (int run = 0; run < options.runs; ++run) {
    for (const CampaignRow& row : readCampaignCsv(runFile(options.out, run))) {
      rows.push_back(row);
      csv += formatCampaignCsvLine(row, names) + "\n";
    }
  }
  writeTextFileAtomic(options.out + "/campaign.csv", csv);
  writeTextFileAtomic(options.out + "/summary.txt", formatCampaignSummary(rows));
  if (options.plot) {
    const std::string script = findPackageFile("scripts/plot_campaign.py");
    if (script.empty()) {
      std::cerr << "campaign: warning: scripts/plot_campaign.py not found; no campaign.png\n";
    } else {
      const std::string command =
          "/usr/bin/python3 " + quote(script) + " --out " + quote(options.out);
      if (std::system(command.c_str()) != 0) {
        std::cerr << "campaign: warning: the plot failed (" << command << ")\n";
      }
    }
  }
  return rows;
}

}  // namespace osc
