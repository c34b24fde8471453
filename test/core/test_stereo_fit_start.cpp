/// @file test_stereo_fit_start.cpp
/// @brief The global stereo fit at start (issue 14): x_camr's rotation from a whole-image fit
/// in the filter's frames (rightRotationSeed), and at image level (rendered drive, the
/// CalibrationPipeline) a start with x_camr's angles 5 deg off re-seeded from it; starts whose
/// baseline guess is far off (the length from motion, baseline_restart.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "online_stereo_calibration/core/filter/state_layout.h"
#include "online_stereo_calibration/core/geometry/rotation.h"
#include "online_stereo_calibration/core/pipeline/right_rotation_seed.h"
#include "online_stereo_calibration/core/sim/image_scenario_runner.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

StereoExtrinsics rig(double roll_r, double pitch_r, double yaw_r) {
  Vector12d p;
  p << 1.5, 0.15, 1.3, 0.0, 0.05, 0.0, 0.0, -0.30, 0.0, roll_r, pitch_r, yaw_r;
  return StereoExtrinsics::fromParameters(p);
}

// The fit's rotation (left -> right optical) comes back as x_camr's body rotation, and the
// distance is the difference's in the combined sigmas. A fit that held the baseline direction
// keeps the estimate's translation and its covariance.
TEST(RightRotationSeed, ConvertsTheOpticalFitToTheBodyRotationAndMeasuresTheDistance) {
  const StereoExtrinsics truth = rig(1.0 * kDeg, -2.0 * kDeg, 0.5 * kDeg);
  GlobalStereoFit fit;
  fit.valid = true;
  fit.R_lopt_ropt = truth.leftToRightOptical().linear();
  fit.baseline_direction = truth.leftToRightOptical().translation().normalized();
  fit.rotation_covariance = Eigen::Matrix3d::Identity() * std::pow(0.1 * kDeg, 2);
  StereoExtrinsics guess = truth;
  guess.T_caml_camr.linear() = truth.T_caml_camr.linear() * expSO3(Eigen::Vector3d(0, 0, 1) * kDeg);
  Matrix12d P = Matrix12d::Identity() * 1e-4;
  P.block<3, 3>(9, 9) = Eigen::Matrix3d::Identity() * std::pow(0.3 * kDeg, 2);
  const RightRotationSeed seed = rightRotationSeed(fit, guess, P, 0.0);
  ASSERT_TRUE(seed.valid);
  EXPECT_LT(rotationAngleBetween(seed.T_caml_camr.linear(), truth.T_caml_camr.linear()), 1e-12);
  EXPECT_LT((seed.T_caml_camr.translation() - truth.T_caml_camr.translation()).norm(), 1e-12);
  EXPECT_NEAR(seed.angle, 1.0 * kDeg, 1e-9);
  // 1 deg apart, sigmas 0.1 and 0.3 deg: 1 / sqrt(0.01 + 0.09) = 3.16 sigmas.
  EXPECT_NEAR(seed.distance, 1.0 / std::sqrt(0.01 + 0.09), 1e-6);
  const Eigen::Matrix3d translation = seed.covariance.topLeftCorner<3, 3>();
  EXPECT_TRUE(translation.isApprox(P.block<3, 3>(6, 6)));
  // The least sigma is added in quadrature.
  const RightRotationSeed floored = rightRotationSeed(fit, guess, P, 0.2 * kDeg);
  EXPECT_NEAR(floored.covariance(3, 3), std::pow(0.1 * kDeg, 2) + std::pow(0.2 * kDeg, 2), 1e-15);
  // ... and about the axis across the baseline and the view (optical y, body z: yaw_r) the
  // along-lines sigma.
  const RightRotationSeed along = rightRotationSeed(fit, guess, P, 0.0, 1.0 * kDeg);
  EXPECT_NEAR(along.covariance(5, 5), std::pow(0.1 * kDeg, 2) + std::pow(1.0 * kDeg, 2), 1e-12);
  EXPECT_NEAR(along.covariance(3, 3), std::pow(0.1 * kDeg, 2), 1e-8);
  EXPECT_NEAR(along.covariance(4, 4), std::pow(0.1 * kDeg, 2), 1e-8);
  EXPECT_FALSE(rightRotationSeed(GlobalStereoFit(), guess, P, 0.0).valid);
}

