/// @file estimator_config_yaml.cpp
/// @brief FilterConfig + FrontEndConfig from one YAML file.
#include "online_stereo_calibration/tools/estimator_config_yaml.h"

#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "config_yaml_detail.h"
#include "online_stereo_calibration/tools/filter_config_yaml.h"

namespace osc {
namespace {

using Type = FrontEndParameterSpec::Type;

constexpr const char* kFrontEndSection = "front_end";

}  // namespace

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
    for (const FrontEndParameterSpec& spec : frontEndParameterTable()) {
      front_end_known.insert(spec.name);
      const YAML::Node node = section[spec.name];
      if (!node) continue;
      const std::string shown = node.IsScalar() ? node.Scalar() : YAML::Dump(node);
      try {
        if (!node.IsScalar()) throw YAML::Exception(YAML::Mark(), "not a scalar");
        switch (spec.type) {
          case Type::kInteger:
            spec.setNumber(&fe, node.as<int>());
            break;
          case Type::kReal:
            spec.setNumber(&fe, node.as<double>());
            break;
          case Type::kBool:
            spec.setBool(&fe, node.as<bool>());
            break;
          case Type::kString:
            spec.setString(&fe, node.as<std::string>());
            break;
        }
      } catch (const YAML::Exception&) {
        const char* what = spec.type == Type::kInteger ? "an integer"
                           : spec.type == Type::kReal  ? "a number"
                           : spec.type == Type::kBool  ? "a boolean (true or false)"
                                                       : "a string";
        problems.push_back(prefix + spec.name + ": '" + shown + "' is not " + what);
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
  out << "# The image front end (osc::FrontEndConfig; the nodelet reads ~front_end/<key>).\n"
      << kFrontEndSection << ":\n";
  bool first = true;
  for (const FrontEndParameterSpec& spec : frontEndParameterTable()) {
    if (!first) out << "\n";
    first = false;
    out << "  # " << spec.doc << " " << spec.allowedText() << "\n"
        << "  " << spec.name << ": " << spec.format(config) << "\n";
  }
  return out.str();
}

std::string formatEstimatorConfigYaml(const EstimatorConfig& config, const std::string& title) {
  return formatFilterConfigYaml(config.filter, title) + "\n" +
         formatFrontEndConfigYaml(config.front_end);
}

}  // namespace osc
