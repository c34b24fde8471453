// Tests of the measurement simulator (measurement_simulator.h): exact projections and true
// motion, the statistics of the motion and pixel noise and of the outliers, track lengths and
// point counts, calibration steps and drift, seeds, camera mountings, depth ranges and speed.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "measurement_simulator_test_support.h"
#include "online_stereo_calibration/core/geometry/rotation.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"

namespace osc {
namespace {

TEST(MeasurementSimulator, NoiseFreeObservationsAreExactProjectionsOfStaticPoints) {
  MeasurementSimulator sim(noiseFree());
  std::map<PointId, Eigen::Vector3d> first_seen;
  size_t checked = 0;
  SimulatedFrame frame;
  while (sim.nextFrame(&frame)) {
    EXPECT_TRUE(frame.measured_motion.T_prev_curr.isApprox(frame.true_motion.T_prev_curr, 1e-15));
    for (const StereoObservation& o : frame.observations) {
      const std::optional<Eigen::Vector3d> point = sim.worldPoint(o.id);
      ASSERT_TRUE(point.has_value());
      // A point keeps its world position for its whole life.
      const auto inserted = first_seen.emplace(o.id, *point);
      EXPECT_EQ(inserted.first->second, *point);
      const TruePixels truth = projectTruth(sim, frame, *point);
      ASSERT_NEAR((o.left_pixel - truth.left).norm(), 0.0, 1e-9) << "id " << o.id;
      ASSERT_NEAR((o.right_pixel - truth.right).norm(), 0.0, 1e-9) << "id " << o.id;
      ++checked;
    }
  }
  EXPECT_GT(checked, 250u * 90u);
}

TEST(MeasurementSimulator, TrueMotionChainsToTheTruePoses) {
  MeasurementSimulator sim(noiseFree());
  const std::vector<SimulatedFrame> frames = runAll(&sim);
  ASSERT_EQ(frames.size(), 300u);
  EXPECT_TRUE(frames[0].true_motion.T_prev_curr.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_TRUE(frames[0].measured_motion.T_prev_curr.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_DOUBLE_EQ(frames[0].measured_motion.dt, 0.1);
  Eigen::Isometry3d chained = frames[0].T_world_veh;
  double path_length = 0.0;
  for (size_t k = 1; k < frames.size(); ++k) {
    EXPECT_DOUBLE_EQ(frames[k].stamp, k * 0.1);
    EXPECT_DOUBLE_EQ(frames[k].true_motion.dt, 0.1);
    chained = chained * frames[k].true_motion.T_prev_curr;
    ASSERT_TRUE(chained.isApprox(frames[k].T_world_veh, 1e-9)) << "frame " << k;
    path_length += (frames[k].T_world_veh.translation() - frames[k - 1].T_world_veh.translation())
                       .head<2>()
                       .norm();
  }
  // 29.9 s at 3.5 m/s along the ground track.
  EXPECT_NEAR(path_length, 3.5 * 29.9, 0.01 * 3.5 * 29.9);
}

TEST(MeasurementSimulator, MotionNoiseHasTheConfiguredStatistics) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 3000;
  s.target_points = 1;  // only the motion matters here
  MeasurementSimulator sim(s);
  std::vector<std::vector<double>> error(6);
  SimulatedFrame frame;
  while (sim.nextFrame(&frame)) {
    if (frame.index == 0) continue;
    const Vector6d e = boxMinus(frame.measured_motion.T_prev_curr, frame.true_motion.T_prev_curr);
    for (int i = 0; i < 6; ++i) error[i].push_back(e(i));
  }
  for (int i = 0; i < 6; ++i) {
    const double sigma = i < 3 ? s.motion_translation_noise : s.motion_rotation_noise;
    EXPECT_NEAR(stddev(error[i]), sigma, 0.1 * sigma) << "axis " << i;
    EXPECT_NEAR(mean(error[i]), 0.0, 4.0 * sigma / std::sqrt(error[i].size())) << "axis " << i;
  }
}

TEST(MeasurementSimulator, MotionNoiseScalesWithTheSquareRootOfTheStep) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 3000;
  s.rate_hz = 40.0;  // dt = 0.025 s: a quarter of the 0.1 s reference step
  s.target_points = 1;
  MeasurementSimulator sim(s);
  std::vector<double> yaw_error;
  SimulatedFrame frame;
  while (sim.nextFrame(&frame)) {
    if (frame.index == 0) continue;
    yaw_error.push_back(
        boxMinus(frame.measured_motion.T_prev_curr, frame.true_motion.T_prev_curr)(5));
  }
  EXPECT_NEAR(stddev(yaw_error), 0.5 * s.motion_rotation_noise, 0.05 * s.motion_rotation_noise);
}

TEST(MeasurementSimulator, PixelNoiseHasTheConfiguredStd) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 200;
  s.pixel_noise = 0.8;
  MeasurementSimulator sim(s);
  std::vector<std::vector<double>> residual(4);
  SimulatedFrame frame;
  while (sim.nextFrame(&frame)) {
    for (const StereoObservation& o : frame.observations) {
      EXPECT_EQ(o.sigma_left, 0.8);
      EXPECT_EQ(o.sigma_right, 0.8);
      const TruePixels truth = projectTruth(sim, frame, *sim.worldPoint(o.id));
      residual[0].push_back(o.left_pixel.x() - truth.left.x());
      residual[1].push_back(o.left_pixel.y() - truth.left.y());
      residual[2].push_back(o.right_pixel.x() - truth.right.x());
      residual[3].push_back(o.right_pixel.y() - truth.right.y());
    }
  }
  for (const auto& r : residual) {
    ASSERT_GT(r.size(), 10000u);
    EXPECT_NEAR(stddev(r), 0.8, 0.08);
    EXPECT_NEAR(mean(r), 0.0, 0.03);
  }
  // Independent per coordinate and camera.
  double cross = 0.0;
  for (size_t i = 0; i < residual[0].size(); ++i) cross += residual[0][i] * residual[2][i];
  EXPECT_NEAR(cross / residual[0].size() / (0.8 * 0.8), 0.0, 0.05);
}

TEST(MeasurementSimulator, OutliersAreGrossAndAtTheConfiguredRate) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 200;
  s.outlier_fraction = 0.2;
  MeasurementSimulator sim(s);
  size_t observations = 0, outliers = 0;
  SimulatedFrame frame;
  while (sim.nextFrame(&frame)) {
    const std::set<PointId> flagged(frame.outlier_ids.begin(), frame.outlier_ids.end());
    for (const StereoObservation& o : frame.observations) {
      const TruePixels truth = projectTruth(sim, frame, *sim.worldPoint(o.id));
      const double error =
          std::max((o.left_pixel - truth.left).norm(), (o.right_pixel - truth.right).norm());
      // Outliers are >= 10 px off, inliers have 0.5 px noise: 6 px separates them surely.
      EXPECT_EQ(error > 6.0, flagged.count(o.id) > 0) << "error " << error;
      EXPECT_TRUE(sim.leftCamera().isInImage(o.left_pixel, -5.0));
      EXPECT_TRUE(sim.rightCamera().isInImage(o.right_pixel, -5.0));
      ++observations;
    }
    outliers += flagged.size();
  }
  EXPECT_NEAR(static_cast<double>(outliers) / observations, 0.2, 0.02);
}

