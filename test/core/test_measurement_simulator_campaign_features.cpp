// Tests of the measurement simulator's campaign features (measurement_simulator.h,
// odometry_error.h): standing still, the odometry's time offset, scale error and Gauss-Markov
// biases, blind frames, moving points, recorded trajectories and the ground track with stops.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <vector>

#include "measurement_simulator_test_support.h"
#include "online_stereo_calibration/core/geometry/pose_interpolation.h"
#include "online_stereo_calibration/core/geometry/rotation.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"
#include "online_stereo_calibration/core/sim/odometry_error.h"

namespace osc {
namespace {

/// Every output of two frames is bit-identical.
void expectIdenticalFrames(const SimulatedFrame& a, const SimulatedFrame& b) {
  ASSERT_EQ(a.index, b.index);
  EXPECT_EQ(a.stamp, b.stamp);
  EXPECT_TRUE(a.measured_motion.T_prev_curr.matrix() == b.measured_motion.T_prev_curr.matrix())
      << "frame " << a.index;
  EXPECT_TRUE(a.true_motion.T_prev_curr.matrix() == b.true_motion.T_prev_curr.matrix());
  EXPECT_TRUE(a.T_world_veh.matrix() == b.T_world_veh.matrix());
  ASSERT_EQ(a.observations.size(), b.observations.size()) << "frame " << a.index;
  for (size_t i = 0; i < a.observations.size(); ++i) {
    EXPECT_EQ(a.observations[i].id, b.observations[i].id);
    EXPECT_EQ(a.observations[i].left_pixel, b.observations[i].left_pixel);
    EXPECT_EQ(a.observations[i].right_pixel, b.observations[i].right_pixel);
  }
  EXPECT_EQ(a.new_point_ids, b.new_point_ids);
  EXPECT_EQ(a.outlier_ids, b.outlier_ids);
  EXPECT_EQ(a.moving_ids, b.moving_ids);
}

TEST(MeasurementSimulator, StandingStillGivesIdentityIncrementsAndStillPixels) {
  MeasurementScenario s = noiseFree();
  s.motion.stops = {{5.0, 3.0}};
  s.motion.stop_ramp = 1.0;
  s.mean_track_length = INFINITY;
  MeasurementSimulator sim(s);
  const std::vector<SimulatedFrame> frames = runAll(&sim);
  std::map<PointId, Eigen::Vector2d> pixel_in_stop;
  int standing = 0;
  for (const SimulatedFrame& f : frames) {
    if (f.index < 1) continue;
    const bool in_stop = f.stamp - 0.1 >= 5.0 - 1e-9 && f.stamp <= 8.0 + 1e-9;
    if (in_stop) {
      ++standing;
      EXPECT_TRUE(f.true_motion.T_prev_curr.matrix() == Eigen::Matrix4d::Identity()) << f.index;
      EXPECT_TRUE(f.measured_motion.T_prev_curr.matrix() == Eigen::Matrix4d::Identity());
      EXPECT_TRUE(f.T_world_veh.matrix() == frames[50].T_world_veh.matrix());
      // Static points stand still in the image too.
      for (const StereoObservation& o : f.observations) {
        const auto seen = pixel_in_stop.emplace(o.id, o.left_pixel);
        EXPECT_EQ(seen.first->second, o.left_pixel) << "id " << o.id;
      }
    } else {
      EXPECT_GT(parametersFromPose(f.true_motion.T_prev_curr).head<3>().norm(), 0.0) << f.index;
    }
  }
  EXPECT_EQ(standing, 30);
}

TEST(MeasurementSimulator, TimeOffsetReportsTheMotionOfTheShiftedInterval) {
  for (double offset : {0.13, -0.27}) {
    SCOPED_TRACE(offset);
    MeasurementScenario s = noiseFree();
    s.frames = 60;
    s.odometry_error.time_offset = offset;
    MeasurementSimulator sim(s);
    const VehicleTrajectory reference(s.motion);
    double largest_true_difference = 0.0;
    for (const SimulatedFrame& f : runAll(&sim)) {
      if (f.index == 0) continue;
      const double t0 = f.stamp - 0.1, t1 = f.stamp;
      const Eigen::Isometry3d shifted =
          reference.pose(t0 + offset).inverse() * reference.pose(t1 + offset);
      ASSERT_TRUE(f.measured_motion.T_prev_curr.isApprox(shifted, 1e-12)) << "frame " << f.index;
      EXPECT_TRUE(f.true_motion.T_prev_curr.isApprox(
          reference.pose(t0).inverse() * reference.pose(t1), 1e-12));
      EXPECT_DOUBLE_EQ(f.measured_motion.dt, 0.1);
      largest_true_difference =
          std::max(largest_true_difference,
                   boxMinus(f.measured_motion.T_prev_curr, f.true_motion.T_prev_curr).norm());
    }
    EXPECT_GT(largest_true_difference, 1e-3) << "the offset must change the reported motion";
  }
}

TEST(MeasurementSimulator, AShiftedReadTakesThatMuchOfTheOffsetOut) {
  // The odometry read at the image stamps minus a shift (the estimator's offset estimate)
  // reports the motion offset - shift later than the cameras saw it, and says so.
  const double offset = 0.13;
  for (double shift : {0.13, 0.05, -0.02}) {
    SCOPED_TRACE(shift);
    MeasurementScenario s = noiseFree();
    s.frames = 30;
    s.odometry_error.time_offset = offset;
    MeasurementSimulator sim(s);
    const VehicleTrajectory reference(s.motion);
    sim.setOdometryTimeShift(shift);
    SimulatedFrame f;
    while (sim.nextFrame(&f)) {
      if (f.index == 0) continue;
      const double t0 = f.stamp - 0.1, t1 = f.stamp, rest = offset - shift;
      const Eigen::Isometry3d read =
          reference.pose(t0 + rest).inverse() * reference.pose(t1 + rest);
      ASSERT_TRUE(f.measured_motion.T_prev_curr.isApprox(read, 1e-12)) << "frame " << f.index;
      EXPECT_EQ(f.measured_motion.time_shift, shift);
      if (shift == offset) {
        EXPECT_TRUE(f.measured_motion.T_prev_curr.isApprox(f.true_motion.T_prev_curr, 1e-12));
      }
    }
  }
}

TEST(MeasurementSimulator, ScaleErrorScalesTheTranslationExactly) {
  MeasurementScenario s = noiseFree();
  s.frames = 50;
  s.odometry_error.scale_error = -0.07;
  MeasurementSimulator sim(s);
  for (const SimulatedFrame& f : runAll(&sim)) {
    const Eigen::Vector3d expected = 0.93 * f.true_motion.T_prev_curr.translation();
    ASSERT_LE((f.measured_motion.T_prev_curr.translation() - expected).norm(),
              1e-15 * (1.0 + expected.norm()))
        << "frame " << f.index;
    ASSERT_TRUE(
        f.measured_motion.T_prev_curr.linear().isApprox(f.true_motion.T_prev_curr.linear(), 1e-15));
  }
}

/// Sample autocorrelation of x at a lag.
double autocorrelation(const std::vector<double>& x, size_t lag) {
  const double m = mean(x);
  double num = 0.0, den = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    den += (x[i] - m) * (x[i] - m);
    if (i + lag < x.size()) num += (x[i] - m) * (x[i + lag] - m);
  }
  return num / den;
}

TEST(MeasurementSimulator, BiasesAreGaussMarkovWithTheConfiguredStdAndCorrelation) {
  MeasurementScenario s = noiseFree();
  s.frames = 20000;  // 2000 s = 2000 correlation times
  s.target_points = 1;
  s.odometry_error.rotation_rate_bias = 0.002;
  s.odometry_error.velocity_bias = 0.05;
  s.odometry_error.bias_correlation_time = 1.0;
  MeasurementSimulator sim(s);
  std::vector<std::vector<double>> bias(6);  // b_v (m/s), b_w (rad/s)
  SimulatedFrame f;
  while (sim.nextFrame(&f)) {
    if (f.index == 0) continue;
    const Vector6d e = boxMinus(f.measured_motion.T_prev_curr, f.true_motion.T_prev_curr) / 0.1;
    for (int i = 0; i < 6; ++i) bias[i].push_back(e(i));
  }
  for (int i = 0; i < 6; ++i) {
    SCOPED_TRACE(i);
    const double sigma = i < 3 ? 0.05 : 0.002;
    // ~1000 independent stretches: the std is known to ~2-3 %.
    EXPECT_NEAR(stddev(bias[i]), sigma, 0.1 * sigma);
    EXPECT_NEAR(mean(bias[i]), 0.0, 0.15 * sigma);
    // E[b(t) b(t + h)] = sigma^2 exp(-h / tau): 0.1 s -> 0.905, 1 s -> 0.368, 3 s -> 0.050.
    EXPECT_NEAR(autocorrelation(bias[i], 1), std::exp(-0.1), 0.02);
    EXPECT_NEAR(autocorrelation(bias[i], 10), std::exp(-1.0), 0.07);
    EXPECT_NEAR(autocorrelation(bias[i], 30), std::exp(-3.0), 0.07);
  }
  // The axes are independent.
  double cross = 0.0;
  for (size_t k = 0; k < bias[3].size(); ++k) cross += bias[3][k] * bias[4][k];
  EXPECT_NEAR(cross / bias[3].size() / (0.002 * 0.002), 0.0, 0.15);
}

TEST(MeasurementSimulator, ZeroOdometryErrorsAndUnusedFeaturesLeaveTheFramesBitIdentical) {
  MeasurementScenario base = paperOffroadScenario();
  base.frames = 200;
  base.outlier_fraction = 0.05;
  MeasurementScenario zero = base;
  zero.odometry_error = OdometryErrorModel();
  zero.odometry_error.bias_correlation_time = 3.0;  // no bias: irrelevant
  zero.motion.stop_ramp = 4.0;                      // no stop: irrelevant
  zero.moving_point_speed = 9.0;                    // no moving point: irrelevant
  MeasurementSimulator a(base), b(zero);
  const auto fa = runAll(&a), fb = runAll(&b);
  ASSERT_EQ(fa.size(), fb.size());
  for (size_t k = 0; k < fa.size(); ++k) expectIdenticalFrames(fa[k], fb[k]);

  // Odometry errors have their own random stream: the points, pixels and truth stay as
  // they were; only the measured motion changes.
  MeasurementScenario errors = base;
  errors.odometry_error.time_offset = 0.05;
  errors.odometry_error.scale_error = 0.02;
  errors.odometry_error.rotation_rate_bias = 0.001;
  errors.odometry_error.velocity_bias = 0.01;
  MeasurementSimulator c(errors);
  const auto fc = runAll(&c);
  for (size_t k = 0; k < fa.size(); ++k) {
    SimulatedFrame expected = fc[k];
    expected.measured_motion = fa[k].measured_motion;
    expectIdenticalFrames(fa[k], expected);
    if (k > 0) {
      EXPECT_FALSE(
          fa[k].measured_motion.T_prev_curr.isApprox(fc[k].measured_motion.T_prev_curr, 1e-9));
    }
  }
}

TEST(MeasurementSimulator, BlindFramesKillEveryTrackAndLaterTracksAreNew) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 120;
  s.blind_frames = {{50, 59}, {80, 80}};
  MeasurementScenario sighted = s;
  sighted.blind_frames.clear();
  MeasurementSimulator sim(s), reference(sighted);
  const auto frames = runAll(&sim), reference_frames = runAll(&reference);
  PointId largest_before = 0;
  for (const SimulatedFrame& f : frames) {
    const bool blind = (f.index >= 50 && f.index <= 59) || f.index == 80;
    EXPECT_EQ(f.blind, blind) << f.index;
    if (f.index < 50) {
      expectIdenticalFrames(f, reference_frames[f.index]);
      for (const StereoObservation& o : f.observations)
        largest_before = std::max(largest_before, o.id);
    }
    if (blind) {
      EXPECT_TRUE(f.observations.empty()) << f.index;
      EXPECT_TRUE(f.new_point_ids.empty()) << f.index;
      // The motion is still reported.
      EXPECT_TRUE(f.measured_motion.T_prev_curr.isApprox(
          reference_frames[f.index].measured_motion.T_prev_curr, 0.0));
    }
    if (f.index == 60 || f.index == 81) {
      // Everything seen right after a blind stretch is newly born, with ids never used before.
      ASSERT_FALSE(f.observations.empty());
      EXPECT_EQ(f.new_point_ids.size(), f.observations.size()) << f.index;
      for (const StereoObservation& o : f.observations) EXPECT_GT(o.id, largest_before);
    }
    for (const StereoObservation& o : f.observations)
      largest_before = std::max(largest_before, o.id);
  }
}

