/// @file scenario_file.cpp
/// @brief Parser of the simulator's scenario files (see scenario_file.h): the top level, the
/// file, the fingerprint; the sections' readers in scenario_file_sections.cpp.
#include "online_stereo_calibration/tools/scenario_file.h"

#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "online_stereo_calibration/tools/tum_trajectory.h"

#include "scenario_file_internal.h"

namespace osc {

using namespace scenario_file_internal;

namespace {

/// Version of the simulator's output; part of the cache fingerprint.
// Not bumped for stops, odometry errors and blind frames: they are keys of the scenario text
// (part of the fingerprint), and a drive without them is bit-identical to before.
// 2: scene along the whole drive, 3: dead-reckoned odometry, 4: the odometry's twists, recorded
// drives on a C1 curve (issue 15)
constexpr const char* kSimulatorVersion = "simulate-4";

MeasurementScenario presetByName(const std::string& name, Problems* p) {
  if (name == "paper_offroad") return paperOffroadScenario();
  if (name == "urban_planar") return urbanPlanarScenario();
  if (name == "drift") return driftScenario();
  p->add("base", "unknown preset '" + name + "' (paper_offroad, urban_planar, drift)");
  return paperOffroadScenario();
}

}  // namespace

SimulationScenario parseScenarioYaml(const std::string& text, const std::string& source_name,
                                     const std::string& base_directory) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(source_name + ": not valid YAML: " + e.what());
  }
  if (!root.IsMap()) throw std::runtime_error(source_name + ": must be a YAML map");
  Problems p;
  checkKeys(root, "",
            {"base",
             "name",
             "frames",
             "rate_hz",
             "seed",
             "left_camera",
             "right_camera",
             "truth",
             "initial_error",
             "step_frame",
             "step",
             "drift_per_second",
             "motion",
             "motion_rotation_noise",
             "motion_translation_noise",
             "odometry_error",
             "blind_frames",
             "moving_point_fraction",
             "moving_point_speed",
             "trajectory",
             "rendering"},
            &p);
  SimulationScenario s;
  s.source_text = text;
  std::string base = "paper_offroad";
  if (root["base"]) base = root["base"].as<std::string>();
  s.measurement = presetByName(base, &p);
  MeasurementScenario& m = s.measurement;
  if (root["name"]) m.name = root["name"].as<std::string>();
  if (root["frames"]) readInt(root["frames"], "frames", &m.frames, &p);
  if (root["rate_hz"]) readDouble(root["rate_hz"], "rate_hz", &m.rate_hz, &p);
  if (root["seed"]) readInt(root["seed"], "seed", &m.seed, &p);
  if (root["left_camera"])
    readCamera(root["left_camera"], "left_camera", base_directory, &m.left, &p);
  if (root["right_camera"]) {
    readCamera(root["right_camera"], "right_camera", base_directory, &m.right, &p);
  }
  if (root["truth"]) readTruth(root["truth"], base_directory, &m.truth, &p);
  if (root["initial_error"])
    readParameters(root["initial_error"], "initial_error", &m.initial_error, &p);
  if (root["step_frame"]) readInt(root["step_frame"], "step_frame", &m.step_frame, &p);
  if (root["step"]) readParameters(root["step"], "step", &m.step, &p);
  if (root["drift_per_second"]) {
    readParameters(root["drift_per_second"], "drift_per_second", &m.drift_per_second, &p);
  }
  if (root["motion"]) readMotion(root["motion"], &m.motion, &p);
  if (root["motion_rotation_noise"]) {
    readDouble(root["motion_rotation_noise"], "motion_rotation_noise", &m.motion_rotation_noise,
               &p);
  }
  if (root["motion_translation_noise"]) {
    readDouble(root["motion_translation_noise"], "motion_translation_noise",
               &m.motion_translation_noise, &p);
  }
  if (root["odometry_error"]) readOdometryError(root["odometry_error"], &m.odometry_error, &p);
  if (root["blind_frames"]) readBlindFrames(root["blind_frames"], &m.blind_frames, &p);
  if (root["moving_point_fraction"]) {
    readDouble(root["moving_point_fraction"], "moving_point_fraction", &m.moving_point_fraction,
               &p);
  }
  if (root["moving_point_speed"]) {
    readDouble(root["moving_point_speed"], "moving_point_speed", &m.moving_point_speed, &p);
  }
  if (root["trajectory"]) readTrajectory(root["trajectory"], base_directory, &s.trajectory, &p);
  if (s.trajectory && p.list.empty()) {
    // The recording replaces the analytic motion for both simulators (validate() checks
    // that it covers the frames).
    try {
      m.recorded_trajectory =
          std::make_shared<const PoseTrajectory>(readTumTrajectory(s.trajectory->file));
      m.recorded_start_offset = s.trajectory->start_offset;
    } catch (const std::exception& e) {
      p.add("trajectory.tum_file", e.what());
    }
  }
  if (root["rendering"]) readRendering(root["rendering"], &s.rendering, &p);
  if (p.list.empty()) {
    for (std::string problem : m.validate()) {
      // The file's name of the field.
      if (problem.find("recorded_start_offset") != std::string::npos) {
        problem += " (recorded_start_offset = trajectory.start_offset in the file)";
      }
      p.list.push_back(problem);
    }
  }
  if (!p.list.empty()) {
    std::string message = source_name + ":";
    for (const std::string& problem : p.list) message += "\n  " + problem;
    throw std::runtime_error(message);
  }
  return s;
}

SimulationScenario readScenarioFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open scenario file '" + path + "'");
  std::ostringstream text;
  text << in.rdbuf();
  const auto slash = path.find_last_of('/');
  const std::string directory = slash == std::string::npos ? "." : path.substr(0, slash);
  return parseScenarioYaml(text.str(), path, directory);
}

std::string scenarioFingerprint(const SimulationScenario& scenario, int frames) {
  const std::string text = std::string(kSimulatorVersion) + "\nframes=" + std::to_string(frames) +
                           "\n" + scenario.source_text;
  std::uint64_t hash = 1469598103934665603ULL;
  for (unsigned char c : text) {
    hash ^= c;
    hash *= 1099511628211ULL;
  }
  char buffer[17];
  std::snprintf(buffer, sizeof buffer, "%016llx", static_cast<unsigned long long>(hash));
  return buffer;
}

}  // namespace osc