TEST(MeasurementSimulator, TracksLastTheConfiguredMeanLength) {
  // A parked vehicle: tracks never leave the view, so only the random loss ends them.
  MeasurementScenario s = paperOffroadScenario();
  s.motion.speed = 0.0;
  s.motion.yaw_rate_amplitude = 0.0;
  s.motion.planar = true;
  s.step_frame = -1;  // the 10 deg step would push ~1/6 of the points out of view at once
  s.frames = 1500;
  MeasurementSimulator sim(s);
  std::map<PointId, int> length;
  std::set<PointId> born_early;
  SimulatedFrame frame;
  while (sim.nextFrame(&frame)) {
    for (const StereoObservation& o : frame.observations) ++length[o.id];
    // Tracks born in the last 200 frames may be cut off by the end of the drive.
    if (frame.index < s.frames - 200) {
      born_early.insert(frame.new_point_ids.begin(), frame.new_point_ids.end());
    }
    // Nothing ever leaves the view of a parked vehicle: the live count stays at the target.
    if (frame.index >= 3) {
      ASSERT_EQ(frame.observations.size(), 100u) << "frame " << frame.index;
    }
  }
  std::vector<double> finished;
  for (PointId id : born_early) finished.push_back(length[id]);
  ASSERT_GT(finished.size(), 5000u);
  // Geometric with mean 15 (std ~14.5): the mean of > 5000 tracks is within ~0.2.
  EXPECT_NEAR(mean(finished), s.mean_track_length, 0.05 * s.mean_track_length);
}

