/// @file epipolar_consistency.h
/// @brief Do a pair's stereo matches lie on the epipolar lines of the current x_camr?
///
/// A stereo pair's epipolar constraint (seed eq. 5) depends on x_camr alone: not on x_caml,
/// the vehicle's motion, the odometry's errors or the points' depths. So it tells a knocked
/// right camera from everything else, even when no tracked point could contradict the knock
/// (a knock inside a stretch without points: the points after it are new, triangulated with
/// the old x_camr; default campaign run 102 then blamed x_caml and kept yaw_r 193 sigma off).
///
/// The test: each pair's algebraic epipolar residual r_i = x_r^T F x_l, normalised by its
/// pixel noise, is linear in x_camr's rotation error d (r_i = a_i^T d + n_i; the baseline's
/// length does not enter, and its direction is taken as exact). The rotation's score
/// b = sum a r has the covariance S = H + H P_theta H if x_camr is within its covariance
/// (H = sum a a^T), so T = b^T S^+ b is chi-square with rank(H) degrees of freedom over the
/// rotations the pairs inform (2: the rotation that slides pixels along the lines, yaw_r of
/// a horizontal rig, does not enter). Pairs far off (mismatches) are down-weighted (Huber)
/// so that one does not decide.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/filter/calibration_filter.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

/// What a pair's stereo matches say about x_camr's rotation.
struct EpipolarEvidence {
  int pairs = 0;           ///< stereo matches used
  int dof = 0;             ///< rank of their information about x_camr's rotation
  double statistic = 0.0;  ///< T above; chi-square with dof degrees of freedom if x_camr holds
  double bound = 0.0;      ///< T's upper quantile at the false-alarm probability asked for
  /// x_camr's rotation error the matches alone indicate (rad, boxPlus tangent of
  /// T_caml_camr; their least-squares fit), and its angle.
  Eigen::Vector3d rotation_shift = Eigen::Vector3d::Zero();
  double angle = 0.0;
  /// statistic > bound, from at least the pairs asked for.
  bool contradicts = false;
  /// "12 of 40 pairs off x_camr's epipolar lines: T 310 > 27.6, 0.52 deg" (for warnings).
  std::string summary() const;
};

/// Tests @p pairs (undistorted pixels [u_l, v_l, u_r, v_r] and their variances) against the
/// epipolar geometry of @p extrinsics' x_camr, which has the tangent covariance
/// @p camr_covariance ([dt (m), dtheta (rad)] of T_caml_camr, the filter's block). The
/// indicated rotation is the pairs' fit with the translation held. Fewer than @p min_pairs
/// usable pairs never contradict.
EpipolarEvidence testEpipolarLines(const std::vector<PointMeasurement>& pairs,
                                   const Eigen::Matrix3d& K_left, const Eigen::Matrix3d& K_right,
                                   const StereoExtrinsics& extrinsics,
                                   const Matrix6d& camr_covariance, double false_alarm,
                                   int min_pairs);

/// The knock test's options (FilterConfig keys).
struct EpipolarKnockOptions {
  double false_alarm = 1e-6;  ///< epipolar_knock_false_alarm per image pair; 0 = off
  int pairs = 1;              ///< epipolar_knock_pairs: contradicting image pairs in a row
  int min_pairs = 8;          ///< jump_min_points: fewest stereo pairs that can contradict

  static EpipolarKnockOptions from(const FilterConfig& config);
};

/// What one image pair's test found.
struct EpipolarKnock {
  bool knocked = false;         ///< `pairs` image pairs in a row contradicted x_camr
  double rotation_sigma = 0.0;  ///< x_camr's rotation re-opening: 3 x the indicated angle (rad)
  std::string warning;          ///< the event's line (empty when nothing was found)
};

/// Change detection, x_camr: the streak of image pairs whose stereo pairs contradict x_camr's
/// epipolar lines (docs/design.md). The caller re-opens x_camr's rotation on a knock, before
/// the update: after a knock the tracked points would pull x_camr with its old sigma, or gate
/// out and be blamed on x_caml.
class EpipolarKnockTest {
 public:
  explicit EpipolarKnockTest(const EpipolarKnockOptions& options) : options_(options) {}
  /// Tests one image pair's stereo pairs (tracked and new; undistorted pixels) against
  /// @p filter's x_camr and its covariance.
  EpipolarKnock test(const std::vector<PointMeasurement>& pairs, const Eigen::Matrix3d& K_left,
                     const Eigen::Matrix3d& K_right, const CalibrationFilter& filter);
  /// Forgets the streak (a reset).
  void reset() { streak_ = 0; }

 private:
  EpipolarKnockOptions options_;
  int streak_ = 0;  ///< image pairs in a row that contradicted x_camr's epipolar lines
};

}  // namespace osc
