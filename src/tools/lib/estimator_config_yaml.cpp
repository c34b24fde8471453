/// @file estimator_config_yaml.cpp
/// @brief FilterConfig + FrontEndConfig from one YAML file.
#include "online_stereo_calibration/tools/estimator_config_yaml.h"

#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "config_yaml_detail.h"

namespace osc {
namespace {

using Type = FrontEndKey::Type;

FrontEndKey integerKey(const char* name, int FrontEndConfig::*field) {
  FrontEndKey k;
  k.name = name;
  k.type = Type::kInteger;
  k.integer_field = field;
  return k;
}

FrontEndKey realKey(const char* name, double FrontEndConfig::*field) {
  FrontEndKey k;
  k.name = name;
  k.type = Type::kReal;
  k.real_field = field;
  return k;
}

FrontEndKey stringKey(const char* name, std::string FrontEndConfig::*field) {
  FrontEndKey k;
  k.name = name;
  k.type = Type::kString;
  k.string_field = field;
  return k;
}

constexpr const char* kFrontEndSection = "front_end";

}  // namespace

const std::vector<FrontEndKey>& frontEndKeyTable() {
  using C = FrontEndConfig;
  static const std::vector<FrontEndKey> table = {
      stringKey("detector", &C::detector),
      integerKey("max_features", &C::max_features),
      integerKey("fast_threshold", &C::fast_threshold),
      integerKey("orb_levels", &C::orb_levels),
      realKey("orb_scale_factor", &C::orb_scale_factor),
      integerKey("detection_grid", &C::detection_grid),
      realKey("border", &C::border),
      realKey("band_sigmas", &C::band_sigmas),
      realKey("min_band", &C::min_band),
      realKey("max_band", &C::max_band),
      realKey("pixel_sigma", &C::pixel_sigma),
      realKey("max_descriptor_distance", &C::max_descriptor_distance),
      realKey("ratio", &C::ratio),
      integerKey("bucket_cols", &C::bucket_cols),
      integerKey("bucket_rows", &C::bucket_rows),
      integerKey("max_new_points_per_frame", &C::max_new_points_per_frame),
      realKey("min_distance_to_track", &C::min_distance_to_track),
      realKey("min_parallax_deg", &C::min_parallax_deg),
      realKey("track_window_sigmas", &C::track_window_sigmas),
      realKey("min_track_window", &C::min_track_window),
      realKey("max_track_window", &C::max_track_window),
      realKey("max_track_descriptor_distance", &C::max_track_descriptor_distance),
      integerKey("min_image_size", &C::min_image_size),
      realKey("min_contrast", &C::min_contrast),
  };
  return table;
}

EstimatorConfig parseEstimatorConfigYaml(const std::string& text, const std::string& source_name,
                                         const EstimatorConfig& base) {
  const YAML::Node root = detail::loadConfigMap(text, source_name);
  EstimatorConfig config = base;
  std::vector<std::string> problems;
  std::set<std::string> known = {kFrontEndSection};
  if (root && root.IsMap()) detail::readFilterKeys(root, &config.filter, &known, &problems);
  if (root && root.IsMap()) {
    for (const auto& entry : root) {
      const std::string key = entry.first.as<std::string>();
      if (!known.count(key)) problems.push_back(key + ": unknown parameter");
    }
  }
  for (const std::string& p : config.filter.validate()) problems.push_back(p);

  const std::string prefix = std::string(kFrontEndSection) + ".";
  const YAML::Node section = root && root.IsMap() ? root[kFrontEndSection] : YAML::Node();
  if (section && !section.IsNull() && !section.IsMap()) {
    problems.push_back(std::string(kFrontEndSection) + ": expected a map of key: value");
  } else if (section && section.IsMap()) {
    std::set<std::string> front_end_known;
    FrontEndConfig& fe = config.front_end;
    for (const FrontEndKey& key : frontEndKeyTable()) {
      front_end_known.insert(key.name);
      const YAML::Node node = section[key.name];
      if (!node) continue;
      const std::string shown = node.IsScalar() ? node.Scalar() : YAML::Dump(node);
      try {
        switch (key.type) {
          case Type::kInteger:
            fe.*key.integer_field = node.as<int>();
            break;
          case Type::kReal:
            fe.*key.real_field = node.as<double>();
            break;
          case Type::kString:
            if (!node.IsScalar()) throw YAML::Exception(YAML::Mark(), "not a string");
            fe.*key.string_field = node.as<std::string>();
            break;
        }
      } catch (const YAML::Exception&) {
        const char* what = key.type == Type::kInteger ? "an integer"
                           : key.type == Type::kReal  ? "a number"
                                                      : "a string";
        problems.push_back(prefix + key.name + ": '" + shown + "' is not " + what);
      }
    }
    for (const auto& entry : section) {
      const std::string key = entry.first.as<std::string>();
      if (!front_end_known.count(key)) problems.push_back(prefix + key + ": unknown parameter");
    }
  }
  for (const std::string& p : config.front_end.validate()) problems.push_back(prefix + p);
  detail::throwIfProblems(source_name, problems);
  return config;
}

EstimatorConfig readEstimatorConfigFile(const std::string& path, const EstimatorConfig& base) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open configuration file '" + path + "'");
  std::stringstream text;
  text << in.rdbuf();
  return parseEstimatorConfigYaml(text.str(), path, base);
}

std::string formatFrontEndConfigYaml(const FrontEndConfig& config) {
  std::ostringstream out;
  out.precision(12);
  out << kFrontEndSection << ":\n";
  for (const FrontEndKey& key : frontEndKeyTable()) {
    out << "  " << key.name << ": ";
    switch (key.type) {
      case Type::kInteger:
        out << config.*key.integer_field;
        break;
      case Type::kReal:
        out << config.*key.real_field;
        break;
      case Type::kString:
        out << config.*key.string_field;
        break;
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace osc
