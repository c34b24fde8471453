/// @file test_baseline_from_motion.cpp
/// @brief The baseline's length from the left camera's motion (baseline_from_motion.h):
/// inverse depths from two views, and the line rho_b = L rho_m + c over synthetic scenes.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "online_stereo_calibration/core/estimator/baseline_from_motion.h"
#include "online_stereo_calibration/core/estimator/baseline_restart.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kFocal = 600.0;

Eigen::Vector2d project(const Eigen::Vector3d& X) { return X.head<2>() / X.z(); }

// A point at depth 8 m seen from a second camera 0.4 m to the side and turned by 2 deg: its
// inverse depth is 1/8 per metre, and 0.4/8 in units of the second camera's distance.
TEST(InverseDepthFromTwoViews, IsTheInverseDepthInUnitsOfTheTranslation) {
  const Eigen::Vector3d X(1.5, -0.7, 8.0);
  const Eigen::Matrix3d R = expSO3(Eigen::Vector3d(0.01, 2.0 * kDeg, -0.02));
  const Eigen::Vector3d t(-0.4, 0.02, 0.03);
  const Eigen::Vector3d ray = X / X.z();
  const Eigen::Vector2d other = project(R * X + t);
  double sigma = 0.0;
  EXPECT_NEAR(inverseDepthFromTwoViews(ray, other, R, t, 0.5 / kFocal, &sigma), 1.0 / 8.0, 1e-12);
  EXPECT_NEAR(inverseDepthFromTwoViews(ray, other, R, t.normalized(), 0.0), t.norm() / 8.0, 1e-12);
  // Half a pixel in each view over a 0.4 m baseline at 600 px: about 0.0029 / m.
  EXPECT_NEAR(sigma, std::sqrt(2.0) * 0.5 / kFocal / 0.4, 0.0005);
  // Without translation there is no parallax: NaN, not a number that looks like a depth.
  EXPECT_TRUE(std::isnan(inverseDepthFromTwoViews(ray, other, R, Eigen::Vector3d::Zero(), 0.0)));
}

/// A 0.3 m rig (right camera at optical +x, turned by @p yaw_error about optical y against
/// what the estimate says) driving forward 0.8 m per pair through points at 4-60 m; the
/// estimate's baseline is @p guessed_length long.
struct Drive {
  double true_length = 0.3;
  double yaw_error = 0.0;
  double step = 0.8;         ///< m forward per pair
  double pixel_noise = 0.3;  ///< px
  int points = 60;

  /// Links of one pair: previous and current normalised left/right coordinates.
  std::vector<StereoLink> pair(std::mt19937* rng) const {
    std::uniform_real_distribution<double> lateral(-12.0, 12.0), height(-2.0, 3.0);
    std::uniform_real_distribution<double> inverse_depth(1.0 / 60.0, 1.0 / 4.0);
    std::normal_distribution<double> noise(0.0, pixel_noise / kFocal);
    const Eigen::Matrix3d R_turn = expSO3(Eigen::Vector3d(0.0, 0.3 * kDeg, 0.0));
    // X_right = R_rl X_left + t_rl: the right camera at +x of the left one.
    const Eigen::Matrix3d R_rl = expSO3(Eigen::Vector3d(0.0, yaw_error, 0.0));
    const Eigen::Vector3d t_rl = -R_rl * Eigen::Vector3d(true_length, 0.0, 0.0);
    std::vector<StereoLink> links;
    while (static_cast<int>(links.size()) < points) {
      const double z = 1.0 / inverse_depth(*rng);
      const Eigen::Vector3d current(lateral(*rng) * z / 20.0, height(*rng), z);
      // The camera moved forward by step and turned a little: X_prev = R X_curr + t.
      const Eigen::Vector3d previous = R_turn * current + Eigen::Vector3d(0.0, 0.0, step);
      if (std::abs(current.x() / current.z()) > 0.6 || std::abs(previous.x() / previous.z()) > 0.6)
        continue;
      auto view = [&](const Eigen::Vector3d& X) {
        Eigen::Vector4d v;
        v << project(X), project(R_rl * X + t_rl);
        for (int k = 0; k < 4; ++k) v(k) += noise(*rng);
        return v;
      };
      links.push_back({view(previous), view(current)});
    }
    return links;
  }
};

Eigen::Isometry3d estimatedRig(double length) {
  // T_lopt_ropt: the right camera at +x, not turned (what the estimate believes).
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(length, 0.0, 0.0);
  return T;
}

BaselineFromMotionConfig config() {
  BaselineFromMotionConfig c;
  c.motion.focal = kFocal;
  c.pixel_noise = 0.3;
  return c;
}

