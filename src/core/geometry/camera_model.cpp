#include "online_stereo_calibration/core/geometry/camera_model.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/LU>
#include <Eigen/SVD>

namespace osc {

DistortionModel distortionModelFromName(const std::string& name) {
  if (name.empty() || name == "none") return DistortionModel::kNone;
  if (name == "plumb_bob") return DistortionModel::kPlumbBob;
  if (name == "rational_polynomial") return DistortionModel::kRationalPolynomial;
  if (name == "equidistant") return DistortionModel::kEquidistant;
  throw std::invalid_argument("unsupported distortion model '" + name +
                              "' (supported: plumb_bob, rational_polynomial, equidistant)");
}

std::string distortionModelName(DistortionModel model) {
  switch (model) {
    case DistortionModel::kNone:
      return "none";
    case DistortionModel::kPlumbBob:
      return "plumb_bob";
    case DistortionModel::kRationalPolynomial:
      return "rational_polynomial";
    case DistortionModel::kEquidistant:
      return "equidistant";
  }
  return "none";
}

Eigen::Matrix3d CameraIntrinsics::K() const {
  Eigen::Matrix3d k;
  k << fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0;
  return k;
}

namespace {

/// Coefficient k(i) or 0 when the vector is shorter (CameraInfo may carry 4 or 5 for plumb_bob).
double coefficient(const std::vector<double>& d, size_t i) { return i < d.size() ? d[i] : 0.0; }

void checkCoefficientCount(const CameraIntrinsics& in) {
  const size_t n = in.distortion.size();
  bool ok = true;
  switch (in.model) {
    case DistortionModel::kNone:
      ok = true;
      break;
    case DistortionModel::kPlumbBob:
      ok = (n == 4 || n == 5);
      break;
    case DistortionModel::kRationalPolynomial:
      ok = (n >= 4 && n <= 8);
      break;
    case DistortionModel::kEquidistant:
      ok = (n == 4);
      break;
  }
  if (!ok) {
    throw std::invalid_argument("camera model '" + distortionModelName(in.model) + "' got " +
                                std::to_string(n) + " distortion coefficients (D)");
  }
}

}  // namespace

CameraModel::CameraModel(const CameraIntrinsics& intrinsics) : intrinsics_(intrinsics) {
  if (intrinsics.width <= 0 || intrinsics.height <= 0) {
    throw std::invalid_argument("camera image size must be positive, got " +
                                std::to_string(intrinsics.width) + "x" +
                                std::to_string(intrinsics.height));
  }
  if (!(intrinsics.fx > 0.0) || !(intrinsics.fy > 0.0) || !std::isfinite(intrinsics.fx) ||
      !std::isfinite(intrinsics.fy)) {
    throw std::invalid_argument(
        "camera focal lengths fx, fy must be positive and finite (K[0], K[4])");
  }
  if (!std::isfinite(intrinsics.cx) || !std::isfinite(intrinsics.cy)) {
    throw std::invalid_argument("camera principal point cx, cy must be finite (K[2], K[5])");
  }
  for (double d : intrinsics.distortion) {
    if (!std::isfinite(d))
      throw std::invalid_argument("camera distortion coefficients (D) must be finite");
  }
  checkCoefficientCount(intrinsics);
  // An all-zero D is the rectified case: skip the distortion arithmetic entirely.
  bool all_zero = true;
  for (double d : intrinsics.distortion) all_zero = all_zero && d == 0.0;
  if (all_zero) intrinsics_.model = DistortionModel::kNone;
}

Eigen::Vector2d CameraModel::distort(const Eigen::Vector2d& n) const {
  const auto& d = intrinsics_.distortion;
  const double x = n.x(), y = n.y();
  switch (intrinsics_.model) {
    case DistortionModel::kNone:
      return n;
    case DistortionModel::kPlumbBob:
    case DistortionModel::kRationalPolynomial: {
      const double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
      const double k1 = coefficient(d, 0), k2 = coefficient(d, 1), p1 = coefficient(d, 2),
                   p2 = coefficient(d, 3), k3 = coefficient(d, 4), k4 = coefficient(d, 5),
                   k5 = coefficient(d, 6), k6 = coefficient(d, 7);
      const double radial =
          (1.0 + k1 * r2 + k2 * r4 + k3 * r6) / (1.0 + k4 * r2 + k5 * r4 + k6 * r6);
      return Eigen::Vector2d(x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
                             y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y);
    }
    case DistortionModel::kEquidistant: {
      const double r = std::sqrt(x * x + y * y);
      if (r < 1e-12) return n;
      const double theta = std::atan(r), t2 = theta * theta;
      const double theta_d = theta * (1.0 + t2 * (d[0] + t2 * (d[1] + t2 * (d[2] + t2 * d[3]))));
      return n * (theta_d / r);
    }
  }
  return n;
}

Eigen::Vector2d CameraModel::undistort(const Eigen::Vector2d& distorted) const {
  Eigen::Vector2d n = distorted;  // kept where the model has no valid ray
  undistort(distorted, &n);
  return n;
}

namespace {

/// Central-difference Jacobian of a 2D -> 2D map.
template <typename Map>
Eigen::Matrix2d numericalJacobian(const Map& f, const Eigen::Vector2d& x) {
  const double h = 1e-7;
  Eigen::Matrix2d jacobian;
  for (int k = 0; k < 2; ++k) {
    Eigen::Vector2d dx = Eigen::Vector2d::Zero();
    dx(k) = h;
    jacobian.col(k) = (f(x + dx) - f(x - dx)) / (2.0 * h);
  }
  return jacobian;
}

}  // namespace

bool CameraModel::undistort(const Eigen::Vector2d& distorted, Eigen::Vector2d* normalized) const {
  if (!distorted.allFinite()) return false;
  if (intrinsics_.model == DistortionModel::kNone) {
    *normalized = distorted;
    return true;
  }
  const auto model = [this](const Eigen::Vector2d& x) { return distort(x); };
  if (intrinsics_.model == DistortionModel::kEquidistant) {
    // Invert theta_d = theta * (1 + k1 t^2 + ...) by Newton, then x = tan(theta) * dir.
    const auto& d = intrinsics_.distortion;
    const double theta_d = distorted.norm();
    if (theta_d < 1e-12) {
      *normalized = distorted;
      return true;
    }
    double theta = theta_d;
    for (int i = 0; i < 30; ++i) {
      const double t2 = theta * theta;
      const double f =
          theta * (1.0 + t2 * (d[0] + t2 * (d[1] + t2 * (d[2] + t2 * d[3])))) - theta_d;
      const double df =
          1.0 + t2 * (3.0 * d[0] + t2 * (5.0 * d[1] + t2 * (7.0 * d[2] + 9.0 * t2 * d[3])));
      if (!(df > 0.0)) return false;  // past the fold of theta_d(theta)
      const double step = f / df;
      theta -= step;
      if (std::abs(step) < 1e-14) break;
    }
    if (!(theta > 0.0 && theta < M_PI / 2.0)) return false;  // behind the camera: no ray
    const Eigen::Vector2d n = distorted * (std::tan(theta) / theta_d);
    if ((distort(n) - distorted).norm() > 1e-9) return false;
    *normalized = n;
    return true;
  }
  // Gauss-Newton on distort(n) = distorted, from the distorted point, kept on the branch
  // that contains the optical axis: a step that would cross the fold (Jacobian determinant
  // <= 0) or not reduce the residual is halved.
  Eigen::Vector2d n = distorted;
  Eigen::Vector2d residual = distort(n) - distorted;
  for (int i = 0; i < 50 && residual.squaredNorm() >= 1e-28; ++i) {
    const Eigen::Matrix2d jacobian = numericalJacobian(model, n);
    if (!(jacobian.determinant() > 0.0)) return false;
    Eigen::Vector2d step = jacobian.inverse() * residual;
    bool improved = false;
    for (int halving = 0; halving < 30 && !improved; ++halving, step *= 0.5) {
      const Eigen::Vector2d candidate = n - step;
      const Eigen::Vector2d candidate_residual = distort(candidate) - distorted;
      if (numericalJacobian(model, candidate).determinant() > 0.0 &&
          candidate_residual.squaredNorm() < residual.squaredNorm()) {
        n = candidate;
        residual = candidate_residual;
        improved = true;
      }
    }
    if (!improved) break;  // stuck at the fold: the pixel is beyond the model's reach
  }
  if (!(residual.norm() < 1e-9)) return false;
  *normalized = n;
  return true;
}

bool CameraModel::project(const Eigen::Vector3d& p, Eigen::Vector2d* pixel) const {
  if (!(p.z() > 1e-6)) return false;
  *pixel = normalizedToPixel(Eigen::Vector2d(p.x() / p.z(), p.y() / p.z()));
  return true;
}

Eigen::Vector2d CameraModel::normalizedToPixel(const Eigen::Vector2d& normalized) const {
  const Eigen::Vector2d d = distort(normalized);
  return Eigen::Vector2d(intrinsics_.fx * d.x() + intrinsics_.cx,
                         intrinsics_.fy * d.y() + intrinsics_.cy);
}

Eigen::Matrix2d CameraModel::lensJacobian(const Eigen::Vector2d& undistorted_pixel) const {
  if (intrinsics_.model == DistortionModel::kNone) return Eigen::Matrix2d::Identity();
  const auto toRaw = [this](const Eigen::Vector2d& u) {
    return normalizedToPixel(Eigen::Vector2d((u.x() - intrinsics_.cx) / intrinsics_.fx,
                                             (u.y() - intrinsics_.cy) / intrinsics_.fy));
  };
  Eigen::Matrix2d jacobian;
  const double h = 0.5;
  for (int k = 0; k < 2; ++k) {
    Eigen::Vector2d du = Eigen::Vector2d::Zero();
    du(k) = h;
    jacobian.col(k) = (toRaw(undistorted_pixel + du) - toRaw(undistorted_pixel - du)) / (2.0 * h);
  }
  return jacobian;
}

double CameraModel::undistortedPixelVariance(const Eigen::Vector2d& undistorted_pixel,
                                             double raw_sigma) const {
  const double raw_variance = raw_sigma * raw_sigma;
  if (intrinsics_.model == DistortionModel::kNone) return raw_variance;
  const double least_stretch =
      Eigen::JacobiSVD<Eigen::Matrix2d>(lensJacobian(undistorted_pixel)).singularValues()(1);
  return raw_variance / (least_stretch * least_stretch);
}

Eigen::Vector2d CameraModel::pixelToNormalized(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d d((pixel.x() - intrinsics_.cx) / intrinsics_.fx,
                          (pixel.y() - intrinsics_.cy) / intrinsics_.fy);
  return undistort(d);
}

bool CameraModel::pixelToNormalized(const Eigen::Vector2d& pixel,
                                    Eigen::Vector2d* normalized) const {
  const Eigen::Vector2d d((pixel.x() - intrinsics_.cx) / intrinsics_.fx,
                          (pixel.y() - intrinsics_.cy) / intrinsics_.fy);
  return undistort(d, normalized);
}

Eigen::Vector2d CameraModel::undistortPixel(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d n = pixelToNormalized(pixel);
  return Eigen::Vector2d(intrinsics_.fx * n.x() + intrinsics_.cx,
                         intrinsics_.fy * n.y() + intrinsics_.cy);
}

bool CameraModel::undistortPixel(const Eigen::Vector2d& pixel, Eigen::Vector2d* undistorted) const {
  Eigen::Vector2d n;
  if (!pixelToNormalized(pixel, &n)) return false;
  *undistorted = Eigen::Vector2d(intrinsics_.fx * n.x() + intrinsics_.cx,
                                 intrinsics_.fy * n.y() + intrinsics_.cy);
  return true;
}

bool CameraModel::isInImage(const Eigen::Vector2d& pixel, double margin) const {
  return pixel.x() >= margin && pixel.y() >= margin &&
         pixel.x() <= intrinsics_.width - 1 - margin &&
         pixel.y() <= intrinsics_.height - 1 - margin;
}

}  // namespace osc
