/// @file simulate_main.cpp
/// @brief Renders a simulated drive into a bag, without a ROS master.
///
///   simulate --scenario config/scenarios/paper_offroad.yaml --out DIR [--frames N]
///
/// Writes DIR/drive.bag (raw mono8 stereo images and camera_info on /stereo/{left,right}/,
/// INS-like noisy /odom at the scenario's odom rate, the true calibration per frame on
/// /ground_truth/calibration, the scenario on /simulation/scenario), DIR/reference.csv (the
/// truth per frame), DIR/truth.yaml (truth at frame 0) and DIR/initial_guess.yaml (truth at
/// frame 0 + the scenario's initial_error). If DIR/drive.bag exists and was made from the
/// same scenario file and frame count, nothing is done (the cache).
#include <sys/stat.h>
#include <unistd.h>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <string>

#include <cv_bridge/cv_bridge.h>
#include <rosbag/bag.h>

#include "bag_io.h"
#include "online_stereo_calibration/tools/bag_evaluation.h"
#include "online_stereo_calibration/tools/calibration_file.h"
#include "online_stereo_calibration/tools/command_line.h"
#include "online_stereo_calibration/tools/drive_simulation.h"
#include "online_stereo_calibration/tools/estimates_csv.h"
#include "online_stereo_calibration/tools/output_directory.h"

namespace {

struct Options {
  std::string scenario = "config/scenarios/paper_offroad.yaml";
  std::string out;
  int frames = -1;
};

/// The command line (`--help` prints it).
osc::CommandLine commandLine(Options* o) {
  osc::CommandLine cli(
      "simulate",
      "Renders a simulated drive (config/scenarios/*.yaml) into DIR/drive.bag with its truth\n"
      "(reference.csv, truth.yaml, initial_guess.yaml); does nothing when DIR already holds the\n"
      "same scenario and frame count.");
  cli.option("--scenario", &o->scenario, "SCENARIO.yaml", "scenario file");
  cli.option("--out", &o->out, "DIR", "output directory").required();
  cli.option("--frames", &o->frames, "N", "frames to render (-1: the scenario's)").range(1, 1e7);
  return cli;
}

bool exists(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0;
}

void writeCalibration(const std::string& path, const osc::Vector12d& parameters, double stamp) {
  osc::CalibrationFile file;
  file.extrinsics = osc::StereoExtrinsics::fromParameters(parameters);
  file.stamp = stamp;
  osc::writeCalibrationFileAtomic(path, file);
}

/// The tool itself, after the command line.
int simulateDrive(const Options& options) {
  const osc::SimulationScenario scenario = osc::readScenarioFile(options.scenario);
  const osc::DriveSimulator simulator(scenario, options.frames);
  const int frames = simulator.frames();
  const std::string fingerprint = osc::scenarioFingerprint(scenario, frames);
  const std::string bag_path = options.out + "/drive.bag";
  const osc::bag::DriveTopics names;
  if (exists(bag_path) && osc::bag::readScenarioFingerprint(bag_path, names) == fingerprint &&
      exists(options.out + "/reference.csv") && exists(options.out + "/truth.yaml") &&
      exists(options.out + "/initial_guess.yaml")) {
    std::cerr << "simulate: " << bag_path << " is up to date (scenario fingerprint " << fingerprint
              << "), nothing to do\n";
    return 0;
  }
  osc::makeDirectories(options.out);
  const osc::MeasurementScenario& m = scenario.measurement;
  std::cerr << "simulating drive '" << m.name << "': " << frames << " frames at " << m.rate_hz
            << " Hz, " << m.left.width << "x" << m.left.height << ", odometry at "
            << scenario.rendering.odom_rate_hz << " Hz, seed " << m.seed << "\n";

  const std::string partial = options.out + "/drive.partial.bag";
  rosbag::Bag bag(partial, rosbag::bagmode::Write);
  ros::Time start_time;
  start_time.fromSec(simulator.frameStamp(0));
  std_msgs::String scenario_message;
  scenario_message.data = "fingerprint: " + fingerprint + "\n" + scenario.source_text;
  bag.write(names.scenario, start_time, scenario_message);
  for (const osc::StampedPose& pose : simulator.odometry()) {
    const nav_msgs::Odometry odom =
        osc::bag::toOdometry(pose, simulator.odometryTwist(pose.stamp), names);
    bag.write(names.odom, odom.header.stamp, odom);
  }

  osc::ReferenceCsvWriter reference(options.out + "/reference.csv");
  const auto start = std::chrono::steady_clock::now();
  auto last_report = start;
  // A terminal gets a progress bar redrawn every second; a log file a line every 10 s.
  const bool terminal = isatty(STDERR_FILENO) != 0;
  const auto report_every = std::chrono::seconds(terminal ? 1 : 10);
  for (int frame = 0; frame < frames; ++frame) {
    const osc::SimulatedImagePair pair = simulator.renderFrame(frame);
    ros::Time stamp;
    stamp.fromSec(pair.stamp);
    std_msgs::Header header;
    header.stamp = stamp;
    header.seq = frame;
    header.frame_id = names.left_frame;
    bag.write(names.left_image, stamp, cv_bridge::CvImage(header, "mono8", pair.left).toImageMsg());
    bag.write(names.left_info, stamp, osc::bag::toCameraInfo(m.left, stamp, names.left_frame));
    header.frame_id = names.right_frame;
    bag.write(names.right_image, stamp,
              cv_bridge::CvImage(header, "mono8", pair.right).toImageMsg());
    bag.write(names.right_info, stamp, osc::bag::toCameraInfo(m.right, stamp, names.right_frame));
    bag.write(names.truth, stamp, osc::bag::toCalibrationMessage(pair.truth, stamp, names));
    osc::ReferenceRow row;
    row.frame = frame;
    row.stamp = pair.stamp;
    row.parameters = pair.truth;
    reference.write(row);

    const auto now = std::chrono::steady_clock::now();
    if (frame + 1 == frames || now - last_report > report_every) {
      last_report = now;
      const double elapsed = std::chrono::duration<double>(now - start).count();
      std::cerr << (terminal ? "\r  " : "  ") << osc::progressLine(frame + 1, frames, elapsed)
                << (terminal ? "" : "\n") << std::flush;
    }
  }
  if (terminal) std::cerr << "\n";
  reference.flush();
  bag.close();
  writeCalibration(options.out + "/truth.yaml", simulator.truthAt(0), simulator.frameStamp(0));
  writeCalibration(options.out + "/initial_guess.yaml", simulator.initialGuess(),
                   simulator.frameStamp(0));
  if (std::rename(partial.c_str(), bag_path.c_str()) != 0) {
    throw std::runtime_error("cannot rename " + partial + " to " + bag_path);
  }
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cerr << "wrote " << bag_path << ", reference.csv, truth.yaml, initial_guess.yaml (" << frames
            << " frames in " << elapsed << " s, " << frames / elapsed << " frames/s)\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options parsed;
  osc::CommandLine cli = commandLine(&parsed);
  return osc::runTool(
      "simulate", [&] { return cli.usage(); },
      [&] {
        if (!cli.parse(argc, argv)) return 0;
        return simulateDrive(parsed);
      });
}
