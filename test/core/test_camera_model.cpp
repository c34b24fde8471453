// Independent unit tests of camera_model.h: projection, distortion and undistortion of the
// plumb_bob, rational-polynomial and equidistant models, the lens Jacobian and noise, and the
// checks of the intrinsics.
//
// Every expected value comes from a source other than the code under test: OpenCV
// (projectPoints, fisheye::projectPoints, undistortPoints), closed forms derived in the
// comments, or the Kannala-Brandt polynomial written out.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "geometry_test_support.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"

namespace osc {
namespace {

/// EuRoC MAV cam0 (radial-tangential, strong barrel distortion).
CameraIntrinsics eurocCam0() {
  CameraIntrinsics in;
  in.width = 752;
  in.height = 480;
  in.fx = 458.654;
  in.fy = 457.296;
  in.cx = 367.215;
  in.cy = 248.375;
  in.model = DistortionModel::kPlumbBob;
  in.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  return in;
}

/// plumb_bob with the optional fifth coefficient k3 (positive: r_d(r) stays monotonic, so every
/// pixel has an undistorted preimage).
CameraIntrinsics plumbBobWithK3() {
  CameraIntrinsics in = eurocCam0();
  in.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0.0121};
  return in;
}

/// A wide lens with the 8-coefficient rational model (values like an OpenCV calibration).
CameraIntrinsics rationalCamera() {
  CameraIntrinsics in;
  in.width = 1280;
  in.height = 720;
  in.fx = 700.2;
  in.fy = 701.9;
  in.cx = 641.3;
  in.cy = 358.9;
  in.model = DistortionModel::kRationalPolynomial;
  in.distortion = {0.82, -0.051, 0.0006, -0.0004, 0.013, 1.13, 0.11, 0.021};
  return in;
}

/// A fisheye (equidistant / Kannala-Brandt).
CameraIntrinsics fisheyeCamera() {
  CameraIntrinsics in;
  in.width = 752;
  in.height = 480;
  in.fx = 380.0;
  in.fy = 380.0;
  in.cx = 376.5;
  in.cy = 239.5;
  in.model = DistortionModel::kEquidistant;
  in.distortion = {-0.01, 0.002, -0.001, 0.0002};
  return in;
}

cv::Mat cvK(const CameraIntrinsics& in) {
  return (cv::Mat_<double>(3, 3) << in.fx, 0, in.cx, 0, in.fy, in.cy, 0, 0, 1);
}

cv::Mat cvD(const CameraIntrinsics& in) { return cv::Mat(in.distortion, true).reshape(1, 1); }

/// OpenCV's projection of optical-frame points (identity pose).
std::vector<Eigen::Vector2d> openCvProject(const CameraIntrinsics& in,
                                           const std::vector<Eigen::Vector3d>& points) {
  std::vector<cv::Point3d> object;
  for (const auto& p : points) object.emplace_back(p.x(), p.y(), p.z());
  std::vector<cv::Point2d> image;
  const cv::Mat rvec = cv::Mat::zeros(3, 1, CV_64F), tvec = cv::Mat::zeros(3, 1, CV_64F);
  if (in.model == DistortionModel::kEquidistant) {
    cv::fisheye::projectPoints(object, image, rvec, tvec, cvK(in), cvD(in));
  } else {
    cv::projectPoints(object, rvec, tvec, cvK(in), cvD(in), image);
  }
  std::vector<Eigen::Vector2d> out;
  for (const auto& q : image) out.emplace_back(q.x, q.y);
  return out;
}

/// OpenCV's undistortion to undistorted pixels (P = K), iterated to convergence.
std::vector<Eigen::Vector2d> openCvUndistortPixels(const CameraIntrinsics& in,
                                                   const std::vector<Eigen::Vector2d>& pixels) {
  std::vector<cv::Point2d> src, dst;
  for (const auto& p : pixels) src.emplace_back(p.x(), p.y());
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 500, 1e-12);
  if (in.model == DistortionModel::kEquidistant) {
    cv::fisheye::undistortPoints(src, dst, cvK(in), cvD(in), cv::Mat::eye(3, 3, CV_64F), cvK(in),
                                 criteria);
  } else {
    cv::undistortPoints(src, dst, cvK(in), cvD(in), cv::noArray(), cvK(in), criteria);
  }
  std::vector<Eigen::Vector2d> out;
  for (const auto& q : dst) out.emplace_back(q.x, q.y);
  return out;
}

