/// @file scenario_file_sections.cpp
/// @brief Readers of the scenario file's values and sections: cameras (or EuRoC's
/// sensor.yaml), truth, motion, odometry error, blind frames, rendering, trajectory.
#include "online_stereo_calibration/tools/scenario_file.h"

#include <sys/stat.h>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "scenario_file_internal.h"

namespace osc {
namespace scenario_file_internal {
namespace {

bool fileExists(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::string resolvePath(const std::string& path, const std::string& base_directory) {
  if (path.empty() || path[0] == '/') return path;
  const std::string relative = base_directory.empty() ? path : base_directory + "/" + path;
  if (fileExists(relative)) return relative;
  if (fileExists(path)) return path;
  return relative;
}

void readVector(const YAML::Node& node, const std::string& key, int size, double* out,
                Problems* p) {
  if (!node.IsSequence() || static_cast<int>(node.size()) != size) {
    p->add(key, "must be a list of " + std::to_string(size) + " numbers");
    return;
  }
  for (int i = 0; i < size; ++i) readDouble(node[i], key, &out[i], p);
}

/// Loads a YAML file that may start with OpenCV's "%YAML:1.0" line (EuRoC files do).
YAML::Node loadOpenCvYaml(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open '" + path + "'");
  std::ostringstream text;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("%YAML", 0) == 0) continue;
    text << line << "\n";
  }
  return YAML::Load(text.str());
}

/// T_BS of an EuRoC sensor.yaml: the sensor (optical) frame in the body (IMU) frame.
Eigen::Isometry3d readEurocTBS(const std::string& path) {
  const YAML::Node root = loadOpenCvYaml(path);
  const YAML::Node data = root["T_BS"]["data"];
  if (!data || !data.IsSequence() || data.size() != 16) {
    throw std::runtime_error(path + ": T_BS.data must hold 16 numbers");
  }
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = data[i].as<double>();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  // Orthonormalise the rotation (the file has ~1e-9 rounding).
  const Eigen::Quaterniond q(Eigen::Matrix3d(m.block<3, 3>(0, 0)));
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = m.block<3, 1>(0, 3);
  return T;
}

/// A list of [a, b] pairs, e.g. [[10, 5], [40, 3]]; false (and a problem) if malformed.
bool readPairs(const YAML::Node& node, const std::string& key,
               std::vector<std::pair<YAML::Node, YAML::Node>>* out, Problems* p) {
  if (!node.IsSequence()) {
    p->add(key, "must be a list of [a, b] pairs");
    return false;
  }
  for (std::size_t i = 0; i < node.size(); ++i) {
    if (!node[i].IsSequence() || node[i].size() != 2) {
      p->add(key + "[" + std::to_string(i) + "]", "must be a pair [a, b]");
      return false;
    }
    out->emplace_back(node[i][0], node[i][1]);
  }
  return true;
}

void readStops(const YAML::Node& node, std::vector<TimeSpan>* stops, Problems* p) {
  std::vector<std::pair<YAML::Node, YAML::Node>> pairs;
  if (!readPairs(node, "motion.stops", &pairs, p)) return;
  stops->clear();
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const std::string key = "motion.stops[" + std::to_string(i) + "]";
    TimeSpan stop;
    readDouble(pairs[i].first, key + ".start", &stop.start, p);
    readDouble(pairs[i].second, key + ".duration", &stop.duration, p);
    stops->push_back(stop);
  }
}

}  // namespace

void checkKeys(const YAML::Node& node, const std::string& prefix,
               const std::set<std::string>& allowed, Problems* problems) {
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    if (!allowed.count(key)) problems->add(prefix + key, "unknown key");
  }
}

bool readDouble(const YAML::Node& node, const std::string& key, double* out, Problems* p) {
  try {
    const double v = node.as<double>();
    if (!std::isfinite(v)) {
      p->add(key, "not finite");
      return false;
    }
    *out = v;
    return true;
  } catch (const YAML::Exception&) {
    p->add(key, "not a number");
    return false;
  }
}

