/// @file test_bag_tools.cpp
/// @brief The bag tools without a ROS master: pose interpolation, stereo pairing, scenario
/// files, and a short simulated drive (320x240, 60 frames) through the built `simulate` and
/// `evaluate` executables: CSV columns, table, plots, RMSE recomputed from the CSVs, truth
/// topic == reference.csv == truth.yaml.
#include <unistd.h>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "../../src/tools/ros/bag_io.h"
#include "online_stereo_calibration/tools/bag_evaluation.h"
#include "online_stereo_calibration/tools/calibration_file.h"
#include "online_stereo_calibration/tools/drive_simulation.h"
#include "online_stereo_calibration/tools/estimates_csv.h"
#include "online_stereo_calibration/tools/evaluation.h"
#include "online_stereo_calibration/tools/scenario_file.h"
#include "online_stereo_calibration/tools/tum_trajectory.h"
#include "tool_test_helpers.h"

namespace {

Eigen::Isometry3d pose(double x, double y, double z, double roll, double pitch, double yaw) {
  osc::Vector6d p;
  p << x, y, z, roll, pitch, yaw;
  return osc::poseFromParameters(p);
}

bool isFile(const std::string& path) { return std::ifstream(path).good(); }

using osc_test::findTool;
using osc_test::readText;

}  // namespace

TEST(PoseInterpolation, LinearAndSlerpBetweenSamples) {
  osc::PoseTrajectory trajectory;
  trajectory.append(10.0, pose(0, 0, 0, 0, 0, 0));
  trajectory.append(11.0, pose(2, -4, 1, 0, 0, 0.4));
  trajectory.append(12.0, pose(2, -4, 1, 0.2, 0, 0.4));
  const auto mid = trajectory.at(10.25);
  ASSERT_TRUE(mid.has_value());
  EXPECT_TRUE(mid->translation().isApprox(Eigen::Vector3d(0.5, -1.0, 0.25), 1e-12));
  const osc::Vector6d p = osc::parametersFromPose(*mid);
  EXPECT_NEAR(p(5), 0.1, 1e-12);  // a quarter of the yaw
  EXPECT_NEAR(p(3), 0.0, 1e-12);
  const auto later = trajectory.at(11.5);
  ASSERT_TRUE(later.has_value());
  EXPECT_NEAR(osc::parametersFromPose(*later)(3), 0.1, 1e-12);
  EXPECT_TRUE(trajectory.at(11.0)->isApprox(pose(2, -4, 1, 0, 0, 0.4), 1e-12));
  EXPECT_FALSE(trajectory.at(9.9).has_value());
  EXPECT_FALSE(trajectory.at(12.1).has_value());
  EXPECT_TRUE(trajectory.at(12.01, 0.02).has_value());

  const auto motion = trajectory.motionBetween(10.0, 11.0);
  ASSERT_TRUE(motion.has_value());
  EXPECT_DOUBLE_EQ(motion->dt, 1.0);
  EXPECT_TRUE(motion->T_prev_curr.isApprox(pose(2, -4, 1, 0, 0, 0.4), 1e-12));
  EXPECT_FALSE(trajectory.motionBetween(11.0, 10.0).has_value());
  EXPECT_THROW(trajectory.append(5.0, pose(0, 0, 0, 0, 0, 0)), std::invalid_argument);

  trajectory.pruneBefore(11.5);
  EXPECT_EQ(trajectory.size(), 2u);
  EXPECT_TRUE(trajectory.at(11.5).has_value());
}

TEST(PoseInterpolation, ReadsTheEurocTumTrajectory) {
  const std::string path =
      std::string(OSC_SOURCE_DIR) + "/../shared/data/trajectories/euroc_V1_01_easy_rep103.tum";
  if (!isFile(path)) GTEST_SKIP() << "no " << path;
  const osc::PoseTrajectory trajectory = osc::readTumTrajectory(path);
  EXPECT_GT(trajectory.size(), 2800u);
  EXPECT_NEAR(trajectory.lastStamp() - trajectory.firstStamp(), 144.7, 1.0);
  EXPECT_NEAR(trajectory.poses().front().pose.translation().x(), 0.878895, 1e-9);
}

