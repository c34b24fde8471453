/// @file config_yaml_detail.h
/// @brief Internal to the tools library: reading FilterConfig keys from a YAML node and
/// writing the generated files' sections, shared by filter_config_yaml.cpp and
/// estimator_config_yaml.cpp.
#pragma once

#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/config/parameter_section.h"

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

// --- the generated files' layout (config/default.yaml): a header, the user's keys by
// section, then one advanced part by section ---

/// @p text and then @p tail (kept on one line, e.g. an allowed range) as comment lines
/// "<indent># ...", wrapped at 100 columns.
std::string commentLines(const std::string& text, const std::string& indent,
                         const std::string& tail = "");

/// "# title" and a few lines on how the file is laid out and read.
std::string formatConfigHeader(const std::string& title);

/// "<indent># ==== name ====" and "<indent># description" (the section's banner).
std::string sectionBanner(const ParameterSection& section, const std::string& indent,
                          bool advanced);

/// The banner that opens a file's advanced part.
std::string advancedBanner();

/// The filter's keys (motion_noise_model and the rows of filterParameterTable()) whose
/// `advanced` is @p advanced, section by section in filterParameterSections() order, each key
/// after a comment with its meaning and allowed range.
std::string formatFilterKeys(const FilterConfig& config, bool advanced);

}  // namespace osc::detail
