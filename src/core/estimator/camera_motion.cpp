#include "online_stereo_calibration/core/estimator/camera_motion.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

/// Sampson distance (normalised units) of x1 <-> x0 under E = [t]x R (x1 = R x0 + t).
double sampson(const Eigen::Matrix3d& E, const Eigen::Vector3d& x0, const Eigen::Vector3d& x1) {
  const Eigen::Vector3d Ex0 = E * x0, Etx1 = E.transpose() * x1;
  const double denominator = Ex0.head<2>().squaredNorm() + Etx1.head<2>().squaredNorm();
  return denominator > 0.0 ? x1.dot(Ex0) / std::sqrt(denominator) : 0.0;
}

/// Gauss-Newton on the Sampson distances of the points within @p threshold of the current
/// model (re-selected each iteration): R <- Exp(dr) R, t <- normalise(t + B dt), B spanning
/// t's orthogonal complement. OpenCV's RANSAC keeps the best minimal sample's E, and its
/// USAC_ACCURATE refinement counted a quarter of the test drive's points (all within 1.4 px
/// of the true E) as outliers: 0.2-1.4 deg rotation error for a sideways camera. Returns the
/// number of points within the threshold.
int refine(const std::vector<Eigen::Vector3d>& x0, const std::vector<Eigen::Vector3d>& x1,
           double threshold, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  int inliers = 0;
  for (int iteration = 0; iteration < 6; ++iteration) {
    Eigen::Vector3d a = t->unitOrthogonal();
    const Eigen::Vector3d b = t->cross(a).normalized();
    auto model = [&](const Eigen::Matrix<double, 5, 1>& d, Eigen::Matrix3d* E) {
      const Eigen::Vector3d tt = (*t + a * d(3) + b * d(4)).normalized();
      *E = skew(tt) * expSO3(d.head<3>()) * *R;
    };
    Eigen::Matrix3d E0;
    model(Eigen::Matrix<double, 5, 1>::Zero(), &E0);
    Eigen::Matrix<double, 5, 5> H = Eigen::Matrix<double, 5, 5>::Zero();
    Eigen::Matrix<double, 5, 1> g = Eigen::Matrix<double, 5, 1>::Zero();
    inliers = 0;
    std::array<Eigen::Matrix3d, 10> shifted;
    const double h = 1e-7;
    for (int k = 0; k < 5; ++k) {
      Eigen::Matrix<double, 5, 1> d = Eigen::Matrix<double, 5, 1>::Zero();
      d(k) = h;
      model(d, &shifted[2 * k]);
      model(-d, &shifted[2 * k + 1]);
    }
    for (size_t i = 0; i < x0.size(); ++i) {
      const double r = sampson(E0, x0[i], x1[i]);
      if (!(std::abs(r) <= threshold)) continue;
      ++inliers;
      Eigen::Matrix<double, 5, 1> J;
      for (int k = 0; k < 5; ++k) {
        J(k) = (sampson(shifted[2 * k], x0[i], x1[i]) - sampson(shifted[2 * k + 1], x0[i], x1[i])) /
               (2.0 * h);
      }
      H += J * J.transpose();
      g += J * r;
    }
    if (inliers < 5) return inliers;
    const Eigen::Matrix<double, 5, 1> step = -H.ldlt().solve(g);
    if (!step.allFinite()) return inliers;
    *R = expSO3(step.head<3>()) * *R;
    *t = (*t + a * step(3) + b * step(4)).normalized();
    if (step.norm() < 1e-10) break;
  }
  return inliers;
}

}  // namespace

