/// @file estimator_config_yaml.h
/// @brief The estimator's whole configuration from one YAML file: the filter's keys
/// (FilterConfig, config/default.yaml) at the top level and the image front end's
/// (FrontEndConfig, the same names as its fields) in a `front_end:` map, the layout the
/// nodelet reads from its private namespace (`~front_end/...`, config/ros.yaml):
///
///   pixel_noise_px: 0.5        # FilterConfig (filterParameterTable names)
///   front_end:                 # FrontEndConfig field names (frontEndParameterTable)
///     detector: FAST_ORB
///     max_features: 1500
///     search_lost_tracks: true
#pragma once

#include <string>
#include <vector>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/frontend/front_end_config.h"

namespace osc {

/// Filter and front-end configuration of a CalibrationPipeline.
struct EstimatorConfig {
  FilterConfig filter;
  FrontEndConfig front_end;
};

/// Reads the filter keys (top level) and the front-end keys (under `front_end:`); keys not
/// given keep the value of @p base. Unknown keys (at either level), values of the wrong type
/// and values out of range (FilterConfig::validate, FrontEndConfig::validate) are errors:
/// throws std::runtime_error naming @p source_name and listing every problem, front-end ones
/// as `front_end.KEY`.
EstimatorConfig parseEstimatorConfigYaml(const std::string& text, const std::string& source_name,
                                         const EstimatorConfig& base = EstimatorConfig());

/// Reads a YAML file (see parseEstimatorConfigYaml). Throws std::runtime_error naming the file.
EstimatorConfig readEstimatorConfigFile(const std::string& path,
                                        const EstimatorConfig& base = EstimatorConfig());

/// The `front_end:` section of a loadable file: every key of frontEndParameterTable() with
/// its value, each after a comment with its meaning and allowed range; the user's keys by
/// section (frontEndParameterSections()), then the advanced ones by section.
std::string formatFrontEndConfigYaml(const FrontEndConfig& config);

/// A whole loadable file (what write_default_configs writes to config/default.yaml): a
/// header; the filter's user keys by section; the `front_end:` map with its user keys; then
/// one advanced part: the front end's advanced keys (closing its map), the filter's advanced
/// keys by section. The same keys and values as formatFilterConfigYaml(config.filter, title)
/// plus formatFrontEndConfigYaml(config.front_end).
std::string formatEstimatorConfigYaml(const EstimatorConfig& config, const std::string& title);

}  // namespace osc
