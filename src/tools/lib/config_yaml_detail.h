/// @file config_yaml_detail.h
/// @brief Internal to the tools library: reading FilterConfig keys from a YAML node, shared
/// by filter_config_yaml.cpp and estimator_config_yaml.cpp.
#pragma once

#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "online_stereo_calibration/core/config/filter_config.h"

namespace osc::detail {

/// Parses YAML text into a map (or a null node for an empty file); throws
/// std::runtime_error naming @p source_name if it is not valid YAML or not a map.
YAML::Node loadConfigMap(const std::string& text, const std::string& source_name);

/// Sets the FilterConfig keys found in @p root on @p config; adds their names to @p known and
/// a line per bad value to @p problems (no range checks: FilterConfig::validate does those).
void readFilterKeys(const YAML::Node& root, FilterConfig* config, std::set<std::string>* known,
                    std::vector<std::string>* problems);

/// Throws std::runtime_error "<source>: invalid configuration:" + one line per problem.
void throwIfProblems(const std::string& source_name, const std::vector<std::string>& problems);

}  // namespace osc::detail
