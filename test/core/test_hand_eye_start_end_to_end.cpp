// The hand-eye start (issue 14) end to end through the estimator (mounting_from_motion.h), at
// measurement and at image level: cameras mounted backwards or sideways and guessed as forward
// ones converge, a forward drive with a good guess is not restarted, and a restart keeps the
// right camera's covariance. Its parts: test_hand_eye_rotation.cpp, test_hand_eye_start.cpp.
// Environment, for investigating only (the asserted tests ignore it unless noted):
// OSC_HAND_EYE_TRACE=1 prints every frame's errors/sigmas and the hand-eye's state;
// OSC_HAND_EYE_ONLY=<yaw rad> runs one mounting of the end-to-end test; for DISABLED_Report,
// OSC_HAND_EYE_FIRST=<frame> (default 30) is the first scored frame and
// OSC_HAND_EYE_CASE=<text> keeps the cases whose name contains it (hand-eye on only).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "online_stereo_calibration/core/estimator/hand_eye_rotation.h"
#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/geometry/rotation.h"
#include "online_stereo_calibration/core/pipeline/calibration_pipeline.h"
#include "online_stereo_calibration/core/sim/image_scenario_runner.h"
#include "online_stereo_calibration/core/sim/scenario_runner.h"
#include "online_stereo_calibration/tools/kitti_sequence.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

/// The mountings of the tests (vehicle -> left camera body [x, y, z, roll, pitch, yaw]): a
/// camera at the tailgate looking backwards, and at the mirrors looking left and right.
const Vector6d kBackward = (Vector6d() << -0.8, 0.0, 1.4, 0.0, 0.0, M_PI).finished();
const Vector6d kLeft = (Vector6d() << 1.0, 0.9, 1.1, 0.0, 0.0, M_PI / 2.0).finished();
const Vector6d kRight = (Vector6d() << 1.0, -0.9, 1.1, 0.0, 0.0, -M_PI / 2.0).finished();

/// The paper's off-road drive (roll, pitch, slow steering) without its step, the left camera
/// mounted with x_caml = @p mounting and guessed with the forward mounting's translation and
/// the identity rotation (campaign_draw.cpp's mountings).
MeasurementScenario mountedScenario(const Vector6d& mounting, int frames) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = frames;
  s.step_frame = -1;
  s.truth.head<6>() = mounting;
  Vector6d guess;
  guess << 1.5, 0.15, 1.3, 0.0, 0.0, 0.0;
  s.initial_error.setZero();
  s.initial_error.head<6>() = guess - mounting;
  return s;
}

struct Scored {
  int frames = 0, all_within_3sigma = 0, beyond_5sigma = 0, restarts = 0, restart_frame = -1;
  double worst = 0.0;  ///< largest |error| / sigma of any parameter from the first scored frame
  int worst_parameter = -1, worst_frame = -1;
  double rotation_error_at_restart = 0.0;  ///< rad, x_caml's right after the restart
};

Scored score(const MeasurementScenario& s, const FilterConfig& config, int first_scored) {
  Scored out;
  MeasurementSimulator simulator(s);
  StereoCalibrationEstimator estimator(config, s.left, s.right, simulator.initialGuess());
  SimulatedFrame frame;
  while (simulator.nextFrame(&frame)) {
    const FrameReport report = estimator.processFrame(frame.measured_motion, frame.observations);
    simulator.dropTracks(report.dropped);
    if (report.has(FrameEvent::kMountingRotationFromMotion)) {
      ++out.restarts;
      out.restart_frame = frame.index;
    }
    const ScenarioFrameResult r = makeFrameResult(frame, estimator.estimate(), report, 0.0);
    if (report.has(FrameEvent::kMountingRotationFromMotion)) {
      out.rotation_error_at_restart = r.tangent_error.segment<3>(3).norm();
    }
    if (getenv("OSC_HAND_EYE_TRACE") != nullptr) {
      std::cout
          << "frame " << r.frame << " points " << r.tracked_points << " err/sigma "
          << r.tangent_error.cwiseQuotient(r.tangent_sigmas).transpose().format(Eigen::IOFormat(2))
          << (report.has(FrameEvent::kMountingRotationFromMotion) ? " RESTART" : "")
          << (report.has(FrameEvent::kRelinearized) ? " relin" : "") << "\n";
      for (const FrameEventLine& e : report.events) std::cout << "  " << e.text << "\n";
      if (!estimator.mountingFromMotion().done()) {
        const HandEyeRotationResult h = estimator.mountingFromMotion().solve();
        std::cout << "  hand-eye: " << h.reason << " res " << h.rotation_residual / kDeg << " "
                  << h.direction_residual / kDeg << "\n";
      }
    }
    if (r.frame < first_scored) continue;
    int parameter = 0;
    const double worst =
        r.tangent_error.cwiseQuotient(r.tangent_sigmas).cwiseAbs().maxCoeff(&parameter);
    if (worst > out.worst) {
      out.worst_parameter = parameter;
      out.worst_frame = r.frame;
    }
    ++out.frames;
    out.all_within_3sigma += worst <= 3.0;
    out.beyond_5sigma += worst > 5.0;
    out.worst = std::max(out.worst, worst);
  }
  return out;
}