void readParameters(const YAML::Node& node, const std::string& key, Vector12d* out, Problems* p) {
  if (!node.IsMap()) {
    p->add(key, "must be a map with vehicle_to_left and/or left_to_right");
    return;
  }
  checkKeys(node, key + ".", {"vehicle_to_left", "left_to_right"}, p);
  if (node["vehicle_to_left"]) {
    readVector(node["vehicle_to_left"], key + ".vehicle_to_left", 6, out->data(), p);
  }
  if (node["left_to_right"]) {
    readVector(node["left_to_right"], key + ".left_to_right", 6, out->data() + 6, p);
  }
}

void readCamera(const YAML::Node& node, const std::string& key, const std::string& base,
                CameraIntrinsics* camera, Problems* p) {
  if (!node.IsMap()) {
    p->add(key, "must be a map");
    return;
  }
  checkKeys(node, key + ".",
            {"width", "height", "fx", "fy", "cx", "cy", "distortion_model", "distortion",
             "euroc_sensor_yaml"},
            p);
  if (node["euroc_sensor_yaml"]) {
    try {
      *camera = readEurocIntrinsics(resolvePath(node["euroc_sensor_yaml"].as<std::string>(), base));
    } catch (const std::exception& e) {
      p->add(key + ".euroc_sensor_yaml", e.what());
    }
  }
  if (node["width"]) readInt(node["width"], key + ".width", &camera->width, p);
  if (node["height"]) readInt(node["height"], key + ".height", &camera->height, p);
  if (node["fx"]) readDouble(node["fx"], key + ".fx", &camera->fx, p);
  if (node["fy"]) readDouble(node["fy"], key + ".fy", &camera->fy, p);
  if (node["cx"]) readDouble(node["cx"], key + ".cx", &camera->cx, p);
  if (node["cy"]) readDouble(node["cy"], key + ".cy", &camera->cy, p);
  if (node["distortion_model"]) {
    try {
      camera->model = distortionModelFromName(node["distortion_model"].as<std::string>());
    } catch (const std::exception& e) {
      p->add(key + ".distortion_model", e.what());
    }
  }
  if (node["distortion"]) {
    if (!node["distortion"].IsSequence()) {
      p->add(key + ".distortion", "must be a list of numbers");
    } else {
      camera->distortion.assign(node["distortion"].size(), 0.0);
      for (std::size_t i = 0; i < camera->distortion.size(); ++i) {
        readDouble(node["distortion"][i], key + ".distortion", &camera->distortion[i], p);
      }
    }
  }
  try {
    CameraModel check(*camera);
  } catch (const std::exception& e) {
    p->add(key, e.what());
  }
}

void readTruth(const YAML::Node& node, const std::string& base, Vector12d* truth, Problems* p) {
  if (node.IsMap() && (node["euroc_left"] || node["euroc_right"] || node["R_body_vehicle"])) {
    checkKeys(node, "truth.", {"euroc_left", "euroc_right", "R_body_vehicle"}, p);
    if (!node["euroc_left"] || !node["euroc_right"] || !node["R_body_vehicle"]) {
      p->add("truth", "euroc_left, euroc_right and R_body_vehicle go together");
      return;
    }
    double r[9];
    const std::size_t before = p->list.size();
    readVector(node["R_body_vehicle"], "truth.R_body_vehicle", 9, r, p);
    if (p->list.size() != before) return;
    Eigen::Matrix3d R_body_vehicle;
    for (int i = 0; i < 9; ++i) R_body_vehicle(i / 3, i % 3) = r[i];
    if (!(R_body_vehicle.transpose() * R_body_vehicle).isIdentity(1e-6)) {
      p->add("truth.R_body_vehicle", "not a rotation matrix");
      return;
    }
    try {
      Eigen::Isometry3d T_vehicle_body = Eigen::Isometry3d::Identity();
      T_vehicle_body.linear() = R_body_vehicle.transpose();
      const Eigen::Isometry3d T_body_optical_inv = bodyFromOptical().inverse();
      const Eigen::Isometry3d left =
          T_vehicle_body * readEurocTBS(resolvePath(node["euroc_left"].as<std::string>(), base)) *
          T_body_optical_inv;
      const Eigen::Isometry3d right =
          T_vehicle_body * readEurocTBS(resolvePath(node["euroc_right"].as<std::string>(), base)) *
          T_body_optical_inv;
      StereoExtrinsics extrinsics;
      extrinsics.T_veh_caml = left;
      extrinsics.T_caml_camr = left.inverse() * right;
      *truth = extrinsics.toParameters();
    } catch (const std::exception& e) {
      p->add("truth", e.what());
    }
    return;
  }
  readParameters(node, "truth", truth, p);
}

