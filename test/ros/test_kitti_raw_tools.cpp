/// @file test_kitti_raw_tools.cpp
/// @brief The built `evaluate --kitti-raw` and `kitti_raw_to_bag` on the first frames of
/// ../shared/data/kitti_raw_2011_09_26_200: the options that conflict with a KITTI folder, the
/// bag the converter writes, and the same estimates from the folder and from its bag.
#include <unistd.h>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../../src/tools/ros/bag_io.h"
#include "../core/temp_dir.h"
#include "online_stereo_calibration/tools/calibration_file.h"
#include "online_stereo_calibration/tools/estimates_csv.h"
#include "online_stereo_calibration/tools/kitti_raw_drive.h"
#include "tool_test_helpers.h"

namespace {

const std::string kDrive = std::string(OSC_SOURCE_DIR) + "/../shared/data/kitti_raw_2011_09_26_200";

using osc_test::findTool;
using osc_test::readText;

/// Runs @p tool with @p arguments, stdout and stderr into @p log; the exit code.
int run(const std::string& tool, const std::string& arguments, const std::string& log) {
  const int status = std::system((tool + " " + arguments + " > " + log + " 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class KittiRawTools : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::ifstream(kDrive + "/calib_cam_to_cam.txt").good()) {
      GTEST_SKIP() << "KITTI raw drive not found at " << kDrive;
    }
    evaluate_ = findTool("evaluate");
    convert_ = findTool("kitti_raw_to_bag");
    ASSERT_FALSE(evaluate_.empty()) << "evaluate not built";
    ASSERT_FALSE(convert_.empty()) << "kitti_raw_to_bag not built";
    // The guess: KITTI's chain with the paper's start errors (0.5 m, 10 deg on x_caml, 0.1 m
    // on yr).
    osc::Vector12d guess = osc::readKittiRawDrive(kDrive).truth();
    guess.head<3>().array() += 0.5;
    guess.segment<3>(3) += Eigen::Vector3d::Constant(10.0 * M_PI / 180.0);
    guess(7) += 0.1;
    osc::CalibrationFile file;
    file.extrinsics = osc::StereoExtrinsics::fromParameters(guess);
    osc::writeCalibrationFileAtomic(dir_.file("guess.yaml"), file);
  }

  osc::TempDir dir_{"kitti_raw_tools"};
  std::string evaluate_, convert_;
};

TEST_F(KittiRawTools, EvaluateRefusesOptionsThatDoNotApplyToAKittiFolder) {
  const std::string out = " --out " + dir_.file("bad");
  const std::string log = dir_.file("cli.log");
  const auto refuses = [&](const std::string& arguments, const std::string& message) {
    EXPECT_EQ(run(evaluate_, arguments + out, log), 2) << arguments;
    EXPECT_NE(readText(log).find(message), std::string::npos) << readText(log);
  };
  refuses("", "give --bag DRIVE.bag or --kitti-raw DIR");
  refuses("--kitti-raw " + kDrive + " --bag x.bag", "give --bag or --kitti-raw, not both");
  refuses("--kitti-raw " + kDrive + " --reference r.yaml",
          "--reference applies to --bag only (a KITTI raw drive's reference is KITTI's own "
          "calibration)");
  refuses("--kitti-raw " + kDrive + " --truth-topic /t", "--truth-topic applies to --bag only");
  refuses("--kitti-raw " + kDrive + " --odom /o", "--odom applies to --bag only");
  refuses("--bag x.bag --oxts-position gps", "--oxts-position applies to --kitti-raw only");
  refuses("--kitti-raw " + kDrive + " --oxts-position imu", "--oxts-position");
  // No guess given and none in the (read-only) drive folder.
  EXPECT_EQ(run(evaluate_, "--kitti-raw " + kDrive + out, log), 1);
  EXPECT_NE(readText(log).find("no initial guess: give --initial-guess GUESS.yaml"),
            std::string::npos)
      << readText(log);
}

// Five pairs written into a bag: its topics, and evaluate gives the same estimates from the
// bag (truth topic) as from the folder.
TEST_F(KittiRawTools, TheBagOfTheFolderEvaluatesAsTheFolder) {
  const std::string bag_path = dir_.file("kitti.bag");
  ASSERT_EQ(run(convert_, "--kitti-raw " + kDrive + " --out " + bag_path + " --frames 5",
                dir_.file("convert.log")),
            0)
      << readText(dir_.file("convert.log"));
  EXPECT_NE(readText(dir_.file("convert.log")).find("skipped frame 22: no right image"),
            std::string::npos);
  {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
    const std::vector<osc::bag::BagTopic> topics = osc::bag::listTopics(bag);
    std::map<std::string, std::size_t> counts;
    for (const osc::bag::BagTopic& t : topics) counts[t.name] = t.messages;
    EXPECT_EQ(counts["/stereo/left/image_raw"], 5u);
    EXPECT_EQ(counts["/stereo/right/camera_info"], 5u);
    EXPECT_EQ(counts["/ground_truth/calibration"], 5u);
    // The records from 3 (the first) to 152, 1 s after frame 6 (the fifth usable frame).
    EXPECT_EQ(counts["/odom"], 150u);
    const auto truth = osc::bag::readCalibrationTopic(bag, "/ground_truth/calibration");
    EXPECT_TRUE(truth.front().second.isApprox(osc::readKittiRawDrive(kDrive).truth(), 1e-12));
  }
  const std::string common = " --initial-guess " + dir_.file("guess.yaml");
  ASSERT_EQ(
      run(evaluate_, "--kitti-raw " + kDrive + " --frames 5 --out " + dir_.file("folder") + common,
          dir_.file("folder.log")),
      0)
      << readText(dir_.file("folder.log"));
  ASSERT_EQ(run(evaluate_,
                "--bag " + bag_path + " --truth-topic /ground_truth/calibration --out " +
                    dir_.file("bag") + common,
                dir_.file("bag.log")),
            0)
      << readText(dir_.file("bag.log"));
  const std::string folder_log = readText(dir_.file("folder.log"));
  EXPECT_NE(folder_log.find("unsynced layout, raw images 1392x512"), std::string::npos)
      << folder_log;
  EXPECT_NE(readText(dir_.file("folder/table.txt")).find("  frame 23: no left image"),
            std::string::npos);
  const auto from_folder = osc::readEstimatesCsv(dir_.file("folder/estimates.csv"));
  const auto from_bag = osc::readEstimatesCsv(dir_.file("bag/estimates.csv"));
  const auto reference = osc::readReferenceCsv(dir_.file("folder/reference.csv"));
  ASSERT_EQ(from_folder.size(), 5u);
  ASSERT_EQ(from_bag.size(), 5u);
  ASSERT_EQ(reference.size(), 5u);
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_NEAR(from_folder[k].stamp, from_bag[k].stamp, 1e-6);
    EXPECT_TRUE(from_folder[k].parameters.isApprox(from_bag[k].parameters, 1e-6))
        << k << "\n"
        << from_folder[k].parameters.transpose() << "\n"
        << from_bag[k].parameters.transpose();
    EXPECT_EQ(from_folder[k].tracked_points, from_bag[k].tracked_points) << k;
  }
  EXPECT_EQ(readText(dir_.file("folder/reference.csv")), readText(dir_.file("bag/reference.csv")));
}