// Issue 14: a camera mounted backwards or sideways, guessed as a forward one (identity
// rotation, the windscreen's translation): the hand-eye start restarts the filter with the
// rotation of the motion within 30 frames (the backward one; see below for the sideways
// ones), and from frame 50 on (the restart, at frame 10-20, plus the 30 frames a normal start
// is given) every parameter is within 3 sigma in >= 95 % of the frames and never beyond 5
// sigma. Without it the backward camera is never found.
TEST(HandEyeStart, BackwardAndSidewaysCamerasGuessedForwardConverge) {
  for (const Vector6d& mounting : {kBackward, kLeft, kRight}) {
    if (getenv("OSC_HAND_EYE_ONLY") != nullptr &&
        std::atof(getenv("OSC_HAND_EYE_ONLY")) != mounting(5)) {
      continue;
    }
    // The hand-eye start itself, without the time-offset state: with it (the default) these
    // drives, which have no offset, are within 3 sigma in 244/224/245 of 250 frames instead of
    // 249/232/250, none beyond 5 sigma (inverse-depth points; with positions 223/205/243
    // against 250/243/248; docs/RESULTS.md "Hand-eye start"; issue 15 note).
    FilterConfig config;
    config.initial_time_offset_sigma = 0.0;
    const Scored s = score(mountedScenario(mounting, 300), config, 50);
    std::cout << "yaw " << mounting(5) << ": restart at frame " << s.restart_frame
              << ", x_caml's rotation then " << s.rotation_error_at_restart / kDeg
              << " deg off; from frame 50 all 12 within 3 sigma in " << s.all_within_3sigma
              << " of " << s.frames << " frames, beyond 5 sigma in " << s.beyond_5sigma
              << ", worst " << s.worst << " (tangent parameter " << s.worst_parameter
              << " at frame " << s.worst_frame << ")\n";
    // 180 deg off is beyond what the filter's updates can turn: the hand-eye restart finds
    // it. A sideways camera 90 deg off was restarted too until the first updates were
    // tempered (max_sigma_shrink_per_update); since then the filter turns to it on its own
    // (no restart; the hand-eye's estimate then agrees with the filter's).
    if (mounting == kBackward) {
      EXPECT_EQ(s.restarts, 1) << "yaw " << mounting(5);
      EXPECT_GT(s.restart_frame, 0);
      EXPECT_LT(s.restart_frame, 30);
      EXPECT_LT(s.rotation_error_at_restart, 5.0 * kDeg);
    } else {
      EXPECT_LE(s.restarts, 1) << "yaw " << mounting(5);
    }
    // Measured with inverse-depth points and tempered updates: 250 of 250 each (backward,
    // left, right; untempered 249 / 232 / 250, the left one with yaw_r 3-3.5 sigma off in
    // frames 47-62, the settling after the restart).
    EXPECT_GE(s.all_within_3sigma, 0.95 * s.frames) << "yaw " << mounting(5);
    EXPECT_EQ(s.beyond_5sigma, 0) << "yaw " << mounting(5) << " worst " << s.worst;
  }
  // Off, the backward camera is never found.
  FilterConfig off;
  off.hand_eye_start = 0;
  const Scored s = score(mountedScenario(kBackward, 100), off, 50);
  EXPECT_EQ(s.restarts, 0);
  EXPECT_GT(s.beyond_5sigma, 40);
}