TEST(StereoPairing, PairsExactStampsOnly) {
  const auto pairs = osc::pairByExactStamp({10, 20, 30, 40, 40, 50}, {5, 20, 31, 40, 50, 60});
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0], std::make_pair(std::size_t(1), std::size_t(1)));
  EXPECT_EQ(pairs[1], std::make_pair(std::size_t(3), std::size_t(3)));
  EXPECT_EQ(pairs[2], std::make_pair(std::size_t(5), std::size_t(4)));
}

TEST(ScenarioFile, ShippedScenariosParse) {
  for (const std::string name : {"paper_offroad", "urban_planar", "drift", "mav_euroc"}) {
    SCOPED_TRACE(name);
    const std::string path = std::string(OSC_SOURCE_DIR) + "/config/scenarios/" + name + ".yaml";
    if (name == "mav_euroc" && !isFile(std::string(OSC_SOURCE_DIR) + "/../shared/data/README.md")) {
      continue;
    }
    const osc::SimulationScenario s = osc::readScenarioFile(path);
    EXPECT_EQ(s.measurement.name, name);
    EXPECT_TRUE(s.measurement.validate().empty());
  }
  const osc::SimulationScenario paper =
      osc::readScenarioFile(std::string(OSC_SOURCE_DIR) + "/config/scenarios/paper_offroad.yaml");
  EXPECT_TRUE(paper.measurement.truth.isApprox(osc::paperOffroadScenario().truth, 1e-12));
  EXPECT_EQ(paper.measurement.step_frame, 774);
}

TEST(ScenarioFile, EurocRigFromSensorYaml) {
  const std::string path = std::string(OSC_SOURCE_DIR) + "/config/scenarios/mav_euroc.yaml";
  const std::string data = std::string(OSC_SOURCE_DIR) + "/../shared/data/README.md";
  if (!isFile(data))
    GTEST_SKIP() << "needs the EuRoC data of ../shared/data: " << data << " not found";
  const osc::SimulationScenario s = osc::readScenarioFile(path);
  EXPECT_EQ(s.measurement.left.width, 752);
  EXPECT_DOUBLE_EQ(s.measurement.left.fx, 458.654);
  EXPECT_EQ(s.measurement.left.distortion.size(), 4u);
  EXPECT_NEAR(s.measurement.truth(7), -0.110, 0.002);  // yr = -baseline
  ASSERT_TRUE(s.trajectory.has_value());
}

