/// @file test_kitti_raw_drive.cpp
/// @brief The KITTI raw reader (tools/kitti_raw_drive.h) on the drive in
/// ../shared/data/kitti_raw_2011_09_26_200 (its README gives the layout, the missing frames
/// and the truth) and on copies of its first frames changed on purpose. The OXTS conversions
/// on synthetic records are in test_oxts_poses.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "online_stereo_calibration/core/geometry/rotation.h"
#include "online_stereo_calibration/tools/estimates_csv.h"
#include "online_stereo_calibration/tools/kitti_raw_drive.h"
#include "online_stereo_calibration/tools/kitti_raw_source.h"
#include "temp_dir.h"

namespace osc {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = M_PI / 180.0;
const std::string kDrive = std::string(OSC_SOURCE_DIR) + "/../shared/data/kitti_raw_2011_09_26_200";

bool haveDrive() { return std::ifstream(kDrive + "/calib_cam_to_cam.txt").good(); }

#define SKIP_WITHOUT_DRIVE() \
  if (!haveDrive()) GTEST_SKIP() << "KITTI raw drive not found at " << kDrive

/// The drive, read once for the tests that do not change it.
const KittiRawDrive& sharedDrive() {
  static const KittiRawDrive drive = readKittiRawDrive(kDrive);
  return drive;
}

std::vector<std::string> readLines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

void writeLines(const std::string& path, const std::vector<std::string>& lines) {
  std::ofstream out(path);
  for (const std::string& line : lines) out << line << "\n";
}

/// A copy of the drive's first @p frames frames (images linked, not copied) and of the OXTS
/// records up to 0.2 s after the last of them, in @p dir.
void copyFirstFrames(const std::string& dir, int frames) {
  for (const char* name :
       {"calib_cam_to_cam.txt", "calib_imu_to_velo.txt", "calib_velo_to_cam.txt"}) {
    fs::copy_file(kDrive + "/" + name, dir + "/" + name);
  }
  for (const char* camera : {"image_00", "image_01"}) {
    fs::create_directories(dir + "/" + camera + "/data");
    std::vector<std::string> stamps = readLines(kDrive + "/" + camera + "/timestamps.txt");
    stamps.resize(static_cast<std::size_t>(frames));
    writeLines(dir + "/" + camera + "/timestamps.txt", stamps);
    for (int i = 0; i < frames; ++i) {
      char name[32];
      std::snprintf(name, sizeof name, "/data/%010d.png", i);
      const std::string source = kDrive + "/" + camera + name;
      if (fs::exists(source)) fs::create_symlink(source, dir + "/" + camera + name);
    }
  }
  // OXTS record n lies at the first image + 0.095 s + n * 0.01 s (the README).
  const int records = static_cast<int>((frames * 0.1033 + 0.2 - 0.095) / 0.01);
  fs::create_directories(dir + "/oxts/data");
  std::vector<std::string> stamps = readLines(kDrive + "/oxts/timestamps.txt");
  stamps.resize(static_cast<std::size_t>(records));
  writeLines(dir + "/oxts/timestamps.txt", stamps);
  for (int i = 0; i < records; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "/oxts/data/%010d.txt", i);
    if (fs::exists(kDrive + name)) fs::copy_file(kDrive + name, dir + name);
  }
}

