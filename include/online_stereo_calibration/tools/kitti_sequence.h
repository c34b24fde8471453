/// @file kitti_sequence.h
/// @brief The KITTI odometry stretches of ../shared/data/kitti_odometry_51 (real rectified
/// stereo images, GPS/INS motion) in the package's terms: the vehicle frame is the left
/// camera's body frame, so x_caml's truth is zero and x_camr's is [0, -baseline, 0, 0, 0, 0]
/// (the data's README).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "online_stereo_calibration/core/estimator/types.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

/// One sequence folder: calib.txt, poses.txt, image_l/, image_r/.
struct KittiSequence {
  CameraIntrinsics left, right;  ///< pinhole, from P0 / P1 and the images' size
  double baseline = 0.0;         ///< m, -P1[0][3] / fx
  /// Pose of the left optical frame at each frame in the one at frame 0 (poses.txt).
  std::vector<Eigen::Isometry3d> T_first_lopt;
  std::vector<std::string> left_images, right_images;  ///< paths, frame order
  /// s between frames: KITTI's cameras run at ~9.65 Hz (the README's 0.1036 s).
  double frame_interval = 0.1036;

  int frames() const { return static_cast<int>(T_first_lopt.size()); }
  /// The true parameters (interface order): x_caml zero, x_camr [0, -baseline, 0, 0, 0, 0].
  Vector12d truth() const;
  /// The vehicle (left body frame) motion from frame k - 1 to frame k (k >= 1).
  MotionIncrement motion(int k) const;
};

/// The *.png files of @p folder, sorted by name (frame order for KITTI and EuRoC folders).
std::vector<std::string> sortedPngs(const std::string& folder);

/// Reads a sequence folder. @throws std::runtime_error naming the file and what is wrong
/// (missing, unreadable, a line without 12 numbers, image and pose counts that differ).
KittiSequence readKittiSequence(const std::string& folder);

}  // namespace osc
