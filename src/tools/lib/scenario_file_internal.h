/// @file scenario_file_internal.h
/// @brief Private to the scenario file's parser (scenario_file*.cpp): the problem list, the
/// value readers and the readers of the file's sections, each adding a problem per bad key.
#pragma once

#include <optional>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "online_stereo_calibration/tools/scenario_file.h"

namespace osc {
namespace scenario_file_internal {

/// Collects problems instead of stopping at the first.
struct Problems {
  std::vector<std::string> list;
  void add(const std::string& key, const std::string& what) { list.push_back(key + ": " + what); }
};

/// Adds "<prefix><key>: unknown key" for each key of the map @p node not in @p allowed.
void checkKeys(const YAML::Node& node, const std::string& prefix,
               const std::set<std::string>& allowed, Problems* problems);

/// A finite number into *out (true), else a problem under @p key (false, *out unchanged).
bool readDouble(const YAML::Node& node, const std::string& key, double* out, Problems* p);

/// An integer into *out, else a problem under @p key.
template <typename Int>
void readInt(const YAML::Node& node, const std::string& key, Int* out, Problems* p) {
  try {
    *out = node.as<Int>();
  } catch (const YAML::Exception&) {
    p->add(key, "not an integer");
  }
}

/// {vehicle_to_left: [6], left_to_right: [6]} into a 12-vector (keys left out keep values).
void readParameters(const YAML::Node& node, const std::string& key, Vector12d* out, Problems* p);

/// The camera map under @p key (its fields, or an EuRoC sensor.yaml resolved against @p base)
/// into *camera; keys left out keep their values.
void readCamera(const YAML::Node& node, const std::string& key, const std::string& base,
                CameraIntrinsics* camera, Problems* p);

/// The truth: the 12 parameters ({vehicle_to_left, left_to_right}) or EuRoC's two sensor.yaml
/// files (resolved against @p base) and R_body_vehicle.
void readTruth(const YAML::Node& node, const std::string& base, Vector12d* truth, Problems* p);

/// blind_frames: a list of [first, last] frame pairs.
void readBlindFrames(const YAML::Node& node, std::vector<FrameSpan>* spans, Problems* p);

/// The odometry_error map.
void readOdometryError(const YAML::Node& node, OdometryErrorModel* e, Problems* p);

/// The motion map: the analytic drive's profile, stops included.
void readMotion(const YAML::Node& node, VehicleMotionProfile* m, Problems* p);

/// The rendering map, with its range checks.
void readRendering(const YAML::Node& node, SceneRenderingOptions* r, Problems* p);

/// The trajectory map: a TUM file (resolved against @p base; it must exist), start offset.
void readTrajectory(const YAML::Node& node, const std::string& base,
                    std::optional<TumTrajectoryOption>* out, Problems* p);

}  // namespace scenario_file_internal
}  // namespace osc
