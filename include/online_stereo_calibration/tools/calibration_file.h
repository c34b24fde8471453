/// @file calibration_file.h
/// @brief The YAML calibration file of interface.md: initial guess, saved result, reference.
///
/// ```
/// vehicle_to_left: [xl, yl, zl, roll_l, pitch_l, yaw_l]   # T_veh_caml, m and rad
/// left_to_right:   [xr, yr, zr, roll_r, pitch_r, yaw_r]   # T_caml_camr, m and rad
/// sigma_vehicle_to_left: [6]   # optional, 1-sigma of the parameters above
/// sigma_left_to_right:   [6]   # optional (both sigma keys or neither)
/// stamp: 1234.5                # optional, s
/// covariance: [144]            # optional, 12x12 covariance of the 12 parameters, row-major
/// ```
/// Other keys are ignored when reading (so a reader that predates `covariance` still reads
/// a file that has it).
#pragma once

#include <optional>
#include <string>

#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

/// Contents of a calibration file.
struct CalibrationFile {
  /// The two extrinsic transforms (camera *body* frames, interface.md).
  StereoExtrinsics extrinsics;
  /// 1-sigma of the 12 parameters [xl..yaw_l, xr..yaw_r] (m, rad), when the file has them.
  std::optional<Vector12d> sigmas;
  /// Time of the estimate (s), when the file has it.
  std::optional<double> stamp;
  /// Full 12x12 covariance of the 12 parameters (m^2, m rad, rad^2), when the file has it.
  /// Symmetric positive definite; its diagonal is sigmas^2 when both are present.
  std::optional<Matrix12d> covariance;
  /// The estimated camera-odometry time offset and its 1 sigma (s; camera clock minus
  /// odometry clock, FilterConfig::initial_time_offset), when the file has them (`time_offset`,
  /// `sigma_time_offset`).
  std::optional<double> time_offset;
  std::optional<double> time_offset_sigma;
};

/// The parameter covariance a file specifies: its full `covariance` if present, else
/// diag(sigmas^2) if it has sigmas (cross-covariances then unknown, taken as 0), else none.
std::optional<Matrix12d> parameterCovariance(const CalibrationFile& file);

/// Parses the YAML text of a calibration file. Throws std::runtime_error naming
/// @p source_name and the bad or missing key (missing, not a list of 6, not a number, NaN or
/// infinite, negative sigma, only one of the two sigma keys; a covariance that is not 144
/// numbers, not symmetric, not positive definite or whose diagonal disagrees with the sigmas).
CalibrationFile parseCalibrationYaml(const std::string& text, const std::string& source_name);

/// Reads and parses a calibration file. Throws std::runtime_error naming the file (cannot
/// open) and, for bad contents, the key (see parseCalibrationYaml).
CalibrationFile readCalibrationFile(const std::string& path);

/// The YAML text writeCalibrationFileAtomic writes: a comment line with units and frames,
/// then the keys, every number with 17 significant digits (reads back bit-exactly).
/// Throws std::runtime_error if a value is NaN or infinite.
std::string formatCalibrationYaml(const CalibrationFile& file);

/// Writes @p file to @p path atomically: a temporary file in the same directory, fsync,
/// rename over @p path, fsync of the directory. Readers see the old file or the new one,
/// never a partial one; on failure the temporary file is removed, the old file is kept and
/// std::runtime_error names the path and the reason.
void writeCalibrationFileAtomic(const std::string& path, const CalibrationFile& file);

}  // namespace osc
