/// @file test_kitti.cpp
/// @brief Real images and real motion: the KITTI stretches of ../shared/data/kitti_odometry_51
/// through the CalibrationPipeline, the right camera started 0.5 deg (each angle) and 5 cm
/// (baseline) off, the left camera at its truth (zero, with the default start sigmas).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "online_stereo_calibration/core/estimator/camera_motion.h"
#include "online_stereo_calibration/core/frontend/feature_detection.h"
#include "online_stereo_calibration/core/frontend/front_end_config.h"
#include "online_stereo_calibration/core/frontend/global_stereo_fit.h"
#include "online_stereo_calibration/core/frontend/stereo_front_end.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/geometry/rotation.h"
#include "online_stereo_calibration/core/pipeline/calibration_pipeline.h"
#include "online_stereo_calibration/tools/evaluation.h"
#include "online_stereo_calibration/tools/kitti_sequence.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;
const std::string kKittiDir = std::string(OSC_SOURCE_DIR) + "/../shared/data/kitti_odometry_51";

/// Per-frame errors (estimate - truth, angles wrapped) and sigmas of one run.
struct KittiRun {
  std::vector<Vector12d> errors, sigmas;
  std::vector<int> points;
  /// The estimator restarted from its current estimate at this pair (re-linearised, tracks
  /// reset: FilterConfig::relinearization_*).
  std::vector<bool> restarted;
  /// The estimated camera-odometry time offset and its sigma (s).
  std::vector<double> time_offsets, time_offset_sigmas;
};

KittiRun runKitti(const KittiSequence& sequence, const Vector12d& start_error,
                  const FilterConfig& config = FilterConfig()) {
  const Vector12d truth = sequence.truth();
  CalibrationPipeline pipeline(config, FrontEndConfig(), sequence.left, sequence.right,
                               StereoExtrinsics::fromParameters(truth + start_error));
  KittiRun run;
  for (int k = 0; k < sequence.frames(); ++k) {
    const cv::Mat left =
        cv::imread(sequence.left_images[static_cast<size_t>(k)], cv::IMREAD_GRAYSCALE);
    const cv::Mat right =
        cv::imread(sequence.right_images[static_cast<size_t>(k)], cv::IMREAD_GRAYSCALE);
    const PipelineResult r =
        pipeline.process(left, right, k > 0 ? sequence.motion(k) : MotionIncrement());
    EXPECT_TRUE(r.processed) << "frame " << k << ": " << r.status;
    run.errors.push_back(parameterErrors(r.estimate.parameters, truth));
    run.sigmas.push_back(r.estimate.sigmas());
    run.points.push_back(static_cast<int>(r.estimate.tracked_points));
    run.restarted.push_back(r.estimator.has(FrameEvent::kRelinearized));
    run.time_offsets.push_back(r.estimate.time_offset);
    run.time_offset_sigmas.push_back(r.estimate.time_offset_sigma);
  }
  return run;
}

// What holds today on real images (docs/RESULTS.md "KITTI"): from 0.5 deg / 5 cm off, x_camr
// comes within 0.07-0.09 deg of KITTI's rig in 5 frames, yr within 2.7 cm (7 mm at the end),
// every pair processed with 50-75 points. Not asserted: honesty against KITTI's zero (sigmas
// 0.003-0.005 deg, roll_r 14-20 sigma off), because the images themselves show a roll of
// 0.03-0.11 deg (DISABLED_VerticalDisparityOfTheMatches): the reference is not good enough.
TEST(Kitti, RightCameraComesNearKittisRigFromHalfADegreeOff) {
  if (!std::ifstream(kKittiDir + "/seq1/calib.txt").good()) {
    GTEST_SKIP() << "KITTI data not found at " << kKittiDir;
  }
  for (const char* seq : {"seq1", "seq2"}) {
    const KittiSequence sequence = readKittiSequence(kKittiDir + "/" + seq);
    ASSERT_EQ(sequence.frames(), 51);
    EXPECT_NEAR(sequence.baseline, 0.537, 0.001);
    Vector12d start = Vector12d::Zero();
    start(7) = 0.05;
    start.tail<3>().setConstant(0.5 * kDeg);
    const KittiRun run = runKitti(sequence, start);
    for (size_t k = 10; k < run.errors.size(); ++k) {
      const Vector12d& e = run.errors[k];
      EXPECT_LT(std::abs(e(7)), 0.035) << seq << " frame " << k << " sigma " << run.sigmas[k](7);
      for (int i = 9; i < 12; ++i) EXPECT_LT(std::abs(e(i)), 0.15 * kDeg) << seq << " " << k;
      // A restart (re-linearisation) resets the tracks: new points come from the next pair.
      if (!run.restarted[k] && !run.restarted[k - 1]) {
        EXPECT_GE(run.points[k], 30) << seq << " frame " << k;
      }
    }
  }
}