// The baseline guessed half as long (0.15 m for 0.3): five pairs of motion give 0.3 m
// within 3 of its sigmas, and that sigma is a few percent; the guess's length does not enter.
TEST(BaselineFromMotion, MeasuresABaselineGuessedHalfShort) {
  std::mt19937 rng(7);
  const Drive drive;
  BaselineFromMotion estimator(config());
  for (int k = 0; k < 5; ++k) {
    EXPECT_FALSE(estimator.estimate().valid);
    EXPECT_TRUE(estimator.addPair(drive.pair(&rng), estimatedRig(0.15), drive.step))
        << estimator.lastWhy();
  }
  const BaselineLength length = estimator.estimate();
  ASSERT_TRUE(length.valid) << length.why;
  EXPECT_NEAR(length.length, 0.3, 3.0 * length.sigma);
  EXPECT_LT(length.sigma, 0.03);
  EXPECT_NEAR(length.offset, 0.0, 1e-3);
  // The guess's length does not matter, only its direction.
  BaselineFromMotion other(config());
  std::mt19937 same(7);
  for (int k = 0; k < 5; ++k) other.addPair(drive.pair(&same), estimatedRig(0.45), drive.step);
  EXPECT_NEAR(other.estimate().length, length.length, 1e-9);
}

// A right camera turned 0.3 deg about optical y against the estimate offsets every disparity
// by 0.3 deg: the line's offset takes it, the slope (the length) stays right. Without the
// offset term a point at 60 m (0.3 m / 60 m = 0.29 deg of disparity) would read twice as near.
TEST(BaselineFromMotion, ARightCameraTurnedAlongTheLinesGoesIntoTheOffset) {
  std::mt19937 rng(11);
  Drive drive;
  drive.yaw_error = 0.3 * kDeg;
  BaselineFromMotion estimator(config());
  for (int k = 0; k < 5; ++k) estimator.addPair(drive.pair(&rng), estimatedRig(0.15), drive.step);
  const BaselineLength length = estimator.estimate();
  ASSERT_TRUE(length.valid) << length.why;
  EXPECT_NEAR(length.length, 0.3, 3.0 * length.sigma);
  EXPECT_NEAR(std::abs(length.offset), 0.3 * kDeg, 0.03 * kDeg);
  EXPECT_GT(std::abs(length.offset), 3.0 * length.offset_sigma);
  // Turned back by the offset, the estimate's right camera is the true one (optical y), and
  // the same drive measured with it has no offset left.
  const Eigen::Isometry3d aligned = withoutDisparityOffset(estimatedRig(0.15), length.offset);
  const Eigen::Matrix3d R_true = expSO3(Eigen::Vector3d(0.0, drive.yaw_error, 0.0));
  EXPECT_LT(logSO3(aligned.linear() * R_true).norm(), 0.05 * kDeg);
  EXPECT_LT((aligned.translation() - Eigen::Vector3d(0.15, 0.0, 0.0)).norm(), 1e-12)
      << "the right camera turns about its centre";
  std::mt19937 again(11);
  BaselineFromMotion refit(config());
  for (int k = 0; k < 5; ++k) refit.addPair(drive.pair(&again), aligned, drive.step);
  EXPECT_LT(std::abs(refit.estimate().offset), 0.03 * kDeg);
}

// A standing camera (or one that moved 2 cm) tells nothing about the length: no pair counts,
// and the estimate says why.
TEST(BaselineFromMotion, AStandingCameraTellsNothing) {
  std::mt19937 rng(3);
  Drive drive;
  drive.step = 0.02;
  BaselineFromMotion estimator(config());
  for (int k = 0; k < 5; ++k) {
    EXPECT_FALSE(estimator.addPair(drive.pair(&rng), estimatedRig(0.15), drive.step));
    EXPECT_NE(estimator.lastWhy().find("the left camera moved 0.02 m"), std::string::npos)
        << estimator.lastWhy();
  }
  const BaselineLength length = estimator.estimate();
  EXPECT_FALSE(length.valid);
  EXPECT_NE(length.why.find("0 pairs"), std::string::npos) << length.why;
}

/// A filter whose x_camr says the right camera is 3 cm to the side (the 0.3 m rig guessed 10x
/// short), with @p translation_sigma on x_camr's translation.
CalibrationFilter shortRigFilter(double translation_sigma) {
  StereoIntrinsics k;
  k.K_left << kFocal, 0, 0, 0, kFocal, 0, 0, 0, 1;
  k.K_right = k.K_left;
  CalibrationFilter filter(FilterConfig(), k);
  StereoExtrinsics guess;
  guess.T_caml_camr.translation() = Eigen::Vector3d(0.0, -0.03, 0.0);  // body: right is -y
  Vector12d sigma = Vector12d::Constant(1e-3);
  sigma.segment<3>(6).setConstant(translation_sigma);
  filter.reset(guess, sigma.array().square().matrix().asDiagonal());
  return filter;
}