// A forward camera with a good guess: the hand-eye start agrees with the filter and changes
// nothing.
TEST(HandEyeStart, ForwardDriveWithAGoodGuessIsNotRestarted) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 200;
  s.step_frame = -1;
  const Scored on = score(s, FilterConfig(), 30);
  EXPECT_EQ(on.restarts, 0);
}

// The restart starts afresh from the guess: x_caml with the hand-eye rotation and the restart
// sigmas, x_camr with the covariance the guess came with (here a saved calibration's).
TEST(HandEyeStart, RestartKeepsTheGuessCovarianceOfTheRightCamera) {
  const MeasurementScenario s = mountedScenario(kBackward, 40);
  MeasurementSimulator simulator(s);
  StereoCalibrationEstimator estimator(FilterConfig(), s.left, s.right, simulator.initialGuess());
  Matrix12d saved = Matrix12d::Zero();
  saved.diagonal().head<3>().setConstant(0.25);                     // 0.5 m
  saved.diagonal().segment<3>(3).setConstant(std::pow(0.1, 2));     // 5.7 deg
  saved.diagonal().segment<3>(6).setConstant(1e-4);                 // 1 cm
  saved.diagonal().tail<3>().setConstant(std::pow(0.2 * kDeg, 2));  // 0.2 deg
  estimator.reset(simulator.initialGuess(), saved);
  SimulatedFrame frame;
  bool restarted = false;
  while (!restarted && simulator.nextFrame(&frame)) {
    const FrameReport report = estimator.processFrame(frame.measured_motion, frame.observations);
    simulator.dropTracks(report.dropped);
    restarted = report.has(FrameEvent::kMountingRotationFromMotion);
    if (!restarted) continue;
    ASSERT_FALSE(report.events.empty());
    const FrameEventLine& event = *report.events.begin();
    EXPECT_EQ(event.kind, FrameEvent::kMountingRotationFromMotion);
    EXPECT_NE(event.text.find("mounting rotation from motion: x_caml restarted"),
              std::string::npos);
    CalibrationEstimate e = estimator.estimate();
    // The filter's own covariance: without what the odometry's scale adds to the report.
    e.tangent_covariance -= e.odometry_scale_covariance;
    // Right after the restart (no update yet): the restart's sigmas and the saved x_camr.
    EXPECT_NEAR(std::sqrt(e.tangent_covariance(0, 0)), 1.5, 1e-9);
    for (int k = 3; k < 6; ++k) EXPECT_GE(std::sqrt(e.tangent_covariance(k, k)), 3.0 * kDeg - 1e-9);
    EXPECT_NEAR(e.tangent_covariance(6, 6), 1e-4, 1e-12);
    EXPECT_NEAR(e.tangent_covariance(11, 11), std::pow(0.2 * kDeg, 2), 1e-12);
    const double cross = e.tangent_covariance.block<6, 6>(0, 6).cwiseAbs().maxCoeff();
    EXPECT_EQ(cross, 0.0);
    EXPECT_TRUE(e.extrinsics.T_caml_camr.isApprox(simulator.initialGuess().T_caml_camr));
    EXPECT_LT(rotationDistance(e.extrinsics.T_veh_caml.linear(), frame.truth.T_veh_caml.linear()),
              5.0 * kDeg);
  }
  EXPECT_TRUE(restarted);
}