TEST(Kitti, MissingFolderIsNamed) {
  try {
    readKittiSequence("/nonexistent/seq9");
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/seq9/calib.txt"), std::string::npos)
        << e.what();
  }
}

TEST(Kitti, DISABLED_Diagnostic) {
  for (const char* seq : {"seq1", "seq2"}) {
    const KittiSequence sequence = readKittiSequence(kKittiDir + "/" + seq);
    // D_ANGLE (deg, each x_camr angle) and D_YR (m) override the start error.
    Vector12d start = Vector12d::Zero();
    start(7) = std::getenv("D_YR") ? std::atof(std::getenv("D_YR")) : 0.05;
    start.tail<3>().setConstant((std::getenv("D_ANGLE") ? std::atof(std::getenv("D_ANGLE")) : 0.5) *
                                kDeg);
    // D_ROT_NOISE (deg), D_TRANS_NOISE (m), D_PIXEL_NOISE (px) override the filter's noises;
    // D_FIT and D_FIT_DISTANCE its options.
    FilterConfig config;
    if (std::getenv("D_ROT_NOISE"))
      config.motion_rotation_noise = std::atof(std::getenv("D_ROT_NOISE")) * kDeg;
    if (std::getenv("D_TRANS_NOISE"))
      config.motion_translation_noise = std::atof(std::getenv("D_TRANS_NOISE"));
    if (std::getenv("D_PIXEL_NOISE")) config.pixel_noise = std::atof(std::getenv("D_PIXEL_NOISE"));
    // D_FIT_DISTANCE: stereo_fit_restart_distance (0: x_camr always re-seeded from the
    // whole-image fit at start); D_FIT 0: the fit at start off.
    if (std::getenv("D_FIT_DISTANCE"))
      config.stereo_fit_restart_distance = std::atof(std::getenv("D_FIT_DISTANCE"));
    if (std::getenv("D_FIT")) config.stereo_fit_start = std::atoi(std::getenv("D_FIT"));
    const KittiRun run = runKitti(sequence, start, config);
    for (size_t k = 0; k < run.errors.size(); k += 5) {
      const Vector12d& e = run.errors[k];
      const Vector12d& s = run.sigmas[k];
      std::printf(
          "%s %2zu pts %3d | xl %+.3f(%.3f) yl %+.3f(%.3f) zl %+.3f(%.3f) pitch_l %+.3f(%.3f) "
          "yaw_l %+.3f(%.3f) | yr %+.4f(%.4f) roll_r %+.3f(%.3f) pitch_r %+.3f(%.3f) yaw_r "
          "%+.3f(%.3f) | dt %+.1f(%.1f) ms\n",
          seq, k, run.points[k], e(0), s(0), e(1), s(1), e(2), s(2), e(4) / kDeg, s(4) / kDeg,
          e(5) / kDeg, s(5) / kDeg, e(7), s(7), e(9) / kDeg, s(9) / kDeg, e(10) / kDeg,
          s(10) / kDeg, e(11) / kDeg, s(11) / kDeg, run.time_offsets[k] * 1e3,
          run.time_offset_sigmas[k] * 1e3);
    }
  }
}