TEST(MeasurementSimulator, MovingPointsMoveHorizontallyAndTheirPixelsFollowThem) {
  MeasurementScenario s = noiseFree();
  s.frames = 200;
  s.moving_point_fraction = 0.3;
  s.moving_point_speed = 2.5;
  MeasurementSimulator sim(s);
  std::set<PointId> moving, born;
  size_t moving_checked = 0;
  SimulatedFrame f;
  while (sim.nextFrame(&f)) {
    born.insert(f.new_point_ids.begin(), f.new_point_ids.end());
    EXPECT_TRUE(std::is_sorted(f.moving_ids.begin(), f.moving_ids.end()));
    const std::set<PointId> moving_now(f.moving_ids.begin(), f.moving_ids.end());
    for (const StereoObservation& o : f.observations) {
      const Eigen::Vector3d at_birth = *sim.worldPoint(o.id);
      const Eigen::Vector3d now = *sim.worldPointAt(o.id, f.stamp);
      const TruePixels truth = projectTruth(sim, f, now);
      ASSERT_NEAR((o.left_pixel - truth.left).norm(), 0.0, 1e-9) << "id " << o.id;
      ASSERT_NEAR((o.right_pixel - truth.right).norm(), 0.0, 1e-9) << "id " << o.id;
      const Eigen::Vector3d velocity = *sim.worldPointAt(o.id, f.stamp + 1.0) - now;
      if (moving_now.count(o.id)) {
        moving.insert(o.id);
        EXPECT_NEAR(velocity.norm(), 2.5, 1e-9);
        EXPECT_EQ(velocity.z(), 0.0);
        EXPECT_EQ(now.z(), at_birth.z());
        ++moving_checked;
      } else {
        EXPECT_FALSE(moving.count(o.id)) << "a moving point reported as static";
        EXPECT_EQ(velocity.norm(), 0.0);
        EXPECT_EQ(now, at_birth);
      }
    }
  }
  EXPECT_GT(moving_checked, 1000u);
  EXPECT_NEAR(static_cast<double>(moving.size()) / born.size(), 0.3, 0.05);
  // Their directions are spread over the horizon (not all along one axis).
  std::vector<double> headings;
  for (PointId id : moving) {
    const Eigen::Vector3d v = *sim.worldPointAt(id, 1.0) - *sim.worldPointAt(id, 0.0);
    headings.push_back(std::atan2(v.y(), v.x()));
  }
  EXPECT_GT(stddev(headings), 1.5);  // uniform on (-pi, pi]: 1.81
}