// A fit that refined the baseline direction: the estimate's length along the fitted
// direction, the direction's covariance (optical, of the unit vector) scaled by the length,
// the length's variance along it, and the rotation-direction correlation carried into the
// body frame. Optical y is body -z, optical x is body -y.
TEST(RightRotationSeed, CarriesTheFittedBaselineDirectionAndItsCorrelation) {
  const StereoExtrinsics truth = rig(0.0, 0.0, 0.0);  // right camera at body y = -0.3
  GlobalStereoFit fit;
  fit.valid = true;
  fit.R_lopt_ropt = truth.leftToRightOptical().linear();
  const double tilt = 0.01;  // rad, the fitted direction tilted towards optical -y (body +z)
  fit.baseline_direction = Eigen::Vector3d(1.0, -tilt, 0.0).normalized();
  fit.rotation_covariance = Eigen::Matrix3d::Identity() * 1e-6;
  fit.baseline_direction_covariance = Eigen::Vector3d(0.0, 1e-4, 1e-4).asDiagonal();
  fit.rotation_direction_covariance(0, 1) = 0.9e-5;  // optical e_x with c_y
  Matrix12d P = Matrix12d::Identity() * 1e-4;
  P(7, 7) = 0.1 * 0.1;  // the length (body y) 0.1 m
  const RightRotationSeed seed = rightRotationSeed(fit, truth, P, 0.0);
  ASSERT_TRUE(seed.valid);
  EXPECT_NEAR(seed.T_caml_camr.translation().norm(), 0.3, 1e-12);
  EXPECT_NEAR(seed.T_caml_camr.translation().z(), 0.3 * tilt, 1e-5);
  // body z: 0.3^2 * 1e-4 across, plus the length's 0.01 along the tilted direction; body y:
  // the length's.
  const double c2 = 1.0 / (1.0 + tilt * tilt);  // the direction's squared body y component
  EXPECT_NEAR(seed.covariance(2, 2), 0.09 * 1e-4 + 0.01 * (1.0 - c2), 1e-12);
  EXPECT_NEAR(seed.covariance(1, 1), 0.01 * c2, 1e-12);
  // Optical (e_x, c_y) is body (-e_y, -c_z): cov(e_y, t_z) = 0.3 * 0.9e-5.
  EXPECT_NEAR(seed.covariance(4, 2), 0.3 * 0.9e-5, 1e-12);
  EXPECT_NEAR(seed.covariance(2, 4), 0.3 * 0.9e-5, 1e-12);
}

struct StartRun {
  int reseeded_at = -1, fits = 0, frames = 0, within = 0, beyond = 0;
  int length_from_motion_at = -1;  ///< first frame with "baseline length from motion"
  double worst = 0.0;
  double fit_z = 0.0;  ///< largest |fit error| / fit sigma per body axis
  double last_rotation_error = 0.0, last_translation_error = 0.0;  ///< x_camr's, rad and m
};

