#include "online_stereo_calibration/core/geometry/stereo_rectification.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "online_stereo_calibration/core/geometry/stereo_geometry.h"

namespace osc {
namespace {

cv::Mat cameraMatrix(const CameraIntrinsics& intrinsics) {
  cv::Mat K;
  cv::eigen2cv(intrinsics.K(), K);
  return K;
}

cv::Mat distortion(const CameraIntrinsics& intrinsics) {
  if (intrinsics.distortion.empty()) return cv::Mat::zeros(1, 5, CV_64F);
  return cv::Mat(intrinsics.distortion, true).reshape(1, 1);
}

bool rectify(const CameraModel& camera, const Eigen::Matrix3d& R,
             const Eigen::Matrix<double, 3, 4>& P, const Eigen::Vector2d& raw,
             Eigen::Vector2d* rectified) {
  Eigen::Vector2d normalized;
  if (!camera.pixelToNormalized(raw, &normalized)) return false;
  const Eigen::Vector3d in_rectified_frame = R * normalized.homogeneous();
  const Eigen::Vector3d pixel = P.leftCols<3>() * in_rectified_frame;
  if (!(pixel.z() > 0.0)) return false;
  *rectified = pixel.head<2>() / pixel.z();
  return rectified->allFinite();
}

double rotationAngle(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

}  // namespace

bool StereoRectification::rectifyLeft(const CameraModel& left, const Eigen::Vector2d& raw,
                                      Eigen::Vector2d* rectified) const {
  return rectify(left, R_left, P_left, raw, rectified);
}

bool StereoRectification::rectifyRight(const CameraModel& right, const Eigen::Vector2d& raw,
                                       Eigen::Vector2d* rectified) const {
  return rectify(right, R_right, P_right, raw, rectified);
}

StereoRectification computeStereoRectification(const CameraIntrinsics& left,
                                               const CameraIntrinsics& right,
                                               const Eigen::Isometry3d& T_lopt_ropt,
                                               const RectificationSettings& settings) {
  // Validates both cameras (throws naming the field).
  const CameraModel left_model(left), right_model(right);
  if (!T_lopt_ropt.matrix().allFinite()) {
    throw std::invalid_argument("stereo rectification: left->right transform is not finite");
  }
  if (!(T_lopt_ropt.translation().norm() > 1e-9)) {
    throw std::invalid_argument("stereo rectification: left->right baseline is zero");
  }
  if (!(settings.alpha >= -1.0 && settings.alpha <= 1.0)) {
    throw std::invalid_argument("stereo rectification: alpha " + std::to_string(settings.alpha) +
                                " outside [-1, 1]");
  }
  if (settings.width < 0 || settings.height < 0) {
    throw std::invalid_argument("stereo rectification: negative output size");
  }
  if (left.model != right.model) {
    throw std::invalid_argument("stereo rectification: left and right distortion models differ (" +
                                distortionModelName(left.model) + ", " +
                                distortionModelName(right.model) + ")");
  }
  // OpenCV's R, T map points from the first (left) camera into the second: T_ropt_lopt.
  const Eigen::Isometry3d T_ropt_lopt = T_lopt_ropt.inverse();
  cv::Mat R, T;
  cv::eigen2cv(Eigen::Matrix3d(T_ropt_lopt.linear()), R);
  cv::eigen2cv(Eigen::Vector3d(T_ropt_lopt.translation()), T);
  const cv::Size input_size(left.width, left.height);
  const cv::Size output_size(settings.width > 0 ? settings.width : left.width,
                             settings.height > 0 ? settings.height : left.height);
  cv::Mat R1, R2, P1, P2, Q;
  if (left.model == DistortionModel::kEquidistant) {
    cv::fisheye::stereoRectify(cameraMatrix(left), distortion(left), cameraMatrix(right),
                               distortion(right), input_size, R, T, R1, R2, P1, P2, Q,
                               cv::CALIB_ZERO_DISPARITY, output_size,
                               std::clamp(settings.alpha, 0.0, 1.0));
  } else {
    cv::stereoRectify(cameraMatrix(left), distortion(left), cameraMatrix(right), distortion(right),
                      input_size, R, T, R1, R2, P1, P2, Q, cv::CALIB_ZERO_DISPARITY, settings.alpha,
                      output_size);
  }
  StereoRectification result;
  cv::cv2eigen(R1, result.R_left);
  cv::cv2eigen(R2, result.R_right);
  cv::cv2eigen(P1, result.P_left);
  cv::cv2eigen(P2, result.P_right);
  result.width = output_size.width;
  result.height = output_size.height;
  result.T_lopt_ropt = T_lopt_ropt;
  if (!result.P_left.allFinite() || !result.P_right.allFinite() || !result.R_left.allFinite() ||
      !result.R_right.allFinite()) {
    throw std::invalid_argument("stereo rectification: OpenCV returned non-finite R or P");
  }
  return result;
}

double rectificationChangePx(const StereoRectification& rectification,
                             const Eigen::Isometry3d& T_lopt_ropt) {
  const double focal = std::max(rectification.P_left(0, 0), rectification.P_left(1, 1));
  const double rotation =
      rotationAngle(rectification.T_lopt_ropt.linear().transpose() * T_lopt_ropt.linear());
  const Eigen::Vector3d old_baseline = rectification.T_lopt_ropt.translation().normalized();
  const Eigen::Vector3d new_baseline = T_lopt_ropt.translation().normalized();
  const double direction =
      std::atan2(old_baseline.cross(new_baseline).norm(), old_baseline.dot(new_baseline));
  const double change = focal * (rotation + direction);
  // A non-finite transform counts as "moved far": the caller recomputes and gets the error.
  return std::isfinite(change) ? change : std::numeric_limits<double>::infinity();
}

std::optional<RectificationError> rectificationError(const std::vector<StereoObservation>& pairs,
                                                     const CameraModel& left,
                                                     const CameraModel& right,
                                                     const StereoRectification& rectification) {
  std::vector<double> vertical;
  vertical.reserve(pairs.size());
  for (const StereoObservation& pair : pairs) {
    Eigen::Vector2d rect_left, rect_right;
    if (!pair.left_pixel.allFinite() || !pair.right_pixel.allFinite()) continue;
    if (!rectification.rectifyLeft(left, pair.left_pixel, &rect_left)) continue;
    if (!rectification.rectifyRight(right, pair.right_pixel, &rect_right)) continue;
    vertical.push_back(std::abs(rect_left.y() - rect_right.y()));
  }
  if (vertical.empty()) return std::nullopt;
  const size_t middle = vertical.size() / 2;
  std::nth_element(vertical.begin(), vertical.begin() + middle, vertical.end());
  double median = vertical[middle];
  if (vertical.size() % 2 == 0) {
    median = 0.5 * (median + *std::max_element(vertical.begin(), vertical.begin() + middle));
  }
  RectificationError error;
  error.median_px = median;
  error.pairs = static_cast<int>(vertical.size());
  return error;
}

std::optional<double> depthOnAxisWithPerturbedCamr(const StereoExtrinsics& truth,
                                                   const Vector6d& delta_camr, double true_depth) {
  // The two rays of the point (0, 0, depth) as the true cameras see it.
  const Eigen::Vector3d point_left(0.0, 0.0, true_depth);
  const Eigen::Vector3d ray_left = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d ray_right = truth.leftToRightOptical().inverse() * point_left;
  StereoExtrinsics perturbed = truth;
  perturbed.T_caml_camr = boxPlus(truth.T_caml_camr, delta_camr);
  const std::optional<Triangulation> triangulated =
      triangulateMidpoint(ray_left, ray_right, perturbed.leftToRightOptical());
  if (!triangulated) return std::nullopt;
  return triangulated->point_left.z();
}

double depthSigmaOnAxis(const StereoExtrinsics& extrinsics, const Matrix12d& tangent_covariance,
                        double depth) {
  if (!(depth > 0.0) || !std::isfinite(depth)) {
    throw std::invalid_argument("depth sigma: depth must be positive and finite (m)");
  }
  if (!tangent_covariance.allFinite()) {
    throw std::invalid_argument("depth sigma: covariance is not finite");
  }
  // Central differences; steps small against any sigma of interest, large against rounding.
  const double steps[6] = {1e-6, 1e-6, 1e-6, 1e-7, 1e-7, 1e-7};  // m, m, m, rad, rad, rad
  Eigen::Matrix<double, 1, 6> jacobian;
  for (int i = 0; i < 6; ++i) {
    Vector6d delta = Vector6d::Zero();
    delta(i) = steps[i];
    const std::optional<double> plus = depthOnAxisWithPerturbedCamr(extrinsics, delta, depth);
    const std::optional<double> minus = depthOnAxisWithPerturbedCamr(extrinsics, -delta, depth);
    if (!plus || !minus) {
      throw std::invalid_argument("depth sigma: a point at " + std::to_string(depth) +
                                  " m on the optical axis does not triangulate (baseline?)");
    }
    jacobian(i) = (*plus - *minus) / (2.0 * steps[i]);
  }
  const Matrix6d camr_covariance = tangent_covariance.block<6, 6>(6, 6);
  const double variance = (jacobian * camr_covariance * jacobian.transpose())(0, 0);
  return std::sqrt(std::max(variance, 0.0));
}

}  // namespace osc