TEST(ScenarioFile, ErrorsNameTheKey) {
  const auto message = [](const std::string& text) {
    try {
      osc::parseScenarioYaml(text, "test.yaml", ".");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message("framez: 10\n").find("framez"), std::string::npos);
  EXPECT_NE(message("motion: {sped: 3}\n").find("motion.sped"), std::string::npos);
  EXPECT_NE(message("rate_hz: fast\n").find("rate_hz"), std::string::npos);
  EXPECT_NE(message("truth: {vehicle_to_left: [1, 2]}\n").find("truth.vehicle_to_left"),
            std::string::npos);
  EXPECT_NE(message("rendering: {supersampling: 9}\n").find("rendering.supersampling"),
            std::string::npos);
  EXPECT_NE(message("frames: -3\n").find("frames"), std::string::npos);
  EXPECT_NE(message("left_camera: {distortion_model: wavy}\n").find("left_camera.distortion_model"),
            std::string::npos);
}

TEST(DriveSimulation, AShortenedDriveIsTheBeginningOfTheFullOne) {
  // simulate --frames N (and scripts/demo.sh) render the first N frames of the same scene.
  const osc::SimulationScenario scenario = osc::parseScenarioYaml(
      "base: paper_offroad\nframes: 300\n"
      "left_camera: {width: 160, height: 120, fx: 150, fy: 150, cx: 79.5, cy: 59.5}\n"
      "right_camera: {width: 160, height: 120, fx: 150, fy: 150, cx: 79.5, cy: 59.5}\n"
      "rendering: {supersampling: 1}\n",
      "short.yaml", ".");
  const osc::DriveSimulator shortened(scenario, 5), full(scenario);
  const osc::SimulatedImagePair a = shortened.renderFrame(4), b = full.renderFrame(4);
  EXPECT_EQ(cv::norm(a.left, b.left, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.right, b.right, cv::NORM_INF), 0.0);
  EXPECT_TRUE(a.truth.isApprox(b.truth, 0.0));
  EXPECT_NE(osc::scenarioFingerprint(scenario, 5), osc::scenarioFingerprint(scenario, 300));
}

// Issue 15: an odometry bag whose twist is all zero while the vehicle moves (a driver, or an
// older `simulate`, that does not fill it) gives no twists, with the reason; a NaN twist
// none around it; the others are read.
TEST(BagTools, OdometryTwistsAreReadUnlessUnset) {
  char dir_template[] = "/tmp/osc_bag_twists_XXXXXX";
  const std::string path = std::string(mkdtemp(dir_template)) + "/odom.bag";
  const osc::bag::DriveTopics names;
  for (const bool unset : {true, false}) {
    {
      rosbag::Bag bag(path, rosbag::bagmode::Write);
      for (int k = 0; k < 20; ++k) {
        const double t = 100.0 + 0.05 * k;
        osc::Vector6d twist = osc::Vector6d::Zero();
        if (!unset) twist << 4.0 + 0.1 * k, 0.0, 0.0, 0.0, 0.0, 0.2;
        if (!unset && k == 12) twist(5) = std::nan("");
        const nav_msgs::Odometry m =
            osc::bag::toOdometry({t, pose(0.2 * k, 0, 0, 0, 0, 0.01 * k)}, twist, names);
        bag.write("/odom", m.header.stamp, m);
      }
    }
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    const osc::bag::OdometryAndCalibration read =
        osc::bag::readOdometryAndCalibration(bag, "/odom", "");
    osc::Vector6d twist;
    if (unset) {
      EXPECT_EQ(read.samples_without_twist, 19);  // the first has nothing to compare with
      EXPECT_NE(read.twist_problem.find("zero"), std::string::npos) << read.twist_problem;
      EXPECT_FALSE(read.odometry_twists.twistAt(100.52, &twist));
    } else {
      EXPECT_EQ(read.samples_without_twist, 1);
      EXPECT_NE(read.twist_problem.find("not finite"), std::string::npos) << read.twist_problem;
      ASSERT_TRUE(read.odometry_twists.twistAt(100.225, &twist));
      EXPECT_NEAR(twist(0), 4.45, 1e-9);
      EXPECT_NEAR(twist(5), 0.2, 1e-12);
      EXPECT_FALSE(read.odometry_twists.twistAt(100.57, &twist));
    }
  }
}

TEST(BagTools, SimulateThenEvaluateShortDrive) {
  const std::string simulate = findTool("simulate");
  const std::string evaluate = findTool("evaluate");
  if (simulate.empty() || evaluate.empty()) {
    GTEST_SKIP() << "simulate/evaluate not built (make simulate evaluate)";
  }
  char dir_template[] = "/tmp/osc_bag_tools_XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  {
    std::ofstream scenario(dir + "/short.yaml");
    scenario << "base: paper_offroad\nname: short\nframes: 60\nrate_hz: 10\nstep_frame: 30\n"
                "left_camera: {width: 320, height: 240, fx: 300, fy: 300, cx: 159.5, cy: 119.5}\n"
                "right_camera: {width: 320, height: 240, fx: 300, fy: 300, cx: 159.5, cy: 119.5}\n"
                "rendering: {supersampling: 1}\n";
  }
  ASSERT_EQ(std::system((simulate + " --scenario " + dir + "/short.yaml --out " + dir + "/sim 2> " +
                         dir + "/simulate.log")
                            .c_str()),
            0)
      << readText(dir + "/simulate.log");
  const std::string bag_path = dir + "/sim/drive.bag";
  ASSERT_TRUE(isFile(bag_path));

  // The truth topic, reference.csv and truth.yaml agree.
  const auto reference = osc::readReferenceCsv(dir + "/sim/reference.csv");
  ASSERT_EQ(reference.size(), 60u);
  {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
    const auto truth = osc::bag::readCalibrationTopic(bag, "/ground_truth/calibration");
    ASSERT_EQ(truth.size(), 60u);
    for (std::size_t k = 0; k < truth.size(); ++k) {
      EXPECT_NEAR(truth[k].first * 1e-9, reference[k].stamp, 1e-6);
      EXPECT_TRUE(truth[k].second.isApprox(reference[k].parameters, 1e-12)) << "frame " << k;
    }
    EXPECT_GT(reference[30].parameters(5) - reference[29].parameters(5), 0.17);  // the step
    const osc::PoseTrajectory odom = osc::bag::readOdometry(bag, "/odom");
    EXPECT_GE(odom.lastStamp(), reference.back().stamp);
    EXPECT_LE(odom.firstStamp(), reference.front().stamp);
    // Issue 15: the odometry carries the vehicle's twist, which `evaluate` reads at the image
    // stamps; it agrees with the (noisy) odometry poses' own mean motion over 1 s.
    const osc::bag::OdometryAndCalibration read =
        osc::bag::readOdometryAndCalibration(bag, "/odom", "");
    EXPECT_EQ(read.samples_without_twist, 0) << read.twist_problem;
    for (int k : {10, 30, 49}) {
      osc::Vector6d twist;
      ASSERT_TRUE(read.odometry_twists.twistAt(reference[k].stamp, &twist)) << "frame " << k;
      const auto mean = odom.motionBetween(reference[k].stamp - 0.5, reference[k].stamp + 0.5);
      ASSERT_TRUE(mean.has_value());
      const osc::Vector6d mean_twist = osc::logSE3(mean->T_prev_curr) / mean->dt;
      EXPECT_NEAR(twist(0), mean_twist(0), 0.1 * std::abs(mean_twist(0))) << "frame " << k;
      EXPECT_GT(twist(0), 1.0);  // forward, at the paper's few m/s
    }
  }
  const osc::CalibrationFile truth_file = osc::readCalibrationFile(dir + "/sim/truth.yaml");
  EXPECT_TRUE(truth_file.extrinsics.toParameters().isApprox(reference[0].parameters, 1e-12));
  const osc::CalibrationFile guess = osc::readCalibrationFile(dir + "/sim/initial_guess.yaml");
  EXPECT_NEAR(guess.extrinsics.toParameters()(0) - reference[0].parameters(0), 0.5, 1e-9);

  // The cache: a second run does nothing.
  ASSERT_EQ(std::system((simulate + " --scenario " + dir + "/short.yaml --out " + dir + "/sim 2> " +
                         dir + "/simulate2.log")
                            .c_str()),
            0);
  EXPECT_NE(readText(dir + "/simulate2.log").find("up to date"), std::string::npos);

  ASSERT_EQ(std::system((evaluate + " --bag " + bag_path + " --out " + dir +
                         "/eval --truth-topic /ground_truth/calibration --window 40 59 > " + dir +
                         "/evaluate.log 2>&1")
                            .c_str()),
            0)
      << readText(dir + "/evaluate.log");
  const std::string csv = readText(dir + "/eval/estimates.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')), osc::estimatesCsvHeader());
  const auto estimates = osc::readEstimatesCsv(dir + "/eval/estimates.csv");
  EXPECT_GE(estimates.size(), 55u);
  EXPECT_TRUE(isFile(dir + "/eval/reference.csv"));
  for (const std::string png : {"vehicle_to_left.png", "left_to_right.png", "errors.png"}) {
    EXPECT_TRUE(isFile(dir + "/eval/" + png)) << png;
  }

  // RMSE of xl and of yaw_l over frames 40-59 recomputed from the CSVs = the table's.
  const std::string table = readText(dir + "/eval/table.txt");
  const auto tableRmse = [&](const std::string& name) {
    const auto line_start = table.find("\n" + name + " ");
    EXPECT_NE(line_start, std::string::npos) << name;
    std::istringstream line(table.substr(line_start + 1));
    std::string label, unit;
    double rmse = NAN;
    line >> label >> unit >> rmse;
    return rmse;
  };
  const auto ownRmse = [&](int p) {
    double sum = 0;
    int n = 0;
    for (const auto& e : estimates) {
      if (e.frame < 40 || e.frame > 59) continue;
      const double error = osc::parameterError(e.parameters, reference[e.frame].parameters, p);
      sum += error * error;
      ++n;
    }
    return std::sqrt(sum / n);
  };
  const double xl = ownRmse(0), yaw_l = ownRmse(5) * 180.0 / M_PI;
  EXPECT_NEAR(tableRmse("xl"), xl, 1e-5 + 1e-4 * xl);
  EXPECT_NEAR(tableRmse("yaw_l"), yaw_l, 1e-5 + 1e-4 * yaw_l);
  EXPECT_NE(table.find("time per frame: median"), std::string::npos);
  EXPECT_NE(table.find("mean NEES"), std::string::npos);

  // A missing topic is named with its option, and the bag's topics are listed.
  const auto run = [&](const std::string& arguments, const std::string& log) {
    return std::system((evaluate + " " + arguments + " > " + dir + "/" + log + " 2>&1").c_str());
  };
  EXPECT_NE(run("--bag " + bag_path + " --out " + dir + "/bad --odom /nope", "missing.log"), 0);
  const std::string missing = readText(dir + "/missing.log");
  EXPECT_NE(missing.find("--odom /nope: not in the bag"), std::string::npos) << missing;
  EXPECT_NE(missing.find("/stereo/left/image_raw  sensor_msgs/Image  (60 messages)"),
            std::string::npos)
      << missing;
  EXPECT_NE(missing.find("/odom  nav_msgs/Odometry"), std::string::npos) << missing;
  EXPECT_NE(run("--bag " + bag_path + " --out " + dir + "/bad --stereo-ns /cam", "ns.log"), 0);
  EXPECT_NE(readText(dir + "/ns.log").find("--right-info /cam/right/camera_info: not in the bag"),
            std::string::npos);
  EXPECT_NE(run("--bag " + bag_path + " --out " + dir + "/bad --left-info /odom", "type.log"), 0);
  EXPECT_NE(readText(dir + "/type.log")
                .find("--left-info /odom: holds nav_msgs/Odometry, not sensor_msgs/CameraInfo"),
            std::string::npos);
  // Command-line and configuration errors name the option or key (exit 2 / 1, no output dir).
  EXPECT_NE(run("--bag " + bag_path + " --out " + dir + "/bad --windoww 1 2", "cli.log"), 0);
  EXPECT_NE(readText(dir + "/cli.log").find("unknown option '--windoww'"), std::string::npos);
  {
    std::ofstream bad(dir + "/bad_config.yaml");
    bad << "pixel_noise_px: 0.5\nfront_end: {detector: ORB, max_featurez: 10}\n";
  }
  EXPECT_NE(run("--bag " + bag_path + " --out " + dir + "/bad --config " + dir + "/bad_config.yaml",
                "config.log"),
            0);
  EXPECT_NE(readText(dir + "/config.log").find("front_end.max_featurez: unknown parameter"),
            std::string::npos)
      << readText(dir + "/config.log");
  EXPECT_FALSE(isFile(dir + "/bad/estimates.csv"));

  // Other topic names: the first 12 frames copied under new names, evaluated with the topic
  // options and a front-end configuration from the --config file.
  const std::string renamed = dir + "/renamed.bag";
  {
    rosbag::Bag in(bag_path, rosbag::bagmode::Read);
    rosbag::Bag out(renamed, rosbag::bagmode::Write);
    const std::map<std::string, std::string> names = {{"/stereo/left/image_raw", "/cam0/image"},
                                                      {"/stereo/right/image_raw", "/cam1/image"},
                                                      {"/stereo/left/camera_info", "/cam0/info"},
                                                      {"/stereo/right/camera_info", "/cam1/info"},
                                                      {"/odom", "/ins/odometry"}};
    const double end = reference[11].stamp + 0.05;
    for (const rosbag::MessageInstance& m : rosbag::View(in)) {
      const auto name = names.find(m.getTopic());
      if (name == names.end() || m.getTime().toSec() > end) continue;
      out.write(name->second, m.getTime(), m);
    }
  }
  {
    std::ofstream good(dir + "/config.yaml");
    good << "front_end:\n  detector: FAST_ORB\n  max_features: 600\n";
  }
  ASSERT_EQ(run("--bag " + renamed + " --out " + dir + "/renamed --initial-guess " + dir +
                    "/sim/initial_guess.yaml --left-image /cam0/image --right-image /cam1/image "
                    "--left-info /cam0/info --right-info /cam1/info --odom /ins/odometry "
                    "--config " +
                    dir + "/config.yaml --reference " + dir + "/sim/truth.yaml",
                "renamed.log"),
            0)
      << readText(dir + "/renamed.log");
  const std::string renamed_log = readText(dir + "/renamed.log");
  EXPECT_NE(renamed_log.find("on /cam0/image"), std::string::npos) << renamed_log;
  EXPECT_NE(renamed_log.find("FAST_ORB front end"), std::string::npos) << renamed_log;
  EXPECT_GE(osc::readEstimatesCsv(dir + "/renamed/estimates.csv").size(), 10u);
  std::system(("rm -rf " + dir).c_str());
}

/// scripts/demo.sh on a tiny drive: renders and evaluates, prints the table and the plots,
/// reuses the rendered drive on a second run and renders again once the scenario changes.
TEST(BagTools, DemoScriptCachesTheRenderedDrive) {
  const std::string simulate = findTool("simulate");
  if (simulate.empty() || findTool("evaluate").empty()) {
    GTEST_SKIP() << "simulate/evaluate not built (make simulate evaluate)";
  }
  char dir_template[] = "/tmp/osc_demo_XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  const auto writeScenario = [&](const std::string& extra) {
    std::ofstream scenario(dir + "/tiny.yaml");
    scenario << "base: paper_offroad\nname: tiny\nframes: 20\n"
                "left_camera: {width: 240, height: 180, fx: 220, fy: 220, cx: 119.5, cy: 89.5}\n"
                "right_camera: {width: 240, height: 180, fx: 220, fy: 220, cx: 119.5, cy: 89.5}\n"
                "rendering: {supersampling: 1}\n"
             << extra;
  };
  writeScenario("");
  const std::string bin_dir = simulate.substr(0, simulate.find_last_of('/'));
  const auto demo = [&](const std::string& log) {
    const std::string command = "OSC_DEMO_SKIP_BUILD=1 OSC_DEMO_BIN_DIR=" + bin_dir +
                                " OSC_DEMO_FRAMES=8 OSC_DEMO_SCENARIO=" + dir +
                                "/tiny.yaml OSC_DEMO_OUT=" + dir + "/out bash " +
                                std::string(OSC_SOURCE_DIR) + "/scripts/demo.sh > " + dir + "/" +
                                log + " 2>&1";
    return std::system(command.c_str());
  };
  ASSERT_EQ(demo("first.log"), 0) << readText(dir + "/first.log");
  const std::string first = readText(dir + "/first.log");
  EXPECT_NE(first.find("demo: rendering 8 frames"), std::string::npos) << first;
  EXPECT_NE(first.find("Table I"), std::string::npos) << first;
  EXPECT_NE(first.find("Convergence plots:"), std::string::npos) << first;
  EXPECT_NE(first.find(dir + "/out/eval/errors.png"), std::string::npos) << first;
  EXPECT_EQ(osc::readReferenceCsv(dir + "/out/drive/reference.csv").size(), 8u);
  EXPECT_GE(osc::readEstimatesCsv(dir + "/out/eval/estimates.csv").size(), 6u);

  ASSERT_EQ(demo("second.log"), 0) << readText(dir + "/second.log");
  const std::string second = readText(dir + "/second.log");
  EXPECT_NE(second.find("demo: reusing the rendered drive"), std::string::npos) << second;
  EXPECT_EQ(second.find("demo: rendering"), std::string::npos) << second;
  EXPECT_NE(second.find("Table I"), std::string::npos) << second;

  writeScenario("seed: 2\n");  // a changed scenario renders again
  ASSERT_EQ(demo("third.log"), 0) << readText(dir + "/third.log");
  EXPECT_NE(readText(dir + "/third.log").find("demo: rendering 8 frames"), std::string::npos);
  std::system(("rm -rf " + dir).c_str());
}