// The vertical disparity of the front end's refined stereo pairs (rectified images: zero
// for KITTI's rig), fitted as a + b (u - cx) + c (v - cy) over all pairs of a sequence: a
// roll_r of theta shows as b = theta, a pitch_r as a constant a = f theta.
TEST(Kitti, DISABLED_VerticalDisparityOfTheMatches) {
  for (const char* seq : {"seq1", "seq2"}) {
    const KittiSequence sequence = readKittiSequence(kKittiDir + "/" + seq);
    CalibrationPipeline pipeline(FilterConfig(), FrontEndConfig(), sequence.left, sequence.right,
                                 StereoExtrinsics::fromParameters(sequence.truth()));
    Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
    Eigen::Vector3d Atb = Eigen::Vector3d::Zero();
    Eigen::Matrix3d AtA_kp = Eigen::Matrix3d::Zero();
    Eigen::Vector3d Atb_kp = Eigen::Vector3d::Zero();
    int n = 0;
    for (int k = 0; k < sequence.frames(); ++k) {
      pipeline.process(cv::imread(sequence.left_images[k], cv::IMREAD_GRAYSCALE),
                       cv::imread(sequence.right_images[k], cv::IMREAD_GRAYSCALE),
                       k > 0 ? sequence.motion(k) : MotionIncrement());
      for (const StereoObservation& o : pipeline.frontEnd().lastStereoMatches()) {
        const Eigen::Vector3d a(1.0, o.left_pixel.x() - sequence.left.cx,
                                o.left_pixel.y() - sequence.left.cy);
        const double dv = o.right_pixel.y() - o.left_pixel.y();
        AtA += a * a.transpose();
        Atb += a * dv;
        ++n;
      }
      for (const StereoObservation& o : pipeline.frontEnd().lastTracked()) {
        const Eigen::Vector3d a(1.0, o.left_pixel.x() - sequence.left.cx,
                                o.left_pixel.y() - sequence.left.cy);
        AtA_kp += a * a.transpose();
        Atb_kp += a * (o.right_pixel.y() - o.left_pixel.y());
      }
    }
    // Independent of our front end: cv::ORB keypoints (sub-pixel by cv::cornerSubPix),
    // cross-checked brute-force matches, nearly horizontal.
    Eigen::Matrix3d AtA_orb = Eigen::Matrix3d::Zero();
    Eigen::Vector3d Atb_orb = Eigen::Vector3d::Zero();
    const cv::Ptr<cv::ORB> orb = cv::ORB::create(2000);
    cv::BFMatcher matcher(cv::NORM_HAMMING, true);
    for (int k = 0; k < sequence.frames(); k += 2) {
      const cv::Mat l = cv::imread(sequence.left_images[k], cv::IMREAD_GRAYSCALE);
      const cv::Mat r = cv::imread(sequence.right_images[k], cv::IMREAD_GRAYSCALE);
      std::vector<cv::KeyPoint> kl, kr;
      cv::Mat dl, dr;
      orb->detectAndCompute(l, cv::noArray(), kl, dl);
      orb->detectAndCompute(r, cv::noArray(), kr, dr);
      std::vector<cv::DMatch> matches;
      matcher.match(dl, dr, matches);
      std::vector<cv::Point2f> pl, pr;
      for (const cv::DMatch& m : matches) {
        const cv::Point2f a = kl[m.queryIdx].pt, b = kr[m.trainIdx].pt;
        if (m.distance > 40 || std::abs(a.y - b.y) > 3.0 || a.x - b.x < 0.0) continue;
        if (kl[m.queryIdx].octave != 0 || kr[m.trainIdx].octave != 0) continue;
        pl.push_back(a);
        pr.push_back(b);
      }
      if (pl.empty()) continue;
      const cv::TermCriteria stop(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 0.01);
      cv::cornerSubPix(l, pl, cv::Size(3, 3), cv::Size(-1, -1), stop);
      cv::cornerSubPix(r, pr, cv::Size(3, 3), cv::Size(-1, -1), stop);
      for (size_t i = 0; i < pl.size(); ++i) {
        const Eigen::Vector3d a(1.0, pl[i].x - sequence.left.cx, pl[i].y - sequence.left.cy);
        const double dv = pr[i].y - pl[i].y;
        if (std::abs(dv) > 2.0) continue;
        AtA_orb += a * a.transpose();
        Atb_orb += a * dv;
      }
    }
    const Eigen::Vector3d o = AtA_orb.ldlt().solve(Atb_orb);
    std::printf(
        "%s: cv::ORB pairs (%.0f): dv = %+.3f px %+.5f (u-cx) %+.5f (v-cy): roll %+.4f deg\n", seq,
        AtA_orb(0, 0), o(0), o(1), o(2), std::atan(o(1)) / kDeg);
    const Eigen::Vector3d x = AtA.ldlt().solve(Atb), t = AtA_kp.ldlt().solve(Atb_kp);
    std::printf("%s: %d new pairs: dv = %+.3f px %+.5f (u-cx) %+.5f (v-cy): roll %+.4f deg\n", seq,
                n, x(0), x(1), x(2), std::atan(x(1)) / kDeg);
    std::printf("%s: tracked pairs: dv = %+.3f px %+.5f (u-cx) %+.5f (v-cy): roll %+.4f deg\n", seq,
                t(0), t(1), t(2), std::atan(t(1)) / kDeg);
  }
}