StartRun runStart(const Vector12d& initial_error, int frames, int stereo_fit_start,
                  unsigned seed = 1, const FrontEndConfig& front_end = FrontEndConfig()) {
  MeasurementScenario scenario = paperOffroadScenario();
  scenario.seed = seed;
  scenario.frames = frames;
  scenario.step_frame = -1;
  scenario.initial_error = initial_error;
  FilterConfig config;
  config.stereo_fit_start = stereo_fit_start;
  StartRun run;
  runImageScenario(
      scenario, config, front_end, {}, [&](const ImageFrameResult& r, const CalibrationPipeline&) {
        if (r.stereo_fit && r.stereo_fit->valid) {
          ++run.fits;
          const Eigen::Matrix3d R_true =
              StereoExtrinsics::fromParameters(r.filter.truth).T_caml_camr.linear();
          const Eigen::Vector3d e = logSO3(R_true.transpose() * r.stereo_fit->T_caml_camr.linear());
          if (getenv("OSC_STEREO_FIT_TRACE") != nullptr) {
            std::cout << "frame " << r.filter.frame << ": fit error " << e.transpose() / kDeg
                      << " deg, sigma "
                      << r.stereo_fit->covariance.diagonal().tail<3>().cwiseSqrt().transpose() /
                             kDeg
                      << " deg, distance " << r.stereo_fit->distance << "\n";
          }
          run.fit_z = e.cwiseQuotient(r.stereo_fit->covariance.diagonal().tail<3>().cwiseSqrt())
                          .cwiseAbs()
                          .maxCoeff();
        }
        for (const std::string& w : r.filter.warnings) {
          if (w.rfind("baseline length from motion", 0) == 0 && run.length_from_motion_at < 0) {
            run.length_from_motion_at = r.filter.frame;
            std::cout << "frame " << r.filter.frame << ": " << w << "\n";
          }
        }
        if (r.right_rotation_from_stereo_fit && run.reseeded_at < 0) {
          run.reseeded_at = r.filter.frame;
        }
        run.last_rotation_error = r.filter.tangent_error.tail<3>().norm();
        run.last_translation_error = r.filter.tangent_error.segment<3>(6).norm();
        if (r.filter.frame < 30) return;
        const double z =
            r.filter.tangent_error.cwiseQuotient(r.filter.tangent_sigmas).cwiseAbs().maxCoeff();
        ++run.frames;
        run.within += z <= 3.0;
        run.beyond += z > 5.0;
        run.worst = std::max(run.worst, z);
      });
  return run;
}

// Issue 14: x_camr's angles 5 deg off (2.5 times the 2 deg start sigma). The whole-image fit
// of the first pair re-seeds x_camr's rotation, and from frame 30 on all 12 errors are within
// 3 sigma in >= 95 % of the frames and never beyond 5 sigma. A good guess is left alone.
TEST(StereoFitStart, RightCameraFiveDegreesOffIsReseededFromTheFirstPair) {
  Vector12d error = paperOffroadScenario().initial_error;
  error.tail<3>().setConstant(5.0 * kDeg);
  const StartRun on = runStart(error, 120, 1);
  std::cout << "x_camr 5 deg off: re-seeded at frame " << on.reseeded_at << ", fit error "
            << on.fit_z << " sigma; from frame 30 all 12 within 3 sigma in " << on.within << " of "
            << on.frames << ", beyond 5 sigma in " << on.beyond << ", worst " << on.worst << "\n";
  EXPECT_EQ(on.reseeded_at, 0);
  EXPECT_EQ(on.fits, 1);
  EXPECT_LT(on.fit_z, 3.0);
  EXPECT_GE(on.within, 0.95 * on.frames);
  EXPECT_EQ(on.beyond, 0) << "worst " << on.worst;

  // The seed's own start errors with x_camr's angles exact: the fit agrees, nothing changes.
  const StartRun good = runStart(paperOffroadScenario().initial_error, 3, 1);
  EXPECT_EQ(good.fits, 1);
  EXPECT_EQ(good.reseeded_at, -1);
}

// x_camr's pitch 4.6 deg off (2.3 of the 2 deg start sigma, and the fit 2.3 combined sigmas
// away, below stereo_fit_restart_distance) beyond the band's 60 px cap (max_band): the guess's
// epipolar band holds (almost) no match, so the fit, the only evidence there is, re-seeds
// x_camr all the same. Before, the start kept the guess (image run 1 of session 14's
// campaign, 975 px focal length, where the cap is 3.5 deg: 1-4 stereo pairs per pair for 60
// pairs, x_caml unlearned, and after a later knock yr 30 sigma off). The paper drive's 600 px
// focal length puts the cap at 5.7 deg, beyond the restart distance; a cap of 30 px (2.9 deg)
// stands for the longer lens.
TEST(StereoFitStart, RightCameraWhoseBandHoldsNoMatchIsReseededThoughWithinItsSigma) {
  Vector12d error = paperOffroadScenario().initial_error;
  error.tail<3>() << 0.0, 4.6 * kDeg, 0.0;
  FrontEndConfig long_lens;
  long_lens.max_band = 30.0;
  const StartRun run = runStart(error, 60, 1, 1, long_lens);
  std::cout << "pitch_r 4.6 deg off: re-seeded at frame " << run.reseeded_at
            << "; from frame 30 all 12 within 3 sigma in " << run.within << " of " << run.frames
            << ", worst " << run.worst << "\n";
  EXPECT_EQ(run.reseeded_at, 0);
  EXPECT_LT(run.last_rotation_error, 0.05 * kDeg);
  EXPECT_GE(run.within, 0.95 * run.frames);
  EXPECT_EQ(run.beyond, 0) << "worst " << run.worst;
}