// Image level (rendered images, the front end, CalibrationPipeline): with x_caml 90-180 deg
// off the front end loses every track (it searches the filter's predicted windows), so the
// hand-eye gets the left images' own keypoint matches (left_motion_matches.h). The rotation is
// found within 20 pairs and the filter is honest from frame 30. The backward camera's first
// pairs pull x_camr off with x_caml (yr 9 sigma at frame 4) until one pair off the epipolar
// lines re-opens its rotation and the whole-image fit re-seeds it at frame 10: the restart at
// frame 11 must return x_camr to the guess, not to that re-seed's translation (within 3 sigma
// in 25 of 30 frames then).
TEST(HandEyeStart, ImageLevelBackwardAndSidewaysCamerasGuessedForward) {
  for (const Vector6d& mounting : {kBackward, kRight}) {
    int determined_at = -1, frames = 0, within = 0, beyond = 0;
    double worst = 0.0;
    runImageScenario(
        mountedScenario(mounting, 60), FilterConfig(), FrontEndConfig(), {},
        [&](const ImageFrameResult& r, const CalibrationPipeline& pipeline) {
          if (determined_at < 0 && pipeline.estimator().mountingFromMotion().done()) {
            determined_at = r.filter.frame;
          }
          if (r.filter.frame < 30) return;
          const double z =
              r.filter.tangent_error.cwiseQuotient(r.filter.tangent_sigmas).cwiseAbs().maxCoeff();
          ++frames;
          within += z <= 3.0;
          beyond += z > 5.0;
          worst = std::max(worst, z);
        });
    std::cout << "image level, yaw " << mounting(5) << ": determined at frame " << determined_at
              << ", from frame 30 within 3 sigma in " << within << " of " << frames
              << " frames, worst " << worst << "\n";
    EXPECT_GT(determined_at, 0);
    EXPECT_LT(determined_at, 20);
    EXPECT_GE(within, 0.95 * frames) << "yaw " << mounting(5);
    EXPECT_EQ(beyond, 0) << "yaw " << mounting(5) << " worst " << worst;
  }
}

// The image-level figures of docs/RESULTS.md ("Hand-eye start"): the three mountings rendered
// (60 frames), and KITTI's two real stretches guessed at KITTI's calibration and with yaw_l +
// 180 deg. Run with --gtest_also_run_disabled_tests.
TEST(HandEyeStart, DISABLED_ImageLevelReport) {
  for (const Vector6d& mounting : {kBackward, kLeft, kRight}) {
    int determined_at = -1;
    double error_then = 0.0, error_at_40 = 0.0, worst_from_30 = 0.0;
    runImageScenario(mountedScenario(mounting, 60), FilterConfig(), FrontEndConfig(), {},
                     [&](const ImageFrameResult& r, const CalibrationPipeline& pipeline) {
                       const double error = r.filter.tangent_error.segment<3>(3).norm();
                       if (determined_at < 0 && pipeline.estimator().mountingFromMotion().done()) {
                         determined_at = r.filter.frame;
                         error_then = error;
                       }
                       if (r.filter.frame == 40) error_at_40 = error;
                       if (r.filter.frame >= 30) {
                         worst_from_30 =
                             std::max(worst_from_30,
                                      r.filter.tangent_error.cwiseQuotient(r.filter.tangent_sigmas)
                                          .cwiseAbs()
                                          .maxCoeff());
                       }
                     });
    std::cout << "rendered, yaw " << mounting(5) / kDeg << " deg: determined at frame "
              << determined_at << ", x_caml's rotation then " << error_then / kDeg
              << " deg off, at frame 40 " << error_at_40 / kDeg << " deg; worst abs(e)/sigma from "
              << "frame 30 " << worst_from_30 << "\n";
  }
  const std::string kitti = std::string(OSC_SOURCE_DIR) + "/../shared/data/kitti_odometry_51";
  if (!std::ifstream(kitti + "/seq1/calib.txt").good()) GTEST_SKIP() << "no KITTI data";
  for (const char* seq : {"seq1", "seq2"}) {
    const KittiSequence sequence = readKittiSequence(kitti + "/" + seq);
    const Vector12d truth = sequence.truth();
    for (double yaw : {0.0, M_PI}) {
      Vector12d guess = truth;
      guess(5) += yaw;
      CalibrationPipeline pipeline(FilterConfig(), FrontEndConfig(), sequence.left, sequence.right,
                                   StereoExtrinsics::fromParameters(guess));
      int restart = -1;
      for (int k = 0; k < sequence.frames(); ++k) {
        const PipelineResult r = pipeline.process(
            cv::imread(sequence.left_images[static_cast<size_t>(k)], cv::IMREAD_GRAYSCALE),
            cv::imread(sequence.right_images[static_cast<size_t>(k)], cv::IMREAD_GRAYSCALE),
            k > 0 ? sequence.motion(k) : MotionIncrement());
        if (r.estimator.has(FrameEvent::kMountingRotationFromMotion)) restart = k;
      }
      const HandEyeRotationResult h = pipeline.estimator().mountingFromMotion().solve();
      const Eigen::Matrix3d X = StereoExtrinsics::fromParameters(truth).T_veh_caml.linear();
      std::cout << "KITTI " << seq << ", guess yaw_l + " << yaw / kDeg << " deg: restart at "
                << restart << "; " << h.reason << "; hand-eye "
                << rotationDistance(h.R_veh_cam, X) / kDeg << " deg from KITTI's; yaw_l at the "
                << "end "
                << wrapAngle(pipeline.estimator().estimate().parameters(5) - truth(5)) / kDeg
                << " deg off\n";
    }
  }
}

