#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "online_stereo_calibration/core/geometry/pose_interpolation.h"
#include "online_stereo_calibration/core/geometry/rotation.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"
#include "online_stereo_calibration/core/sim/odometry_error.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

/// Runs a simulator to its end and keeps all frames.
std::vector<SimulatedFrame> runAll(MeasurementSimulator* sim) {
  std::vector<SimulatedFrame> frames;
  SimulatedFrame frame;
  while (sim->nextFrame(&frame)) frames.push_back(frame);
  return frames;
}

MeasurementScenario noiseFree() {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = 300;
  s.pixel_noise = 0.0;
  s.motion_rotation_noise = 0.0;
  s.motion_translation_noise = 0.0;
  return s;
}

struct TruePixels {
  Eigen::Vector2d left, right;
};

/// Projects a world point with the frame's true pose and calibration, independently of the
/// simulator's internals (the task statement's formula).
TruePixels projectTruth(const MeasurementSimulator& sim, const SimulatedFrame& frame,
                        const Eigen::Vector3d& point_world) {
  const Eigen::Isometry3d T_lopt_world =
      (frame.T_world_veh * frame.truth.vehicleToLeftOptical()).inverse();
  const Eigen::Vector3d in_left = T_lopt_world * point_world;
  const Eigen::Vector3d in_right = frame.truth.leftToRightOptical().inverse() * in_left;
  TruePixels pixels;
  EXPECT_TRUE(sim.leftCamera().project(in_left, &pixels.left));
  EXPECT_TRUE(sim.rightCamera().project(in_right, &pixels.right));
  return pixels;
}

double mean(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return sum / v.size();
}

double stddev(const std::vector<double>& v) {
  const double m = mean(v);
  double sum = 0.0;
  for (double x : v) sum += (x - m) * (x - m);
  return std::sqrt(sum / (v.size() - 1));
}

bool containsProblemAbout(const std::vector<std::string>& problems, const std::string& field) {
  for (const std::string& p : problems) {
    if (p.find(field) != std::string::npos) return true;
  }
  return false;
}

TEST(MeasurementScenario, DefaultsAreThePaperExperiment) {
  const MeasurementScenario s = paperOffroadScenario();
  EXPECT_TRUE(s.validate().empty());
  EXPECT_EQ(s.frames, 1500);
  EXPECT_NEAR(s.truth(2), 1.3, 1e-12);
  EXPECT_NEAR(s.truth(7), -0.30, 1e-12);
  EXPECT_NEAR(s.initial_error(0), 0.5, 1e-12);
  EXPECT_NEAR(s.initial_error(5), 10 * kDeg, 1e-12);
  EXPECT_NEAR(s.initial_error(7), 0.1, 1e-12);
  EXPECT_NEAR(s.step(5), 10 * kDeg, 1e-12);
  EXPECT_NEAR(s.step.norm(), 10 * kDeg, 1e-12);
  EXPECT_TRUE(urbanPlanarScenario().validate().empty());
  EXPECT_TRUE(urbanPlanarScenario().motion.planar);
  EXPECT_LT(urbanPlanarScenario().step_frame, 0);
  EXPECT_TRUE(driftScenario().validate().empty());
}

TEST(MeasurementScenario, DriftScenarioDriftsByTheStatedAmountOverTheDrive) {
  const MeasurementScenario s = driftScenario();
  const Vector12d change = s.truthParametersAt(s.frames) - s.truthParametersAt(0);
  EXPECT_NEAR(change(7), 0.002, 1e-12);
  EXPECT_NEAR(change(11), 0.2 * kDeg, 1e-12);
  EXPECT_NEAR(change.head<6>().norm(), 0.0, 1e-15);
}

