/// @file campaign_replay.cpp
/// @brief --only K of `campaign`: one run alone with the files and plots of `evaluate`.
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "online_stereo_calibration/tools/campaign.h"
#include "online_stereo_calibration/tools/estimates_csv.h"
#include "online_stereo_calibration/tools/output_directory.h"
#include "online_stereo_calibration/tools/package_files.h"

namespace osc {
namespace {

/// One line per frame in which the estimator tempered its update or warned (restarts,
/// re-openings, re-seeds: each says so in its warning); nothing for a quiet frame.
void appendFrameEvents(const ScenarioFrameResult& r, std::ostream* out) {
  std::ostringstream line;
  if (r.tempering > 1.0) line << " update tempered x" << r.tempering << ";";
  for (const std::string& warning : r.warnings) line << " " << warning << ";";
  if (line.tellp() > 0) *out << "frame " << r.frame << ":" << line.str() << "\n";
}

}  // namespace

CampaignRow replayCampaignRun(const CampaignInputs& inputs, const std::string& out, int run,
                              bool plot, std::ostream* report) {
  makeDirectories(out);
  storeOrCheckCampaignInputs(out, inputs);
  const CampaignRunSpec spec = drawCampaignRun(inputs, run);
  const std::string dir = out + "/run_" + std::to_string(run);
  makeDirectories(dir);
  if (report) {
    *report << "campaign: replaying run " << run << " (seed " << spec.seed << ", "
            << spec.scenario.frames << " frames" << (inputs.images ? ", images" : "") << ") into "
            << dir << "\n";
  }
  EstimatesCsvWriter estimates(dir + "/estimates.csv");
  ReferenceCsvWriter reference(dir + "/reference.csv");
  std::ostringstream events;  // what the estimator did when, to read beside the plots
  const auto on_frame = [&](const ScenarioFrameResult& r) {
    estimates.write(estimateRowOf(r));
    reference.write(referenceRowOf(r));
    appendFrameEvents(r, &events);
  };
  CampaignRow row;
  try {
    row.score = scoreCampaignRun(simulateCampaignRun(spec, inputs.config, inputs.images, on_frame),
                                 unseenChangeSpans(spec.scenario));
  } catch (const std::exception& e) {
    row = failedCampaignRow(run, spec.seed, inputs.frames, spec.settings, e.what());
  }
  row.run = run;
  row.seed = spec.seed;
  row.frames = inputs.frames;
  row.settings = spec.settings;
  estimates.flush();
  reference.flush();
  writeTextFileAtomic(dir + "/events.txt", events.str());

  const std::vector<std::string> names = campaignSettingNames(inputs.images);
  writeTextFileAtomic(dir + "/run.csv",
                      campaignCsvHeader(names) + "\n" + formatCampaignCsvLine(row, names) + "\n");
  std::ostringstream text;
  text << "run " << run << ", seed " << spec.seed << ", " << inputs.frames << " frames at 10 Hz"
       << (inputs.images ? ", images" : ", measurement level") << ": "
       << (row.ok() ? (row.honest() ? "honest" : "NOT honest") : row.status) << "\n"
       << "share_within_3sigma " << row.score.share_within_3sigma << ", frames_beyond_5sigma "
       << row.score.frames_beyond_5sigma << ", max_z " << row.score.max_z << " ("
       << row.score.max_z_parameter << "), first_frame_beyond_5sigma "
       << row.score.first_frame_beyond_5sigma << ", nees_mean " << row.score.nees_mean
       << ", converged_frame " << row.score.converged_frame << ", frames_converged "
       << row.score.frames_converged << " (beyond 3 sigma "
       << row.score.frames_converged_beyond_3sigma << ")\n\ndrawn settings:\n";
  for (const auto& [name, value] : spec.settings) text << "  " << name << " = " << value << "\n";
  if (report) *report << text.str();
  writeTextFileAtomic(dir + "/settings.txt", text.str());

  if (report) report->flush();  // before the script's own output
  const std::string script =
      plot ? findPackageFile("scripts/plot_convergence.py", "OSC_PLOT_SCRIPT") : "";
  if (!plot) {
  } else if (script.empty()) {
    std::cerr << "campaign: warning: scripts/plot_convergence.py not found; no plots\n";
  } else {
    std::string command = "/usr/bin/python3 '" + script + "' --out '" + dir + "'";
    if (spec.scenario.step_frame >= 0) {
      command += " --step-frame " + std::to_string(spec.scenario.step_frame);
    }
    if (std::system(command.c_str()) != 0) {
      std::cerr << "campaign: warning: the plots failed (" << command << ")\n";
    }
  }
  if (report) {
    *report << "wrote " << dir << "/estimates.csv, reference.csv, events.txt, run.csv, settings.txt"
            << (plot ? ", plots" : "") << "\n";
  }
  return row;
}

}  // namespace osc
