/// @file package_files.h
/// @brief Finding a file shipped with the package (scripts/plot_convergence.py,
/// scripts/plot_campaign.py, config/campaign.yaml) from an offline tool, in one place.
#pragma once

#include <string>

namespace osc {

/// The first existing regular file among: the file named by the environment variable
/// @p environment_variable (if given and set); REL in each ROS_PACKAGE_PATH entry that is this
/// package (its package.xml names online_stereo_calibration) and in
/// ENTRY/online_stereo_calibration; beside the running executable (installed scripts) and in
/// ../../share/online_stereo_calibration from it (installed config); in the current directory; in
/// the source tree the tools were built from. REL = @p relative_path (e.g.
/// "scripts/plot_convergence.py"). "" if none exists.
std::string findPackageFile(const std::string& relative_path,
                            const char* environment_variable = nullptr);

}  // namespace osc