void readBlindFrames(const YAML::Node& node, std::vector<FrameSpan>* spans, Problems* p) {
  std::vector<std::pair<YAML::Node, YAML::Node>> pairs;
  if (!readPairs(node, "blind_frames", &pairs, p)) return;
  spans->clear();
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const std::string key = "blind_frames[" + std::to_string(i) + "]";
    FrameSpan span;
    readInt(pairs[i].first, key + ".first", &span.first, p);
    readInt(pairs[i].second, key + ".last", &span.last, p);
    spans->push_back(span);
  }
}

void readOdometryError(const YAML::Node& node, OdometryErrorModel* e, Problems* p) {
  if (!node.IsMap()) {
    p->add("odometry_error", "must be a map");
    return;
  }
  checkKeys(node, "odometry_error.",
            {"time_offset", "scale_error", "rotation_rate_bias", "velocity_bias",
             "bias_correlation_time"},
            p);
  const std::pair<const char*, double*> fields[] = {
      {"time_offset", &e->time_offset},
      {"scale_error", &e->scale_error},
      {"rotation_rate_bias", &e->rotation_rate_bias},
      {"velocity_bias", &e->velocity_bias},
      {"bias_correlation_time", &e->bias_correlation_time}};
  for (const auto& f : fields) {
    if (node[f.first]) {
      readDouble(node[f.first], std::string("odometry_error.") + f.first, f.second, p);
    }
  }
}

void readMotion(const YAML::Node& node, VehicleMotionProfile* m, Problems* p) {
  if (!node.IsMap()) {
    p->add("motion", "must be a map");
    return;
  }
  checkKeys(node, "motion.",
            {"speed", "roll_amplitude", "pitch_amplitude", "roll_period", "pitch_period",
             "yaw_rate_amplitude", "yaw_period", "yaw_phase", "heave_amplitude", "heave_period",
             "planar", "stops", "stop_ramp"},
            p);
  const std::pair<const char*, double*> fields[] = {{"speed", &m->speed},
                                                    {"roll_amplitude", &m->roll_amplitude},
                                                    {"pitch_amplitude", &m->pitch_amplitude},
                                                    {"roll_period", &m->roll_period},
                                                    {"pitch_period", &m->pitch_period},
                                                    {"yaw_rate_amplitude", &m->yaw_rate_amplitude},
                                                    {"yaw_period", &m->yaw_period},
                                                    {"yaw_phase", &m->yaw_phase},
                                                    {"heave_amplitude", &m->heave_amplitude},
                                                    {"heave_period", &m->heave_period},
                                                    {"stop_ramp", &m->stop_ramp}};
  for (const auto& f : fields) {
    if (node[f.first]) readDouble(node[f.first], std::string("motion.") + f.first, f.second, p);
  }
  if (node["planar"]) {
    try {
      m->planar = node["planar"].as<bool>();
    } catch (const YAML::Exception&) {
      p->add("motion.planar", "not a boolean");
    }
  }
  if (node["stops"]) readStops(node["stops"], &m->stops, p);
}