/// A robust mean of noisy per-frame values: the median, with its standard error from the
/// median absolute deviation (1.4826 MAD is a sigma; the median's efficiency is 2/pi).
struct RobustMean {
  double value = 0.0, standard_error = 0.0;
  int count = 0;
};

RobustMean robustMean(std::vector<double> values) {
  const auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  RobustMean mean;
  mean.count = static_cast<int>(values.size());
  if (values.empty()) return mean;
  mean.value = median(values);
  for (double& v : values) v = std::abs(v - mean.value);
  mean.standard_error = 1.4826 * median(values) * std::sqrt(M_PI / 2.0 / mean.count);
  return mean;
}

/// x_caml's pitch and yaw (rad) as the left images alone show them: the direction of the
/// camera's translation between consecutive frames (essential matrix, estimateCameraMotion)
/// against the direction of the poses' translation in the same (left body) frame. With
/// vehicle frame = left camera body frame the two agree unless the poses' own frame is turned
/// against the camera (KITTI's GPS/INS-to-camera calibration). Frame by frame the fit is
/// noisy (0.3-0.7 deg, some far off), hence the robust mean.
std::pair<RobustMean, RobustMean> leftCameraAnglesFromTheImages(const KittiSequence& sequence) {
  const cv::Ptr<cv::ORB> orb = cv::ORB::create(2000);
  cv::BFMatcher matcher(cv::NORM_HAMMING, true);
  CameraMotionConfig config;
  config.focal = sequence.left.fx;
  const CameraModel camera(sequence.left);
  const auto normalised = [&](const cv::Point2f& p) {
    return camera.pixelToNormalized(Eigen::Vector2d(p.x, p.y));
  };
  std::vector<double> pitches, yaws;
  std::vector<cv::KeyPoint> previous_keys;
  cv::Mat previous_descriptors;
  for (int k = 0; k < sequence.frames(); ++k) {
    std::vector<cv::KeyPoint> keys;
    cv::Mat descriptors;
    orb->detectAndCompute(cv::imread(sequence.left_images[k], cv::IMREAD_GRAYSCALE), cv::noArray(),
                          keys, descriptors);
    if (k > 0) {
      std::vector<cv::DMatch> matches;
      matcher.match(previous_descriptors, descriptors, matches);
      std::vector<Eigen::Vector2d> a, b;
      for (const cv::DMatch& m : matches) {
        if (m.distance > 50) continue;
        a.push_back(normalised(previous_keys[m.queryIdx].pt));
        b.push_back(normalised(keys[m.trainIdx].pt));
      }
      const CameraMotion fit = estimateCameraMotion(a, b, config);
      if (fit.valid) {
        const Eigen::Vector3d t_odo = sequence.motion(k).T_prev_curr.translation().normalized();
        const Eigen::Vector3d& t_cam = fit.translation_direction;
        // A camera yawed by psi against the vehicle sees the motion's azimuth less psi, one
        // pitched by theta (nose down positive) its elevation plus theta.
        yaws.push_back(std::atan2(t_odo.y(), t_odo.x()) - std::atan2(t_cam.y(), t_cam.x()));
        pitches.push_back(std::atan2(t_cam.z(), t_cam.head<2>().norm()) -
                          std::atan2(t_odo.z(), t_odo.head<2>().norm()));
      }
    }
    previous_keys = keys;
    previous_descriptors = descriptors;
  }
  return {robustMean(pitches), robustMean(yaws)};
}

