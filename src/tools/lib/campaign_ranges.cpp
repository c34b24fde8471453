#include "online_stereo_calibration/tools/campaign_ranges.h"

#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace osc {

double KindChoice::weight(const std::string& kind) const {
  for (const auto& [name, w] : weights) {
    if (name == kind) return w;
  }
  return 0.0;
}

const std::vector<DrawRangeSpec>& drawRangeSpecs() {
  using R = CampaignRanges;
  const double inf = INFINITY;
  static const std::vector<DrawRangeSpec> specs = {
      {"rig.baseline_m", &R::baseline_m, 0.01, 5.0, false},
      {"rig.image_width_px", &R::image_width_px, 64, 8192, false},
      {"rig.focal_px", &R::focal_px, 10, 1e5, false},
      {"rig.plumb_bob_k1", &R::plumb_bob_k1, -1.0, 1.0, false},
      {"rig.equidistant_k1", &R::equidistant_k1, -0.5, 0.5, false},
      {"rig.forward_pitch_down_deg", &R::forward_pitch_down_deg, -60, 60, false},
      {"motion.offroad_speed_mps", &R::offroad_speed_mps, 0, 50, false},
      {"motion.offroad_roll_pitch_std_deg", &R::offroad_roll_pitch_std_deg, 0, 20, false},
      {"motion.offroad_heave_m", &R::offroad_heave_m, 0, 1, false},
      {"motion.offroad_yaw_rate_deg_s", &R::offroad_yaw_rate_deg_s, 0, 90, false},
      {"motion.yaw_phase_deg", &R::yaw_phase_deg, -360, 360, false},
      {"motion.urban_speed_mps", &R::urban_speed_mps, 0, 50, false},
      {"motion.urban_stops", &R::urban_stops, 0, 10, true},
      {"motion.urban_stop_duration_s", &R::urban_stop_duration_s, 0.1, 600, false},
      {"motion.urban_stop_ramp_s", &R::urban_stop_ramp_s, 0, 30, false},
      {"start_errors.caml_translation_m", &R::caml_translation_error_m, 0, 5, false},
      {"start_errors.caml_angle_deg", &R::caml_angle_error_deg, 0, 45, false},
      {"start_errors.camr_baseline_percent", &R::camr_baseline_error_percent, -90, 200, false},
      {"start_errors.camr_translation_m", &R::camr_translation_error_m, 0, 1, false},
      {"start_errors.camr_angle_deg", &R::camr_angle_error_deg, 0, 45, false},
      {"events.at_fraction", &R::event_at_fraction, 0, 1, false},
      {"events.caml_yaw_step_deg", &R::caml_yaw_step_deg, 0, 90, false},
      {"events.camr_knock_deg", &R::camr_knock_deg, 0, 45, false},
      {"events.camr_drift_deg_per_min", &R::camr_drift_deg_per_min, 0, 60, false},
      {"events.camr_drift_mm_per_min", &R::camr_drift_mm_per_min, 0, 1000, false},
      {"odometry.time_offset_ms", &R::time_offset_ms, -500, 500, false},
      {"odometry.scale_error_percent", &R::scale_error_percent, -20, 20, false},
      {"odometry.rotation_rate_bias_deg_s", &R::rotation_rate_bias_deg_s, 0, 10, false},
      {"odometry.velocity_bias_mps", &R::velocity_bias_mps, 0, 10, false},
      {"odometry.white_noise_factor", &R::white_noise_factor, 1, 100, false},
      {"odometry.bias_correlation_time_s", &R::bias_correlation_time_s, 0.1, inf, false},
      {"scene.blind_stretches", &R::blind_stretches, 0, 10, true},
      {"scene.blind_duration_s", &R::blind_duration_s, 0.1, 600, false},
      {"scene.moving_point_fraction", &R::moving_point_fraction, 0, 1, false},
      {"scene.moving_point_speed_mps", &R::moving_point_speed_mps, 0, 50, false},
      {"images.noise_grey", &R::image_noise_grey, 0, 50, false},
      {"images.blur_px", &R::image_blur_px, 0, 10, false},
      {"images.exposure_flicker", &R::exposure_flicker, 0, 0.9, false},
  };
  return specs;
}

