/// @file kitti_raw_drive_internal.h
/// @brief Private to the KITTI raw reader's source files (kitti_raw_*.cpp): the error
/// messages' prefix, number formatting, and the calibration files' reader.
#pragma once

#include <cstdio>
#include <string>

#include "online_stereo_calibration/tools/kitti_raw_drive.h"

namespace osc {
namespace kitti_raw_drive_internal {

/// "KITTI raw: @p path: ", the start of the reader's error messages about a file.
inline std::string errorPrefix(const std::string& path) { return "KITTI raw: " + path + ": "; }

/// @p value printed with @p decimals decimals.
inline std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

/// The calibration: intrinsics and the chain T_imu_lopt, T_lopt_ropt, for raw or rectified
/// images told apart by the size of the first left image.
void readCalibration(const std::string& folder, const std::string& first_left_image,
                     KittiRawDrive* drive);

}  // namespace kitti_raw_drive_internal
}  // namespace osc
