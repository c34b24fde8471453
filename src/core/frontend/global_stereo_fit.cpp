/// @file global_stereo_fit.cpp
/// @brief fitStereoGeometry: whole-image matching + five-point RANSAC.
#include "online_stereo_calibration/core/frontend/global_stereo_fit.h"

#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Cholesky>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "online_stereo_calibration/core/frontend/feature_detection.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

/// Best and second-best distance of keypoint i of @p from among all of @p to.
struct Nearest {
  int best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  double second_distance = std::numeric_limits<double>::infinity();
};

void keep(Nearest* n, int index, double d) {
  if (d < n->best_distance) {
    n->second_distance = n->best_distance;
    n->best_distance = d;
    n->best = index;
  } else if (d < n->second_distance) {
    n->second_distance = d;
  }
}

/// Nearest and second-nearest neighbours in both directions from one pass over all pairs.
void nearestNeighbours(const FeatureSet& left, const FeatureSet& right,
                       std::vector<Nearest>* left_to_right, std::vector<Nearest>* right_to_left) {
  left_to_right->assign(left.size(), Nearest());
  right_to_left->assign(right.size(), Nearest());
  for (size_t i = 0; i < left.size(); ++i) {
    for (size_t j = 0; j < right.size(); ++j) {
      const double d = left.distance(static_cast<int>(i), right, static_cast<int>(j));
      keep(&(*left_to_right)[i], static_cast<int>(j), d);
      keep(&(*right_to_left)[j], static_cast<int>(i), d);
    }
  }
}

/// Undistorted pixel (K * normalised) -> normalised image coordinates.
cv::Point2d normalised(const Eigen::Matrix3d& K_inv, const Eigen::Vector2d& undistorted_pixel) {
  const Eigen::Vector3d ray = K_inv * undistorted_pixel.homogeneous();
  return {ray.x() / ray.z(), ray.y() / ray.z()};
}

/// Sampson distance (normalised units) of a ray pair under E = R_ropt_lopt [c]x, the
/// essential matrix of a right camera at c (unit) in the left optical frame.
double sampson(const Eigen::Matrix3d& E, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d Ea = E * a, Etb = E.transpose() * b;
  const double denominator = Ea.head<2>().squaredNorm() + Etb.head<2>().squaredNorm();
  return denominator > 0.0 ? b.dot(Ea) / std::sqrt(denominator) : 0.0;
}

/// The Sampson distances of the ray pairs under E = R_lopt_ropt^T [c]x (normalised units).
Eigen::VectorXd sampsonDistances(const Eigen::Matrix3d& R_lopt_ropt, const Eigen::Vector3d& c,
                                 const std::vector<Eigen::Vector3d>& left,
                                 const std::vector<Eigen::Vector3d>& right) {
  const Eigen::Matrix3d E = R_lopt_ropt.transpose() * skew(c);
  Eigen::VectorXd r(static_cast<Eigen::Index>(left.size()));
  for (size_t i = 0; i < left.size(); ++i)
    r(static_cast<Eigen::Index>(i)) = sampson(E, left[i], right[i]);
  return r;
}

struct RotationRefinement {
  Eigen::Matrix3d R_lopt_ropt;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double rms = 0.0;
  bool rotation_covariance_ok = false;
};

/// Gauss-Newton on the Sampson distances over R_lopt_ropt = R * Exp(e), c held fixed.
RotationRefinement refineRotation(const Eigen::Matrix3d& R_start, const Eigen::Vector3d& c,
                                  const std::vector<Eigen::Vector3d>& left,
                                  const std::vector<Eigen::Vector3d>& right) {
  RotationRefinement out;
  out.R_lopt_ropt = R_start;
  const int n = static_cast<int>(left.size());
  if (n < 4) return out;
  const auto residuals = [&](const Eigen::Matrix3d& R_lopt_ropt) {
    return sampsonDistances(R_lopt_ropt, c, left, right);
  };
  constexpr double kStep = 1e-7;  // rad, numeric derivative
  Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
  Eigen::VectorXd r = residuals(out.R_lopt_ropt);
  for (int iteration = 0; iteration < 8; ++iteration) {
    Eigen::MatrixXd J(n, 3);
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Matrix3d R = out.R_lopt_ropt * expSO3(kStep * Eigen::Vector3d::Unit(axis));
      J.col(axis) = (residuals(R) - r) / kStep;
    }
    JtJ = J.transpose() * J;
    const Eigen::Vector3d step = JtJ.ldlt().solve(-J.transpose() * r);
    if (!step.allFinite()) return out;
    out.R_lopt_ropt = out.R_lopt_ropt * expSO3(step);
    r = residuals(out.R_lopt_ropt);
    if (step.norm() < 1e-10) break;
  }
  out.rms = std::sqrt(r.squaredNorm() / n);
  // Sampson distances in normalised units are angles: s^2 (J^T J)^-1, s from the fit itself.
  const double s2 = r.squaredNorm() / std::max(1, n - 3);
  const Eigen::Matrix3d covariance = s2 * JtJ.inverse();
  out.rotation_covariance_ok = covariance.allFinite() && covariance.diagonal().minCoeff() > 0.0;
  if (out.rotation_covariance_ok) out.covariance = 0.5 * (covariance + covariance.transpose());
  return out;
}

