/// @file test_epipolar_consistency.cpp
/// @brief The test of a pair's stereo matches against x_camr's epipolar lines
/// (epipolar_consistency.h): chi-square when x_camr holds, a knock found and measured.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "online_stereo_calibration/core/estimator/epipolar_consistency.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Matrix3d intrinsics() {
  Eigen::Matrix3d K;
  K << 800.0, 0.0, 320.0, 0.0, 800.0, 240.0, 0.0, 0.0, 1.0;
  return K;
}

/// A 0.3 m horizontal rig (interface parameters: the right camera 0.3 m to the right of the
/// left one), its right camera turned by @p roll, @p pitch, @p yaw (rad) from the estimate.
StereoExtrinsics rig(double roll = 0.0, double pitch = 0.0, double yaw = 0.0) {
  Vector12d parameters = Vector12d::Zero();
  parameters(7) = -0.3;
  parameters.tail<3>() << roll, pitch, yaw;
  return StereoExtrinsics::fromParameters(parameters);
}

/// @p count stereo pairs of points at 3-40 m in the 640x480 images of @p truth, with
/// @p noise px per coordinate; @p outliers of them have a right pixel 10-50 px off.
std::vector<PointMeasurement> pairs(const StereoExtrinsics& truth, int count, double noise,
                                    std::mt19937* rng, int outliers = 0) {
  const Eigen::Matrix3d K = intrinsics();
  const Eigen::Isometry3d T_ropt_lopt = truth.leftToRightOptical().inverse();
  std::uniform_real_distribution<double> u(0.0, 640.0), v(0.0, 480.0), depth(3.0, 40.0);
  std::uniform_real_distribution<double> far(10.0, 50.0), angle(0.0, 2.0 * M_PI);
  std::normal_distribution<double> pixel(0.0, noise);
  std::vector<PointMeasurement> result;
  while (static_cast<int>(result.size()) < count) {
    const Eigen::Vector3d ray = K.inverse() * Eigen::Vector3d(u(*rng), v(*rng), 1.0);
    const Eigen::Vector3d in_right = T_ropt_lopt * (depth(*rng) * ray);
    const Eigen::Vector3d right = K * (in_right / in_right.z());
    if (right.x() < 0.0 || right.x() > 640.0 || right.y() < 0.0 || right.y() > 480.0) continue;
    PointMeasurement m;
    m.id = result.size();
    m.z << (K * ray).head<2>(), right.head<2>();
    for (int k = 0; k < 4; ++k) m.z(k) += pixel(*rng);
    if (static_cast<int>(result.size()) < outliers) {
      const double distance = far(*rng), direction = angle(*rng);
      m.z.tail<2>() += distance * Eigen::Vector2d(std::cos(direction), std::sin(direction));
    }
    m.variance.setConstant(noise * noise);
    result.push_back(m);
  }
  return result;
}

/// x_camr's tangent covariance ([dt, dtheta]) with these sigmas on every axis.
Matrix6d camrCovariance(double rotation_sigma, double translation_sigma) {
  Vector6d variances;
  variances << Eigen::Vector3d::Constant(translation_sigma * translation_sigma),
      Eigen::Vector3d::Constant(rotation_sigma * rotation_sigma);
  return variances.asDiagonal();
}

const Matrix6d kConverged = camrCovariance(0.003 * kDeg, 1e-5);

// Under the right x_camr the statistic is chi-square: its mean over many pairs is its degrees of
// freedom, and the 1e-6 bound is not passed. A wrongly scaled noise (a residual not divided by
// its sigma, or by the wrong one) fails the mean.
TEST(EpipolarLines, AreChiSquareWhenTheRightCameraHolds) {
  std::mt19937 rng(3);
  double sum = 0.0;
  int dof = 0, contradicting = 0;
  constexpr int kTrials = 300;
  for (int trial = 0; trial < kTrials; ++trial) {
    const EpipolarEvidence evidence = testEpipolarLines(pairs(rig(), 80, 0.5, &rng), intrinsics(),
                                                        intrinsics(), rig(), kConverged, 1e-6, 8);
    EXPECT_EQ(evidence.pairs, 80);
    sum += evidence.statistic;
    dof = evidence.dof;
    contradicting += evidence.contradicts ? 1 : 0;
  }
  ASSERT_GE(dof, 2);  // at least the rotations across the lines (roll_r, pitch_r)
  // Standard deviation of the mean: sqrt(2 dof / kTrials), about 0.14 for 3 dof.
  EXPECT_NEAR(sum / kTrials, dof, 0.5);
  EXPECT_EQ(contradicting, 0);
}

// A right camera knocked by 0.3 deg about its optical axis (roll_r: vertical disparity growing
// with the column) and 0.2 deg about the baseline (pitch_r: a constant one) contradicts the
// converged estimate, and the indicated rotation turns the estimate onto the truth.
TEST(EpipolarLines, FindAndMeasureAKnockedRightCamera) {
  std::mt19937 rng(5);
  const StereoExtrinsics truth = rig(0.3 * kDeg, -0.2 * kDeg, 0.0);
  const EpipolarEvidence evidence = testEpipolarLines(pairs(truth, 60, 0.5, &rng), intrinsics(),
                                                      intrinsics(), rig(), kConverged, 1e-6, 8);
  EXPECT_TRUE(evidence.contradicts) << evidence.summary();
  EXPECT_GT(evidence.statistic, 10.0 * evidence.bound);
  Vector6d shift = Vector6d::Zero();
  shift.tail<3>() = evidence.rotation_shift;
  const Vector12d turned =
      StereoExtrinsics{rig().T_veh_caml, boxPlus(rig().T_caml_camr, shift)}.toParameters();
  EXPECT_NEAR(turned(9), 0.3 * kDeg, 0.02 * kDeg);
  EXPECT_NEAR(turned(10), -0.2 * kDeg, 0.02 * kDeg);
  EXPECT_NEAR(evidence.angle, std::hypot(0.3, 0.2) * kDeg, 0.05 * kDeg);
}