/// Points in front of the camera on a grid of viewing directions (normalized coordinates within
/// +-max_x, +-max_y) and several depths.
std::vector<Eigen::Vector3d> pointGrid(double max_x, double max_y) {
  std::vector<Eigen::Vector3d> points;
  for (double z : {0.3, 2.0, 17.0}) {
    for (int i = -10; i <= 10; ++i) {
      for (int j = -10; j <= 10; ++j) {
        points.emplace_back(max_x * i / 10.0 * z, max_y * j / 10.0 * z, z);
      }
    }
  }
  return points;
}

/// Every step-th pixel of the image, including the last row and column.
std::vector<Eigen::Vector2d> pixelGrid(const CameraIntrinsics& in, int step) {
  std::vector<Eigen::Vector2d> pixels;
  std::vector<double> us, vs;
  for (int u = 0; u < in.width; u += step) us.push_back(u);
  for (int v = 0; v < in.height; v += step) vs.push_back(v);
  us.push_back(in.width - 1);
  vs.push_back(in.height - 1);
  for (double u : us) {
    for (double v : vs) pixels.emplace_back(u + 0.25, v + 0.25);
  }
  for (double u : us) pixels.emplace_back(u, in.height - 1);  // exact border pixels
  for (double v : vs) pixels.emplace_back(0.0, v);
  return pixels;
}

void expectProjectionMatchesOpenCv(const CameraIntrinsics& in, double max_x, double max_y) {
  const CameraModel camera(in);
  const auto points = pointGrid(max_x, max_y);
  const auto expected = openCvProject(in, points);
  ASSERT_EQ(expected.size(), points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(camera.project(points[i], &pixel));
    EXPECT_NEAR(pixel.x(), expected[i].x(), 1e-6) << points[i].transpose();
    EXPECT_NEAR(pixel.y(), expected[i].y(), 1e-6) << points[i].transpose();
  }
}

void expectPixelRoundTrip(const CameraIntrinsics& in) {
  const CameraModel camera(in);
  for (const Eigen::Vector2d& pixel : pixelGrid(in, 4)) {
    const Eigen::Vector2d normalized = camera.pixelToNormalized(pixel);
    ASSERT_TRUE(normalized.allFinite()) << pixel.transpose();
    EXPECT_TRUE(matrixNear(camera.normalizedToPixel(normalized), pixel, 1e-6))
        << "pixel " << pixel.transpose();
    // The same through project() of a 3D point on the ray.
    Eigen::Vector2d projected;
    ASSERT_TRUE(camera.project(4.2 * normalized.homogeneous(), &projected));
    EXPECT_TRUE(matrixNear(projected, pixel, 1e-6)) << "pixel " << pixel.transpose();
    // undistortPixel is K * normalized.
    EXPECT_TRUE(matrixNear(
        camera.undistortPixel(pixel),
        Eigen::Vector2d(in.fx * normalized.x() + in.cx, in.fy * normalized.y() + in.cy), 1e-9));
  }
}

void expectUndistortPixelMatchesOpenCv(const CameraIntrinsics& in) {
  const CameraModel camera(in);
  const auto pixels = pixelGrid(in, 16);
  const auto expected = openCvUndistortPixels(in, pixels);
  ASSERT_EQ(expected.size(), pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i) {
    EXPECT_TRUE(matrixNear(camera.undistortPixel(pixels[i]), expected[i], 1e-3))
        << "pixel " << pixels[i].transpose();
  }
}

TEST(CameraModel, PlumbBobProjectionMatchesOpenCv) {
  expectProjectionMatchesOpenCv(eurocCam0(), 1.1, 0.75);       // 4 coefficients
  expectProjectionMatchesOpenCv(plumbBobWithK3(), 1.1, 0.75);  // 5 coefficients
}

TEST(CameraModel, RationalPolynomialProjectionMatchesOpenCv) {
  expectProjectionMatchesOpenCv(rationalCamera(), 1.2, 0.7);
}

TEST(CameraModel, EquidistantProjectionMatchesOpenCvFisheye) {
  expectProjectionMatchesOpenCv(fisheyeCamera(), 2.5, 1.5);
}

