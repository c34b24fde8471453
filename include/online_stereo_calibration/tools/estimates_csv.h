/// @file estimates_csv.h
/// @brief The per-frame estimates CSV of interface.md and a reference CSV for simulated truth.
///
/// Estimates (one line per processed image pair, m and rad):
/// `frame,stamp,xl,...,yaw_r,sigma_xl,...,sigma_yaw_r,tracked_points,time_ms`, then the
/// further columns `time_offset_ms,sigma_time_offset_ms`.
/// Reference: `frame,stamp,xl,yl,zl,roll_l,pitch_l,yaw_l,xr,yr,zr,roll_r,pitch_r,yaw_r`.
/// `stamp` is written with at least 9 decimals (more when needed to read back the same
/// double), every other value with 17 significant digits. Readers accept further columns
/// after the listed ones and ignore them.
#pragma once

#include <fstream>
#include <string>
#include <vector>

#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

struct CalibrationFile;      // calibration_file.h
struct ScenarioFrameResult;  // core/sim/scenario_runner.h

/// One line of the estimates CSV.
struct EstimateRow {
  int frame = 0;                             ///< image pair index, from 0
  double stamp = 0;                          ///< s
  Vector12d parameters = Vector12d::Zero();  ///< [xl..yaw_l, xr..yaw_r], m and rad
  Vector12d sigmas = Vector12d::Zero();      ///< 1-sigma of @ref parameters
  int tracked_points = 0;                    ///< points in the filter after the update
  double time_ms = 0;                        ///< processing time of this pair (ms)
  /// Camera-odometry time offset estimate and its 1 sigma (s; 0 and 0: not estimated),
  /// written as the further columns time_offset_ms, sigma_time_offset_ms.
  double time_offset = 0;
  double time_offset_sigma = 0;
};

/// One line of the reference (truth) CSV.
struct ReferenceRow {
  int frame = 0;                             ///< image pair index, from 0
  double stamp = 0;                          ///< s
  Vector12d parameters = Vector12d::Zero();  ///< true [xl..yaw_l, xr..yaw_r], m and rad
};

/// The estimates row of a simulated frame's result.
EstimateRow estimateRowOf(const ScenarioFrameResult& result);
/// The reference (truth) row of a simulated frame's result.
ReferenceRow referenceRowOf(const ScenarioFrameResult& result);
/// The calibration file of a row (the last one: a run's final calibration): extrinsics,
/// sigmas, stamp, and the time offset when it was estimated (sigma > 0).
CalibrationFile calibrationFileOf(const EstimateRow& row);

/// Column names of the estimates CSV, in order (interface.md); the reader requires these.
const std::vector<std::string>& estimatesCsvColumns();
/// The further columns the writer adds after them (interface.md allows more).
const std::vector<std::string>& estimatesCsvFurtherColumns();
/// Column names of the reference CSV, in order.
const std::vector<std::string>& referenceCsvColumns();
/// The header line (columns joined by ','), without newline.
std::string estimatesCsvHeader();
/// The header line of the reference CSV, without newline.
std::string referenceCsvHeader();

/// Writes the estimates CSV: the header on construction, one line per write().
class EstimatesCsvWriter {
 public:
  /// Creates (truncates) @p path and writes the header; throws std::runtime_error if it
  /// cannot open the file.
  explicit EstimatesCsvWriter(const std::string& path);
  /// Appends one line; throws std::runtime_error on a write error.
  void write(const EstimateRow& row);
  /// Flushes to the OS; throws std::runtime_error on a write error.
  void flush();

 private:
  std::string path_;
  std::ofstream out_;
};

/// Writes the reference CSV: the header on construction, one line per write().
class ReferenceCsvWriter {
 public:
  /// Creates (truncates) @p path and writes the header; throws std::runtime_error if it
  /// cannot open the file.
  explicit ReferenceCsvWriter(const std::string& path);
  /// Appends one line; throws std::runtime_error on a write error.
  void write(const ReferenceRow& row);
  /// Flushes to the OS; throws std::runtime_error on a write error.
  void flush();

 private:
  std::string path_;
  std::ofstream out_;
};

/// Reads an estimates CSV. Throws std::runtime_error naming the file and line if it cannot
/// be opened, the header does not start with estimatesCsvColumns(), or a field is missing
/// or not a number. "nan" and "inf" are accepted (a diverged filter is a result too).
std::vector<EstimateRow> readEstimatesCsv(const std::string& path);

/// Reads a reference CSV; errors as readEstimatesCsv.
std::vector<ReferenceRow> readReferenceCsv(const std::string& path);

}  // namespace osc