// The figures of docs/RESULTS.md ("Hand-eye start (issue 14)"): ten seeds per mounting, with
// the hand-eye start on and off. Run with --gtest_also_run_disabled_tests.
TEST(HandEyeStart, DISABLED_Report) {
  struct Case {
    const char* name;
    Vector6d mounting;
    bool planar;
    bool paper_start;  ///< the paper's start errors instead of the forward guess
  };
  std::vector<Case> cases(9);
  const char* only = getenv("OSC_HAND_EYE_CASE");
  cases[0] = {"backward, guessed forward", kBackward, false, false};
  cases[1] = {"sideways left, guessed forward", kLeft, false, false};
  cases[2] = {"sideways right, guessed forward", kRight, false, false};
  cases[3] = {"backward, guessed forward, planar", cases[0].mounting, true, false};
  cases[4] = {"sideways left, guessed forward, planar", cases[1].mounting, true, false};
  cases[5] = {"forward, paper start errors", Vector6d::Zero(), false, true};
  cases[5].mounting << 1.5, 0.15, 1.3, 0.0, 0.05, 0.0;
  cases[6] = {"forward, exact guess", cases[5].mounting, false, false};
  cases[7] = {"sideways right, exact guess", cases[2].mounting, false, false};
  cases[8] = {"backward, exact guess", cases[0].mounting, false, false};
  for (const Case& c : cases) {
    if (only != nullptr && std::string(c.name).find(only) == std::string::npos) continue;
    for (int on = 1; on >= 0; --on) {
      if (only != nullptr && on == 0) continue;
      int honest = 0, restarts = 0, none_beyond_5 = 0;
      std::vector<int> restart_frames;
      double worst = 0.0;
      for (unsigned seed = 1; seed <= 10; ++seed) {
        MeasurementScenario s = mountedScenario(c.mounting, 300);
        if (c.paper_start) s.initial_error = paperOffroadScenario().initial_error;
        if (std::string(c.name).find("exact") != std::string::npos) s.initial_error.setZero();
        s.motion.planar = c.planar;
        if (c.planar) s.motion.speed = 10.0;
        s.seed = seed;
        FilterConfig config;
        config.hand_eye_start = on;
        const int first_scored =
            getenv("OSC_HAND_EYE_FIRST") ? std::atoi(getenv("OSC_HAND_EYE_FIRST")) : 30;
        const Scored r = score(s, config, first_scored);
        if (getenv("OSC_HAND_EYE_TRACE") != nullptr) {
          std::cout << c.name << " seed " << seed << " on " << on << " restart " << r.restart_frame
                    << " error there " << r.rotation_error_at_restart / kDeg << " deg, within "
                    << r.all_within_3sigma << "/" << r.frames << " beyond5 " << r.beyond_5sigma
                    << " worst " << r.worst << " param " << r.worst_parameter << " frame "
                    << r.worst_frame << "\n";
        }
        honest += r.all_within_3sigma >= 0.95 * r.frames && r.beyond_5sigma == 0;
        none_beyond_5 += r.beyond_5sigma == 0;
        restarts += r.restarts;
        if (r.restarts > 0) restart_frames.push_back(r.restart_frame);
        worst = std::max(worst, r.worst);
      }
      std::sort(restart_frames.begin(), restart_frames.end());
      std::cout << "| " << c.name << " | " << (on ? "on" : "off") << " | " << honest << " | "
                << none_beyond_5 << " | " << restarts << " | "
                << (restart_frames.empty() ? -1 : restart_frames.front()) << "-"
                << (restart_frames.empty() ? -1 : restart_frames.back()) << " | " << worst
                << " |\n";
    }
  }
}

}  // namespace
}  // namespace osc
