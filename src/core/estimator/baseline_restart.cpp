#include "online_stereo_calibration/core/estimator/baseline_restart.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "online_stereo_calibration/core/filter/state_layout.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {
namespace {

/// The baseline's length from motion restarts x_camr only while the length's 1 sigma is above
/// this share of it (a 0.3 m rig: 9 cm; the guess's sigma points then reach below half the
/// length). Measured on the default campaign: without it, run 90 (its points kept out by x_caml
/// 20 deg off) was restarted at the right length with x_camr's wrong rotation, 570 frames
/// beyond 5 sigma.
constexpr double kUnknownLengthShare = 0.3;
/// The least 1 sigma of a length from motion, as a share of it (the fit's own sigma is doubled).
constexpr double kLeastLengthSigma = 0.05;
/// Pairs linked to one reference pair at most while the camera's parallax since it is too
/// small (a hovering MAV): then the reference moves on.
constexpr int kMostPairsOnOneReference = 20;

BaselineFromMotionConfig measurementConfig(const FilterConfig& config,
                                           const Eigen::Matrix3d& K_left) {
  BaselineFromMotionConfig b;
  b.pixel_noise = config.pixel_noise;
  b.motion.focal = K_left(0, 0);
  return b;
}

}  // namespace

BaselineRestart::BaselineRestart(const FilterConfig& config, const Eigen::Matrix3d& K_left,
                                 const Eigen::Matrix3d& K_right)
    : K_left_inverse_(K_left.inverse()),
      K_right_inverse_(K_right.inverse()),
      measurement_(measurementConfig(config, K_left)) {}

void BaselineRestart::setLinks(std::vector<std::pair<PointMeasurement, PointMeasurement>> links,
                               bool given) {
  given_links_ = std::move(links);
  links_given_ = given;
}

void BaselineRestart::forget() {
  measurement_.clear();
  previous_candidates_.clear();
  given_links_.clear();
  links_given_ = false;
  since_reference_ = Eigen::Isometry3d::Identity();
  pairs_on_reference_ = 0;
}

std::string BaselineRestart::progress() const {
  const BaselineLength length = measurement_.estimate();
  std::string text = length.valid ? "so far " + std::to_string(length.length) + " m" : length.why;
  if (!measurement_.lastWhy().empty())
    text += "; the last pair did not count: " + measurement_.lastWhy();
  return text;
}