TEST(CameraModel, ProjectRejectsPointsNotInFront) {
  const CameraModel camera(eurocCam0());
  const Eigen::Vector2d sentinel(-7, -7);
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.1, 0.2, 0.0), Eigen::Vector3d(1, 1, -3), Eigen::Vector3d(0, 0, 1e-9)}) {
    Eigen::Vector2d pixel = sentinel;
    EXPECT_FALSE(camera.project(p, &pixel)) << p.transpose();
    EXPECT_EQ(pixel, sentinel);
  }
}

TEST(CameraModel, PlumbBobPixelRoundTripAcrossTheImage) {
  expectPixelRoundTrip(eurocCam0());
  expectPixelRoundTrip(plumbBobWithK3());
}

TEST(CameraModel, RationalPolynomialPixelRoundTripAcrossTheImage) {
  expectPixelRoundTrip(rationalCamera());
}

TEST(CameraModel, EquidistantPixelRoundTripAcrossTheImage) {
  expectPixelRoundTrip(fisheyeCamera());
}

TEST(CameraModel, UndistortPixelMatchesOpenCvUndistortPoints) {
  expectUndistortPixelMatchesOpenCv(eurocCam0());
  expectUndistortPixelMatchesOpenCv(plumbBobWithK3());
  expectUndistortPixelMatchesOpenCv(rationalCamera());
  expectUndistortPixelMatchesOpenCv(fisheyeCamera());
}

TEST(CameraModel, DistortAndUndistortAreInverseOnNormalizedCoordinates) {
  // The fisheye corner reaches theta ~ 68 deg; sample the normalized plane inside that.
  for (const CameraIntrinsics& in : {eurocCam0(), rationalCamera(), fisheyeCamera()}) {
    const CameraModel camera(in);
    for (int i = -10; i <= 10; ++i) {
      for (int j = -10; j <= 10; ++j) {
        const Eigen::Vector2d n(1.0 * i / 10.0, 0.6 * j / 10.0);
        EXPECT_TRUE(matrixNear(camera.undistort(camera.distort(n)), n, 1e-10))
            << distortionModelName(in.model) << " " << n.transpose();
      }
    }
    EXPECT_TRUE(matrixNear(camera.distort(Eigen::Vector2d::Zero()), Eigen::Vector2d::Zero(), 0.0));
  }
}

// A strong barrel polynomial (plumb_bob k1 = -0.28 alone) turns back at r = 1 / sqrt(3 * 0.28)
// = 1.09, where the distorted radius peaks at 0.727: pixels beyond that radius have no ray,
// and inside it the ray must be the one on the optical axis' side of the fold.
TEST(CameraModel, UndistortStaysOnTheUnfoldedBranchAndRejectsUnreachablePixels) {
  CameraIntrinsics in;
  in.width = 752;
  in.height = 480;
  in.fx = in.fy = 460.0;
  in.cx = 376.0;
  in.cy = 240.0;
  in.model = DistortionModel::kPlumbBob;
  in.distortion = {-0.28, 0.0, 0.0, 0.0, 0.0};
  const CameraModel camera(in);
  const double fold_radius = 1.0 / std::sqrt(3.0 * 0.28);
  const double peak = fold_radius * (1.0 - 0.28 * fold_radius * fold_radius);
  const Eigen::Vector2d direction = Eigen::Vector2d(376.0, 240.0).normalized();
  for (double rd : {0.2, 0.5, 0.7, 0.99 * peak}) {
    Eigen::Vector2d n;
    ASSERT_TRUE(camera.undistort(rd * direction, &n)) << rd;
    EXPECT_LT(n.norm(), fold_radius) << rd;  // the axis-side branch, not the folded one
    EXPECT_TRUE(matrixNear(camera.distort(n), rd * direction, 1e-9)) << rd;
  }
  // The image corner (distorted radius 0.97) is beyond the peak: no ray, nothing written.
  Eigen::Vector2d untouched(7.0, 7.0);
  EXPECT_FALSE(camera.pixelToNormalized(Eigen::Vector2d(0.0, 0.0), &untouched));
  EXPECT_EQ(untouched, Eigen::Vector2d(7.0, 7.0));
  EXPECT_FALSE(camera.undistort(1.01 * peak * direction, &untouched));
  // The best-effort form returns its input there instead of a folded ray.
  EXPECT_EQ(camera.undistort(1.01 * peak * direction), 1.01 * peak * direction);
  // Non-finite input is rejected, not iterated.
  EXPECT_FALSE(camera.undistort(Eigen::Vector2d(std::nan(""), 0.0), &untouched));
  // Equidistant: a distorted angle past 90 deg has no ray in front of the camera.
  CameraIntrinsics fisheye = in;
  fisheye.model = DistortionModel::kEquidistant;
  fisheye.distortion = {0.001, 0.0, 0.0, 0.0};  // (all zero would be a plain pinhole)
  const CameraModel equidistant(fisheye);
  EXPECT_TRUE(equidistant.undistort(Eigen::Vector2d(1.2, 0.0), &untouched));
  EXPECT_GT(untouched.x(), std::tan(1.19));
  EXPECT_TRUE(matrixNear(equidistant.distort(untouched), Eigen::Vector2d(1.2, 0.0), 1e-9));
  EXPECT_FALSE(equidistant.undistort(Eigen::Vector2d(1.7, 0.0), &untouched));
}