TEST(MeasurementSimulator, KeepsTheTargetNumberOfPointsOnThePaperDrive) {
  MeasurementSimulator sim(paperOffroadScenario());
  std::vector<double> counts;
  SimulatedFrame frame;
  std::set<PointId> ids_seen;
  while (sim.nextFrame(&frame)) {
    std::set<PointId> ids;
    for (const StereoObservation& o : frame.observations) ids.insert(o.id);
    EXPECT_EQ(ids.size(), frame.observations.size()) << "duplicate ids in frame " << frame.index;
    for (PointId id : frame.new_point_ids) {
      EXPECT_TRUE(ids.count(id)) << "new id not observed";
      EXPECT_FALSE(ids_seen.count(id)) << "new id was seen before";
    }
    ids_seen.insert(ids.begin(), ids.end());
    EXPECT_LE(frame.new_point_ids.size(), 40u);
    if (frame.index >= 5) counts.push_back(frame.observations.size());
  }
  EXPECT_NEAR(mean(counts), 100.0, 5.0);
  EXPECT_GE(*std::min_element(counts.begin(), counts.end()), 80.0);
}

TEST(MeasurementSimulator, StepIsAppliedExactlyAtTheStepFrame) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 800;
  s.target_points = 5;
  MeasurementSimulator sim(s);
  const StereoExtrinsics before = StereoExtrinsics::fromParameters(s.truth);
  const StereoExtrinsics after = StereoExtrinsics::fromParameters(s.truth + s.step);
  SimulatedFrame frame;
  while (sim.nextFrame(&frame)) {
    const StereoExtrinsics& expected = frame.index < 774 ? before : after;
    ASSERT_TRUE(frame.truth.T_veh_caml.isApprox(expected.T_veh_caml, 1e-12)) << frame.index;
    ASSERT_TRUE(frame.truth.T_caml_camr.isApprox(expected.T_caml_camr, 1e-12)) << frame.index;
  }
  EXPECT_NEAR(
      rotationDistance(sim.truthAt(773).T_veh_caml.linear(), sim.truthAt(774).T_veh_caml.linear()),
      10 * kDeg, 1e-9);
  // The initial guess is the frame-0 truth plus the initial error.
  const Vector12d guess = sim.initialGuess().toParameters();
  EXPECT_TRUE(guess.isApprox(s.truth + s.initial_error, 1e-12));
}

TEST(MeasurementSimulator, DriftMovesTheTruthLinearly) {
  MeasurementScenario s = driftScenario();
  s.target_points = 5;
  MeasurementSimulator sim(s);
  SimulatedFrame frame;
  while (sim.nextFrame(&frame)) {
    const Vector12d p = frame.truth.toParameters();
    ASSERT_NEAR(p(11), s.truth(11) + s.drift_per_second(11) * frame.stamp, 1e-12);
    ASSERT_NEAR(p(7), s.truth(7) + s.drift_per_second(7) * frame.stamp, 1e-12);
  }
}

TEST(MeasurementSimulator, SameSeedSameFramesOtherSeedOtherFrames) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 100;
  s.outlier_fraction = 0.05;
  MeasurementSimulator a(s), b(s);
  s.seed += 1;
  MeasurementSimulator c(s);
  const auto fa = runAll(&a), fb = runAll(&b), fc = runAll(&c);
  ASSERT_EQ(fa.size(), fb.size());
  bool differs = false;
  for (size_t k = 0; k < fa.size(); ++k) {
    ASSERT_EQ(fa[k].observations.size(), fb[k].observations.size());
    for (size_t i = 0; i < fa[k].observations.size(); ++i) {
      EXPECT_EQ(fa[k].observations[i].id, fb[k].observations[i].id);
      EXPECT_EQ(fa[k].observations[i].left_pixel, fb[k].observations[i].left_pixel);
      EXPECT_EQ(fa[k].observations[i].right_pixel, fb[k].observations[i].right_pixel);
    }
    EXPECT_EQ(fa[k].new_point_ids, fb[k].new_point_ids);
    EXPECT_EQ(fa[k].outlier_ids, fb[k].outlier_ids);
    EXPECT_TRUE(fa[k].measured_motion.T_prev_curr.matrix() ==
                fb[k].measured_motion.T_prev_curr.matrix());
    differs = differs || !(fa[k].measured_motion.T_prev_curr.matrix() ==
                           fc[k].measured_motion.T_prev_curr.matrix());
    if (!fc[k].observations.empty() && !fa[k].observations.empty()) {
      differs = differs || fa[k].observations[0].left_pixel != fc[k].observations[0].left_pixel;
    }
  }
  EXPECT_TRUE(differs);
  // The point positions differ too, not just the noise.
  EXPECT_NE(*a.worldPoint(1), *c.worldPoint(1));
}

