// Prediction model (eq. 7-8), process noise (eq. 10-27) and the config table.
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/filter/calibration_filter.h"
#include "online_stereo_calibration/core/filter/motion_excitation.h"
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

TEST(ProcessModel, CameraPositionErrorActsThroughTheExcitedRotation) {
  Vector6d cal;
  cal << 1.5, 0.2, 1.3, 0.05, -0.1, 0.2;
  const Eigen::Isometry3d T_veh_lopt = poseFromParameters(cal) * bodyFromOptical();
  Vector6d m;
  m << 0.4, 0.1, 0.01, 0.02, -0.03, 0.05;
  const Eigen::Isometry3d motion = poseFromParameters(m);
  const Eigen::Vector3d p(1.0, -0.5, 12.0), dt(0.03, -0.02, 0.05);
  Eigen::Isometry3d shifted = T_veh_lopt;
  shifted.translation() += dt;
  // With the measured rotation as the excited one: the plain eq. 7-8.
  EXPECT_LT(
      (predictPoint(p, shifted, motion, dt, motion.linear()) - predictPoint(p, shifted, motion))
          .norm(),
      1e-12);
  // With no excited rotation a camera-position error changes nothing (eq. 8: it enters
  // only through R_motion^T - I).
  EXPECT_LT((predictPoint(p, shifted, motion, dt, Eigen::Matrix3d::Identity()) -
             predictPoint(p, T_veh_lopt, motion))
                .norm(),
            1e-12);
  // In between: exactly the lever-arm term of the excited rotation, by hand.
  const Eigen::Matrix3d R_half = expSO3(0.5 * logSO3(motion.linear()));
  const Eigen::Vector3d expected =
      predictPoint(p, T_veh_lopt, motion) +
      T_veh_lopt.linear().transpose() * (R_half.transpose() - Eigen::Matrix3d::Identity()) * dt;
  EXPECT_LT((predictPoint(p, shifted, motion, dt, R_half) - expected).norm(), 1e-12);
}

// Rotation indistinguishable from the motion sensor's noise is not excitation; strong
// rotation is used as measured (motion_excitation.h).
TEST(MotionExcitation, NoiseIsNotExcitationButRealRotationIs) {
  FilterConfig config;  // sigma 0.02 deg per 0.1 s, window 5 s
  MotionExcitation excitation(config);
  std::srand(7);
  const auto gaussian = [] {
    double u = (std::rand() + 1.0) / (RAND_MAX + 2.0), v = (std::rand() + 1.0) / (RAND_MAX + 2.0);
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * M_PI * v);
  };
  const double sigma = config.motion_rotation_noise;
  for (int k = 0; k < 300; ++k) {
    // Flat road: roll and pitch are sensor noise only; yaw is a steady 5 deg/s turn.
    const Eigen::Vector3d rotation(sigma * gaussian(), sigma * gaussian(),
                                   0.5 * kDeg + sigma * gaussian());
    excitation.update(expSO3(rotation), 0.1);
  }
  const Eigen::Vector3d gains = excitation.gains();
  EXPECT_LT(gains(0), 0.5);
  EXPECT_LT(gains(1), 0.5);
  EXPECT_GT(gains(2), 0.99);
  // The excited rotation keeps the yaw and drops (most of) the noise roll.
  const Eigen::Vector3d measured(2.0 * sigma, 0.0, 0.5 * kDeg);
  const Eigen::Vector3d excited = logSO3(excitation.excitedRotation(expSO3(measured)));
  EXPECT_LT(std::abs(excited(0)), sigma);
  EXPECT_NEAR(excited(2), 0.5 * kDeg, 0.01 * kDeg);
  // Off-road: roll of a few degrees per second is excitation.
  for (int k = 0; k < 300; ++k) {
    excitation.update(expSO3(Eigen::Vector3d(0.5 * kDeg * std::sin(0.2 * k), 0.0, 0.0)), 0.1);
  }
  EXPECT_GT(excitation.gains()(0), 0.98);
  // Disabled (the paper): everything is used as measured.
  config.motion_excitation_window = 0.0;
  const MotionExcitation off(config);
  EXPECT_EQ(off.gains(), Eigen::Vector3d::Ones());
  EXPECT_LT((off.excitedRotation(expSO3(measured)) - expSO3(measured)).norm(), 1e-15);
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
  EXPECT_DOUBLE_EQ(paperFilterConfig().point_position_noise, 0.2);             // eq. 14
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
