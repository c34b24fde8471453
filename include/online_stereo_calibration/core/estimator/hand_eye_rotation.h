/// @file hand_eye_rotation.h
/// @brief The rotation of a camera on a vehicle from their motions alone (hand-eye rotation,
/// after VINS-Mono's InitialEXRotation::CalibrationExRotation): no points, no guess.
///
/// Two kinds of pairs, both written as q_v (x) q = q (x) q_c for the unit quaternion q of
/// X = R_veh_cam and stacked into one homogeneous system solved by SVD:
/// - rotation pairs: the vehicle's rotation increment R_v = R_{v0 v1} (odometry) and the
///   camera's R_c = R_{c0 c1} between the same two frames: R_v X = X R_c;
/// - direction pairs: the vehicle's translation direction u_v (in v0) and the camera's u_c
///   (in c0, essential matrix): u_v ~= X u_c, which holds when the camera's lever arm turns
///   little against the distance driven (|dtheta| |p| << |t|). A car on a flat road rotates
///   about its vertical axis only, which leaves X free about that axis; the driving direction
///   is the second, non-parallel constraint.
/// Pairs are weighted by the robust scatter of their kind and a Huber weight of their
/// residual (VINS: angle above a threshold), iterated. The uncertainty is the Gauss-Newton
/// covariance of the residuals at the solution, in the filter's tangent (pose.h boxPlus:
/// X Exp(dtheta), dtheta in the camera body frame). VINS accepts when the second-smallest
/// singular value exceeds 0.25; here the same conditioning is asked in physical units: the
/// largest 1 sigma over all axes below max_sigma.
#pragma once

#include <deque>
#include <string>

#include <Eigen/Core>

namespace osc {

/// Settings of the hand-eye rotation solver.
struct HandEyeRotationConfig {
  int min_pairs = 20;   ///< fewest pairs (both kinds) before a solution is offered
  size_t window = 400;  ///< most recent pairs kept per kind
  double max_sigma = 1.5 * 0.0174532925199432958;  ///< rad: accepted when every axis is below
  /// rad: rotation pairs whose vehicle rotation is smaller are ignored: a rotation within the
  /// odometry's noise is no excitation, and the linearised information of such pairs is
  /// spurious (errors in variables: 400 noise-only pairs of a straight drive claimed roll
  /// within 2.3 deg).
  double min_rotation = 0.1 * 0.0174532925199432958;
  double huber_sigmas = 3.0;  ///< residuals beyond this many sigmas of their kind are damped
  /// rad: lower bounds of the per-axis residual sigma of each kind (the scatter estimated from
  /// few pairs can be tiny by chance).
  double min_rotation_residual = 0.005 * 0.0174532925199432958;
  double min_direction_residual = 0.2 * 0.0174532925199432958;
};

/// The solver's answer.
struct HandEyeRotationResult {
  /// True when the window holds enough pairs and every axis is determined within max_sigma.
  bool determined = false;
  /// X = R_veh_cam: the camera body frame's rotation in the vehicle frame (pose.h).
  Eigen::Matrix3d R_veh_cam = Eigen::Matrix3d::Identity();
  /// Covariance (rad^2) of the tangent error dtheta of R_veh_cam Exp(dtheta), camera body
  /// frame; infinite diagonal where the pairs do not determine an axis at all.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  double max_sigma = 0.0;  ///< rad, 1 sigma of the worst-determined axis
  /// That axis in the vehicle frame (unit).
  Eigen::Vector3d weakest_axis_vehicle = Eigen::Vector3d::UnitZ();
  int rotation_pairs = 0, direction_pairs = 0;
  /// Robust per-axis residual sigma of each kind (rad).
  double rotation_residual = 0.0, direction_residual = 0.0;
  /// VINS's conditioning number: the second-smallest singular value of the stacked, weighted
  /// system over the largest (0 when only one axis is constrained).
  double conditioning = 0.0;
  std::string reason;  ///< why not determined yet, or a summary when determined
};

/// Collects pairs and solves for R_veh_cam.
class HandEyeRotation {
 public:
  explicit HandEyeRotation(const HandEyeRotationConfig& config = HandEyeRotationConfig());

  /// A rotation pair: R_{v0 v1} of the vehicle and R_{c0 c1} of the camera body between the
  /// same two instants. Ignored if the vehicle's rotation is below min_rotation.
  void addRotationPair(const Eigen::Matrix3d& R_vehicle, const Eigen::Matrix3d& R_camera);
  /// A direction pair: the vehicle's translation t_{v0 v1} (in v0, any length > 0) and the
  /// camera's translation direction (in c0 body, any length > 0) between the same instants.
  void addDirectionPair(const Eigen::Vector3d& t_vehicle, const Eigen::Vector3d& t_camera);
  void clear();

  /// Solves with the pairs in the window (cheap: a 4x4 eigenproblem per iteration).
  HandEyeRotationResult solve() const;

  int rotationPairs() const { return static_cast<int>(rotations_.size()); }
  int directionPairs() const { return static_cast<int>(directions_.size()); }

 private:
  struct RotationPair {
    Eigen::Matrix3d vehicle, camera;
  };
  struct DirectionPair {
    Eigen::Vector3d vehicle, camera;  ///< unit
  };
  HandEyeRotationConfig config_;
  std::deque<RotationPair> rotations_;
  std::deque<DirectionPair> directions_;
};

}  // namespace osc