TEST(MeasurementScenario, ValidateNamesEveryBadField) {
  MeasurementScenario s;
  s.frames = 0;
  s.rate_hz = 0.0;
  s.pixel_noise = -1.0;
  s.motion_rotation_noise = -0.1;
  s.motion_translation_noise = std::nan("");
  s.min_depth = 10.0;
  s.max_depth = 5.0;
  s.target_points = 0;
  s.max_new_points_per_frame = 0;
  s.mean_track_length = 0.5;
  s.outlier_fraction = 1.5;
  s.motion.speed = -1.0;
  s.motion.yaw_period = 0.0;
  s.left.fx = -1.0;
  s.truth(3) = std::nan("");
  const std::vector<std::string> problems = s.validate();
  for (const char* field :
       {"frames", "rate_hz", "pixel_noise", "motion_rotation_noise", "motion_translation_noise",
        "max_depth", "target_points", "max_new_points_per_frame", "mean_track_length",
        "outlier_fraction", "motion.speed", "motion.yaw_period", "left", "truth"}) {
    EXPECT_TRUE(containsProblemAbout(problems, field)) << "no problem names " << field;
  }
  EXPECT_FALSE(containsProblemAbout(problems, "right")) << "the right camera is valid";
  EXPECT_EQ(problems.size(), 14u);
}

TEST(MeasurementScenario, ValidateRejectsSingleProblemsWithTheirFieldName) {
  const auto problemsOf = [](auto mutate) {
    MeasurementScenario s;
    mutate(&s);
    return s.validate();
  };
  auto p = problemsOf([](MeasurementScenario* s) { s->frames = -3; });
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NE(p[0].find("frames"), std::string::npos);
  EXPECT_NE(p[0].find("-3"), std::string::npos) << "the message shows the bad value";
  p = problemsOf([](MeasurementScenario* s) { s->min_depth = s->max_depth; });
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NE(p[0].find("max_depth"), std::string::npos);
  p = problemsOf([](MeasurementScenario* s) { s->min_depth = 0.5; });
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NE(p[0].find("min_depth"), std::string::npos);
  p = problemsOf([](MeasurementScenario* s) { s->rate_hz = -10.0; });
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NE(p[0].find("rate_hz"), std::string::npos);
  p = problemsOf([](MeasurementScenario* s) { s->motion.yaw_phase = std::nan(""); });
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NE(p[0].find("motion.yaw_phase"), std::string::npos);
  // Boundary values that are allowed.
  EXPECT_TRUE(problemsOf([](MeasurementScenario* s) {
                s->pixel_noise = 0.0;
                s->outlier_fraction = 1.0;
                s->mean_track_length = INFINITY;
                s->min_depth = 1.0;
                s->motion.yaw_phase = -7.0;  // any finite phase
              }).empty());
}

TEST(MeasurementSimulator, ConstructorThrowsListingTheProblems) {
  MeasurementScenario s;
  s.frames = 0;
  s.pixel_noise = -0.5;
  try {
    MeasurementSimulator sim(s);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("frames"), std::string::npos) << what;
    EXPECT_NE(what.find("pixel_noise"), std::string::npos) << what;
  }
  s = MeasurementScenario();
  s.rate_hz = 0.0;
  EXPECT_THROW(MeasurementSimulator{s}, std::invalid_argument);
}

