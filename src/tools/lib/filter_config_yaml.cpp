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

namespace detail {

std::string commentLines(const std::string& text, const std::string& indent,
                         const std::string& tail) {
  constexpr size_t kWidth = 100;
  const std::string prefix = indent + "#";
  std::vector<std::string> words;
  std::istringstream in(text);
  for (std::string word; in >> word;) words.push_back(word);
  if (!tail.empty()) words.push_back(tail);
  std::ostringstream out;
  std::string line = prefix;
  for (const std::string& word : words) {
    if (line.size() > prefix.size() && line.size() + 1 + word.size() > kWidth) {
      out << line << "\n";
      line = prefix;
    }
    line += " " + word;
  }
  out << line << "\n";
  return out.str();
}

std::string formatConfigHeader(const std::string& title) {
  return "# " + title + "\n" +
         commentLines(
             "The keys are grouped by the component that uses them: first the keys a user may "
             "set for a new rig, odometry or lens, then the advanced part (thresholds tuned on "
             "measurements). docs/configuration.md says which keys to touch. The unit is the "
             "key's suffix (_m, _deg, _s, _ms, _px, _mps, _dps, _percent). A file given with "
             "--config needs only the keys it changes (the nodelet reads the same keys as private "
             "parameters, ~key and ~front_end/key); an unknown key, or a value outside the range "
             "after its comment, is an error naming the key.",
             "");
}

std::string sectionBanner(const ParameterSection& section, const std::string& indent,
                          bool advanced) {
  return indent + "# ==== " + section.name + (advanced ? " (advanced)" : "") + " ====\n" +
         commentLines(section.description, indent);
}

std::string advancedBanner() {
  const std::string rule = "# " + std::string(78, '#') + "\n";
  return rule +
         commentLines(
             "ADVANCED: thresholds tuned by the developers on the benches of docs/RESULTS.md. "
             "Change one only with a measurement (docs/RESULTS.md). In a file with the front "
             "end, its advanced keys come first, still inside the front_end: map (indented); "
             "the filter's follow at the top level.",
             "") +
         rule;
}

std::string formatFilterKeys(const FilterConfig& config, bool advanced) {
  std::ostringstream out;
  for (const ParameterSection& section : filterParameterSections()) {
    std::ostringstream keys;
    if (section.name == kMotionNoiseModelSection && advanced == kMotionNoiseModelAdvanced) {
      keys << "\n"
           << commentLines(
                  "how the odometry's error enters the points' prediction: per_point is the "
                  "seed's eq. 15-27 (an independent error per point: overconfident), shared: one "
                  "6-DoF error per step shared by all points (ours)",
                  "", "{per_point, shared}")
           << "motion_noise_model: " << motionNoiseModelName(config.motion_noise_model) << "\n";
    }
    for (const ParameterSpec& spec : filterParameterTable()) {
      if (spec.section != section.name || spec.advanced != advanced) continue;
      std::ostringstream range;
      range << std::setprecision(12) << "[" << spec.min_value << ", " << spec.max_value << "]";
      keys << "\n"
           << commentLines(spec.doc, "", range.str()) << spec.name << ": "
           << formatFileValue(spec, config) << "\n";
    }
    if (keys.str().empty()) continue;
    out << "\n" << sectionBanner(section, "", advanced) << keys.str();
  }
  return out.str();
}

}  // namespace detail

std::string formatFilterConfigYaml(const FilterConfig& config, const std::string& title) {
  return detail::formatConfigHeader(title) + detail::formatFilterKeys(config, false) + "\n" +
         detail::advancedBanner() + detail::formatFilterKeys(config, true);
}

}  // namespace osc
