// campaign: many simulated drives drawn from ranges, each scored for the filter's honesty
// (issue 13; docs/campaign.md).
//
//   campaign --runs N --out DIR [--seed S] [--jobs J] [--frames F] [--images]
//            [--ranges FILE] [--config PARAMS.yaml] [--only K]
//
// Writes DIR/campaign.csv (one row per run), DIR/summary.txt, DIR/campaign.png, the rows of
// single runs in DIR/runs/ and the campaign's inputs in DIR/inputs/; --only K replays run K
// into DIR/run_K/ (estimates.csv, reference.csv, plots, settings.txt).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>

#include "online_stereo_calibration/tools/campaign.h"
#include "online_stereo_calibration/tools/campaign_ranges.h"
#include "online_stereo_calibration/tools/command_line.h"
#include "online_stereo_calibration/tools/package_files.h"
#include "online_stereo_calibration/tools/perfect_filter.h"

namespace {

struct Options {
  int runs = -1;
  std::string out;
  int seed = 1;
  int jobs = 1;
  int frames = 600;
  bool images = false;
  std::string ranges;
  std::string config;
  int only = -1;
};

const char* kDescription =
    "Draws N scenarios from ranges (rig, motion, start errors, events, odometry errors, scene,\n"
    "images; see docs/campaign.md and config/campaign.yaml, which documents every key),\n"
    "reproducibly (run k uses seed S + k), simulates each, runs the estimator with --config\n"
    "and scores it against the truth. Measurement level by default (simulated pixel tracks,\n"
    "seconds per run); --images renders the drive and runs the whole pipeline (front end +\n"
    "filter), as simulate + evaluate do. Frames at 10 Hz. The simulator adds 0.5 px of pixel\n"
    "noise; at measurement level the estimator assumes --config's pixel_noise_px, with\n"
    "--images the front end declares its own.\n"
    "\n"
    "Default ranges: rig baseline 0.08-0.6 m, image 640x480-1280x960, focal 400-1400 px,\n"
    "pinhole / plumb_bob (k1 -0.3..0) / equidistant, mounted forward (pitched down 0-30 deg),\n"
    "backward or sideways; motion off-road (paper-like, drawn speed and amplitudes), urban\n"
    "(planar, 8-15 m/s, 1-2 stops of 2-10 s) or a stretch of a recorded trajectory; start\n"
    "errors x_caml 0-0.5 m and 0-10 deg per axis, x_camr baseline -50..+50 %, 0-2 cm, 0-5 deg;\n"
    "events none, yaw step of x_caml 2-10 deg, knock of the right camera 0.1-1 deg, drift of\n"
    "x_camr up to 0.5 deg and 5 mm per minute; odometry time offset -30..30 ms, scale error\n"
    "up to 2 %, slowly varying biases; 0-1 texture-poor stretches of 2-5 s, 0-20 % moving\n"
    "points; with --images noise 0-3 grey levels, blur 0-1 px, flicker 0-0.2.\n"
    "\n"
    "J runs at once, each in its own process; a progress bar (runs done, ETA, runs honest so\n"
    "far) on stderr. Re-running with the same DIR skips the finished runs (a larger N adds\n"
    "runs; runs whose process was killed run again); DIR/inputs keeps ranges, configuration,\n"
    "frames, seed and --images, and a DIR made with other inputs is refused. A run that\n"
    "fails or crashes is recorded as failed and does not stop the campaign.\n"
    "\n"
    "DIR/campaign.csv, one row per run: run,seed,frames,share_within_3sigma,\n"
    "frames_beyond_5sigma,frames_beyond_5sigma_unseen,max_z,max_z_parameter,\n"
    "first_frame_beyond_5sigma,nees_mean,converged_frame,frames_converged,\n"
    "frames_converged_beyond_3sigma,time_ms_median, rmse_<p> for the 12 parameters over the\n"
    "last 150 frames (m, rad), mean_z_<p> (mean signed error / sigma from frame 30 on), the\n"
    "drawn settings, run_s (wall time of the run) and status (ok / failed: why).\n"
    "  share_within_3sigma: share of frames from frame 30 on with all 12 errors (estimate -\n"
    "    truth, angles wrapped) within 3 reported sigmas; frames_beyond_5sigma: frames from 30\n"
    "    on with some error beyond 5 sigma (first_frame_beyond_5sigma: the first, -1 if none);\n"
    "    frames_beyond_5sigma_unseen: those of them in which the calibration had changed\n"
    "    (event_frame) inside a blind stretch with nothing tracked since: no estimator could\n"
    "    know of the change yet (they still count in frames_beyond_5sigma);\n"
    "  max_z: largest |error| / sigma from frame 30 on, max_z_parameter its parameter;\n"
    "  nees_mean: mean from frame 30 on of the 12-dof NEES / 12 (about 1 when honest);\n"
    "  converged_frame: first frame in the CONVERGED state (convergence.h), -1 if never;\n"
    "  frames_converged: frames in the CONVERGED state; frames_converged_beyond_3sigma: those\n"
    "    of them with some error beyond 3 sigma (about 3 % when honest);\n"
    "  time_ms_median: median estimator time per frame (ms).\n"
    "Drawn settings: baseline_m, image_width, image_height, focal_px, lens, k1, mounting,\n"
    "pitch_down_deg, motion, trajectory, trajectory_start_s, speed_mps, roll_pitch_std_deg,\n"
    "heave_m, yaw_rate_deg_s, yaw_phase_deg, stops, stop_s, start_caml_m, start_caml_deg\n"
    "(largest |error| per axis), start_baseline_percent, start_camr_m, start_camr_deg, event,\n"
    "event_frame, event_deg, event_mm_per_min, odo_time_offset_ms, odo_scale_percent,\n"
    "odo_rotation_bias_deg_s, odo_velocity_bias_mps, blind_s, moving_fraction,\n"
    "moving_speed_mps; with --images also image_noise, image_blur_px, image_flicker.\n"
    "DIR/summary.txt: runs, share honest (share_within_3sigma >= 0.95 and\n"
    "frames_beyond_5sigma = 0), each parameter's mean_z over the runs with its standard\n"
    "error (far from 0: biased), the worst runs with seeds and settings, and the same by each\n"
    "setting's bucket. DIR/campaign.png (scripts/plot_campaign.py): share_within_3sigma and\n"
    "max_z against start errors, baseline, motion, mounting and event.";

osc::CommandLine commandLine(Options* o) {
  osc::CommandLine cli("campaign", kDescription);
  cli.option("--runs", &o->runs, "N", "number of runs (required unless --only)")
      .range(1, 1e6)
      .defaultText("");
  cli.option("--out", &o->out, "DIR", "campaign directory").required();
  cli.option("--seed", &o->seed, "S", "seed of run 0; run k uses S + k").range(0, 2147483647);
  cli.option("--jobs", &o->jobs, "J", "runs at once, in separate processes").range(1, 256);
  cli.option("--frames", &o->frames, "F",
             "frames per run at 10 Hz (scored from frame 30, RMSE over the last 150)")
      .range(31, 1e6);
  cli.flag("--images", &o->images,
           "render the drives and run the whole pipeline (front end + filter; slow)");
  cli.option("--ranges", &o->ranges, "FILE",
             "ranges YAML replacing the shipped config/campaign.yaml (keys not given keep its "
             "defaults)")
      .defaultText("config/campaign.yaml");
  cli.option("--config", &o->config, "PARAMS.yaml",
             "estimator parameters (config/default.yaml keys, front_end: section)")
      .defaultText("the shipped defaults");
  cli.option("--only", &o->only, "K",
             "replay run K alone into DIR/run_K: estimates.csv, reference.csv, the plots of "
             "evaluate, settings.txt")
      .range(0, 1e6)
      .defaultText("");
  return cli;
}

osc::CampaignInputs loadInputs(const Options& o) {
  osc::CampaignInputs inputs;
  std::string ranges_path = o.ranges;
  if (ranges_path.empty()) {
    ranges_path = osc::findPackageFile("config/campaign.yaml");
    if (ranges_path.empty()) {
      throw std::runtime_error("the shipped config/campaign.yaml was not found; give --ranges");
    }
  }
  inputs.ranges_text = osc::readTextFile(ranges_path);
  inputs.ranges = osc::readCampaignRangesFile(ranges_path);
  if (!o.config.empty()) inputs.config = osc::readEstimatorConfigFile(o.config);
  inputs.frames = o.frames;
  inputs.seed = static_cast<unsigned>(o.seed);
  inputs.images = o.images;
  return inputs;
}

}  // namespace