const std::vector<KindChoiceSpec>& kindChoiceSpecs() {
  using R = CampaignRanges;
  static const std::vector<KindChoiceSpec> specs = {
      {"rig.lens", &R::lens, {"pinhole", "plumb_bob", "equidistant"}},
      {"rig.mounting", &R::mounting, {"forward", "backward", "sideways"}},
      {"motion.kind", &R::motion, {"offroad", "urban", "recorded"}},
      {"events.kind", &R::event, {"none", "caml_yaw_step", "camr_knock", "camr_drift"}},
  };
  return specs;
}

std::string readTextFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read '" + path + "'");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

namespace {

std::string dump(const YAML::Node& node) {
  YAML::Emitter out;
  out << YAML::Flow << node;
  return out.c_str();
}

bool isDirectory(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

/// The *.tum files of a directory, sorted.
std::vector<std::string> tumFiles(const std::string& dir) {
  std::vector<std::string> files;
  if (DIR* d = opendir(dir.c_str())) {
    while (const dirent* entry = readdir(d)) {
      const std::string name = entry->d_name;
      if (name.size() > 4 && name.compare(name.size() - 4, 4, ".tum") == 0) {
        files.push_back(dir + "/" + name);
      }
    }
    closedir(d);
  }
  std::sort(files.begin(), files.end());
  return files;
}

void readRange(const YAML::Node& node, const DrawRangeSpec& spec, DrawRange* range,
               std::vector<std::string>* problems) {
  DrawRange r;
  try {
    if (node.IsScalar()) {
      r.min = r.max = node.as<double>();
    } else if (node.IsSequence() && node.size() == 2) {
      r.min = node[0].as<double>();
      r.max = node[1].as<double>();
    } else {
      problems->push_back(spec.key + ": '" + dump(node) + "' is not a number or [min, max]");
      return;
    }
  } catch (const YAML::Exception&) {
    problems->push_back(spec.key + ": '" + dump(node) + "' is not a number or [min, max]");
    return;
  }
  std::ostringstream where;
  where << spec.key << ": [" << r.min << ", " << r.max << "]";
  if (!std::isfinite(r.min) || !std::isfinite(r.max)) {
    problems->push_back(where.str() + " must be finite");
  } else if (r.min > r.max) {
    problems->push_back(where.str() + ": min > max");
  } else if (r.min < spec.low || r.max > spec.high) {
    std::ostringstream limits;
    limits << " must lie within [" << spec.low << ", " << spec.high << "]";
    problems->push_back(where.str() + limits.str());
  } else if (spec.integer && (r.min != std::floor(r.min) || r.max != std::floor(r.max))) {
    problems->push_back(where.str() + " must be integers");
  } else {
    *range = r;
  }
}

void readKinds(const YAML::Node& node, const KindChoiceSpec& spec, KindChoice* choice,
               std::vector<std::string>* problems) {
  const auto known = [&](const std::string& kind) {
    return std::find(spec.kinds.begin(), spec.kinds.end(), kind) != spec.kinds.end();
  };
  std::string list;
  for (const std::string& k : spec.kinds) list += (list.empty() ? "" : ", ") + k;
  KindChoice result;
  const size_t before = problems->size();
  try {
    if (node.IsScalar()) {
      const std::string kind = node.as<std::string>();
      if (!known(kind)) {
        problems->push_back(spec.key + ": unknown kind '" + kind + "' (" + list + ")");
      }
      result.weights.push_back({kind, 1.0});
    } else if (node.IsMap()) {
      double sum = 0.0;
      for (const auto& entry : node) {
        const std::string kind = entry.first.as<std::string>();
        if (!known(kind)) {
          problems->push_back(spec.key + ": unknown kind '" + kind + "' (" + list + ")");
          continue;
        }
        double w = NAN;
        try {
          w = entry.second.as<double>();
        } catch (const YAML::Exception&) {
        }
        if (!(w >= 0.0 && std::isfinite(w))) {
          problems->push_back(spec.key + "." + kind + ": weight '" + dump(entry.second) +
                              "' must be a number >= 0");
          continue;
        }
        result.weights.push_back({kind, w});
        sum += w;
      }
      if (problems->size() == before && !(sum > 0.0)) {
        problems->push_back(spec.key + ": at least one weight must be > 0");
      }
    } else {
      problems->push_back(spec.key + ": '" + dump(node) + "' is not a kind or {kind: weight}");
    }
  } catch (const YAML::Exception&) {
    problems->push_back(spec.key + ": '" + dump(node) + "' is not a kind or {kind: weight}");
  }
  if (problems->size() == before) *choice = result;
}

}  // namespace

CampaignRanges parseCampaignRanges(const std::string& text, const std::string& source_name,
                                   const std::string& base_dir) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(source_name + ": not valid YAML: " + e.what());
  }
  CampaignRanges ranges;
  std::vector<std::string> problems;
  if (root && !root.IsNull() && !root.IsMap()) {
    throw std::runtime_error(source_name + ": expected a map of sections (rig, motion, ...)");
  }
  std::set<std::string> known_keys, sections;
  for (const DrawRangeSpec& s : drawRangeSpecs()) known_keys.insert(s.key);
  for (const KindChoiceSpec& s : kindChoiceSpecs()) known_keys.insert(s.key);
  for (const std::string& key : known_keys) sections.insert(key.substr(0, key.find('.')));

  std::string trajectories_dir;
  bool has_dir = false;
  if (root && root.IsMap()) {
    for (const auto& entry : root) {
      const std::string section = entry.first.as<std::string>();
      if (section == "trajectories_dir") {
        try {
          trajectories_dir = entry.second.as<std::string>();
          has_dir = true;
        } catch (const YAML::Exception&) {
          problems.push_back("trajectories_dir: '" + dump(entry.second) + "' is not a path");
        }
        continue;
      }
      if (!sections.count(section)) {
        problems.push_back(section + ": unknown key");
        continue;
      }
      if (!entry.second.IsMap()) {
        if (!entry.second.IsNull()) problems.push_back(section + ": expected a map of keys");
        continue;
      }
      for (const auto& item : entry.second) {
        const std::string key = section + "." + item.first.as<std::string>();
        if (!known_keys.count(key)) problems.push_back(key + ": unknown key");
      }
    }
    for (const DrawRangeSpec& s : drawRangeSpecs()) {
      const size_t dot = s.key.find('.');
      const YAML::Node section = root[s.key.substr(0, dot)];
      if (!section || !section.IsMap()) continue;
      if (const YAML::Node node = section[s.key.substr(dot + 1)]) {
        readRange(node, s, &(ranges.*s.member), &problems);
      }
    }
    for (const KindChoiceSpec& s : kindChoiceSpecs()) {
      const size_t dot = s.key.find('.');
      const YAML::Node section = root[s.key.substr(0, dot)];
      if (!section || !section.IsMap()) continue;
      if (const YAML::Node node = section[s.key.substr(dot + 1)]) {
        readKinds(node, s, &(ranges.*s.member), &problems);
      }
    }
  }

  if (ranges.motion.weight("recorded") > 0.0) {
    if (!has_dir) {
      problems.push_back(
          "trajectories_dir: not given, but motion.kind 'recorded' has a weight > 0");
    } else {
      std::string dir;
      const std::string beside =
          (trajectories_dir.rfind('/', 0) == 0 ? "" : base_dir + "/") + trajectories_dir;
      if (isDirectory(beside)) {
        dir = beside;
      } else if (isDirectory(trajectories_dir)) {
        dir = trajectories_dir;
      }
      std::string missing;
      if (dir.empty()) {
        missing = "trajectories_dir: '" + trajectories_dir +
                  "' is not a directory (looked beside the ranges file, '" + beside +
                  "', and in the current directory)";
      } else {
        ranges.trajectory_files = tumFiles(dir);
        if (ranges.trajectory_files.empty()) {
          missing = "trajectories_dir: '" + dir + "' holds no *.tum file";
        }
      }
      if (!missing.empty()) {
        // Drop the kind rather than refuse the campaign: a clone without the recorded
        // trajectories beside it still runs the drawn motions.
        for (auto& kind_weight : ranges.motion.weights) {
          if (kind_weight.first == "recorded") kind_weight.second = 0.0;
        }
        bool other = false;
        for (const auto& kind_weight : ranges.motion.weights) other |= kind_weight.second > 0.0;
        if (other) {
          ranges.dropped_recorded =
              missing + ": motion.kind 'recorded' dropped, the other motions drawn";
        } else {
          problems.push_back(missing + "; needed by motion.kind 'recorded', the only kind");
        }
      }
    }
  }
  if (!problems.empty()) {
    std::string message = source_name + ": invalid ranges:";
    for (const std::string& p : problems) message += "\n  " + p;
    throw std::runtime_error(message);
  }
  return ranges;
}

CampaignRanges readCampaignRangesFile(const std::string& path) {
  const std::string text = readTextFile(path);
  const auto slash = path.find_last_of('/');
  return parseCampaignRanges(text, path, slash == std::string::npos ? "." : path.substr(0, slash));
}

}  // namespace osc