// The same knock is within the covariance of an x_camr known to 1 deg (a start): no
// contradiction. And fewer pairs than asked never contradict.
TEST(EpipolarLines, AKnockWithinTheCovarianceOrTooFewPairsDoNotContradict) {
  std::mt19937 rng(7);
  const StereoExtrinsics truth = rig(0.3 * kDeg, -0.2 * kDeg, 0.0);
  const Matrix6d wide = camrCovariance(1.0 * kDeg, 1e-5);
  EXPECT_FALSE(testEpipolarLines(pairs(truth, 60, 0.5, &rng), intrinsics(), intrinsics(), rig(),
                                 wide, 1e-6, 8)
                   .contradicts);
  const EpipolarEvidence few = testEpipolarLines(pairs(truth, 7, 0.5, &rng), intrinsics(),
                                                 intrinsics(), rig(), kConverged, 1e-6, 8);
  EXPECT_FALSE(few.contradicts);
  EXPECT_EQ(few.pairs, 7);
}

// Mismatches 10-50 px off in 10 % of the pairs do not make a knock of a right camera that
// holds (each is down-weighted to a residual of 3 sigma).
TEST(EpipolarLines, MismatchesAloneDoNotContradict) {
  std::mt19937 rng(11);
  int contradicting = 0;
  for (int trial = 0; trial < 50; ++trial) {
    contradicting += testEpipolarLines(pairs(rig(), 80, 0.5, &rng, 8), intrinsics(), intrinsics(),
                                       rig(), kConverged, 1e-6, 8)
                         .contradicts;
  }
  EXPECT_EQ(contradicting, 0);
}

/// A filter at rig() with x_camr converged (0.003 deg, 0.01 mm) and x_caml at the default
/// start sigmas.
CalibrationFilter convergedFilter() {
  StereoIntrinsics k;
  k.K_left = k.K_right = intrinsics();
  CalibrationFilter filter(FilterConfig(), k);
  Matrix12d covariance = Matrix12d::Identity() * 0.01;
  covariance.bottomRightCorner<6, 6>() = kConverged;
  filter.reset(rig(), covariance);
  return filter;
}

// The component the estimator calls with every image pair: a knock found in the pair that
// shows it (epipolar_knock_pairs 1), x_camr's rotation to be re-opened to 3 times the angle
// the pairs indicate; with 2, at the second pair in a row; never when off or when x_camr holds.
TEST(EpipolarKnockTest, AKnockIsReportedAfterTheConfiguredPairsInARow) {
  std::mt19937 rng(23);
  const CalibrationFilter filter = convergedFilter();
  const StereoExtrinsics knocked = rig(0.2 * kDeg, 0.0, 0.0);
  FilterConfig config;
  EpipolarKnockTest first(EpipolarKnockOptions::from(config));
  const EpipolarKnock knock =
      first.test(pairs(knocked, 60, 0.5, &rng), intrinsics(), intrinsics(), filter);
  ASSERT_TRUE(knock.knocked);
  EXPECT_NEAR(knock.rotation_sigma, 3.0 * 0.2 * kDeg, 0.3 * kDeg);
  EXPECT_NE(knock.warning.find("left x_camr's epipolar lines in this image pair"),
            std::string::npos)
      << knock.warning;

  config.epipolar_knock_pairs = 2;
  EpipolarKnockTest second(EpipolarKnockOptions::from(config));
  EXPECT_FALSE(
      second.test(pairs(knocked, 60, 0.5, &rng), intrinsics(), intrinsics(), filter).knocked);
  const EpipolarKnock later =
      second.test(pairs(knocked, 60, 0.5, &rng), intrinsics(), intrinsics(), filter);
  EXPECT_TRUE(later.knocked);
  EXPECT_NE(later.warning.find("in 2 image pairs in a row"), std::string::npos) << later.warning;
  // A pair that agrees in between starts the streak afresh.
  EXPECT_FALSE(
      second.test(pairs(knocked, 60, 0.5, &rng), intrinsics(), intrinsics(), filter).knocked);
  EXPECT_FALSE(
      second.test(pairs(rig(), 60, 0.5, &rng), intrinsics(), intrinsics(), filter).knocked);
  EXPECT_FALSE(
      second.test(pairs(knocked, 60, 0.5, &rng), intrinsics(), intrinsics(), filter).knocked);

  config.epipolar_knock_false_alarm = 0.0;
  EpipolarKnockTest off(EpipolarKnockOptions::from(config));
  EXPECT_FALSE(off.test(pairs(knocked, 60, 0.5, &rng), intrinsics(), intrinsics(), filter).knocked);
  EpipolarKnockTest holds(EpipolarKnockOptions::from(FilterConfig()));
  for (int trial = 0; trial < 20; ++trial) {
    EXPECT_FALSE(
        holds.test(pairs(rig(), 60, 0.5, &rng), intrinsics(), intrinsics(), filter).knocked);
  }
}

}  // namespace
}  // namespace osc