// KITTI's zero for x_caml is its GPS/INS-to-camera calibration, good to a few tenths of a
// degree. Measured (docs/RESULTS.md "KITTI"): the images show a pitch of -0.26 (seq1) and
// -0.48 deg (seq2) against the poses, 3-6 standard errors from zero; the filter's pitch_l
// follows them (-0.24, -0.37 deg with sigma 0.06 at frame 50). So x_caml's angles are judged
// against the images' own translation direction, from frame 10 on, within 3 sigma of the
// difference (the filter's sigma and the images' standard error).
TEST(Kitti, LeftCameraAnglesAgreeWithTheImagesOwnTranslationDirection) {
  if (!std::ifstream(kKittiDir + "/seq1/calib.txt").good()) {
    GTEST_SKIP() << "KITTI data not found at " << kKittiDir;
  }
  for (const char* seq : {"seq1", "seq2"}) {
    const KittiSequence sequence = readKittiSequence(kKittiDir + "/" + seq);
    const auto [pitch, yaw] = leftCameraAnglesFromTheImages(sequence);
    std::printf("%s: the images' pitch %+.3f (%.3f) deg, yaw %+.3f (%.3f) deg from %d fits\n", seq,
                pitch.value / kDeg, pitch.standard_error / kDeg, yaw.value / kDeg,
                yaw.standard_error / kDeg, pitch.count);
    ASSERT_GE(pitch.count, 40) << seq;
    // A reference sharp enough to judge the filter by (else any sigma would pass).
    EXPECT_LT(pitch.standard_error, 0.15 * kDeg) << seq;
    EXPECT_LT(yaw.standard_error, 0.35 * kDeg) << seq;  // seq1: 0.19-0.24 deg
    Vector12d start = Vector12d::Zero();
    start(7) = 0.05;
    start.tail<3>().setConstant(0.5 * kDeg);
    const KittiRun run = runKitti(sequence, start);
    for (size_t k = 10; k < run.errors.size(); ++k) {
      for (const auto& [index, reference] : {std::make_pair(4, pitch), std::make_pair(5, yaw)}) {
        const double sigma = std::hypot(run.sigmas[k](index), reference.standard_error);
        EXPECT_LT(std::abs(run.errors[k](index) - reference.value), 3.0 * sigma)
            << seq << " frame " << k << (index == 4 ? " pitch_l " : " yaw_l ")
            << run.errors[k](index) / kDeg << " deg, sigma " << run.sigmas[k](index) / kDeg;
      }
    }
  }
}

TEST(Kitti, DISABLED_WholeImageFit) {
  for (const char* seq : {"seq1", "seq2"}) {
    const KittiSequence sequence = readKittiSequence(kKittiDir + "/" + seq);
    const CameraModel left(sequence.left), right(sequence.right);
    const FeatureDetector detector{FrontEndConfig()};
    for (int k = 0; k < sequence.frames(); k += 10) {
      const GlobalStereoFit fit = fitStereoGeometry(
          detector.detect(cv::imread(sequence.left_images[k], cv::IMREAD_GRAYSCALE), left),
          detector.detect(cv::imread(sequence.right_images[k], cv::IMREAD_GRAYSCALE), right), left,
          right, Eigen::Vector3d::UnitX());
      // Optical axes: x right (pitch_r is about -y_body = ... print the optical rotation vector).
      const Eigen::Vector3d w = logSO3(fit.R_lopt_ropt) / kDeg;
      std::printf("%s %2d %s: optical rotation vector [%+.4f %+.4f %+.4f] deg, sigma %.4f\n", seq,
                  k, fit.why.c_str(), w.x(), w.y(), w.z(),
                  std::sqrt(fit.rotation_covariance.diagonal().maxCoeff()) / kDeg);
    }
  }
}

}  // namespace
}  // namespace osc