TEST(CameraModel, UndistortedPixelNoiseIsTheRawNoiseStretchedByTheLens) {
  // Without distortion an undistorted pixel is the raw one: the same variance, exactly.
  CameraIntrinsics pinhole = fisheyeCamera();
  pinhole.model = DistortionModel::kNone;
  pinhole.distortion.clear();
  EXPECT_EQ(CameraModel(pinhole).undistortedPixelVariance(Eigen::Vector2d(700.0, 20.0), 0.5), 0.25);
  // A fisheye 50 deg off its axis: r_u = f tan(theta) against r_d ~ f theta, so a raw pixel's
  // noise is stretched by 1 / cos^2(theta) = 2.4 radially (tan(theta) / theta = 1.4
  // tangentially); the variance takes the larger stretch.
  const CameraModel fisheye(fisheyeCamera());
  const double theta = 50.0 * M_PI / 180.0;
  const Eigen::Vector2d undistorted(376.5 + 380.0 * std::tan(theta), 239.5);
  const double radial = (1.0 / std::pow(std::cos(theta), 2)) * 0.5;
  EXPECT_NEAR(fisheye.undistortedPixelVariance(undistorted, 0.5), radial * radial,
              0.1 * radial * radial);  // the lens's small k1..k4 change it by a few percent
  // At the centre the lens barely stretches.
  EXPECT_NEAR(fisheye.undistortedPixelVariance(Eigen::Vector2d(376.5, 239.5), 0.5), 0.25, 0.01);
}

TEST(CameraModel, EquidistantDistortionIsTheKannalaBrandtPolynomial) {
  // theta = atan(r), theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8),
  // distorted = normalized * theta_d / r.
  const CameraIntrinsics in = fisheyeCamera();
  const CameraModel camera(in);
  const Eigen::Vector2d n(0.7, -0.4);
  const double r = n.norm(), t = std::atan(r);
  const double theta_d = t + in.distortion[0] * std::pow(t, 3) + in.distortion[1] * std::pow(t, 5) +
                         in.distortion[2] * std::pow(t, 7) + in.distortion[3] * std::pow(t, 9);
  EXPECT_TRUE(matrixNear(camera.distort(n), n * theta_d / r, 1e-15));
}

