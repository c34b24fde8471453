// The odometry noise matcher (odometry_noise_matcher.h): the motion error's score statistic
// has its model's mean and grows with the odometry's extra noise as the evidence says; the
// matcher keeps the configured noise when the data agree, learns a noisier odometry, and
// forgets it once the window holds agreeing data; at measurement level, the paper's drive with
// a 5x noisier odometry translation is learned and stays honest, the shipped drive untouched.
#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "online_stereo_calibration/core/estimator/odometry_noise_matcher.h"
#include "online_stereo_calibration/core/sim/scenario_runner.h"
#include "online_stereo_calibration/tools/evaluation.h"

namespace osc {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

/// A linear-Gaussian update with the filter's layout: a persistent block (12, the calibration)
/// with a correlated prior, then the step's motion error with prior a * Q (independent of it),
/// N points r_i = J_i dg + n_i, n_i ~ N(0, I). The true motion error has k * Q.
class NoisyMotionUpdate {
 public:
  static constexpr int kPersistent = 12;
  static constexpr int kG = kPersistent + 6;

  explicit NoisyMotionUpdate(std::mt19937* rng) : rng_(rng) {
    MatrixXd L = MatrixXd::Zero(kPersistent, kPersistent);
    for (int a = 0; a < kPersistent; ++a)
      for (int b = 0; b <= a; ++b) L(a, b) = 0.2 * normal_(*rng_);
    calibration_prior_ = L * L.transpose() + 0.01 * MatrixXd::Identity(kPersistent, kPersistent);
    Q_.setZero();
    Q_.diagonal() << 0.2, 0.3, 0.25, 0.1, 0.15, 0.12;
    for (int i = 0; i < kPoints; ++i) {
      MatrixXd Ji(4, kG);
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < kG; ++b) Ji(a, b) = normal_(*rng_);
      J_.push_back(Ji);
    }
  }

  const Matrix6& Q() const { return Q_; }

  /// One update's evidence with the prior's motion block a_p Q_p and the truth's k_p Q_p.
  MotionNoiseEvidence draw(const std::array<double, 2>& applied, const std::array<double, 2>& k) {
    MatrixXd prior = MatrixXd::Zero(kG, kG), truth = MatrixXd::Zero(kG, kG);
    prior.topLeftCorner(kPersistent, kPersistent) = calibration_prior_;
    truth.topLeftCorner(kPersistent, kPersistent) = calibration_prior_;
    for (int p = 0; p < 2; ++p) {
      prior.block(kPersistent + 3 * p, kPersistent + 3 * p, 3, 3) =
          applied[p] * Q_.block<3, 3>(3 * p, 3 * p);
      truth.block(kPersistent + 3 * p, kPersistent + 3 * p, 3, 3) =
          k[p] * Q_.block<3, 3>(3 * p, 3 * p);
    }
    VectorXd z(kG);
    for (int a = 0; a < kG; ++a) z(a) = normal_(*rng_);
    const VectorXd dg = truth.llt().matrixL() * z;
    MatrixXd A = MatrixXd::Zero(kG, kG);
    VectorXd b = VectorXd::Zero(kG);
    for (const MatrixXd& Ji : J_) {
      Eigen::Vector4d n;
      for (int a = 0; a < 4; ++a) n(a) = normal_(*rng_);
      A += Ji.transpose() * Ji;
      b += Ji.transpose() * (Ji * dg + n);
    }
    const MatrixXd P_post = (prior.inverse() + A).inverse();
    return motionNoiseEvidence(globalScore(A, b, P_post), Q_, applied);
  }

 private:
  static constexpr int kPoints = 6;
  std::mt19937* rng_;
  std::normal_distribution<double> normal_;
  MatrixXd calibration_prior_;
  Matrix6 Q_;
  std::vector<MatrixXd> J_;
};

OdometryNoiseMatcherOptions options(double window) {
  OdometryNoiseMatcherOptions o;
  o.window = window;
  return o;
}

