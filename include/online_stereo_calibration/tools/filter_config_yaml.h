/// @file filter_config_yaml.h
/// @brief FilterConfig <-> YAML (config/default.yaml, config/paper.yaml) through the one
/// parameter table of filter_config.h.
#pragma once

#include <string>

#include "online_stereo_calibration/core/config/filter_config.h"

namespace osc {

/// Reads the keys of the parameter table (and motion_noise_model) from YAML text; keys not
/// given keep the value of @p base. Unknown keys, non-numbers and out-of-range values are
/// errors: throws std::runtime_error listing every problem, each naming the key.
FilterConfig parseFilterConfigYaml(const std::string& text, const std::string& source_name,
                                   const FilterConfig& base = FilterConfig());

/// Reads a YAML file (see parseFilterConfigYaml). Throws std::runtime_error naming the file.
FilterConfig readFilterConfigFile(const std::string& path,
                                  const FilterConfig& base = FilterConfig());

/// Every key with its value and its doc line as a comment: a complete, loadable file. A
/// header, then the user's keys (ParameterSpec::advanced false) section by section
/// (filterParameterSections()), then the advanced part, also by section.
std::string formatFilterConfigYaml(const FilterConfig& config, const std::string& title);

}  // namespace osc
