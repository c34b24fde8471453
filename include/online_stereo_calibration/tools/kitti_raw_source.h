/// @file kitti_raw_source.h
/// @brief A KITTI raw drive folder (kitti_raw_drive.h) as the input of the offline evaluation
/// (drive_evaluation.h): its usable frames in order, its OXTS motion, and KITTI's calibration
/// chain as the fixed reference.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "online_stereo_calibration/tools/command_line.h"
#include "online_stereo_calibration/tools/drive_evaluation.h"
#include "online_stereo_calibration/tools/kitti_raw_drive.h"

namespace osc {

/// The reader's options on a tool's command line (--oxts-position, --oxts-max-gap): one
/// definition for `evaluate --kitti-raw` and `kitti_raw_to_bag`. Lives as long as the
/// CommandLine it was added to (the options write into it).
class KittiRawCommandLine {
 public:
  /// @p help_prefix: put before each option's help (e.g. "KITTI raw: ").
  void addTo(CommandLine* cli, const std::string& help_prefix = "");
  /// The parsed values as the reader's options (the other fields at their defaults).
  KittiRawOptions options() const;

 private:
  std::string position_ = "velocity";
  double max_oxts_gap_ = KittiRawOptions().max_oxts_gap;
};

/// A read drive (readKittiRawDrive) as a DriveSource; owns it.
class KittiRawSource : public DriveSource {
 public:
  explicit KittiRawSource(KittiRawDrive drive) : drive_(std::move(drive)) {}

  std::string name() const override { return "KITTI raw drive " + drive_.folder; }
  CameraIntrinsics leftCamera() const override { return drive_.left; }
  CameraIntrinsics rightCamera() const override { return drive_.right; }
  int pairCount() const override { return static_cast<int>(drive_.frames.size()); }
  /// The next usable frame's images, read as stored (8-bit grey for image_00/01).
  /// @throws std::runtime_error naming an image that cannot be read.
  bool next(StereoPairInput* pair) override;
  std::optional<MotionIncrement> motionBetween(double from, double to) const override {
    return drive_.motionBetween(from, to);
  }
  bool hasReference() const override { return true; }
  std::optional<Vector12d> referenceAt(std::int64_t) const override { return drive_.truth(); }

  const KittiRawDrive& drive() const { return drive_; }

 private:
  KittiRawDrive drive_;
  std::size_t next_ = 0;
};

}  // namespace osc