TEST(CameraModel, LensJacobianIsTheEquidistantLensStretch) {
  // A pure equidistant lens (r_raw = f theta, r_pinhole = f tan theta): offsets along the
  // radius shrink by d theta / d tan theta = cos^2 theta, across it by theta / tan theta.
  CameraIntrinsics in = fisheyeCamera();
  in.distortion = {1e-12, 0.0, 0.0, 0.0};  // all zero would be a plain pinhole
  const CameraModel camera(in);
  const double n = 0.5, theta = std::atan(n);
  const double radial = 1.0 / (1.0 + n * n), across = theta / n;
  const Eigen::Matrix2d on_x = camera.lensJacobian(Eigen::Vector2d(in.cx + in.fx * n, in.cy));
  const Eigen::Matrix2d on_y = camera.lensJacobian(Eigen::Vector2d(in.cx, in.cy - in.fy * n));
  EXPECT_TRUE(matrixNear(on_x, Eigen::Vector2d(radial, across).asDiagonal().toDenseMatrix(), 1e-4))
      << on_x;
  EXPECT_TRUE(matrixNear(on_y, Eigen::Vector2d(across, radial).asDiagonal().toDenseMatrix(), 1e-4))
      << on_y;
  // Any lens: the Jacobian predicts where a small offset lands in the raw image.
  const CameraModel euroc(eurocCam0());
  const Eigen::Vector2d u(600.0, 50.0), du(0.3, -0.2);
  const auto toRaw = [&](const Eigen::Vector2d& x) {
    const CameraIntrinsics& k = euroc.intrinsics();
    return euroc.normalizedToPixel(Eigen::Vector2d((x.x() - k.cx) / k.fx, (x.y() - k.cy) / k.fy));
  };
  EXPECT_TRUE(matrixNear(toRaw(u + du) - toRaw(u), euroc.lensJacobian(u) * du, 1e-3));
  // Without distortion it is exactly the identity.
  CameraIntrinsics none = in;
  none.distortion = {0.0, 0.0, 0.0, 0.0};
  EXPECT_TRUE(matrixNear(CameraModel(none).lensJacobian(u), Eigen::Matrix2d::Identity(), 0.0));
}