struct JointRefinement {
  bool ok = false;
  Eigen::Matrix3d R_lopt_ropt;
  Eigen::Vector3d c;
  Eigen::Matrix<double, 5, 5> covariance;  ///< [rotation e (3), direction d (2) in basis B]
  Eigen::Matrix<double, 3, 2> B;           ///< basis of the plane perpendicular to the prior c
};

/// Gauss-Newton over R_lopt_ropt = R * Exp(e) and c = normalised(c0 + B d) on the Sampson
/// distances divided by their spread @p s (normalised units) and the prior residual on d
/// (whitened by the prior's covariance in the plane perpendicular to c0).
JointRefinement refineRotationAndDirection(const Eigen::Matrix3d& R_start,
                                           const Eigen::Vector3d& c0,
                                           const Eigen::Matrix3d& direction_covariance, double s,
                                           const std::vector<Eigen::Vector3d>& left,
                                           const std::vector<Eigen::Vector3d>& right) {
  JointRefinement out;
  const int n = static_cast<int>(left.size());
  if (n < 6 || !(s > 0.0)) return out;
  // A basis of the plane perpendicular to c0.
  const Eigen::Vector3d helper =
      std::abs(c0.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  out.B.col(0) = c0.cross(helper).normalized();
  out.B.col(1) = c0.cross(out.B.col(0)).normalized();
  const Eigen::Matrix2d prior = out.B.transpose() * direction_covariance * out.B;
  const Eigen::LLT<Eigen::Matrix2d> prior_llt(0.5 * (prior + prior.transpose()));
  if (prior_llt.info() != Eigen::Success) return out;
  const Eigen::Matrix2d W = prior_llt.matrixL().solve(Eigen::Matrix2d::Identity());
  const auto residuals = [&](const Eigen::Matrix3d& R_lopt_ropt, const Eigen::Vector2d& d) {
    Eigen::VectorXd r(n + 2);
    r.head(n) = sampsonDistances(R_lopt_ropt, (c0 + out.B * d).normalized(), left, right) / s;
    r.tail<2>() = W * d;
    return r;
  };
  constexpr double kStep = 1e-7;  // numeric derivative
  Eigen::Matrix3d R = R_start;
  Eigen::Vector2d d = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 5, 5> JtJ = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::VectorXd r = residuals(R, d);
  for (int iteration = 0; iteration < 12; ++iteration) {
    Eigen::MatrixXd J(n + 2, 5);
    for (int k = 0; k < 5; ++k) {
      const Eigen::VectorXd moved = k < 3
                                        ? residuals(R * expSO3(kStep * Eigen::Vector3d::Unit(k)), d)
                                        : residuals(R, d + kStep * Eigen::Vector2d::Unit(k - 3));
      J.col(k) = (moved - r) / kStep;
    }
    JtJ = J.transpose() * J;
    const Eigen::Matrix<double, 5, 1> step = JtJ.ldlt().solve(-J.transpose() * r);
    if (!step.allFinite()) return out;
    R = R * expSO3(step.head<3>());
    d += step.tail<2>();
    r = residuals(R, d);
    if (step.norm() < 1e-10) break;
  }
  out.R_lopt_ropt = R;
  out.c = (c0 + out.B * d).normalized();
  out.covariance = JtJ.inverse();
  out.covariance = 0.5 * (out.covariance + out.covariance.transpose());
  out.ok = out.covariance.allFinite() && out.covariance.diagonal().minCoeff() > 0.0;
  return out;
}

}  // namespace

double rotationAngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return logSO3(a.transpose() * b).norm();
}

