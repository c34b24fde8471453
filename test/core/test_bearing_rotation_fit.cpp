// Independent unit tests of bearing_rotation_fit.h: the rotation that turns one set of bearings
// into another, from clean bearings, with outliers trimmed, and its refusals. All random numbers
// are seeded.
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "online_stereo_calibration/core/geometry/bearing_rotation_fit.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

/// Bearings of random points in front of a camera, and the same seen after turning it.
struct TurnedBearings {
  std::vector<Eigen::Vector3d> before, after;
};

TurnedBearings turnedBearings(const Eigen::Matrix3d& R, int count, int outliers, double noise_angle,
                              std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> n(0.0, noise_angle);
  TurnedBearings b;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d p(0.6 * u(*rng), 0.4 * u(*rng), 1.0);
    b.before.push_back(p);
    Eigen::Vector3d q = R * p.normalized();
    q += Eigen::Vector3d(n(*rng), n(*rng), n(*rng));
    // An outlier: a direction 5-10 deg away from where the turn puts it.
    if (i < outliers) q = expSO3(Eigen::Vector3d(u(*rng), u(*rng), 0).normalized() * 7 * kDeg) * q;
    b.after.push_back(3.0 * q);  // the length does not matter
  }
  return b;
}

TEST(BearingRotationFit, RecoversTheTurnExactlyFromCleanBearings) {
  std::mt19937_64 rng(5);
  const Eigen::Matrix3d R = rotationFromRpy(Eigen::Vector3d(0.3, -4.0, 8.8) * kDeg);
  const TurnedBearings b = turnedBearings(R, 30, 0, 0.0, &rng);
  BearingRotationFit fit;
  ASSERT_TRUE(fitBearingRotation(b.before, b.after, 1e-3, 8, &fit));
  EXPECT_LT(rotationDistance(fit.rotation, R), 1e-12);
  EXPECT_EQ(fit.inliers, 30);
  EXPECT_LT(fit.rms_angle, 1e-12);
}

TEST(BearingRotationFit, TrimsOutliersAndStaysWithinTheNoise) {
  std::mt19937_64 rng(6);
  const Eigen::Matrix3d R = rotationFromRpy(Eigen::Vector3d(0.0, 0.0, -5.0) * kDeg);
  const double noise = 1.0 / 600.0;  // one pixel at 600 px focal length
  const TurnedBearings b = turnedBearings(R, 100, 25, noise, &rng);
  BearingRotationFit fit;
  ASSERT_TRUE(fitBearingRotation(b.before, b.after, 5.0 / 600.0, 8, &fit));
  EXPECT_EQ(fit.inliers, 75);  // the 25 directions 7 deg off are all trimmed
  // 75 bearings with 1 px of noise determine the turn to ~0.01 deg; the outliers, kept,
  // would pull it by ~1 deg.
  EXPECT_LT(rotationDistance(fit.rotation, R), 0.03 * kDeg);
  EXPECT_LT(fit.rms_angle, 3.0 * noise);
}

TEST(BearingRotationFit, RefusesTooFewPairsAndNonFiniteDirections) {
  std::mt19937_64 rng(7);
  TurnedBearings b = turnedBearings(Eigen::Matrix3d::Identity(), 6, 0, 0.0, &rng);
  BearingRotationFit fit;
  fit.inliers = -1;
  EXPECT_FALSE(fitBearingRotation(b.before, b.after, 1e-3, 8, &fit));
  EXPECT_TRUE(fitBearingRotation(b.before, b.after, 1e-3, 6, &fit));
  b.after[2].x() = std::numeric_limits<double>::quiet_NaN();
  fit.inliers = -1;
  EXPECT_FALSE(fitBearingRotation(b.before, b.after, 1e-3, 6, &fit));
  EXPECT_EQ(fit.inliers, -1);  // untouched
  b.after.pop_back();
  EXPECT_FALSE(fitBearingRotation(b.before, b.after, 1e-3, 3, &fit));  // sizes differ
}

}  // namespace
}  // namespace osc