std::string constructionError(const CameraIntrinsics& in) {
  try {
    CameraModel camera(in);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

void expectRejectedNaming(const CameraIntrinsics& in, const std::string& field) {
  EXPECT_THROW(CameraModel{in}, std::invalid_argument) << field;
  const std::string message = constructionError(in);
  EXPECT_NE(message.find(field), std::string::npos)
      << "message '" << message << "' lacks '" << field << "'";
}

TEST(CameraModel, InvalidIntrinsicsThrowNamingTheField) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto with = [](const std::function<void(CameraIntrinsics&)>& change) {
    CameraIntrinsics in = eurocCam0();
    change(in);
    return in;
  };
  expectRejectedNaming(with([](CameraIntrinsics& in) { in.fx = 0.0; }), "fx");
  expectRejectedNaming(with([](CameraIntrinsics& in) { in.fx = -458.0; }), "fx");
  expectRejectedNaming(with([&](CameraIntrinsics& in) { in.fx = inf; }), "fx");
  expectRejectedNaming(with([](CameraIntrinsics& in) { in.fy = -1.0; }), "fy");
  expectRejectedNaming(with([&](CameraIntrinsics& in) { in.fy = nan; }), "fy");
  expectRejectedNaming(with([&](CameraIntrinsics& in) { in.cx = nan; }), "cx");
  expectRejectedNaming(with([&](CameraIntrinsics& in) { in.cy = inf; }), "cy");
  expectRejectedNaming(with([](CameraIntrinsics& in) { in.width = 0; }), "size");
  expectRejectedNaming(with([](CameraIntrinsics& in) { in.height = -480; }), "size");
  expectRejectedNaming(with([&](CameraIntrinsics& in) { in.distortion[1] = nan; }), "(D)");
  // Wrong number of coefficients for the model.
  expectRejectedNaming(with([](CameraIntrinsics& in) {
                         in.distortion = {-0.28, 0.07, 0.0};
                       }),
                       "(D)");
  expectRejectedNaming(with([](CameraIntrinsics& in) { in.distortion.resize(8, 0.01); }), "(D)");
  expectRejectedNaming(with([](CameraIntrinsics& in) { in.distortion.clear(); }), "(D)");
  expectRejectedNaming(with([](CameraIntrinsics& in) {
                         in.model = DistortionModel::kEquidistant;
                         in.distortion = {-0.01, 0.002, -0.001, 0.0002, 0.0001};
                       }),
                       "(D)");
  expectRejectedNaming(with([](CameraIntrinsics& in) {
                         in.model = DistortionModel::kEquidistant;
                         in.distortion = {-0.01, 0.002, -0.001};
                       }),
                       "(D)");
  expectRejectedNaming(with([](CameraIntrinsics& in) {
                         in.model = DistortionModel::kRationalPolynomial;
                         in.distortion = std::vector<double>(9, 0.01);
                       }),
                       "(D)");
  expectRejectedNaming(with([](CameraIntrinsics& in) {
                         in.model = DistortionModel::kRationalPolynomial;
                         in.distortion = {0.1, 0.01};
                       }),
                       "(D)");
  // The valid base case does not throw.
  EXPECT_NO_THROW(CameraModel{eurocCam0()});
}

TEST(CameraModel, DistortionModelNamesParseAndRejectUnknownNames) {
  EXPECT_EQ(distortionModelFromName("plumb_bob"), DistortionModel::kPlumbBob);
  EXPECT_EQ(distortionModelFromName("rational_polynomial"), DistortionModel::kRationalPolynomial);
  EXPECT_EQ(distortionModelFromName("equidistant"), DistortionModel::kEquidistant);
  EXPECT_EQ(distortionModelFromName(""), DistortionModel::kNone);
  EXPECT_EQ(distortionModelFromName("none"), DistortionModel::kNone);
  for (DistortionModel m : {DistortionModel::kNone, DistortionModel::kPlumbBob,
                            DistortionModel::kRationalPolynomial, DistortionModel::kEquidistant}) {
    EXPECT_EQ(distortionModelFromName(distortionModelName(m)), m);
  }
  for (const std::string bad : {"fisheye", "Plumb_Bob", "radtan", "kannala_brandt", "plumb_bob "}) {
    try {
      distortionModelFromName(bad);
      ADD_FAILURE() << "'" << bad << "' was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST(CameraModel, AllZeroDistortionIsAPlainPinhole) {
  // image_geometry's convention: all-zero D means no distortion, whatever the model name.
  for (const CameraIntrinsics& base : {eurocCam0(), rationalCamera(), fisheyeCamera()}) {
    CameraIntrinsics in = base;
    std::fill(in.distortion.begin(), in.distortion.end(), 0.0);
    const CameraModel camera(in);
    const Eigen::Vector3d p(1.3, -0.8, 2.1);
    Eigen::Vector2d pixel;
    ASSERT_TRUE(camera.project(p, &pixel));
    const Eigen::Vector2d pinhole(in.fx * p.x() / p.z() + in.cx, in.fy * p.y() / p.z() + in.cy);
    EXPECT_TRUE(matrixNear(pixel, pinhole, 1e-12)) << distortionModelName(base.model);
    EXPECT_TRUE(matrixNear(camera.pixelToNormalized(pinhole),
                           Eigen::Vector2d(p.x() / p.z(), p.y() / p.z()), 1e-14));
    EXPECT_TRUE(matrixNear(camera.undistortPixel(Eigen::Vector2d(10.5, 400.25)),
                           Eigen::Vector2d(10.5, 400.25), 1e-12));
  }
  // model "none" likewise, and K() is the documented matrix.
  CameraIntrinsics none = eurocCam0();
  none.model = DistortionModel::kNone;
  none.distortion.clear();
  const CameraModel camera(none);
  Eigen::Matrix3d K;
  K << none.fx, 0, none.cx, 0, none.fy, none.cy, 0, 0, 1;
  EXPECT_TRUE(matrixNear(camera.K(), K, 0.0));
  EXPECT_TRUE(
      matrixNear(camera.distort(Eigen::Vector2d(0.4, -0.3)), Eigen::Vector2d(0.4, -0.3), 0.0));
}

TEST(CameraModel, IsInImageHonoursTheBordersAndTheMargin) {
  const CameraModel camera(eurocCam0());  // 752 x 480
  EXPECT_TRUE(camera.isInImage(Eigen::Vector2d(0, 0)));
  EXPECT_TRUE(camera.isInImage(Eigen::Vector2d(751, 479)));
  EXPECT_TRUE(camera.isInImage(Eigen::Vector2d(376, 240)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(-0.01, 240)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(376, -0.01)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(752, 240)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(376, 480)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(-1e6, 1e6)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(std::nan(""), 240)));
  // With a 10 px margin.
  EXPECT_TRUE(camera.isInImage(Eigen::Vector2d(10, 10), 10));
  EXPECT_TRUE(camera.isInImage(Eigen::Vector2d(741, 469), 10));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(9.9, 240), 10));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(376, 9.9), 10));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(741.1, 240), 10));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(376, 469.1), 10));
}

}  // namespace
}  // namespace osc