TEST(MeasurementSimulator, NoiseLevelsDoNotChangeWhichPointsExist) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 100;
  MeasurementSimulator noisy(s);
  MeasurementSimulator clean(noiseFree());
  for (int k = 0; k < 100; ++k) {
    SimulatedFrame a, b;
    ASSERT_TRUE(noisy.nextFrame(&a));
    ASSERT_TRUE(clean.nextFrame(&b));
    ASSERT_EQ(a.new_point_ids, b.new_point_ids) << "frame " << k;
  }
}

TEST(MeasurementSimulator, DroppedTracksAreNeverReportedAgain) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 60;
  MeasurementSimulator sim(s);
  std::set<PointId> dropped;
  SimulatedFrame frame;
  while (sim.nextFrame(&frame)) {
    for (const StereoObservation& o : frame.observations) {
      ASSERT_FALSE(dropped.count(o.id)) << "dropped id " << o.id << " reported again";
    }
    // Drop every third observed point, plus ids the simulator does not know.
    std::vector<PointId> drop = {0, 999999};
    for (size_t i = 0; i < frame.observations.size(); i += 3) {
      drop.push_back(frame.observations[i].id);
    }
    const int live_before = sim.liveTrackCount();
    sim.dropTracks(drop);
    EXPECT_EQ(sim.liveTrackCount(), live_before - static_cast<int>(drop.size()) + 2);
    dropped.insert(drop.begin(), drop.end());
    // Dropped points stay queryable for evaluation.
    EXPECT_TRUE(sim.worldPoint(drop.back()).has_value());
  }
  EXPECT_GT(dropped.size(), 400u);
}

/// Runs a mounting and returns the mean number of observations after warm-up.
double meanPointsForMounting(const Vector6d& x_caml) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 400;
  s.truth.head<6>() = x_caml;
  MeasurementSimulator sim(s);
  std::vector<double> counts;
  SimulatedFrame frame;
  while (sim.nextFrame(&frame)) {
    if (frame.index >= 10) counts.push_back(frame.observations.size());
  }
  return mean(counts);
}

TEST(MeasurementSimulator, AnyCameraMountingGetsItsPoints) {
  Vector6d down, backwards, sideways;
  down << 0.5, 0.0, 1.5, 0.0, M_PI / 2, 0.0;
  backwards << -0.5, 0.0, 1.3, 0.0, 0.1, M_PI;
  sideways << 0.0, 0.8, 1.3, 0.0, 0.0, M_PI / 2;
  EXPECT_GT(meanPointsForMounting(down), 90.0);
  EXPECT_GT(meanPointsForMounting(backwards), 90.0);
  EXPECT_GT(meanPointsForMounting(sideways), 90.0);
}

TEST(MeasurementSimulator, BornPointsLieInTheConfiguredDepthRange) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 50;
  s.pixel_noise = 0.0;
  MeasurementSimulator sim(s);
  std::vector<double> inverse_depth;
  SimulatedFrame frame;
  while (sim.nextFrame(&frame)) {
    const Eigen::Isometry3d T_lopt_world =
        (frame.T_world_veh * frame.truth.vehicleToLeftOptical()).inverse();
    for (PointId id : frame.new_point_ids) {
      const double depth = (T_lopt_world * *sim.worldPoint(id)).z();
      ASSERT_GE(depth, s.min_depth - 1e-9);
      ASSERT_LE(depth, s.max_depth + 1e-9);
      inverse_depth.push_back(1.0 / depth);
    }
  }
  // Uniform in inverse depth (slightly biased to far points by the right-image check).
  EXPECT_NEAR(mean(inverse_depth), 0.5 * (1.0 / 3.0 + 1.0 / 60.0), 0.02);
}

TEST(MeasurementSimulator, ProducesExactlyTheConfiguredFramesQuickly) {
  const auto start = std::chrono::steady_clock::now();
  MeasurementSimulator sim(paperOffroadScenario());
  SimulatedFrame frame;
  int count = 0;
  while (sim.nextFrame(&frame)) ++count;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(count, 1500);
  EXPECT_EQ(frame.index, 1499) << "the last nextFrame() must not touch the frame";
  EXPECT_FALSE(sim.nextFrame(&frame));
  EXPECT_EQ(sim.framesProduced(), 1500);
  // Generous for a loaded CI machine; typically ~30 ms in RelWithDebInfo.
  EXPECT_LT(seconds, 1.0);
}

}  // namespace
}  // namespace osc
