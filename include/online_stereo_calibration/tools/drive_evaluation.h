/// @file drive_evaluation.h
/// @brief The offline evaluation of one drive (`evaluate`), without ROS: the stereo pairs and
/// the vehicle motion of a DriveSource (a bag: src/tools/ros/evaluate_main.cpp; a KITTI raw
/// folder: kitti_raw_source.h) through the CalibrationPipeline as the nodelet runs it, then
/// DIR/estimates.csv and calibration.yaml, and with a reference DIR/reference.csv, table.txt
/// (Table I) and the plots of scripts/plot_convergence.py (docs/evaluation.md "evaluate").
#pragma once

#include <cstdint>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "online_stereo_calibration/core/estimator/types.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/tools/estimator_config_yaml.h"

namespace osc {

/// One stereo pair of a drive.
struct StereoPairInput {
  double stamp = 0.0;         ///< s
  std::int64_t stamp_ns = 0;  ///< the same stamp in ns (the key of referenceAt)
  cv::Mat left, right;        ///< mono8, mono16, bgr8 or bgra8
  /// Keeps the memory the images point into alive (e.g. the messages they were read from).
  std::shared_ptr<const void> owner;
};

/// Where an evaluation reads its drive: images, motion and the reference.
class DriveSource {
 public:
  virtual ~DriveSource() = default;
  /// Names the input in table.txt ("Bag drive.bag", "KITTI raw drive DIR").
  virtual std::string name() const = 0;
  virtual CameraIntrinsics leftCamera() const = 0;
  virtual CameraIntrinsics rightCamera() const = 0;
  /// How many pairs next() will give at most (for the progress line).
  virtual int pairCount() const = 0;
  /// The next stereo pair, in stamp order; false at the end.
  virtual bool next(StereoPairInput* pair) = 0;
  /// The vehicle motion from @p from to @p to (s): T_prev_curr, dt and, where the source
  /// measures them, the twists at both ends. Nothing where the source cannot tell.
  virtual std::optional<MotionIncrement> motionBetween(double from, double to) const = 0;
  /// Whether the source has a reference (a fixed calibration or a per-pair truth).
  virtual bool hasReference() const = 0;
  /// The reference parameters for the pair of stamp @p stamp_ns; nothing where there is none.
  virtual std::optional<Vector12d> referenceAt(std::int64_t stamp_ns) const = 0;
};

/// How evaluateDrive runs, besides the source.
struct DriveEvaluationOptions {
  std::string out;  ///< output directory (created with its parents)
  /// Frames of the Table I RMSE (inclusive); -1: 1000-1150 clipped to the drive.
  int window_first = -1, window_last = -1;
  int max_pairs = -1;  ///< stop after this many stereo pairs (-1: all)
  /// Redraw one progress bar twice a second (a terminal) rather than a line every 10 s.
  bool progress_bar = false;
  /// Lines appended to table.txt and the printed figures (e.g. the frames a reader skipped).
  std::vector<std::string> notes;
};

/// Runs the pipeline from @p guess over every pair of @p source, as fast as it goes, and
/// writes the files above into options.out. The figures (also table.txt) go to @p out, the
/// progress and per-pair events to @p log. A pair without motion restarts the tracking; a
/// pair the pipeline refuses is counted and named. Returns 0.
/// @throws std::runtime_error if no pair was processed or a file cannot be written.
int evaluateDrive(DriveSource& source, const EstimatorConfig& config, const StereoExtrinsics& guess,
                  const DriveEvaluationOptions& options, std::ostream& out, std::ostream& log);

}  // namespace osc