// Issue 14: the baseline guessed 50 % long (yr -0.45 m for -0.30), with the seed's other start
// errors (x_caml 0.5 m / 10 deg per axis off). The fit agrees with x_camr's rotation (the
// guess's angles are exact), so nothing is re-seeded; the length comes from the motion. From
// frame 30 on all 12 errors within 3 sigma in >= 95 % of the frames and none beyond 5 sigma.
TEST(StereoFitStart, BaselineGuessedHalfLongIsHonestFromFrame30) {
  Vector12d error = paperOffroadScenario().initial_error;
  error(7) = -0.15;
  const StartRun run = runStart(error, 120, 1);
  std::cout << "baseline 50 % long: from frame 30 all 12 within 3 sigma in " << run.within << " of "
            << run.frames << ", beyond 5 sigma in " << run.beyond << ", worst " << run.worst
            << "; x_camr at the end " << 1e3 * run.last_translation_error << " mm\n";
  EXPECT_EQ(run.reseeded_at, -1);
  EXPECT_GE(run.within, 0.95 * run.frames);
  EXPECT_EQ(run.beyond, 0) << "worst " << run.worst;
  EXPECT_LT(run.last_translation_error, 0.005);
}

// Issue 14: the baseline guessed 50 % short (yr -0.15 m for -0.30, sigma 0.1 m). With the
// guess no new point passes the depth check (some of x_camr's sigma points have almost no
// baseline), so the length is measured from the left camera's motion over five pairs of
// candidates matched by their left descriptors (FilterConfig::baseline_from_motion), and the
// filter starts from it. From frame 30 on all 12 errors within 3 sigma in >= 95 % of the
// frames and none beyond 5 sigma; the baseline within 5 mm at the end.
TEST(StereoFitStart, BaselineGuessedHalfShortIsMeasuredFromMotionAndHonestFromFrame30) {
  Vector12d error = paperOffroadScenario().initial_error;
  error(7) = 0.15;
  const StartRun run = runStart(error, 120, 1);
  std::cout << "baseline 50 % short: length from motion at frame " << run.length_from_motion_at
            << "; from frame 30 all 12 within 3 sigma in " << run.within << " of " << run.frames
            << ", beyond 5 sigma in " << run.beyond << ", worst " << run.worst
            << "; x_camr at the end " << 1e3 * run.last_translation_error << " mm\n";
  EXPECT_GE(run.length_from_motion_at, 5);
  EXPECT_LE(run.length_from_motion_at, 20);
  EXPECT_GE(run.within, 0.95 * run.frames);
  EXPECT_EQ(run.beyond, 0) << "worst " << run.worst;
  EXPECT_LT(run.last_translation_error, 0.005);
}

