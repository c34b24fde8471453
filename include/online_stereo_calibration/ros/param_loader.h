/// @file param_loader.h
/// @brief Reads FilterConfig (through filterParameterTable(), one place for names),
/// FrontEndConfig (through frontEndParameterTable()) and RosConfig from the parameter server,
/// collecting every problem.
#pragma once

#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/frontend/front_end_config.h"
#include "online_stereo_calibration/ros/ros_config.h"

namespace online_stereo_calibration {

/// Everything the nodelet is configured with.
struct NodeConfig {
  osc::FilterConfig filter;
  osc::FrontEndConfig front_end;  ///< keys under `front_end/`
  RosConfig ros;
};

/// Reads every parameter from @p nh (the private node handle). Problems (wrong type,
/// out of range, unknown names, failed validate()) are appended to @p problems; the
/// config then holds defaults where values were bad.
NodeConfig loadNodeConfig(const ros::NodeHandle& nh, std::vector<std::string>* problems);

/// Reads the filter keys of filterParameterTable() (and motion_noise_model) only.
osc::FilterConfig loadFilterConfig(const ros::NodeHandle& nh, std::vector<std::string>* problems);

/// Reads the front end's keys: every row of frontEndParameterTable() as `front_end/<name>`
/// (the FrontEndConfig field names).
osc::FrontEndConfig loadFrontEndConfig(const ros::NodeHandle& nh,
                                       std::vector<std::string>* problems);

/// Reads RosConfig only.
RosConfig loadRosConfig(const ros::NodeHandle& nh, std::vector<std::string>* problems);

}  // namespace online_stereo_calibration