// E[T_p] = dof_p + (k_p - a_p) growth_p (the file comment of update_scores.h): with the
// prior right, with the translation's noise 4x its prior, and with the rotation's prior
// twice its truth; each within 4 standard errors of 4000 draws.
TEST(MotionNoiseEvidence, StatisticHasItsModelMean) {
  std::mt19937 rng(3);
  NoisyMotionUpdate update(&rng);
  const std::array<double, 2> applied = {1.0, 2.0};
  for (const std::array<double, 2>& k :
       {std::array<double, 2>{1.0, 2.0}, std::array<double, 2>{4.0, 1.0}}) {
    constexpr int kDraws = 4000;
    std::array<double, 2> mean = {0.0, 0.0}, expected = {0.0, 0.0}, square = {0.0, 0.0};
    for (int d = 0; d < kDraws; ++d) {
      const MotionNoiseEvidence e = update.draw(applied, k);
      for (int p = 0; p < 2; ++p) {
        ASSERT_EQ(e.dof[p], 3);
        EXPECT_GT(e.growth[p], 0.0);
        EXPECT_EQ(e.applied_factor[p], applied[p]);
        mean[p] += e.statistic[p] / kDraws;
        square[p] += e.statistic[p] * e.statistic[p] / kDraws;
        expected[p] += (e.dof[p] + (k[p] - applied[p]) * e.growth[p]) / kDraws;
      }
    }
    for (int p = 0; p < 2; ++p) {
      const double standard_error = std::sqrt((square[p] - mean[p] * mean[p]) / kDraws);
      EXPECT_NEAR(mean[p], expected[p], 4.0 * standard_error) << "part " << p << ", k " << k[p];
    }
  }
}

// Data that agree with the configured noise keep it: over 600 updates (60 s) the factor is 1
// in at least 99 % of them (the bound's false alarm is 0.1 % a window).
TEST(OdometryNoiseMatcher, KeepsTheConfiguredNoiseWhenTheDataAgree) {
  std::mt19937 rng(11);
  NoisyMotionUpdate update(&rng);
  OdometryNoiseMatcher matcher(options(20.0));
  int raised = 0;
  for (int step = 0; step < 600; ++step) {
    matcher.addUpdate(0.1, nullptr, 0.0);  // a step without an update changes nothing ...
    const MotionNoiseEvidence e = update.draw(matcher.factors(), {1.0, 1.0});
    matcher.addUpdate(0.0, &e, 0.0);  // ... the evidence does
    raised += matcher.factors()[0] > 1.0 || matcher.factors()[1] > 1.0;
  }
  EXPECT_LE(raised, 6);
  EXPECT_EQ(matcher.status().window_updates, 200);
  EXPECT_TRUE(matcher.status().message().empty());
}

// A translation 3x noisier than configured (k = 9), the rotation as configured, the learned
// factors fed back into the prior as the estimator does: after 20 s the translation's estimate
// is 9 within 4 of its standard errors and the factor near it, the rotation's factor 1. Once
// the odometry agrees again, a window later the factor is back at 1.
TEST(OdometryNoiseMatcher, LearnsANoisierOdometryAndForgetsIt) {
  std::mt19937 rng(5);
  NoisyMotionUpdate update(&rng);
  OdometryNoiseMatcherOptions o = options(20.0);
  o.translation_noise = 0.002;
  OdometryNoiseMatcher matcher(o);
  for (int step = 0; step < 200; ++step) {
    const MotionNoiseEvidence e = update.draw(matcher.factors(), {9.0, 1.0});
    matcher.addUpdate(0.1, &e, 0.0);
  }
  const OdometryNoiseStatus& learned = matcher.status();
  EXPECT_NEAR(learned.estimate[0], 9.0, 4.0 * learned.standard_error[0]);
  EXPECT_LT(learned.standard_error[0], 1.0);
  EXPECT_GT(learned.factor[0], 5.0);
  EXPECT_LE(learned.factor[0], 9.0 + learned.standard_error[0]);
  EXPECT_EQ(learned.factor[1], 1.0);
  EXPECT_NEAR(learned.sigma[0], 0.002 * std::sqrt(learned.factor[0]), 1e-12);
  EXPECT_NE(learned.message().find("translation 2.0 -> "), std::string::npos) << learned.message();
  EXPECT_EQ(learned.message().find("rotation"), std::string::npos) << learned.message();

  for (int step = 0; step < 201; ++step) {
    const MotionNoiseEvidence e = update.draw(matcher.factors(), {1.0, 1.0});
    matcher.addUpdate(0.1, &e, 0.0);
  }
  EXPECT_EQ(matcher.factors()[0], 1.0);
  matcher.reset();
  EXPECT_EQ(matcher.status().window_updates, 0);
}

