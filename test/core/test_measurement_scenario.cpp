// Tests of the measurement simulator's scenario (measurement_simulator.h): the paper's defaults,
// the drift scenario, and validate() naming every bad field, recorded trajectories too short
// included; the simulator refuses a bad scenario listing the problems.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "measurement_simulator_test_support.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"

namespace osc {
namespace {

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

}  // namespace
}  // namespace osc