void readRendering(const YAML::Node& node, SceneRenderingOptions* r, Problems* p) {
  if (!node.IsMap()) {
    p->add("rendering", "must be a map");
    return;
  }
  checkKeys(node, "rendering.",
            {"scene_seed", "ground_undulation", "structure_density", "image_noise", "blur_sigma",
             "supersampling", "odom_rate_hz", "start_stamp", "room_margin", "room_height"},
            p);
  if (node["scene_seed"]) readInt(node["scene_seed"], "rendering.scene_seed", &r->scene_seed, p);
  if (node["supersampling"]) {
    readInt(node["supersampling"], "rendering.supersampling", &r->supersampling, p);
  }
  const std::pair<const char*, double*> fields[] = {{"ground_undulation", &r->ground_undulation},
                                                    {"structure_density", &r->structure_density},
                                                    {"image_noise", &r->image_noise},
                                                    {"blur_sigma", &r->blur_sigma},
                                                    {"odom_rate_hz", &r->odom_rate_hz},
                                                    {"start_stamp", &r->start_stamp},
                                                    {"room_margin", &r->room_margin},
                                                    {"room_height", &r->room_height}};
  for (const auto& f : fields) {
    if (node[f.first]) readDouble(node[f.first], std::string("rendering.") + f.first, f.second, p);
  }
  if (r->ground_undulation < 0) p->add("rendering.ground_undulation", "must be >= 0");
  if (r->structure_density < 0) p->add("rendering.structure_density", "must be >= 0");
  if (r->image_noise < 0) p->add("rendering.image_noise", "must be >= 0");
  if (r->blur_sigma < 0) p->add("rendering.blur_sigma", "must be >= 0");
  if (r->supersampling < 1 || r->supersampling > 4)
    p->add("rendering.supersampling", "must be 1-4");
  if (!(r->odom_rate_hz > 0)) p->add("rendering.odom_rate_hz", "must be > 0");
  if (!(r->start_stamp >= 1)) p->add("rendering.start_stamp", "must be >= 1 s");
  if (!(r->room_margin >= 0 && r->room_margin <= 100)) {
    p->add("rendering.room_margin", "must be 0 (outdoors) to 100 m");
  }
  if (!(r->room_height > 0 && r->room_height <= 100)) {
    p->add("rendering.room_height", "must be in (0, 100] m");
  }
}

void readTrajectory(const YAML::Node& node, const std::string& base,
                    std::optional<TumTrajectoryOption>* out, Problems* p) {
  if (!node.IsMap()) {
    p->add("trajectory", "must be a map");
    return;
  }
  checkKeys(node, "trajectory.", {"tum_file", "start_offset"}, p);
  if (!node["tum_file"]) {
    p->add("trajectory.tum_file", "missing");
    return;
  }
  TumTrajectoryOption option;
  option.file = resolvePath(node["tum_file"].as<std::string>(), base);
  if (!fileExists(option.file)) p->add("trajectory.tum_file", "no such file '" + option.file + "'");
  if (node["start_offset"]) {
    readDouble(node["start_offset"], "trajectory.start_offset", &option.start_offset, p);
    if (option.start_offset < 0) p->add("trajectory.start_offset", "must be >= 0");
  }
  *out = option;
}

}  // namespace scenario_file_internal

using namespace scenario_file_internal;

CameraIntrinsics readEurocIntrinsics(const std::string& path) {
  const YAML::Node root = loadOpenCvYaml(path);
  const YAML::Node resolution = root["resolution"];
  const YAML::Node intrinsics = root["intrinsics"];
  const YAML::Node distortion = root["distortion_coefficients"];
  if (!resolution || resolution.size() != 2 || !intrinsics || intrinsics.size() != 4 ||
      !distortion) {
    throw std::runtime_error(path +
                             ": needs resolution [2], intrinsics [4] and "
                             "distortion_coefficients");
  }
  const std::string model =
      root["distortion_model"] ? root["distortion_model"].as<std::string>() : "radial-tangential";
  if (model != "radial-tangential") {
    throw std::runtime_error(path + ": distortion_model '" + model + "' not supported");
  }
  CameraIntrinsics c;
  c.width = resolution[0].as<int>();
  c.height = resolution[1].as<int>();
  c.fx = intrinsics[0].as<double>();
  c.fy = intrinsics[1].as<double>();
  c.cx = intrinsics[2].as<double>();
  c.cy = intrinsics[3].as<double>();
  c.model = DistortionModel::kPlumbBob;
  for (const auto& d : distortion) c.distortion.push_back(d.as<double>());
  return c;
}

}  // namespace osc