// The figures of docs/RESULTS.md "Stereo fit at start": image-level starts with x_camr's
// angles 5 deg off and the baseline 50 % short and long (the seed's other start errors),
// seeds 1-3, with the fit at start off and on. Run with --gtest_also_run_disabled_tests;
// OSC_STEREO_FIT_FRAMES (250) and OSC_STEREO_FIT_SEEDS (3) change the drives.
TEST(StereoFitStart, DISABLED_Report) {
  const int frames =
      getenv("OSC_STEREO_FIT_FRAMES") ? std::atoi(getenv("OSC_STEREO_FIT_FRAMES")) : 250;
  const int seeds = getenv("OSC_STEREO_FIT_SEEDS") ? std::atoi(getenv("OSC_STEREO_FIT_SEEDS")) : 3;
  struct Case {
    const char* name;
    Vector12d error;
  };
  std::vector<Case> cases;
  const Vector12d paper = paperOffroadScenario().initial_error;
  Vector12d e = paper;
  e.tail<3>() << 5.0 * kDeg, 5.0 * kDeg, 5.0 * kDeg;
  cases.push_back({"x_camr angles +5/+5/+5 deg", e});
  e.tail<3>() << -5.0 * kDeg, 5.0 * kDeg, -5.0 * kDeg;
  cases.push_back({"x_camr angles -5/+5/-5 deg", e});
  e = paper;
  e(7) = 0.15;  // yr -0.30 guessed -0.15
  cases.push_back({"baseline 50 % short", e});
  e(7) = -0.15;
  cases.push_back({"baseline 50 % long", e});
  std::cout << "| start | fit | seed | re-seeded at | within 3 sigma from frame 30 | max z | "
               "x_camr at the end |\n|---|---|---|---|---|---|---|\n";
  // OSC_STEREO_FIT_ON: only off (0) or on (1); OSC_STEREO_FIT_CASE: only case k (0-3).
  const int only_on = getenv("OSC_STEREO_FIT_ON") ? std::atoi(getenv("OSC_STEREO_FIT_ON")) : -1;
  const int only_case =
      getenv("OSC_STEREO_FIT_CASE") ? std::atoi(getenv("OSC_STEREO_FIT_CASE")) : -1;
  for (size_t k = 0; k < cases.size(); ++k) {
    if (only_case >= 0 && static_cast<int>(k) != only_case) continue;
    const Case& c = cases[k];
    for (int on = 0; on <= 1; ++on) {
      if (only_on >= 0 && on != only_on) continue;
      for (int seed = 1; seed <= seeds; ++seed) {
        const StartRun r = runStart(c.error, frames, on, static_cast<unsigned>(seed));
        std::printf("| %s | %s | %d | %s | %.2f | %.1f | %.1f mm, %.3f deg |\n", c.name,
                    on ? "on" : "off", seed,
                    r.reseeded_at >= 0 ? std::to_string(r.reseeded_at).c_str() : "-",
                    static_cast<double>(r.within) / std::max(1, r.frames), r.worst,
                    1e3 * r.last_translation_error, r.last_rotation_error / kDeg);
        std::fflush(stdout);
      }
    }
  }
}

}  // namespace
}  // namespace osc