int main(int argc, char** argv) {
  Options parsed;
  osc::CommandLine cli = commandLine(&parsed);
  return osc::runTool(
      "campaign", [&] { return cli.usage(); },
      [&] {
        if (!cli.parse(argc, argv)) return 0;
        if (parsed.only < 0 && parsed.runs < 1) {
          throw osc::CommandLineError("--runs is required (or --only K)");
        }
        const osc::CampaignInputs inputs = loadInputs(parsed);
        if (!inputs.ranges.dropped_recorded.empty()) {
          std::cout << "campaign: " << inputs.ranges.dropped_recorded
                    << " (the recorded trajectories are in the project's ../shared/data)\n";
        }
        if (parsed.only >= 0) {
          osc::replayCampaignRun(inputs, parsed.out, parsed.only, true, &std::cout);
          return 0;
        }
        osc::CampaignOptions options;
        options.runs = parsed.runs;
        options.jobs = parsed.jobs;
        options.out = parsed.out;
        const std::vector<osc::CampaignRow> rows = osc::runCampaign(inputs, options);
        int honest = 0;
        for (const osc::CampaignRow& row : rows) honest += row.honest();
        const osc::PerfectFilterScore perfect = osc::perfectFilterScore(inputs.frames);
        std::cout << "campaign: " << honest << " of " << rows.size() << " runs honest (a perfect "
                  << "filter: " << std::lround(100.0 * perfect.honest_low) << "-"
                  << std::lround(100.0 * perfect.honest_high) << " %); wrote " << parsed.out
                  << "/campaign.csv, summary.txt, campaign.png\n";
        return 0;
      });
}