GlobalStereoFit fitStereoGeometry(const FeatureSet& left, const FeatureSet& right,
                                  const CameraModel& left_camera, const CameraModel& right_camera,
                                  const Eigen::Vector3d& baseline_direction,
                                  const GlobalStereoFitConfig& config) {
  GlobalStereoFit fit;
  if (left.size() < 5 || right.size() < 5 || left.descriptors.type() != right.descriptors.type()) {
    fit.why = "fewer than 5 keypoints in an image";
    return fit;
  }
  // Mutual best matches that pass the distance bound and the ratio test in both directions.
  std::vector<Nearest> left_to_right, right_to_left;
  nearestNeighbours(left, right, &left_to_right, &right_to_left);
  const Eigen::Matrix3d Kl_inv = left_camera.K().inverse(), Kr_inv = right_camera.K().inverse();
  std::vector<cv::Point2d> points_left, points_right;
  for (size_t i = 0; i < left.size(); ++i) {
    const Nearest& forward = left_to_right[i];
    if (forward.best < 0 || forward.best_distance > config.max_descriptor_distance) continue;
    if (!(forward.best_distance < config.ratio * forward.second_distance)) continue;
    const Nearest& backward = right_to_left[static_cast<size_t>(forward.best)];
    if (backward.best != static_cast<int>(i)) continue;
    if (!(backward.best_distance < config.ratio * backward.second_distance)) continue;
    points_left.push_back(normalised(Kl_inv, left.undistorted[i]));
    points_right.push_back(
        normalised(Kr_inv, right.undistorted[static_cast<size_t>(forward.best)]));
  }
  fit.matches = static_cast<int>(points_left.size());
  if (fit.matches < std::max(5, config.min_inliers)) {
    fit.why = std::to_string(fit.matches) + " descriptor matches over the whole images";
    return fit;
  }
  // The threshold in normalised units of the mean focal length of the two cameras.
  const double focal = 0.25 * (left_camera.K()(0, 0) + left_camera.K()(1, 1) +
                               right_camera.K()(0, 0) + right_camera.K()(1, 1));
  cv::Mat mask;
  const cv::Mat E = cv::findEssentialMat(points_left, points_right, 1.0, cv::Point2d(0, 0),
                                         cv::RANSAC, 0.999, config.ransac_threshold / focal, mask);
  if (E.rows != 3 || E.cols != 3) {
    fit.why = "no essential matrix from " + std::to_string(fit.matches) + " matches";
    return fit;
  }
  cv::Mat R, t;
  fit.inliers = cv::recoverPose(E, points_left, points_right, R, t, 1.0, cv::Point2d(0, 0), mask);
  if (fit.inliers < config.min_inliers) {
    fit.why = std::to_string(fit.inliers) + " inliers of " + std::to_string(fit.matches) +
              " matches (least " + std::to_string(config.min_inliers) + ")";
    return fit;
  }
  // recoverPose: x_right = R x_left + t, i.e. T_ropt_lopt = [R | t].
  Eigen::Matrix3d R_ropt_lopt;
  Eigen::Vector3d t_ropt_lopt;
  cv::cv2eigen(R, R_ropt_lopt);
  cv::cv2eigen(t, t_ropt_lopt);
  fit.free_baseline_direction = (-(R_ropt_lopt.transpose() * t_ropt_lopt)).normalized();
  std::vector<Eigen::Vector3d> rays_left, rays_right;
  for (size_t k = 0; k < points_left.size(); ++k) {
    if (!mask.at<unsigned char>(static_cast<int>(k))) continue;
    rays_left.emplace_back(points_left[k].x, points_left[k].y, 1.0);
    rays_right.emplace_back(points_right[k].x, points_right[k].y, 1.0);
  }
  const RotationRefinement refined = refineRotation(
      R_ropt_lopt.transpose(), baseline_direction.normalized(), rays_left, rays_right);
  fit.R_lopt_ropt = refined.R_lopt_ropt;
  fit.rotation_covariance = refined.covariance;
  fit.rms_px = refined.rms * focal;
  fit.valid = refined.rotation_covariance_ok;
  fit.baseline_direction = baseline_direction.normalized();
  if (fit.valid && !config.baseline_direction_covariance.isZero()) {
    // The inliers' own spread about their lines (held fit, 3 dof) weighs them against the
    // direction's prior.
    const int n = static_cast<int>(rays_left.size());
    const double s = refined.rms * std::sqrt(static_cast<double>(n) / std::max(1, n - 3));
    const JointRefinement joint =
        refineRotationAndDirection(refined.R_lopt_ropt, fit.baseline_direction,
                                   config.baseline_direction_covariance, s, rays_left, rays_right);
    fit.valid = joint.ok;
    if (joint.ok) {
      fit.R_lopt_ropt = joint.R_lopt_ropt;
      fit.baseline_direction = joint.c;
      fit.rotation_covariance = joint.covariance.topLeftCorner<3, 3>();
      fit.rotation_direction_covariance =
          joint.covariance.topRightCorner<3, 2>() * joint.B.transpose();
      fit.baseline_direction_covariance =
          joint.B * joint.covariance.bottomRightCorner<2, 2>() * joint.B.transpose();
    }
  }
  fit.why = std::to_string(fit.inliers) + " inliers of " + std::to_string(fit.matches) +
            " matches, " + std::to_string(fit.rms_px) + " px RMS" +
            (fit.valid ? "" : ", rotation not determined");
  return fit;
}

}  // namespace osc
