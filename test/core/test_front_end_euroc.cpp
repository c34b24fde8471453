/// @file test_front_end_euroc.cpp
/// @brief The image front end on real images, EuRoC V1_01_easy (752x480, plumb_bob) with their
/// reference calibration: epipolar-guided matching, and the global stereo fit recovering the
/// rig without a calibration. Skipped without ../shared/data/euroc_v101_micro.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "front_end_test_support.h"
#include "online_stereo_calibration/core/frontend/feature_detection.h"
#include "online_stereo_calibration/core/frontend/global_stereo_fit.h"
#include "online_stereo_calibration/core/frontend/stereo_front_end.h"
#include "online_stereo_calibration/core/geometry/stereo_geometry.h"
#include "online_stereo_calibration/tools/kitti_sequence.h"

namespace osc {
namespace {

const std::string kEurocDir = std::string(OSC_SOURCE_DIR) + "/../shared/data/euroc_v101_micro";

struct EurocCamera {
  CameraIntrinsics intrinsics;
  Eigen::Isometry3d T_body_sensor = Eigen::Isometry3d::Identity();
};

EurocCamera readEurocCamera(const std::string& file) {
  cv::FileStorage fs(file, cv::FileStorage::READ);
  EurocCamera c;
  std::vector<double> k, d, t;
  std::vector<int> res;
  fs["intrinsics"] >> k;
  fs["distortion_coefficients"] >> d;
  fs["resolution"] >> res;
  fs["T_BS"]["data"] >> t;
  c.intrinsics.width = res.at(0);
  c.intrinsics.height = res.at(1);
  c.intrinsics.fx = k.at(0);
  c.intrinsics.fy = k.at(1);
  c.intrinsics.cx = k.at(2);
  c.intrinsics.cy = k.at(3);
  c.intrinsics.model = DistortionModel::kPlumbBob;
  c.intrinsics.distortion = {d.at(0), d.at(1), d.at(2), d.at(3), 0.0};
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = t.at(static_cast<size_t>(i));
  c.T_body_sensor.matrix() = m;
  return c;
}

TEST(FrontEndEuroc, EpipolarGuidedMatchingOnRealImages) {
  if (!std::ifstream(kEurocDir + "/cam0/sensor.yaml").good()) {
    GTEST_SKIP() << "EuRoC data not found at " << kEurocDir;
  }
  const EurocCamera cam0 = readEurocCamera(kEurocDir + "/cam0/sensor.yaml");
  const EurocCamera cam1 = readEurocCamera(kEurocDir + "/cam1/sensor.yaml");
  const Eigen::Isometry3d T_lopt_ropt = cam0.T_body_sensor.inverse() * cam1.T_body_sensor;
  StereoExtrinsics reference;
  reference.T_caml_camr = bodyFromOptical() * T_lopt_ropt * bodyFromOptical().inverse();
  ASSERT_TRUE(reference.leftToRightOptical().isApprox(T_lopt_ropt, 1e-9));
  EXPECT_NEAR(T_lopt_ropt.translation().norm(), 0.110, 0.002);

  // The reference calibration, with a small uncertainty.
  Matrix12d P = Matrix12d::Zero();
  P.diagonal() << Eigen::Vector3d::Constant(0.01 * 0.01), Eigen::Vector3d::Constant(1e-4),
      Eigen::Vector3d::Constant(1e-6), Eigen::Vector3d::Constant(std::pow(0.05 * kDeg, 2));
  CalibrationPipeline pipeline(FilterConfig(), FrontEndConfig(), cam0.intrinsics, cam1.intrinsics,
                               reference);
  const CameraModel left(cam0.intrinsics), right(cam1.intrinsics);
  const Eigen::Matrix3d F = fundamentalMatrix(left.K(), right.K(), T_lopt_ropt);
  const std::vector<std::string> left_files = sortedPngs(kEurocDir + "/cam0");
  const std::vector<std::string> right_files = sortedPngs(kEurocDir + "/cam1");
  ASSERT_EQ(left_files.size(), right_files.size());
  ASSERT_GE(left_files.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    pipeline.reset(reference, P);
    const cv::Mat l = cv::imread(left_files[i * left_files.size() / 4], cv::IMREAD_UNCHANGED);
    const cv::Mat r = cv::imread(right_files[i * left_files.size() / 4], cv::IMREAD_UNCHANGED);
    const PipelineResult result = pipeline.process(l, r, MotionIncrement());
    ASSERT_TRUE(result.processed) << result.status;
    const std::vector<StereoObservation>& matches = pipeline.frontEnd().lastStereoMatches();
    std::vector<double> sampson, depth;
    for (const StereoObservation& m : matches) {
      const Eigen::Vector2d ul = left.undistortPixel(m.left_pixel);
      const Eigen::Vector2d ur = right.undistortPixel(m.right_pixel);
      sampson.push_back(sampsonDistance(F, ul, ur) / std::sqrt(2.0));
      const auto tri = triangulateMidpoint(left.K().inverse() * ul.homogeneous(),
                                           right.K().inverse() * ur.homogeneous(), T_lopt_ropt);
      depth.push_back(tri ? tri->point_left.z() : -1.0);
    }
    ASSERT_GE(matches.size(), 200u);
    std::nth_element(sampson.begin(), sampson.begin() + sampson.size() / 2, sampson.end());
    const double median_sampson = sampson[sampson.size() / 2];
    const long plausible =
        std::count_if(depth.begin(), depth.end(), [](double z) { return z >= 1.0 && z <= 15.0; });
    std::printf("  pair %zu: %zu matches, median Sampson %.3f px, %.1f %% depths in 1-15 m\n", i,
                matches.size(), median_sampson, 100.0 * plausible / matches.size());
    EXPECT_LE(median_sampson, 0.3);
    EXPECT_GE(plausible, 0.95 * matches.size());
  }
}

// Issue 14: the rig's rotation and baseline direction from the images alone. On the EuRoC
// pairs the fit agrees with the reference calibration within 0.1 deg and within 4 of its own
// sigmas; two unrelated images give no valid fit (no false evidence of a knock).
TEST(GlobalStereoFit, RecoversTheRigOfRealEurocPairsWithoutACalibration) {
  if (!std::ifstream(kEurocDir + "/cam0/sensor.yaml").good()) {
    GTEST_SKIP() << "EuRoC data not found at " << kEurocDir;
  }
  const EurocCamera cam0 = readEurocCamera(kEurocDir + "/cam0/sensor.yaml");
  const EurocCamera cam1 = readEurocCamera(kEurocDir + "/cam1/sensor.yaml");
  const Eigen::Isometry3d T_lopt_ropt = cam0.T_body_sensor.inverse() * cam1.T_body_sensor;
  const CameraModel left(cam0.intrinsics), right(cam1.intrinsics);
  const FeatureDetector detector{FrontEndConfig()};
  const std::vector<std::string> left_files = sortedPngs(kEurocDir + "/cam0");
  const std::vector<std::string> right_files = sortedPngs(kEurocDir + "/cam1");
  ASSERT_GE(left_files.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    const size_t k = i * left_files.size() / 4;
    const FeatureSet l = detector.detect(cv::imread(left_files[k], cv::IMREAD_GRAYSCALE), left);
    const FeatureSet r = detector.detect(cv::imread(right_files[k], cv::IMREAD_GRAYSCALE), right);
    // The baseline direction a user would assume: along the left camera's x axis.
    const GlobalStereoFit fit = fitStereoGeometry(l, r, left, right, Eigen::Vector3d::UnitX());
    ASSERT_TRUE(fit.valid) << fit.why;
    const double angle = rotationAngleBetween(fit.R_lopt_ropt, T_lopt_ropt.linear());
    const double sigma = std::sqrt(fit.rotation_covariance.eigenvalues().real().maxCoeff());
    const double free_direction = std::acos(
        std::min(1.0, fit.free_baseline_direction.dot(T_lopt_ropt.translation().normalized())));
    std::printf(
        "  pair %zu: %s; rotation off by %.4f deg (sigma %.4f); the free five-point solution's "
        "baseline direction %.1f deg off\n",
        i, fit.why.c_str(), angle / kDeg, sigma / kDeg, free_direction / kDeg);
    EXPECT_LT(angle, 0.1 * kDeg);
    EXPECT_LT(angle, 4.0 * sigma);
  }
  // Unrelated content in the two images (independent random textures): no valid fit.
  cv::Mat noise_left(480, 752, CV_8UC1), noise_right(480, 752, CV_8UC1);
  cv::RNG rng(5);
  rng.fill(noise_left, cv::RNG::UNIFORM, 0, 255);
  rng.fill(noise_right, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(noise_left, noise_left, cv::Size(3, 3), 0);
  cv::GaussianBlur(noise_right, noise_right, cv::Size(3, 3), 0);
  const GlobalStereoFit none =
      fitStereoGeometry(detector.detect(noise_left, left), detector.detect(noise_right, right),
                        left, right, Eigen::Vector3d::UnitX());
  EXPECT_FALSE(none.valid) << none.why;
}

}  // namespace
}  // namespace osc