BaselineReseed BaselineRestart::afterPair(const MotionIncrement& motion, bool motion_links_pairs,
                                          const std::vector<PointMeasurement>& candidates,
                                          const CalibrationFilter& filter) {
  BaselineReseed result;
  const auto normalised = [&](const PointMeasurement& m) {
    Eigen::Vector4d n;
    n << (K_left_inverse_ * m.z.head<2>().homogeneous()).head<2>(),
        (K_right_inverse_ * m.z.tail<2>().homogeneous()).head<2>();
    return n;
  };
  std::unordered_map<PointId, Eigen::Vector4d> current;
  std::vector<StereoLink> links;
  for (const PointMeasurement& m : candidates) {
    current[m.id] = normalised(m);
    const auto previous = previous_candidates_.find(m.id);
    if (!links_given_ && previous != previous_candidates_.end())
      links.push_back({previous->second, current[m.id]});
  }
  for (const auto& [previous, now] : given_links_)
    links.push_back({normalised(previous), normalised(now)});
  given_links_.clear();
  links_given_ = false;
  // The left camera's motion since the reference pair, at the odometry's scale (its length
  // hardly depends on x_caml: only through the lever arm of the vehicle's rotation).
  const StereoExtrinsics& extrinsics = filter.extrinsics();
  const Eigen::Isometry3d& T_veh_caml = extrinsics.T_veh_caml;
  const Eigen::Isometry3d since_reference = since_reference_ * motion.T_prev_curr;
  const bool linked = motion_links_pairs && !links.empty();
  bool counted = false;
  if (linked) {
    const double moved = (T_veh_caml.inverse() * since_reference * T_veh_caml).translation().norm();
    counted = measurement_.addPair(links, extrinsics.leftToRightOptical(), moved);
  }
  // Too little parallax since the reference: the next pair is linked to the same one.
  if (linked && !counted && measurement_.lastLackedParallax() &&
      pairs_on_reference_ < kMostPairsOnOneReference) {
    since_reference_ = since_reference;
    ++pairs_on_reference_;
    return result;
  }
  previous_candidates_.swap(current);
  since_reference_ = Eigen::Isometry3d::Identity();
  pairs_on_reference_ = 0;
  if (!counted) return result;
  const BaselineLength length = measurement_.estimate();
  if (!length.valid) return result;
  forget();
  // The seed's sigma: twice the fit's (the pairs' motion fits err in common, which the
  // per-point sigmas do not see) and at least 5 % of the length.
  const double sigma = std::max(2.0 * length.sigma, kLeastLengthSigma * length.length);
  using namespace layout;
  const Eigen::Vector3d t = extrinsics.T_caml_camr.translation();
  const double old_length = t.norm();
  if (!(old_length > 0.0)) return result;  // no direction to put the length along
  const Matrix12d P = filter.covariance();
  const Eigen::Vector3d c = t / old_length;
  const double old_sigma =
      std::sqrt(c.dot(P.block<3, 3>(kCamr + kTranslation, kCamr + kTranslation) * c));
  const bool offset_significant = std::abs(length.offset) > 3.0 * length.offset_sigma;
  if (!(old_sigma > kUnknownLengthShare * old_length) || !(sigma < 0.5 * old_sigma)) {
    // The length known, something else keeps the pairs out. (Turning x_camr by the disparity
    // offset then measured mixed: docs/experiments.md, disparity_offset_turn.)
    return result;
  }
  // The length along the baseline's direction; across it the translation's covariance as it
  // was, in metres: the length says nothing about it. (Scaled with the length, as a direction
  // uncertainty, it grew tenfold for an 11 cm rig guessed at 1 cm: 1.1 m across a 0.11 m
  // baseline, which no linearisation follows; one of 16 seeds of that start locked in the
  // baseline's direction 75 deg off, xr 14 sigma, and three more ended not honest:
  // docs/history/RESULTS-sessions-1-40.md "Session 38".) Only a shorter length scales it down
  // with the baseline.
  const double ratio = std::min(1.0, length.length / old_length);
  const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - c * c.transpose();
  Matrix6d block = P.block<6, 6>(kCamr, kCamr);
  block.topLeftCorner<3, 3>() = ratio * ratio * across * block.topLeftCorner<3, 3>() * across +
                                sigma * sigma * c * c.transpose();
  block.topRightCorner<3, 3>() = ratio * across * block.topRightCorner<3, 3>();
  block.bottomLeftCorner<3, 3>() = block.topRightCorner<3, 3>().transpose();
  Eigen::Isometry3d T_caml_camr = extrinsics.T_caml_camr;
  T_caml_camr.translation() = length.length * c;
  // The offset is x_camr's rotation about the axis across the baseline and the view being off
  // (yaw_r for a horizontal rig; the stereo fit at a start hardly determines it): re-centred
  // when significant, its sigma kept (the filter linearises near the truth, and nothing it
  // did not learn is claimed).
  const bool turned = offset_significant;
  if (turned) T_caml_camr.linear() = turnedByDisparityOffset(extrinsics, length.offset).linear();
  result.reseed = true;
  result.T_caml_camr = T_caml_camr;
  result.covariance = block;
  std::ostringstream message;
  message.precision(3);
  message << "baseline length from motion: x_camr's translation restarted at " << length.length
          << " m, 1 sigma " << sigma << " m (was " << old_length << " m, 1 sigma " << old_sigma
          << " m; " << length.inliers << " points in " << length.pairs
          << " pairs of the left camera's motion)";
  message << "; disparity offset " << length.offset * 180.0 / M_PI << " deg, 1 sigma "
          << length.offset_sigma * 180.0 / M_PI << " deg"
          << (turned ? ": x_camr turned by it about the axis across the baseline and the view"
                     : "");
  message << "; tracks reset";
  result.message = message.str();
  return result;
}

Eigen::Isometry3d turnedByDisparityOffset(const StereoExtrinsics& extrinsics, double offset) {
  const Eigen::Matrix3d& R_bo = rotationBodyOptical();
  const Eigen::Isometry3d T_lopt_ropt =
      withoutDisparityOffset(extrinsics.leftToRightOptical(), offset);
  Eigen::Isometry3d T_caml_camr = extrinsics.T_caml_camr;
  T_caml_camr.linear() = R_bo * T_lopt_ropt.linear() * R_bo.transpose();
  return T_caml_camr;
}

}  // namespace osc