/// Feeds @p pairs pairs of the drive as given links (normalised -> pixels at kFocal) and
/// returns the last proposal.
BaselineReseed drive(BaselineRestart* restart, const CalibrationFilter& filter, int pairs) {
  std::mt19937 rng(7);
  const Drive scene;
  MotionIncrement motion;
  motion.dt = 0.1;
  motion.T_prev_curr.translation() = Eigen::Vector3d(scene.step, 0.0, 0.0);
  BaselineReseed reseed;
  for (int k = 0; k < pairs && !reseed.reseed; ++k) {
    std::vector<std::pair<PointMeasurement, PointMeasurement>> links;
    for (const StereoLink& link : scene.pair(&rng)) {
      PointMeasurement a, b;
      a.z = kFocal * link.previous;
      b.z = kFocal * link.current;
      links.emplace_back(a, b);
    }
    restart->setLinks(std::move(links), true);
    reseed = restart->afterPair(motion, true, {}, filter);
  }
  return reseed;
}

// A length the filter does not know (3 cm guessed, 10 cm sigma) is restarted at the length from
// motion along the guess's direction, with that length's sigma along it; a length it knows
// (1 mm sigma) is not: then something else keeps the points out.
TEST(BaselineRestart, AnUnknownLengthIsRestartedAtTheMeasuredOneAKnownOneIsNot) {
  const CalibrationFilter unknown = shortRigFilter(0.1);
  BaselineRestart restart(FilterConfig(), unknown.intrinsics().K_left,
                          unknown.intrinsics().K_right);
  const BaselineReseed reseed = drive(&restart, unknown, 8);
  ASSERT_TRUE(reseed.reseed);
  const Eigen::Vector3d t = reseed.T_caml_camr.translation();
  EXPECT_NEAR(t.norm(), 0.3, 0.03);
  EXPECT_LT(std::abs(t.x()) + std::abs(t.z()), 1e-12) << "along the guess's direction";
  const double along = std::sqrt(reseed.covariance(1, 1));
  EXPECT_GE(along, 0.05 * t.norm() - 1e-12);  // at least 5 % of the length
  EXPECT_LT(along, 0.05);
  EXPECT_NE(reseed.message.find("baseline length from motion: x_camr's translation restarted"),
            std::string::npos)
      << reseed.message;

  const CalibrationFilter known = shortRigFilter(0.001);
  BaselineRestart kept(FilterConfig(), known.intrinsics().K_left, known.intrinsics().K_right);
  EXPECT_FALSE(drive(&kept, known, 8).reseed);
}

// A slow camera (2 cm per pair: a MAV at 20 Hz in a room) moves too little between two pairs
// for the length (min_translation 5 cm, then a pixel of parallax). The pairs are linked to an
// earlier reference pair until the camera has moved enough since it, and the length is
// measured; linking each pair to the one before, no pair would ever count.
TEST(BaselineRestart, ASlowCameraIsLinkedToAnEarlierPairUntilItHasMovedEnough) {
  const CalibrationFilter unknown = shortRigFilter(0.1);
  BaselineRestart restart(FilterConfig(), unknown.intrinsics().K_left,
                          unknown.intrinsics().K_right);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> lateral(-12.0, 12.0), height(-2.0, 3.0);
  std::uniform_real_distribution<double> inverse_depth(1.0 / 30.0, 1.0 / 3.0);
  std::normal_distribution<double> noise(0.0, 0.3);
  std::vector<Eigen::Vector3d> scene;  // the first pair's left optical frame
  while (scene.size() < 150) {
    const double z = 1.0 / inverse_depth(rng);
    const Eigen::Vector3d X(lateral(rng) * z / 20.0, height(rng), z);
    if (std::abs(X.x() / X.z()) < 0.5) scene.push_back(X);
  }
  constexpr double kStep = 0.02;  // m forward per pair (vehicle x = the camera's optical z)
  MotionIncrement motion;
  motion.T_prev_curr.translation() = Eigen::Vector3d(kStep, 0.0, 0.0);
  int reseeded_at = -1, kept = 0;
  BaselineReseed reseed;
  for (int k = 0; k < 60 && reseeded_at < 0; ++k) {
    std::vector<PointMeasurement> candidates;
    for (size_t i = 0; i < scene.size(); ++i) {
      const Eigen::Vector3d X = scene[i] - Eigen::Vector3d(0.0, 0.0, k * kStep);
      PointMeasurement m;
      m.id = static_cast<PointId>(i);
      m.z << kFocal * project(X), kFocal * project(X - Eigen::Vector3d(0.3, 0.0, 0.0));
      for (int c = 0; c < 4; ++c) m.z(c) += noise(rng);
      candidates.push_back(m);
    }
    reseed = restart.afterPair(motion, k > 0, candidates, unknown);
    kept += restart.keepsReference();
    if (reseed.reseed) reseeded_at = k;
  }
  ASSERT_GE(reseeded_at, 0) << restart.progress();
  EXPECT_GE(kept, 5 * 2);  // five pairs counted, each after at least two kept
  EXPECT_NEAR(reseed.T_caml_camr.translation().norm(), 0.3, 0.03);
}

}  // namespace
}  // namespace osc