// scripts/information_by_motion.py on a made-up drive of three pairs: the second pitches at
// 10 deg/s and is where zl's sigma shrinks, the third drives straight and shrinks xl's. Each
// parameter's information is put in the class of the pair that gained it, and a parameter
// that gained nothing has no share; estimates on another clock are matched with an offset.
TEST(InformationByMotion, PutsEachPairsGainInTheClassOfItsMotion) {
  osc::TempDir dir("information_by_motion");
  const std::string drive = dir.file("drive");
  ASSERT_EQ(std::system(("mkdir -p " + drive + "/oxts/data").c_str()), 0);
  std::ofstream stamps(drive + "/oxts/timestamps.txt");
  const double pitch_rates[3] = {0.0, 10.0 * M_PI / 180.0, 0.0};  // rad/s
  for (int k = 0; k < 3; ++k) {
    stamps << "1970-01-01 00:00:10." << k << "00000000\n";
    std::ofstream record(drive + "/oxts/data/000000000" + std::to_string(k) + ".txt");
    for (int field = 0; field < 30; ++field)
      record << (field == 21 ? pitch_rates[k] : field == 8 ? 8.0 : 0.0) << " ";
  }
  stamps.close();
  std::ofstream estimates(dir.file("estimates.csv"));
  estimates << "frame,stamp,sigma_xl,sigma_yl,sigma_zl,sigma_roll_l,sigma_pitch_l,sigma_yaw_l\n"
            << "0,10.0,1,1,1,1,1,1\n1,10.1,1,1,0.5,1,1,1\n2,10.2,0.5,1,0.5,1,1,1\n";
  estimates.close();
  const std::string script = std::string(OSC_SOURCE_DIR) + "/scripts/information_by_motion.py";
  ASSERT_EQ(run("/usr/bin/python3 " + script, dir.file("estimates.csv") + " " + drive,
                dir.file("out.txt")),
            0)
      << readText(dir.file("out.txt"));
  const std::string out = readText(dir.file("out.txt"));
  EXPECT_NE(out.find("| xl | 0 % | 0 % | 100 % |"), std::string::npos) << out;
  EXPECT_NE(out.find("| zl | 0 % | 100 % | 0 % |"), std::string::npos) << out;
  EXPECT_NE(out.find("| yl | - | - | - |"), std::string::npos) << out;
  EXPECT_NE(out.find("pair 1: speed 8.0 m/s, roll/pitch/yaw rate 0.0/10.0/0.0 deg/s"),
            std::string::npos)
      << out;
  // A simulated drive's clock: its stamps 5 s later, --stamp-offset -5 finds the same records.
  std::ofstream shifted(dir.file("shifted.csv"));
  shifted << "frame,stamp,sigma_xl,sigma_yl,sigma_zl,sigma_roll_l,sigma_pitch_l,sigma_yaw_l\n"
          << "0,15.0,1,1,1,1,1,1\n1,15.1,1,1,0.5,1,1,1\n2,15.2,0.5,1,0.5,1,1,1\n";
  shifted.close();
  ASSERT_EQ(
      run("/usr/bin/python3 " + script,
          dir.file("shifted.csv") + " " + drive + " --stamp-offset=-5", dir.file("shifted.txt")),
      0);
  EXPECT_EQ(readText(dir.file("shifted.txt")), out);
  // A missing estimates file is named.
  EXPECT_NE(run("/usr/bin/python3 " + script, dir.file("none.csv") + " " + drive,
                dir.file("missing.txt")),
            0);
  EXPECT_NE(readText(dir.file("missing.txt")).find("none.csv not found"), std::string::npos);
}

}  // namespace