/// The message of the runtime_error that @p read throws ("" and a failure if none).
std::string errorOf(const std::function<void()>& read) {
  try {
    read();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no std::runtime_error";
  return "";
}

const KittiRawSkippedFrame* findSkipped(const KittiRawDrive& drive, int index) {
  for (const KittiRawSkippedFrame& s : drive.skipped) {
    if (s.index == index) return &s;
  }
  return nullptr;
}

// The README's table, in its units (m, deg) and to its printed digits. Each value computed
// here is within half a unit of the last printed digit except yaw_l: 0.48693 deg, which the
// README prints as 0.4870 (0.7 units). So one unit is the tolerance: a wrong inverse, a
// transposed rotation or a body/optical mix-up moves these by far more.
TEST(KittiRawDrive, TruthIsTheReadmeTable) {
  SKIP_WITHOUT_DRIVE();
  const Vector12d truth = sharedDrive().truth();
  const double table[12] = {1.0833,  -0.3099, 0.7299,  -0.8132, -0.7253, 0.4870,
                            -0.0040, -0.5371, -0.0053, 1.0663,  0.5156,  -1.7577};
  const char* names[12] = {"xl", "yl", "zl", "roll_l", "pitch_l", "yaw_l",
                           "xr", "yr", "zr", "roll_r", "pitch_r", "yaw_r"};
  for (int i = 0; i < 12; ++i) {
    const bool angle = i % 6 >= 3;
    EXPECT_NEAR(truth(i) / (angle ? kDeg : 1.0), table[i], 1.0e-4) << names[i];
  }
}

TEST(KittiRawDrive, ReadsTheRawUnsyncedLayoutAndItsIntrinsics) {
  SKIP_WITHOUT_DRIVE();
  const KittiRawDrive& drive = sharedDrive();
  EXPECT_FALSE(drive.rectified);
  EXPECT_FALSE(drive.synced);
  EXPECT_EQ(drive.left.width, 1392);
  EXPECT_EQ(drive.left.height, 512);
  EXPECT_EQ(drive.left.model, DistortionModel::kPlumbBob);
  // K_00 and D_00 (k1 k2 p1 p2 k3) of calib_cam_to_cam.txt.
  EXPECT_DOUBLE_EQ(drive.left.fx, 984.2439);
  EXPECT_DOUBLE_EQ(drive.left.fy, 980.8141);
  EXPECT_DOUBLE_EQ(drive.left.cx, 690.0);
  EXPECT_DOUBLE_EQ(drive.left.cy, 233.1966);
  ASSERT_EQ(drive.left.distortion.size(), 5u);
  EXPECT_DOUBLE_EQ(drive.left.distortion[0], -0.3728755);
  EXPECT_DOUBLE_EQ(drive.left.distortion[4], -0.07233722);
  EXPECT_DOUBLE_EQ(drive.right.fx, 989.5267);
  EXPECT_DOUBLE_EQ(drive.right.cy, 245.559);
  EXPECT_DOUBLE_EQ(drive.right.distortion[1], 0.1790019);
  EXPECT_EQ(drive.oxts_stamps, 2201);
  EXPECT_NE(drive.summary().find("unsynced layout, raw images 1392x512"), std::string::npos)
      << drive.summary();
}

TEST(KittiRawDrive, FramesWithoutBothImagesOrOxtsAreSkippedAndReported) {
  SKIP_WITHOUT_DRIVE();
  const KittiRawDrive& drive = sharedDrive();
  // 200 stamps; 22 has no right image, 23 no left one; 0 and 1 lie before the first OXTS
  // record (record 3, 0.125 s after frame 0: records 0-2 are not in the source).
  ASSERT_EQ(drive.frames.size() + drive.skipped.size(), 200u);
  ASSERT_EQ(drive.skipped.size(), 4u) << drive.summary();
  const KittiRawSkippedFrame* f22 = findSkipped(drive, 22);
  const KittiRawSkippedFrame* f23 = findSkipped(drive, 23);
  ASSERT_TRUE(f22 && f23);
  EXPECT_NE(f22->reason.find("no right image"), std::string::npos) << f22->reason;
  EXPECT_NE(f22->reason.find("image_01/data/0000000022.png"), std::string::npos) << f22->reason;
  EXPECT_NE(f23->reason.find("no left image"), std::string::npos) << f23->reason;
  for (int early : {0, 1}) {
    const KittiRawSkippedFrame* s = findSkipped(drive, early);
    ASSERT_TRUE(s) << early;
    EXPECT_NE(s->reason.find("before the first OXTS record"), std::string::npos) << s->reason;
  }
  EXPECT_EQ(drive.frames.front().index, 2);
  EXPECT_EQ(drive.frames.back().index, 199);
  for (std::size_t k = 1; k < drive.frames.size(); ++k) {
    const int step = drive.frames[k].index - drive.frames[k - 1].index;
    EXPECT_EQ(step, drive.frames[k].index == 24 ? 3 : 1) << drive.frames[k].index;
  }
  EXPECT_EQ(drive.skippedLines()[2].substr(0, 10), "frame 22: ");
  EXPECT_NE(drive.summary().find("196 usable, 4 skipped (0, 1, 22, 23)"), std::string::npos)
      << drive.summary();
  // The left image's stamp: frame 2 of image_00/timestamps.txt.
  EXPECT_EQ(drive.frames.front().stamp_ns, parseKittiTimestamp("2011-09-26 14:05:35.706851072"));
}

TEST(KittiRawDrive, MissingOxtsRecordsAreInterpolatedFromTheirNeighbours) {
  SKIP_WITHOUT_DRIVE();
  const KittiRawDrive& drive = sharedDrive();
  // 361 records in oxts/data, from 3 to 2198, never more than 0.25 s apart: all 2196
  // records between are there, 1835 of them interpolated.
  ASSERT_EQ(drive.oxts.size(), 2196u);
  EXPECT_EQ(drive.oxts_interpolated, 1835);
  EXPECT_TRUE(drive.oxts_gaps.empty());
  EXPECT_EQ(drive.oxts.front().index, 3);
  EXPECT_EQ(drive.oxts.back().index, 2198);
  // Records 3 and 6 are in the source, 4 and 5 lie a third and two thirds between them.
  const OxtsRecord &r3 = drive.oxts[0], &r4 = drive.oxts[1], &r5 = drive.oxts[2],
                   &r6 = drive.oxts[3];
  EXPECT_FALSE(r3.interpolated);
  EXPECT_TRUE(r4.interpolated);
  EXPECT_TRUE(r5.interpolated);
  EXPECT_FALSE(r6.interpolated);
  EXPECT_DOUBLE_EQ(r3.values[0], 49.032378698576);  // oxts/data/0000000003.txt
  for (int field : {0, 1, 2, 5, 7, 19}) {
    EXPECT_NEAR(r4.values[field], r3.values[field] + (r6.values[field] - r3.values[field]) / 3,
                1e-9 * (1 + std::abs(r3.values[field])))
        << field;
    EXPECT_NEAR(r5.values[field], r3.values[field] + 2 * (r6.values[field] - r3.values[field]) / 3,
                1e-9 * (1 + std::abs(r3.values[field])))
        << field;
  }
  EXPECT_EQ(r4.stamp_ns, parseKittiTimestamp("2011-09-26 14:05:35.635923136"));

  // A limit below the drive's longest gaps (0.14-0.25 s) leaves them open, and the frames in
  // them are skipped, each named with its gap.
  KittiRawOptions strict;
  strict.max_oxts_gap = 0.1;
  const KittiRawDrive gappy = readKittiRawDrive(kDrive, strict);
  EXPECT_FALSE(gappy.oxts_gaps.empty());
  EXPECT_LT(gappy.oxts_interpolated, drive.oxts_interpolated);
  int in_gap = 0;
  for (const KittiRawSkippedFrame& s : gappy.skipped) {
    if (s.reason.find("gap of the OXTS records (limit 0.100 s)") != std::string::npos) ++in_gap;
  }
  EXPECT_GT(in_gap, 0) << gappy.summary();
  EXPECT_EQ(gappy.frames.size() + gappy.skipped.size(), 200u);
  // No motion is read across a gap.
  const auto& [gap_start, gap_end] = gappy.oxts_gaps.front();
  EXPECT_FALSE(gappy.motionBetween(gap_start - 0.01, gap_end + 0.01));
  EXPECT_TRUE(drive.motionBetween(gap_start - 0.01, gap_end + 0.01));
}

// The first 30 frames: increments of one frame period (0.103 s; 0.31 s across the missing 22
// and 23), forward along the IMU's x at the OXTS speed (the README's ~5-9 m/s; the drive
// starts at 4.3 m/s and speeds up), turning at the OXTS yaw rate.
TEST(KittiRawDrive, MotionIncrementsFollowTheOxtsSpeedAndTurnRate) {
  SKIP_WITHOUT_DRIVE();
  const KittiRawDrive& drive = sharedDrive();
  KittiRawOptions gps_options;
  gps_options.position = OxtsPositionSource::kGps;
  const KittiRawDrive gps = readKittiRawDrive(kDrive, gps_options);
  EXPECT_FALSE(drive.motion(0));
  double gps_difference = 0;
  int increments = 0;
  for (std::size_t k = 1; k < drive.frames.size() && drive.frames[k].index < 30; ++k) {
    const auto m = drive.motion(k);
    ASSERT_TRUE(m) << k;
    const int frames = drive.frames[k].index - drive.frames[k - 1].index;
    EXPECT_NEAR(m->dt, 0.1032 * frames, 0.008) << drive.frames[k].index;
    const Eigen::Vector3d t = m->T_prev_curr.translation();
    const double speed = t.norm() / m->dt;
    EXPECT_GT(speed, 4.0);
    EXPECT_LT(speed, 10.0);
    EXPECT_GT(t.x(), 0.99 * t.norm()) << "not forward: " << t.transpose();
    // The OXTS speed and yaw rate half-way (the twists at both ends, averaged).
    ASSERT_TRUE(m->has_twists);
    const Vector6d twist = 0.5 * (m->twist_start + m->twist_end);
    EXPECT_NEAR(speed, twist.head<3>().norm(), 0.02 * speed) << drive.frames[k].index;
    const double yaw = rpyFromRotation(m->T_prev_curr.linear()).z();
    EXPECT_NEAR(yaw / m->dt, twist(5), 0.03) << drive.frames[k].index;
    // GPS positions give the same increments but for their 2-3 cm of jitter.
    const auto g = gps.motion(k);
    ASSERT_TRUE(g);
    gps_difference += (g->T_prev_curr.translation() - t).norm();
    EXPECT_TRUE(g->T_prev_curr.linear().isApprox(m->T_prev_curr.linear(), 1e-12));
    ++increments;
  }
  EXPECT_EQ(increments, 25);  // frames 2-29 without 22 and 23: 26 frames
  EXPECT_LT(gps_difference / increments, 0.06);
  EXPECT_GT(gps_difference / increments, 0.002);  // they are not the same numbers
  // Read 20 ms earlier (the estimator's time shift): other numbers, the shift recorded.
  const auto shifted = drive.motion(5, 0.02);
  ASSERT_TRUE(shifted);
  EXPECT_DOUBLE_EQ(shifted->time_shift, 0.02);
  EXPECT_GT(
      (shifted->T_prev_curr.translation() - drive.motion(5)->T_prev_curr.translation()).norm(),
      1e-4);
}

TEST(KittiRawDrive, CorruptedCopiesNameTheFileAndTheProblem) {
  SKIP_WITHOUT_DRIVE();
  {
    TempDir dir("kitti_raw");
    copyFirstFrames(dir.path(), 30);
    const KittiRawDrive copy = readKittiRawDrive(dir.path());
    EXPECT_EQ(copy.frames.size(), 26u);  // 2-29 without 22, 23 (the last record: 0.1 s after 29)
    EXPECT_EQ(copy.truth(), sharedDrive().truth());
    // A calibration line cut short.
    std::vector<std::string> calib = readLines(dir.file("calib_cam_to_cam.txt"));
    for (std::string& line : calib) {
      if (line.rfind("K_00:", 0) == 0) line = line.substr(0, line.rfind(' '));
    }
    writeLines(dir.file("calib_cam_to_cam.txt"), calib);
    const std::string truncated = errorOf([&] { readKittiRawDrive(dir.path()); });
    EXPECT_NE(truncated.find(dir.file("calib_cam_to_cam.txt")), std::string::npos) << truncated;
    EXPECT_NE(truncated.find("K_00 has 8 numbers, expected 9"), std::string::npos) << truncated;
  }
  {
    TempDir dir("kitti_raw");
    copyFirstFrames(dir.path(), 10);
    fs::remove(dir.file("oxts/timestamps.txt"));
    const std::string missing = errorOf([&] { readKittiRawDrive(dir.path()); });
    EXPECT_NE(missing.find("cannot open " + dir.file("oxts/timestamps.txt")), std::string::npos)
        << missing;
  }
  {
    TempDir dir("kitti_raw");
    copyFirstFrames(dir.path(), 10);
    writeLines(dir.file("oxts/data/0000000006.txt"), {"49.03 8.34 112.3 0.04"});
    const std::string short_record = errorOf([&] { readKittiRawDrive(dir.path()); });
    EXPECT_NE(
        short_record.find(dir.file("oxts/data/0000000006.txt") + ": expected 30 numbers, read 4"),
        std::string::npos)
        << short_record;
  }
  {
    TempDir dir("kitti_raw");
    copyFirstFrames(dir.path(), 10);
    std::vector<std::string> stamps = readLines(dir.file("image_01/timestamps.txt"));
    stamps[4] = "2011-09-26 14:05:3x.000000000";
    writeLines(dir.file("image_01/timestamps.txt"), stamps);
    const std::string bad_stamp = errorOf([&] { readKittiRawDrive(dir.path()); });
    EXPECT_NE(bad_stamp.find(dir.file("image_01/timestamps.txt") + ": line 5: "), std::string::npos)
        << bad_stamp;
  }
  {
    // Only frames 0 and 1, both before the first OXTS record: nothing usable.
    TempDir dir("kitti_raw");
    copyFirstFrames(dir.path(), 2);
    const std::string none = errorOf([&] { readKittiRawDrive(dir.path()); });
    EXPECT_NE(none.find("no usable frame of 2 (first: frame 0: before the first OXTS record"),
              std::string::npos)
        << none;
  }
  {
    // The calibration where KITTI ships it: in the date folder above the drive folder.
    TempDir dir("kitti_raw");
    fs::create_directories(dir.file("drive"));
    copyFirstFrames(dir.file("drive"), 10);
    for (const char* name :
         {"calib_cam_to_cam.txt", "calib_imu_to_velo.txt", "calib_velo_to_cam.txt"}) {
      fs::rename(dir.file(std::string("drive/") + name), dir.file(name));
    }
    EXPECT_EQ(readKittiRawDrive(dir.file("drive")).truth(), sharedDrive().truth());
    fs::remove(dir.file("calib_velo_to_cam.txt"));
    const std::string no_calib = errorOf([&] { readKittiRawDrive(dir.file("drive")); });
    EXPECT_NE(no_calib.find("calib_velo_to_cam.txt"), std::string::npos) << no_calib;
  }
}

// Rectified images (told by their size, S_rect_00) take P_rect and the rectified frames: both
// cameras turned by R_rect_00 from camera 0, the right one P_rect_01's baseline to the right.
// OXTS stamps one per frame, each near its image's, make the synced layout.
TEST(KittiRawDrive, RectifiedImagesAndTheSyncedLayoutAreRecognised) {
  SKIP_WITHOUT_DRIVE();
  TempDir dir("kitti_raw");
  copyFirstFrames(dir.path(), 12);
  const std::vector<std::string> image_stamps = readLines(dir.file("image_00/timestamps.txt"));
  for (const char* camera : {"image_00", "image_01"}) {
    for (int i = 0; i < 12; ++i) {
      char name[48];
      std::snprintf(name, sizeof name, "%s/data/%010d.png", camera, i);
      fs::remove(dir.file(name));
      cv::imwrite(dir.file(name), cv::Mat(375, 1242, CV_8UC1, cv::Scalar(100)));
    }
  }
  // The synced layout: OXTS record i 4 ms after image i; the files of the records 3 and 6 as
  // records 0-11.
  fs::remove_all(dir.file("oxts"));
  fs::create_directories(dir.file("oxts/data"));
  std::vector<std::string> oxts_stamps;
  for (int i = 0; i < 12; ++i) {
    const std::int64_t t = parseKittiTimestamp(image_stamps[static_cast<std::size_t>(i)]) + 4000000;
    const std::int64_t s = t / 1000000000;
    char stamp[64];
    std::snprintf(stamp, sizeof stamp, "2011-09-26 %02d:%02d:%02d.%09lld",
                  static_cast<int>(s / 3600 % 24), static_cast<int>(s / 60 % 60),
                  static_cast<int>(s % 60), static_cast<long long>(t % 1000000000));
    oxts_stamps.push_back(stamp);
    char name[40];
    std::snprintf(name, sizeof name, "oxts/data/%010d.txt", i);
    fs::copy_file(kDrive + (i % 2 ? "/oxts/data/0000000006.txt" : "/oxts/data/0000000003.txt"),
                  dir.file(name));
  }
  writeLines(dir.file("oxts/timestamps.txt"), oxts_stamps);
  const KittiRawDrive drive = readKittiRawDrive(dir.path());
  EXPECT_TRUE(drive.rectified);
  EXPECT_TRUE(drive.synced);
  EXPECT_EQ(drive.left.model, DistortionModel::kNone);
  EXPECT_EQ(drive.left.width, 1242);
  EXPECT_DOUBLE_EQ(drive.left.fx, 721.5377);
  EXPECT_DOUBLE_EQ(drive.right.cx, 609.5593);
  // Frame 0 lies 4 ms before OXTS record 0; 1-11 are usable.
  EXPECT_EQ(drive.frames.size(), 11u) << drive.summary();
  ASSERT_EQ(drive.skipped.size(), 1u);
  EXPECT_NE(drive.skipped[0].reason.find("before the first OXTS record (0.004 s later)"),
            std::string::npos)
      << drive.skipped[0].reason;
  const Vector12d truth = drive.truth();
  const Vector12d raw = sharedDrive().truth();
  EXPECT_NEAR(truth(7), -387.5744 / 721.5377, 1e-9);  // yr: P_rect_01's baseline
  for (int i : {6, 8, 9, 10, 11}) EXPECT_NEAR(truth(i), 0.0, 1e-12) << i;
  EXPECT_TRUE(truth.head<3>().isApprox(raw.head<3>(), 1e-12));  // the same camera centre
  // The left camera turned by R_rect_00 (0.75 deg): R_imu_rect0 = R_imu_cam0 R_rect_00^T.
  const Eigen::Matrix3d R_raw = poseFromParameters(raw.head<6>()).linear();
  const Eigen::Matrix3d R_rect = poseFromParameters(truth.head<6>()).linear();
  EXPECT_NEAR(rotationDistance(R_raw, R_rect), 0.749 * kDeg, 0.001 * kDeg);
}

// evaluate's loop (drive_evaluation.h) on the drive's first six usable frames: the pairs in
// order with their stamps, KITTI's chain as every pair's reference, the skipped frames in
// table.txt.
TEST(KittiRawDrive, EvaluationRunsOnTheFirstFramesAgainstKittisChain) {
  SKIP_WITHOUT_DRIVE();
  TempDir dir("kitti_raw_eval");
  KittiRawSource source(sharedDrive());
  EXPECT_EQ(source.name(), "KITTI raw drive " + kDrive);
  EXPECT_EQ(source.pairCount(), 196);
  DriveEvaluationOptions options;
  options.out = dir.file("eval");
  options.max_pairs = 6;
  options.notes = {"skipped: " + sharedDrive().skippedLines()[2]};
  Vector12d guess = sharedDrive().truth();
  guess(0) += 0.5;
  guess(7) += 0.1;
  std::ostringstream out, log;
  ASSERT_EQ(evaluateDrive(source, EstimatorConfig(), StereoExtrinsics::fromParameters(guess),
                          options, out, log),
            0);
  const std::vector<EstimateRow> estimates = readEstimatesCsv(dir.file("eval/estimates.csv"));
  const std::vector<ReferenceRow> reference = readReferenceCsv(dir.file("eval/reference.csv"));
  ASSERT_EQ(estimates.size(), 6u) << log.str();
  ASSERT_EQ(reference.size(), 6u);
  for (std::size_t k = 0; k < 6; ++k) {
    EXPECT_EQ(estimates[k].frame, static_cast<int>(k));
    EXPECT_NEAR(estimates[k].stamp, sharedDrive().frames[k].stamp(), 1e-6);
    EXPECT_TRUE(reference[k].parameters.isApprox(sharedDrive().truth(), 1e-12));
    EXPECT_GT(estimates[k].tracked_points, 0) << k;
  }
  // The first pair has no motion: xl is still at the guess.
  EXPECT_NEAR(estimates[0].parameters(0), guess(0), 0.3);
  const std::string table = out.str();
  EXPECT_NE(table.find("KITTI raw drive " + kDrive + ", RMSE over frames 0-5"), std::string::npos)
      << table;
  EXPECT_NE(table.find("skipped: frame 22: no right image"), std::string::npos) << table;
  EXPECT_EQ(log.str().find("no odometry around pair"), std::string::npos) << log.str();
  EXPECT_TRUE(fs::exists(dir.file("eval/calibration.yaml")));
}

TEST(KittiRawDrive, TimestampsParseToNanosecondsSince1970) {
  EXPECT_EQ(parseKittiTimestamp("1970-01-01 00:00:01.5"), 1500000000);
  EXPECT_EQ(parseKittiTimestamp("1970-01-02 00:00:00"), 86400000000000);
  // calendar.timegm((2011, 9, 26, 14, 5, 35)) = 1317045935.
  EXPECT_EQ(parseKittiTimestamp("2011-09-26 14:05:35.500923136"), 1317045935500923136);
  EXPECT_EQ(parseKittiTimestamp("2000-03-01 00:00:00.000000001\r"), 951868800000000001);
  for (const char* bad : {"2011-09-26", "2011-09-26 14:05:35.5009231361", "2011-13-26 14:05:35",
                          "2011-09-26 14:05:35.5 x", ""}) {
    EXPECT_THROW(parseKittiTimestamp(bad), std::invalid_argument) << bad;
  }
}

}  // namespace
}  // namespace osc