namespace osc {
namespace {

/// An image-level start of the paper drive with the rig's baseline @p truth_length long and
/// guessed @p guess_length (the seed's other start errors).
struct BaselineStart {
  int restarted_at = -1;  ///< the baseline-from-motion restart's pair (-1: none)
  int started_at = -1;    ///< the first pair from which the filter holds points to the end
  int frames = 0, within = 0, beyond = 0;  ///< from started_at + 30 on
  /// Pairs without a point in the filter before the restart, and the whole-image fits the
  /// knock test made in them (CalibrationPipeline::wholeImageFits).
  int pairs_without_points = 0, fits_without_points = 0;
  double worst = 0.0;
  double length = 0.0, length_sigma = 0.0;  ///< at the end, m
};

BaselineStart runBaselineStart(double truth_length, double guess_length, int frames,
                               unsigned seed) {
  MeasurementScenario scenario = paperOffroadScenario();
  scenario.seed = seed;
  scenario.frames = frames;
  scenario.step_frame = -1;
  scenario.truth(7) = -truth_length;  // body y: the right camera is to the right
  scenario.initial_error(7) = truth_length - guess_length;
  std::vector<ScenarioFrameResult> all;
  BaselineStart run;
  runImageScenario(scenario, FilterConfig(), FrontEndConfig(), {},
                   [&](const ImageFrameResult& r, const CalibrationPipeline& pipeline) {
                     all.push_back(r.filter);
                     for (const std::string& w : r.filter.warnings) {
                       if (w.rfind("baseline length from motion", 0) == 0 && run.restarted_at < 0)
                         run.restarted_at = r.filter.frame;
                     }
                     if (run.restarted_at < 0 && r.filter.tracked_points == 0) {
                       ++run.pairs_without_points;
                       run.fits_without_points = pipeline.wholeImageFits();
                     }
                   });
  for (int k = static_cast<int>(all.size()) - 1; k >= 0 && all[k].tracked_points > 0; --k)
    run.started_at = all[k].frame;
  for (const ScenarioFrameResult& f : all) {
    if (run.started_at < 0 || f.frame < run.started_at + 30) continue;
    const double z = f.tangent_error.cwiseQuotient(f.tangent_sigmas).cwiseAbs().maxCoeff();
    ++run.frames;
    run.within += z <= 3.0;
    run.beyond += z > 5.0;
    run.worst = std::max(run.worst, z);
  }
  run.length = -all.back().parameters(7);
  run.length_sigma = all.back().sigmas(7);
  return run;
}

// Issue "Real drives in": an 11 cm rig guessed at 1 cm. No point can be initialised with the
// guess, so the length is measured from the left camera's motion and x_camr restarted at it;
// from 30 pairs after the start all 12 errors within 3 sigma in >= 95 % of the pairs, none
// beyond 5. Measured: started at pair 6, since the front end keeps the pairs whose depth is
// in range for some length within 3 sigma while the filter holds no point (31 when the 1 cm
// length alone judged them and few far points fed the fit). (Seeds 1-5:
// DISABLED_BaselineGuessReport.)
TEST(BaselineStart, ElevenCentimetreRigGuessedAtOneCentimetreStartsWithin15PairsAndIsHonest) {
  const BaselineStart run = runBaselineStart(0.11, 0.01, 90, 1);
  std::cout << "11 cm guessed 1 cm: restarted at " << run.restarted_at << ", started at "
            << run.started_at << " (" << run.fits_without_points << " whole-image fits in "
            << run.pairs_without_points << " pairs without points); within 3 sigma in "
            << run.within << " of " << run.frames << ", worst " << run.worst << "; length "
            << run.length << " +- " << run.length_sigma << " m\n";
  EXPECT_GE(run.restarted_at, 0);
  EXPECT_GE(run.started_at, 0);
  EXPECT_LE(run.started_at, 15);
  EXPECT_GE(run.frames, 10);
  EXPECT_GE(run.within, 0.95 * run.frames);
  EXPECT_EQ(run.beyond, 0) << "worst " << run.worst;
  EXPECT_NEAR(run.length, 0.11, 3.0 * run.length_sigma);
  // Without a point the knock test's whole-image fit ran in one pair of five, not in each
  // (a pair without points cost 130 ms, one with them 30).
  EXPECT_GE(run.pairs_without_points, 5);
  EXPECT_LE(run.fits_without_points, run.pairs_without_points / 5 + 1);
  EXPECT_GE(run.fits_without_points, 1);
}

// A 0.3 m rig guessed at 0.6 m: points pass the depth check with the long guess, so the filter
// starts at once and learns the length from them; honest from pair 30.
TEST(BaselineStart, ThirtyCentimetreRigGuessedAtSixtyStartsAtOnceAndIsHonest) {
  const BaselineStart run = runBaselineStart(0.30, 0.60, 70, 1);
  std::cout << "0.3 m guessed 0.6 m: started at " << run.started_at << "; within 3 sigma in "
            << run.within << " of " << run.frames << ", worst " << run.worst << "; length "
            << run.length << " +- " << run.length_sigma << " m\n";
  EXPECT_EQ(run.restarted_at, -1);
  EXPECT_EQ(run.started_at, 0);
  EXPECT_GE(run.within, 0.95 * run.frames);
  EXPECT_EQ(run.beyond, 0) << "worst " << run.worst;
  EXPECT_NEAR(run.length, 0.30, 3.0 * run.length_sigma);
}

// The figures of docs/RESULTS.md "Far-off baseline guesses": both starts over seeds 1-5,
// 150 pairs. Run with --gtest_also_run_disabled_tests.
TEST(BaselineStart, DISABLED_BaselineGuessReport) {
  std::cout << "| rig | guess | seed | restarted at | started at | within 3 sigma from start + 30 "
               "| max z | length at the end |\n|---|---|---|---|---|---|---|---|\n";
  for (const auto& [truth, guess] : {std::pair{0.11, 0.01}, std::pair{0.30, 0.60}}) {
    for (unsigned seed = 1; seed <= 5; ++seed) {
      const BaselineStart r = runBaselineStart(truth, guess, 150, seed);
      std::printf("| %.2f m | %.2f m | %u | %d | %d | %d of %d | %.2f | %.4f +- %.4f m |\n", truth,
                  guess, seed, r.restarted_at, r.started_at, r.within, r.frames, r.worst, r.length,
                  r.length_sigma);
      std::fflush(stdout);
    }
  }
}

}  // namespace
}  // namespace osc