TEST(MeasurementSimulator, RecordedTrajectoryGivesTheInterpolatedPoses) {
  VehicleMotionProfile recorded_motion;
  recorded_motion.speed = 6.0;
  recorded_motion.yaw_rate_amplitude = 0.4;
  MeasurementScenario s = noiseFree();
  s.frames = 150;
  s.rate_hz = 15.0;  // frames fall between the 20 Hz samples
  s.recorded_trajectory = recordingOf(recorded_motion, 20.0);
  s.recorded_start_offset = 3.3;
  s.odometry_error.time_offset = -0.2;
  MeasurementSimulator sim(s);
  const PoseTrajectory& file = *s.recorded_trajectory;
  for (const SimulatedFrame& f : runAll(&sim)) {
    const double stamp = 1000.0 + 3.3 + f.index / 15.0;
    ASSERT_TRUE(f.T_world_veh.isApprox(*file.smoothAt(stamp), 1e-12)) << "frame " << f.index;
    EXPECT_TRUE(sim.truePose(f.stamp).matrix() == f.T_world_veh.matrix());
    if (f.index == 0) continue;
    const Eigen::Isometry3d shifted =
        file.smoothAt(stamp - 1.0 / 15.0 - 0.2)->inverse() * *file.smoothAt(stamp - 0.2);
    ASSERT_TRUE(f.measured_motion.T_prev_curr.isApprox(shifted, 1e-12)) << "frame " << f.index;
  }
  // Observations follow the recorded poses (exact projections of static points).
  MeasurementSimulator again(s);
  SimulatedFrame f;
  while (again.nextFrame(&f)) {
    for (const StereoObservation& o : f.observations) {
      const TruePixels truth = projectTruth(again, f, *again.worldPoint(o.id));
      ASSERT_NEAR((o.left_pixel - truth.left).norm(), 0.0, 1e-9);
    }
  }
  // The ground track for the renderer runs along the recording over the drive.
  const std::vector<Eigen::Vector2d> track = sim.groundTrack();
  EXPECT_TRUE(track.front().isApprox(sim.truePose(0.0).translation().head<2>(), 1e-12));
  EXPECT_TRUE(track.back().isApprox(sim.truePose(10.0).translation().head<2>(), 1e-12));
  for (size_t i = 1; i < track.size(); ++i) EXPECT_LT((track[i] - track[i - 1]).norm(), 1.0);
  EXPECT_THROW(sim.truePose(30.0), std::out_of_range);
}

