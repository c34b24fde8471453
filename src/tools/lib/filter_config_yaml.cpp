#include "online_stereo_calibration/tools/filter_config_yaml.h"

#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace osc {

FilterConfig parseFilterConfigYaml(const std::string& text, const std::string& source_name,
                                   const FilterConfig& base) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(source_name + ": not valid YAML: " + e.what());
  }
  FilterConfig config = base;
  std::vector<std::string> problems;
  if (root && !root.IsNull() && !root.IsMap()) {
    throw std::runtime_error(source_name + ": expected a map of parameter: value");
  }
  std::set<std::string> known = {"motion_noise_model"};
  for (const ParameterSpec& spec : filterParameterTable()) {
    known.insert(spec.name);
    const YAML::Node node = root[spec.name];
    if (!node) continue;
    try {
      spec.set(&config, node.as<double>());
    } catch (const YAML::Exception&) {
      problems.push_back(spec.name + ": '" + YAML::Dump(node) + "' is not a number");
    }
  }
  if (const YAML::Node node = root["motion_noise_model"]) {
    try {
      config.motion_noise_model = motionNoiseModelFromName(node.as<std::string>());
    } catch (const std::exception& e) {
      problems.push_back(e.what());
    }
  }
  if (root.IsMap()) {
    for (const auto& entry : root) {
      const std::string key = entry.first.as<std::string>();
      if (!known.count(key)) problems.push_back(key + ": unknown parameter");
    }
  }
  for (const std::string& p : config.validate()) problems.push_back(p);
  if (!problems.empty()) {
    std::string message = source_name + ": invalid configuration:";
    for (const std::string& p : problems) message += "\n  " + p;
    throw std::runtime_error(message);
  }
  return config;
}

FilterConfig readFilterConfigFile(const std::string& path, const FilterConfig& base) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open configuration file '" + path + "'");
  std::stringstream text;
  text << in.rdbuf();
  return parseFilterConfigYaml(text.str(), path, base);
}

std::string formatFilterConfigYaml(const FilterConfig& config, const std::string& title) {
  std::ostringstream out;
  out << "# " << title << "\n"
      << "# Every parameter of the estimator; the unit is the key's suffix (_m, _deg, _s, _px).\n"
      << "# Per-step noise sigmas refer to reference_period_s and scale with sqrt(dt / it).\n\n"
      << "# per_point: the seed's eq. 15-27 (independent per point, overconfident);\n"
      << "# shared: one 6-DoF motion error per step shared by all points (ours).\n"
      << "motion_noise_model: " << motionNoiseModelName(config.motion_noise_model) << "\n";
  for (const ParameterSpec& spec : filterParameterTable()) {
    out << "\n# " << spec.doc << " [" << spec.min_value << ", " << spec.max_value << "]\n"
        << spec.name << ": " << std::setprecision(12) << spec.get(config) << "\n";
  }
  return out.str();
}

}  // namespace osc
