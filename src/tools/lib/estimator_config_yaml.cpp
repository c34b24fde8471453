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

namespace {

/// The front end's keys whose `advanced` is @p advanced, indented for the `front_end:` map,
/// section by section in frontEndParameterSections() order, each after a comment with its
/// meaning and allowed range.
std::string formatFrontEndKeys(const FrontEndConfig& config, bool advanced) {
  const std::string indent = "  ";
  std::ostringstream out;
  for (const ParameterSection& section : frontEndParameterSections()) {
    std::ostringstream keys;
    for (const FrontEndParameterSpec& spec : frontEndParameterTable()) {
      if (spec.section != section.name || spec.advanced != advanced) continue;
      keys << "\n"
           << detail::commentLines(spec.doc, indent, spec.allowedText()) << indent << spec.name
           << ": " << spec.format(config) << "\n";
    }
    if (keys.str().empty()) continue;
    out << "\n"
        << detail::sectionBanner(
               {std::string(kFrontEndSection) + ": " + section.name, section.description}, indent,
               advanced)
        << keys.str();
  }
  return out.str();
}

/// The map's opening: its banner and `front_end:`.
std::string frontEndMapOpening() {
  return detail::sectionBanner({"image front end (front_end:)",
                                "the image front end (osc::FrontEndConfig; the nodelet reads "
                                "~front_end/<key>): features, stereo matches and tracks"},
                               "", false) +
         kFrontEndSection + ":\n";
}

}  // namespace

std::string formatFrontEndConfigYaml(const FrontEndConfig& config) {
  return frontEndMapOpening() + formatFrontEndKeys(config, false) + "\n" +
         detail::commentLines(
             "ADVANCED front-end keys: change one only with a measurement (docs/RESULTS.md).",
             "  ") +
         formatFrontEndKeys(config, true);
}

std::string formatEstimatorConfigYaml(const EstimatorConfig& config, const std::string& title) {
  // The user's keys (the filter's, then the front end's), then one advanced part: the front
  // end's advanced keys close its map, the filter's follow at the top level.
  return detail::formatConfigHeader(title) + detail::formatFilterKeys(config.filter, false) + "\n" +
         frontEndMapOpening() + formatFrontEndKeys(config.front_end, false) + "\n" +
         detail::advancedBanner() + formatFrontEndKeys(config.front_end, true) +
         detail::formatFilterKeys(config.filter, true);
}

}  // namespace osc