CameraMotion estimateCameraMotion(const std::vector<Eigen::Vector2d>& previous,
                                  const std::vector<Eigen::Vector2d>& current,
                                  const CameraMotionConfig& config) {
  CameraMotion motion;
  motion.points = static_cast<int>(std::min(previous.size(), current.size()));
  if (motion.points < std::max(5, config.min_points)) {
    motion.why = std::to_string(motion.points) + " common points (least " +
                 std::to_string(config.min_points) + ")";
    return motion;
  }
  std::vector<cv::Point2d> p0, p1;
  p0.reserve(static_cast<size_t>(motion.points));
  p1.reserve(static_cast<size_t>(motion.points));
  for (int k = 0; k < motion.points; ++k) {
    p0.emplace_back(previous[static_cast<size_t>(k)].x(), previous[static_cast<size_t>(k)].y());
    p1.emplace_back(current[static_cast<size_t>(k)].x(), current[static_cast<size_t>(k)].y());
  }
  cv::Mat mask;
  const cv::Mat E = cv::findEssentialMat(p0, p1, 1.0, cv::Point2d(0, 0), cv::RANSAC, 0.999,
                                         config.ransac_threshold / config.focal, mask);
  if (E.rows != 3 || E.cols != 3) {
    motion.why = "no essential matrix from " + std::to_string(motion.points) + " points";
    return motion;
  }
  // The overload with a distance threshold: the default one drops points beyond 50 motion
  // lengths as "at infinity" from the count (most points of a slow drive).
  cv::Mat R_cv, t_cv, triangulated;
  motion.inliers =
      cv::recoverPose(E, p0, p1, cv::Mat::eye(3, 3, CV_64F), R_cv, t_cv, 1e6, mask, triangulated);
  if (motion.inliers < config.min_inliers) {
    motion.why = std::to_string(motion.inliers) + " inliers of " + std::to_string(motion.points);
    return motion;
  }
  // recoverPose: x1 = R x0 + t (optical frames), i.e. T_o1_o0 = [R | t].
  Eigen::Matrix3d R_o1_o0;
  Eigen::Vector3d t_o1_o0;
  cv::cv2eigen(R_cv, R_o1_o0);
  cv::cv2eigen(t_cv, t_o1_o0);
  std::vector<Eigen::Vector3d> rays0, rays1;
  for (int k = 0; k < motion.points; ++k) {
    rays0.emplace_back(p0[k].x, p0[k].y, 1.0);
    rays1.emplace_back(p1[k].x, p1[k].y, 1.0);
  }
  motion.inliers = refine(rays0, rays1, config.ransac_threshold / config.focal, &R_o1_o0, &t_o1_o0);
  if (motion.inliers < config.min_inliers) {
    motion.why = std::to_string(motion.inliers) + " inliers of " + std::to_string(motion.points) +
                 " after refinement";
    return motion;
  }
  // Parallax: the angle between each current ray and the previous one rotated into the
  // current frame; without it the translation (and E) is noise.
  std::vector<double> parallax;
  const Eigen::Matrix3d E_refined = skew(t_o1_o0) * R_o1_o0;
  for (int k = 0; k < motion.points; ++k) {
    if (!(std::abs(sampson(E_refined, rays0[k], rays1[k])) <=
          config.ransac_threshold / config.focal)) {
      continue;
    }
    const Eigen::Vector3d r0 = (R_o1_o0 * Eigen::Vector3d(p0[k].x, p0[k].y, 1.0)).normalized();
    const Eigen::Vector3d r1 = Eigen::Vector3d(p1[k].x, p1[k].y, 1.0).normalized();
    parallax.push_back(std::atan2(r0.cross(r1).norm(), r0.dot(r1)) * config.focal);
  }
  std::nth_element(parallax.begin(), parallax.begin() + parallax.size() / 2, parallax.end());
  motion.parallax = parallax[parallax.size() / 2];
  if (motion.parallax < config.min_parallax) {
    motion.why = "median parallax " + std::to_string(motion.parallax) + " px (least " +
                 std::to_string(config.min_parallax) + ")";
    return motion;
  }
  // Body frames: R_c0_c1 = B R_o0_o1 B^T; c1's origin in o0 is -R_o1_o0^T t_o1_o0.
  const Eigen::Matrix3d& B = rotationBodyOptical();
  motion.R_prev_curr = B * R_o1_o0.transpose() * B.transpose();
  motion.translation_direction = (B * (-(R_o1_o0.transpose() * t_o1_o0))).normalized();
  motion.valid = true;
  return motion;
}

}  // namespace osc
