// Prediction model (eq. 7-8), process noise (eq. 10-27) and the config table.
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/filter/calibration_filter.h"
#include "online_stereo_calibration/core/filter/process_model.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(ProcessModel, PredictPointKeepsTheWorldPointFixed) {
  // Independent check through a world frame: p_world = T_w_v(k-1) T_v_c p(k-1) must equal
  // T_w_v(k) T_v_c p(k).
  Vector6d cal;
  cal << 1.5, 0.2, 1.3, 0.05, -0.1, 0.2;
  const Eigen::Isometry3d T_veh_lopt = poseFromParameters(cal) * bodyFromOptical();
  Vector6d w0, w1;
  w0 << 10, 5, 0.3, 0.02, -0.03, 0.4;
  w1 << 10.4, 5.1, 0.31, 0.03, -0.01, 0.43;
  const Eigen::Isometry3d T_w_v0 = poseFromParameters(w0), T_w_v1 = poseFromParameters(w1);
  const Eigen::Vector3d p0(1.0, -0.5, 12.0);
  const Eigen::Vector3d p1 = predictPoint(p0, T_veh_lopt, T_w_v0.inverse() * T_w_v1);
  EXPECT_LT((T_w_v0 * T_veh_lopt * p0 - T_w_v1 * T_veh_lopt * p1).norm(), 1e-12);
}

TEST(ProcessModel, PaperPointNoiseMatchesHandComputation) {
  // Point at body (10, -1, 0), i.e. optical (1, 0, 10); sigma = 0.01 rad, sigma_p = 0.1 m.
  // By eq. 16-27 (see the derivation in the test's comment): q_body = (s^2 + sp^2,
  // 100 s^2 + sp^2, 101 s^2 + sp^2) with s = sin(sigma); optical axes x = -y_b, y = -z_b, z = x_b.
  const double sigma = 0.01, sp = 0.1, s2 = std::pow(std::sin(sigma), 2);
  const Eigen::Matrix3d Q = paperPointProcessNoise(Eigen::Vector3d(1, 0, 10), sigma, sp);
  EXPECT_NEAR(Q(0, 0), 100 * s2 + sp * sp, 1e-12);
  EXPECT_NEAR(Q(1, 1), 101 * s2 + sp * sp, 1e-12);
  EXPECT_NEAR(Q(2, 2), s2 + sp * sp, 1e-12);
  EXPECT_NEAR(Q(0, 1), 0.0, 1e-15);
  EXPECT_NEAR(Q(0, 2), 0.0, 1e-15);
}

TEST(ProcessModel, PaperPointNoiseYawErrorMovesOnlyTheHorizontalPlane) {
  // A point straight ahead at height 0 in the body frame: roll sweeps nothing (r_yz = 0) and
  // yaw/pitch move it sideways/up only; along x only sigma_p remains.
  const Eigen::Matrix3d Q = paperPointProcessNoise(Eigen::Vector3d(0, 0, 20), 0.001, 0.0);
  EXPECT_NEAR(Q(2, 2), 0.0, 1e-15);  // optical z = body x
  EXPECT_NEAR(Q(0, 0), std::pow(20 * std::sin(0.001), 2), 1e-12);
}

TEST(ProcessModel, CalibrationDriftIsTheSeedsValuesPerStep) {
  const FilterConfig config = paperFilterConfig();
  const Matrix12d Q = calibrationDriftCovariance(config, 0.1);
  EXPECT_NEAR(std::sqrt(Q(0, 0)), 0.05e-3, 1e-15);          // eq. 10
  EXPECT_NEAR(std::sqrt(Q(3, 3)), 0.005 * kDeg, 1e-15);     // eq. 11
  EXPECT_NEAR(std::sqrt(Q(6, 6)), 0.01e-3, 1e-15);          // eq. 12
  EXPECT_NEAR(std::sqrt(Q(11, 11)), 0.0005 * kDeg, 1e-15);  // eq. 13
  // A random walk: twice the time, twice the variance.
  EXPECT_NEAR(calibrationDriftCovariance(config, 0.2)(0, 0), 2 * Q(0, 0), 1e-20);
}

TEST(FilterConfig, DefaultsAndPaperValuesAreValid) {
  EXPECT_TRUE(FilterConfig().validate().empty());
  EXPECT_TRUE(paperFilterConfig().validate().empty());
  EXPECT_DOUBLE_EQ(paperFilterConfig().point_position_noise, 0.2);  // eq. 14
  EXPECT_NEAR(paperFilterConfig().motion_rotation_noise, 0.02 * kDeg, 1e-15);  // eq. 15
}

TEST(FilterConfig, InvalidValuesAreNamedWithTheirRange) {
  FilterConfig config;
  config.ut_alpha = 5.0;
  config.max_points = 0;
  config.pixel_noise = std::nan("");
  const auto problems = config.validate();
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_NE(problems[0].find("ut_alpha"), std::string::npos);
  EXPECT_NE(problems[0].find("[0.001, 1]"), std::string::npos);
  bool named_pixel = false, named_points = false;
  for (const auto& p : problems) {
    named_pixel |= p.find("pixel_noise_px") != std::string::npos;
    named_points |= p.find("max_points") != std::string::npos;
  }
  EXPECT_TRUE(named_pixel);
  EXPECT_TRUE(named_points);
  try {
    CalibrationFilter filter(config, StereoIntrinsics{});
    FAIL() << "an invalid config must not construct a filter";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ut_alpha"), std::string::npos);
  }
}

TEST(FilterConfig, DepthRangeMustBeOrdered) {
  FilterConfig config;
  config.min_point_depth = 50;
  config.max_point_depth = 40;
  ASSERT_EQ(config.validate().size(), 1u);
  EXPECT_NE(config.validate()[0].find("min_point_depth_m"), std::string::npos);
}

TEST(FilterConfig, TableConvertsFileUnits) {
  FilterConfig config;
  for (const ParameterSpec& spec : filterParameterTable()) {
    if (spec.name == "caml_rotation_drift_deg") {
      spec.set(&config, 0.5);
      EXPECT_NEAR(config.caml_rotation_drift, 0.5 * kDeg, 1e-15);
      EXPECT_NEAR(spec.get(config), 0.5, 1e-12);
    }
  }
  // Every name is unique and carries a doc line.
  std::set<std::string> names;
  for (const ParameterSpec& spec : filterParameterTable()) {
    EXPECT_TRUE(names.insert(spec.name).second) << spec.name;
    EXPECT_FALSE(spec.doc.empty()) << spec.name;
  }
  EXPECT_THROW(motionNoiseModelFromName("independent"), std::invalid_argument);
  EXPECT_EQ(motionNoiseModelFromName("per_point"), MotionNoiseModel::kPerPoint);
}

}  // namespace
}  // namespace osc