// An update made while x_caml's rotation is known no better than 1 deg (a start far off) is
// not evidence: 100 of a 25x noisier odometry leave the window empty; settled, they count.
TEST(OdometryNoiseMatcher, UpdatesBeforeTheMountingRotationSettledAreNotEvidence) {
  std::mt19937 rng(9);
  NoisyMotionUpdate update(&rng);
  OdometryNoiseMatcher matcher(options(20.0));
  const double unsettled = 1.5 * OdometryNoiseMatcher::kSettledRotationSigma;
  for (int step = 0; step < 100; ++step) {
    const MotionNoiseEvidence e = update.draw(matcher.factors(), {25.0, 25.0});
    matcher.addUpdate(0.1, &e, unsettled);
  }
  EXPECT_EQ(matcher.status().window_updates, 0);
  EXPECT_EQ(matcher.factors()[0], 1.0);
  for (int step = 0; step < 100; ++step) {
    const MotionNoiseEvidence e = update.draw(matcher.factors(), {25.0, 25.0});
    matcher.addUpdate(0.1, &e, OdometryNoiseMatcher::kSettledRotationSigma);
  }
  EXPECT_EQ(matcher.status().window_updates, 100);
  EXPECT_GT(matcher.factors()[0], 5.0);
  EXPECT_GT(matcher.factors()[1], 5.0);
}

// Off (window 0): no evidence is kept and the factors stay 1.
TEST(OdometryNoiseMatcher, OffLearnsNothing) {
  std::mt19937 rng(2);
  NoisyMotionUpdate update(&rng);
  OdometryNoiseMatcher matcher(options(0.0));
  for (int step = 0; step < 100; ++step) {
    const MotionNoiseEvidence e = update.draw({1.0, 1.0}, {25.0, 25.0});
    matcher.addUpdate(0.1, &e, 0.0);
  }
  EXPECT_FALSE(matcher.status().enabled);
  EXPECT_EQ(matcher.factors()[0], 1.0);
  EXPECT_EQ(matcher.factors()[1], 1.0);
  EXPECT_EQ(matcher.status().window_updates, 0);
}

/// Share of frames from 30 on with all 12 errors within 3 sigma, and the last frame's factors.
struct DriveOutcome {
  double within_3sigma = 0.0;
  std::array<double, 2> factor = {1.0, 1.0};
  bool raised_after_50 = false;  ///< a factor above 1 from frame 50 on
  double largest = 1.0;          ///< the largest factor of the drive
};

DriveOutcome drive(double translation_noise, double window) {
  MeasurementScenario scenario = paperOffroadScenario();
  scenario.frames = 400;  // before the paper's step of x_caml at frame 774
  scenario.motion_translation_noise = translation_noise;
  FilterConfig config;
  config.odometry_noise_window = window;
  DriveOutcome outcome;
  int frames = 0, within = 0;
  for (const ScenarioFrameResult& r : runMeasurementScenario(scenario, config)) {
    outcome.factor = r.odometry_noise_factor;
    if (r.frame < 30) continue;
    ++frames;
    within +=
        (parameterErrors(r.parameters, r.truth).cwiseAbs().array() <= 3.0 * r.sigmas.array()).all();
  }
  outcome.within_3sigma = static_cast<double>(within) / frames;
  return outcome;
}

// The paper's drive with the odometry's translation noise 5x the configured 2 mm a step:
// the factor learned is that of the truth (25) within a factor 2, and all 12 errors are within
// 3 sigma in at least 90 % of the frames from frame 30 (below 50 % without the matcher). With
// the configured noise the factor is 1 from frame 50 on.
TEST(OdometryNoiseMatcher, PaperDriveWithANoisierOdometryIsLearned) {
  const DriveOutcome noisy = drive(0.01, 20.0);
  const DriveOutcome unlearned = drive(0.01, 0.0);
  EXPECT_GT(noisy.factor[0], 12.5);
  EXPECT_LT(noisy.factor[0], 50.0);
  EXPECT_GE(noisy.within_3sigma, 0.9);      // 0.94 (learned from frame ~20 on, x_caml settled)
  EXPECT_LT(unlearned.within_3sigma, 0.5);  // 0.03
  const DriveOutcome matched = drive(0.002, 20.0);
  EXPECT_FALSE(matched.raised_after_50);
  EXPECT_LT(matched.largest, 4.0);
}

}  // namespace
}  // namespace osc