TEST(VehicleTrajectory, MovesAtTheProfileSpeedWithPaperLikeRollAndPitch) {
  const VehicleMotionProfile profile;
  const VehicleTrajectory trajectory(profile);
  EXPECT_TRUE(trajectory.pose(0.0).isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  std::vector<double> roll, pitch;
  const double h = 1e-4;
  for (double t = 0.0; t < 150.0; t += 0.1) {
    // The ground track is the integral of speed * heading: check its derivative.
    const Eigen::Vector2d velocity =
        (trajectory.groundPosition(t + h) - trajectory.groundPosition(t - h)) / (2 * h);
    const double yaw = trajectory.yaw(t);
    ASSERT_NEAR(velocity.x(), profile.speed * std::cos(yaw), 1e-6) << "t = " << t;
    ASSERT_NEAR(velocity.y(), profile.speed * std::sin(yaw), 1e-6) << "t = " << t;
    const Vector6d p = parametersFromPose(trajectory.pose(t));
    roll.push_back(p(3));
    pitch.push_back(p(4));
  }
  // Std of 1.75 deg as in the seed's off-road drive (algorithm.md).
  EXPECT_NEAR(stddev(roll), 1.75 * kDeg, 0.1 * kDeg);
  EXPECT_NEAR(stddev(pitch), 1.75 * kDeg, 0.1 * kDeg);
}

TEST(VehicleTrajectory, PositionIsContinuousAcrossSteeringPeriods) {
  // The whole-period shortcut and the quadrature must agree at the period boundaries.
  const VehicleMotionProfile profile;
  const VehicleTrajectory trajectory(profile);
  for (int k = 1; k < 6; ++k) {
    const double t = k * profile.yaw_period;
    const Eigen::Vector2d before = trajectory.groundPosition(t - 1e-9);
    const Eigen::Vector2d after = trajectory.groundPosition(t + 1e-9);
    EXPECT_LT((after - before).norm(), 1e-7) << "period " << k;
  }
}

TEST(VehicleTrajectory, TheSteeringPhaseStartsTheDriveInItsTurnAndHalfAPeriodMirrorsIt) {
  VehicleMotionProfile left_first, right_first, straight;
  right_first.yaw_phase = M_PI;
  straight.yaw_phase = M_PI / 2.0;  // yaw rate A cos(w t + pi/2) = -A sin(w t): then right
  const VehicleTrajectory left(left_first), right(right_first), ahead(straight);
  const double amplitude = left_first.yaw_rate_amplitude, h = 1e-4;
  const auto rate = [h](const VehicleTrajectory& v, double t) {
    return (v.yaw(t + h) - v.yaw(t - h)) / (2.0 * h);
  };
  // Every phase starts at the world's origin heading along +x.
  for (const VehicleTrajectory* v : {&left, &right, &ahead}) {
    EXPECT_NEAR(v->yaw(0.0), 0.0, 1e-15);
    EXPECT_TRUE(v->pose(0.0).isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  }
  EXPECT_NEAR(rate(left, 0.0), amplitude, 1e-6);
  EXPECT_NEAR(rate(right, 0.0), -amplitude, 1e-6);
  EXPECT_NEAR(rate(ahead, 0.0), 0.0, 1e-6);
  EXPECT_LT(rate(ahead, 2.0), -0.1 * amplitude);
  // Phase pi steers phase 0's drive mirrored in the x-z plane: yaw and y change sign, x stays
  // (roll, pitch and heave keep their own phases).
  for (double t = 0.0; t < 60.0; t += 0.7) {
    EXPECT_NEAR(right.yaw(t), -left.yaw(t), 1e-12) << t;
    const Eigen::Vector2d l = left.groundPosition(t), r = right.groundPosition(t);
    EXPECT_NEAR(r.x(), l.x(), 1e-9) << t;
    EXPECT_NEAR(r.y(), -l.y(), 1e-9) << t;
    EXPECT_EQ(right.roll(t), left.roll(t));
    EXPECT_EQ(right.heave(t), left.heave(t));
  }
  // The ground track still repeats every steering period (the whole-period shortcut).
  for (int k = 1; k < 4; ++k) {
    const double t = k * straight.yaw_period;
    EXPECT_LT((ahead.groundPosition(t + 1e-9) - ahead.groundPosition(t - 1e-9)).norm(), 1e-7);
  }
}

TEST(VehicleTrajectory, PhaseZeroIsTheUnshiftedSteeringBitForBit) {
  // Scenarios written before the phase existed must drive exactly as before.
  const VehicleMotionProfile profile;
  ASSERT_EQ(profile.yaw_phase, 0.0);
  const VehicleTrajectory trajectory(profile);
  const double heading_amplitude = profile.yaw_rate_amplitude * profile.yaw_period / (2 * M_PI);
  for (double t = 0.0; t < 100.0; t += 0.31) {
    EXPECT_EQ(trajectory.yaw(t), heading_amplitude * std::sin(2.0 * M_PI * t / profile.yaw_period));
  }
}

TEST(VehicleTrajectory, PlanarProfileHasNoRollPitchOrHeave) {
  VehicleMotionProfile profile;
  profile.planar = true;
  const VehicleTrajectory trajectory(profile);
  for (double t = 0.0; t < 30.0; t += 0.37) {
    const Eigen::Isometry3d pose = trajectory.pose(t);
    EXPECT_NEAR(pose.translation().z(), 0.0, 1e-15);
    EXPECT_NEAR((pose.linear() * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ()).norm(), 0.0,
                1e-15);
  }
}

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

// ---------------------------------------------------------------------------------------------
// Campaign features: stops, odometry errors, blind frames, moving points, recorded trajectories
// ---------------------------------------------------------------------------------------------

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

/// Ground speed (m/s) by central differences.
double groundSpeed(const VehicleTrajectory& trajectory, double t) {
  const double h = 1e-5;
  return (trajectory.groundPosition(t + h) - trajectory.groundPosition(t - h)).norm() / (2 * h);
}

TEST(VehicleTrajectory, StopsStandStillWithSmoothRampsAndThenDriveOn) {
  VehicleMotionProfile profile;
  profile.stops = {{10.0, 5.0}, {30.0, 2.0}};
  profile.stop_ramp = 2.0;
  const VehicleTrajectory stopping(profile);
  VehicleMotionProfile plain = profile;
  plain.stops.clear();
  const VehicleTrajectory driving(plain);
  // Before the first slow-down: the same drive, bit for bit.
  for (double t = 0.0; t <= 8.0; t += 0.5) {
    EXPECT_TRUE(stopping.pose(t).matrix() == driving.pose(t).matrix()) << "t = " << t;
  }
  // Inside the stop everything stands: the same pose, zero speed, exactly identity motion.
  const Eigen::Isometry3d standing = stopping.pose(10.0);
  for (double t = 10.0; t <= 15.0; t += 0.1) {
    EXPECT_TRUE(stopping.pose(t).matrix() == standing.matrix()) << "t = " << t;
    EXPECT_TRUE(stopping.motionBetween(10.0, t).matrix() == Eigen::Matrix4d::Identity());
    EXPECT_EQ(stopping.profileRate(t), 0.0);
  }
  EXPECT_NEAR(groundSpeed(stopping, 12.5), 0.0, 1e-9);
  // Smooth speed: it follows speed * rate, without jumps, full before and after the ramps.
  double previous = groundSpeed(stopping, 7.0);
  EXPECT_NEAR(previous, profile.speed, 1e-6);
  for (double t = 7.0; t <= 18.0; t += 0.01) {
    const double speed = groundSpeed(stopping, t);
    ASSERT_NEAR(speed, profile.speed * stopping.profileRate(t), 1e-5) << "t = " << t;
    // Max slope of the smoothstep ramp: 1.5 / stop_ramp per s.
    ASSERT_LE(std::abs(speed - previous), profile.speed * 1.5 / profile.stop_ramp * 0.01 + 1e-5)
        << "speed jumps at t = " << t;
    previous = speed;
  }
  EXPECT_NEAR(groundSpeed(stopping, 17.5), profile.speed, 1e-6);
  // Afterwards the profile continues where it stopped: it lags by duration + ramp per stop.
  EXPECT_DOUBLE_EQ(stopping.profileTime(25.0), 25.0 - 7.0);
  EXPECT_TRUE(stopping.pose(25.0).isApprox(driving.pose(18.0), 1e-12));
  EXPECT_TRUE(stopping.pose(40.0).isApprox(driving.pose(40.0 - 7.0 - 4.0), 1e-12));
  // The yaw, roll, pitch and heave are frozen with the vehicle's clock.
  EXPECT_EQ(stopping.roll(11.0), stopping.roll(14.0));
  EXPECT_EQ(stopping.yaw(31.0), driving.yaw(30.0 - 7.0 - 1.0));
}

TEST(VehicleTrajectory, AnAbruptStopWithoutRampAlsoStandsStill) {
  VehicleMotionProfile profile;
  profile.stops = {{0.0, 3.0}};
  profile.stop_ramp = 0.0;
  const VehicleTrajectory trajectory(profile);
  EXPECT_TRUE(trajectory.pose(0.0).matrix() == trajectory.pose(3.0).matrix());
  EXPECT_EQ(trajectory.profileTime(5.0), 2.0);
  EXPECT_NEAR(groundSpeed(trajectory, 5.0), profile.speed, 1e-6);
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

/// Samples a VehicleTrajectory at 20 Hz from stamp 1000 into a PoseTrajectory (a recording).
std::shared_ptr<const PoseTrajectory> recordingOf(const VehicleMotionProfile& profile,
                                                  double seconds) {
  const VehicleTrajectory trajectory(profile);
  std::vector<StampedPose> poses;
  for (int k = 0; k * 0.05 <= seconds; ++k) {
    poses.push_back({1000.0 + k * 0.05, trajectory.pose(k * 0.05)});
  }
  return std::make_shared<const PoseTrajectory>(poses);
}

// Issue 15: a recorded drive's twists must be the derivative of its pose, also across the
// recorded samples; at()'s linear pieces jump there, smoothAt() does not.
TEST(PoseTrajectory, SmoothAtPassesThroughThePosesWithContinuousVelocityAndRate) {
  VehicleMotionProfile profile;
  profile.speed = 6.0;
  profile.yaw_rate_amplitude = 0.4;
  const VehicleTrajectory analytic(profile);
  const std::shared_ptr<const PoseTrajectory> recording = recordingOf(profile, 5.0);
  const auto twist = [](const auto& poseAt, double t0, double t1) -> Vector6d {
    return logSE3(poseAt(t0).inverse() * poseAt(t1)) / (t1 - t0);
  };
  const auto smooth = [&recording](double t) { return *recording->smoothAt(t); };
  const auto linear = [&recording](double t) { return *recording->at(t); };
  const double h = 1e-5;
  double smooth_jump = 0.0, linear_jump = 0.0, smooth_error = 0.0, linear_error = 0.0;
  for (int k = 1; k < 99; ++k) {
    const double t = 1000.0 + 0.05 * k;
    ASSERT_TRUE(smooth(t).isApprox(recording->poses()[k].pose, 1e-12)) << "sample " << k;
    // The twist just before and just after the sample.
    smooth_jump = std::max(smooth_jump, (twist(smooth, t - h, t) - twist(smooth, t, t + h)).norm());
    linear_jump = std::max(linear_jump, (twist(linear, t - h, t) - twist(linear, t, t + h)).norm());
    // Between samples, against the drive that was recorded.
    const double between = t + 0.02;
    smooth_error += boxMinus(smooth(between), analytic.pose(between - 1000.0)).norm();
    linear_error += boxMinus(linear(between), analytic.pose(between - 1000.0)).norm();
  }
  EXPECT_LT(smooth_jump, 1e-3);  // m/s + rad/s: only the finite difference's own error
  EXPECT_GT(linear_jump, 0.05);  // 6 m/s, 0.4 rad/s of steering: the twist turns by 0.1
  EXPECT_LT(smooth_error, 0.2 * linear_error);
  // The ends and outside behave as at().
  EXPECT_TRUE(recording->smoothAt(1000.0)->isApprox(*recording->at(1000.0), 1e-12));
  EXPECT_FALSE(recording->smoothAt(999.0).has_value());
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

TEST(MeasurementScenario, RecordedTrajectoryTooShortNamesFramesAndStartOffset) {
  MeasurementScenario s = noiseFree();
  s.frames = 200;  // 19.9 s
  s.recorded_trajectory = recordingOf(VehicleMotionProfile(), 20.0);
  EXPECT_TRUE(s.validate().empty());
  s.recorded_start_offset = 0.2;
  try {
    MeasurementSimulator sim(s);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("frames"), std::string::npos) << what;
    EXPECT_NE(what.find("recorded_start_offset"), std::string::npos) << what;
  }
  // The time offset must fit too, at both ends.
  s.recorded_start_offset = 0.0;
  s.odometry_error.time_offset = 0.2;
  EXPECT_TRUE(containsProblemAbout(s.validate(), "recorded_start_offset"));
  s.odometry_error.time_offset = -0.2;
  EXPECT_TRUE(containsProblemAbout(s.validate(), "recorded_start_offset"));
  s.recorded_start_offset = 0.2;
  s.frames = 190;
  EXPECT_TRUE(s.validate().empty());
  // Stops belong to the analytic motion, which the recording replaces.
  s.motion.stops = {{1.0, 1.0}};
  EXPECT_TRUE(containsProblemAbout(s.validate(), "motion.stops"));
}

TEST(MeasurementScenario, ValidateNamesEveryBadNewField) {
  const auto problemsOf = [](auto mutate) {
    MeasurementScenario s;
    mutate(&s);
    return s.validate();
  };
  const auto expectOnly = [](const std::vector<std::string>& problems, const std::string& field) {
    ASSERT_EQ(problems.size(), 1u) << (problems.empty() ? "none" : problems[0]);
    EXPECT_NE(problems[0].find(field), std::string::npos) << problems[0];
  };
  expectOnly(problemsOf([](MeasurementScenario* s) { s->motion.stop_ramp = -1.0; }),
             "motion.stop_ramp");
  expectOnly(problemsOf([](MeasurementScenario* s) {
               s->motion.stops = {{-1.0, 2.0}};
             }),
             "motion.stops[0].start");
  expectOnly(problemsOf([](MeasurementScenario* s) {
               s->motion.stops = {{5.0, 0.0}};
             }),
             "motion.stops[0].duration");
  expectOnly(problemsOf([](MeasurementScenario* s) {
               s->motion.stops = {{140.0, 10.0}};
             }),
             "motion.stops[0]");  // beyond the 149.9 s drive
  expectOnly(problemsOf([](MeasurementScenario* s) {
               s->motion.stops = {{20.0, 5.0}, {10.0, 1.0}};
             }),
             "motion.stops[1]");  // out of order
  expectOnly(problemsOf([](MeasurementScenario* s) {
               s->motion.stops = {{10.0, 5.0}, {16.5, 1.0}};
             }),
             "motion.stops[1]");  // the ramps (1 s each) overlap
  EXPECT_TRUE(problemsOf([](MeasurementScenario* s) {
                s->motion.stops = {{0.0, 5.0}, {7.0, 1.0}, {140.0, 9.5}};
              }).empty());
  expectOnly(problemsOf([](MeasurementScenario* s) { s->odometry_error.time_offset = 0.6; }),
             "odometry_error.time_offset");
  expectOnly(problemsOf([](MeasurementScenario* s) { s->odometry_error.scale_error = -0.3; }),
             "odometry_error.scale_error");
  expectOnly(problemsOf([](MeasurementScenario* s) { s->odometry_error.rotation_rate_bias = -1; }),
             "odometry_error.rotation_rate_bias");
  expectOnly(problemsOf([](MeasurementScenario* s) { s->odometry_error.velocity_bias = NAN; }),
             "odometry_error.velocity_bias");
  expectOnly(
      problemsOf([](MeasurementScenario* s) { s->odometry_error.bias_correlation_time = 0; }),
      "odometry_error.bias_correlation_time");
  expectOnly(problemsOf([](MeasurementScenario* s) {
               s->blind_frames = {{-1, 3}};
             }),
             "blind_frames[0].first");
  expectOnly(problemsOf([](MeasurementScenario* s) {
               s->blind_frames = {{5, 3}};
             }),
             "blind_frames[0].last");
  expectOnly(problemsOf([](MeasurementScenario* s) {
               s->blind_frames = {{1495, 1500}};
             }),
             "blind_frames[0].last");
  expectOnly(problemsOf([](MeasurementScenario* s) {
               s->blind_frames = {{10, 20}, {20, 30}};
             }),
             "blind_frames[1].first");
  EXPECT_TRUE(problemsOf([](MeasurementScenario* s) {
                s->blind_frames = {{0, 0}, {1, 1499}};
              }).empty());
  expectOnly(problemsOf([](MeasurementScenario* s) { s->moving_point_fraction = 1.1; }),
             "moving_point_fraction");
  expectOnly(problemsOf([](MeasurementScenario* s) { s->moving_point_speed = -2; }),
             "moving_point_speed");
  expectOnly(problemsOf([](MeasurementScenario* s) { s->recorded_start_offset = -1; }),
             "recorded_start_offset");
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