TEST(MeasurementSimulator, AnalyticGroundTrackCoversTheDriveWithStops) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 300;
  s.motion.stops = {{10.0, 8.0}};
  MeasurementSimulator sim(s);
  const std::vector<Eigen::Vector2d> track = sim.groundTrack();
  EXPECT_TRUE(track.front().isApprox(sim.truePose(0.0).translation().head<2>(), 1e-12));
  EXPECT_TRUE(track.back().isApprox(sim.truePose(30.0).translation().head<2>(), 1e-12));
  for (size_t i = 1; i < track.size(); ++i) EXPECT_LE((track[i] - track[i - 1]).norm(), 1.0);
}

TEST(OdometryErrorProcess, ZeroModelChangesNothingAndBiasesStartInTheSteadyState) {
  MotionIncrement truth;
  truth.T_prev_curr =
      poseFromParameters((Vector6d() << 0.3, 0.01, -0.02, 0.01, 0.02, 0.05).finished());
  truth.dt = 0.1;
  OdometryErrorProcess zero(OdometryErrorModel(), 1);
  EXPECT_TRUE(zero.isZero());
  EXPECT_TRUE(zero.apply(truth).T_prev_curr.matrix() == truth.T_prev_curr.matrix());
  // The bias at the first step is already drawn with the steady-state std.
  OdometryErrorModel model;
  model.rotation_rate_bias = 0.01;
  std::vector<double> first;
  for (unsigned seed = 1; seed <= 2000; ++seed) {
    OdometryErrorProcess process(model, seed);
    first.push_back(process.rotationRateBias().x());
  }
  EXPECT_NEAR(stddev(first), 0.01, 0.001);
}

}  // namespace
}  // namespace osc
