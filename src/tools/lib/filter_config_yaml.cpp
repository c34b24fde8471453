#include "online_stereo_calibration/tools/filter_config_yaml.h"

#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "config_yaml_detail.h"
#include "online_stereo_calibration/tools/estimator_config_yaml.h"

namespace osc {

namespace detail {

YAML::Node loadConfigMap(const std::string& text, const std::string& source_name) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(source_name + ": not valid YAML: " + e.what());
  }
  if (root && !root.IsNull() && !root.IsMap()) {
    throw std::runtime_error(source_name + ": expected a map of parameter: value");
  }
  return root;
}

void readFilterKeys(const YAML::Node& root, FilterConfig* config, std::set<std::string>* known,
                    std::vector<std::string>* problems) {
  known->insert("motion_noise_model");
  for (const ParameterSpec& spec : filterParameterTable()) {
    known->insert(spec.name);
    const YAML::Node node = root[spec.name];
    if (!node) continue;
    try {
      spec.set(config, node.as<double>());
    } catch (const YAML::Exception&) {
      problems->push_back(spec.name + ": '" + YAML::Dump(node) + "' is not a number");
    }
  }
  if (const YAML::Node node = root["motion_noise_model"]) {
    try {
      config->motion_noise_model = motionNoiseModelFromName(node.as<std::string>());
    } catch (const std::exception& e) {
      problems->push_back(e.what());
    }
  }
}

void throwIfProblems(const std::string& source_name, const std::vector<std::string>& problems) {
  if (problems.empty()) return;
  std::string message = source_name + ": invalid configuration:";
  for (const std::string& p : problems) message += "\n  " + p;
  throw std::runtime_error(message);
}

}  // namespace detail

FilterConfig parseFilterConfigYaml(const std::string& text, const std::string& source_name,
                                   const FilterConfig& base) {
  // The same file may carry the front end's section (estimator_config_yaml.h); it is checked
  // too, so a file is either valid for every tool or refused by every tool.
  EstimatorConfig estimator;
  estimator.filter = base;
  return parseEstimatorConfigYaml(text, source_name, estimator).filter;
}

FilterConfig readFilterConfigFile(const std::string& path, const FilterConfig& base) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open configuration file '" + path + "'");
  std::stringstream text;
  text << in.rdbuf();
  return parseFilterConfigYaml(text.str(), path, base);
}

namespace {

/// @p spec's value in file units with the fewest significant digits (12 to 17) that read
/// back to the identical internal value: a `_deg` key's internal radians survive the trip
/// through degrees, so a run with the written file equals one with the built-in config.
std::string formatFileValue(const ParameterSpec& spec, const FilterConfig& config) {
  const double value = spec.get(config);
  std::string text;
  for (int digits = 12; digits <= 17; ++digits) {
    std::ostringstream out;
    out << std::setprecision(digits) << value;
    text = out.str();
    FilterConfig read_back = config;
    spec.set(&read_back, std::stod(text));
    const bool same = spec.real_field ? read_back.*spec.real_field == config.*spec.real_field
                                      : read_back.*spec.integer_field == config.*spec.integer_field;
    if (same) break;
  }
  return text;
}

}  // namespace

std::string formatFilterConfigYaml(const FilterConfig& config, const std::string& title) {
  std::ostringstream out;
  out << "# " << title << "\n"
      << "# Every parameter of the estimator; the unit is the key's suffix (_m, _deg, _s, _px).\n"
      << "# Per-step noise sigmas refer to reference_period_s and scale with sqrt(dt / it).\n\n"
      << "# per_point: the seed's eq. 15-27 (independent per point, overconfident);\n"
      << "# shared: one 6-DoF motion error per step shared by all points (ours).\n"
      << "motion_noise_model: " << motionNoiseModelName(config.motion_noise_model) << "\n";
  for (const ParameterSpec& spec : filterParameterTable()) {
    out << "\n# " << spec.doc << " [" << std::setprecision(12) << spec.min_value << ", "
        << spec.max_value << "]\n"
        << spec.name << ": " << formatFileValue(spec, config) << "\n";
  }
  return out.str();
}

}  // namespace osc
