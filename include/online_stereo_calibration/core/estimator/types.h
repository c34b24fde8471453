/// @file types.h
/// @brief Plain data exchanged between the front ends (image pipeline, simulators, ROS
/// adapter) and the estimator. No ROS, no OpenCV.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace osc {

/// Identifies one tracked static point for as long as it is tracked.
using PointId = std::uint64_t;

/// Measured vehicle motion between two consecutive image pairs.
struct MotionIncrement {
  /// T_{veh(k-1)}_{veh(k)}: pose of the vehicle at the current image pair expressed in the
  /// vehicle frame at the previous one (the inverse of the paper's H^veh_veh(k+1|k)).
  Eigen::Isometry3d T_prev_curr = Eigen::Isometry3d::Identity();
  /// Time between the two image pairs (s); > 0.
  double dt = 0.1;
  /// The vehicle's body twist [v (3), w (3)] (m/s, rad/s, vehicle frame) at the start and at
  /// the end of the increment as the odometry measured it, if it did (has_twists). The
  /// time-offset model needs how the motion changes (process_model.h twistsAtEnds); without
  /// them it is taken from the earlier increments.
  bool has_twists = false;
  Eigen::Matrix<double, 6, 1> twist_start = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> twist_end = Eigen::Matrix<double, 6, 1>::Zero();
  /// The covariance of this increment's error [dt (3), dtheta (3)] (pose.h boxPlus: m, rad)
  /// as the odometry states it, if it does (has_covariance): the shared motion-noise model
  /// then uses it instead of the configured motion noise. Symmetric positive semi-definite.
  bool has_covariance = false;
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  /// s: the odometry was read at the two image stamps minus this (and the twists there), so
  /// that this much of the camera-odometry time offset is already taken out; the filter's
  /// first-order correction covers only the rest (FilterConfig::initial_time_offset's
  /// convention). Callers that can read the odometry at any time use
  /// StereoCalibrationEstimator::odometryTimeShift() (as VINS / OpenVINS read the IMU at the
  /// image time plus the estimated offset); 0 = read at the image stamps.
  double time_shift = 0.0;
};

/// One point seen in both images of a stereo pair.
struct StereoObservation {
  PointId id = 0;
  Eigen::Vector2d left_pixel = Eigen::Vector2d::Zero();   ///< raw (distorted) pixel, left image
  Eigen::Vector2d right_pixel = Eigen::Vector2d::Zero();  ///< raw (distorted) pixel, right image
  /// Pixel standard deviation of this measurement in each image; <= 0 means "use the
  /// configured pixel_noise".
  double sigma_left = 0.0;
  double sigma_right = 0.0;
};

}  // namespace osc
