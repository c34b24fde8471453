/// @file restore.cpp
/// @brief rostest (test/ros/restore.test): save -> restart -> restore through a nodelet
/// manager. calib_a calibrates on a rendered drive; ~save_calibration must write exactly the
/// last published calibration and covariance; unloading it (shutdown) must write the file
/// again; calib_b, loaded afterwards with resume, must start from exactly that calibration and
/// full 12x12 covariance (its first published message, whose pair only adds points and so
/// leaves the calibration block untouched); calib_c, resumed from the same file stripped of
/// its `covariance` key, must start from the diagonal covariance of the file's sigmas.
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>

#include <gtest/gtest.h>
#include <nodelet/NodeletLoad.h>
#include <nodelet/NodeletUnload.h>
#include <std_srvs/Trigger.h>

#include "online_stereo_calibration/tools/calibration_file.h"
#include "rostest_helpers.h"

namespace {

using osc_test::StereoCalibration;

bool fileExists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

bool loadNodelet(const std::string& name) {
  nodelet::NodeletLoad load;
  load.request.name = name;
  load.request.type = "online_stereo_calibration/CalibrationNodelet";
  return ros::service::call("/manager/load_nodelet", load) && load.response.success;
}

bool unloadNodelet(const std::string& name) {
  nodelet::NodeletUnload unload;
  unload.request.name = name;
  return ros::service::call("/manager/unload_nodelet", unload) && unload.response.success;
}

osc::Matrix12d covarianceOf(const StereoCalibration& message) {
  osc::Matrix12d P;
  for (int i = 0; i < 144; ++i) P(i / 12, i % 12) = message.covariance[i];
  return P;
}

osc::Vector12d parametersOf(const StereoCalibration& message) {
  osc::Vector12d p;
  for (int i = 0; i < 12; ++i) p(i) = message.parameters[i];
  return p;
}

/// Largest |correlation| between two different parameters.
double largestCorrelation(const osc::Matrix12d& P) {
  double largest = 0.0;
  for (int i = 0; i < 12; ++i) {
    for (int j = 0; j < i; ++j) {
      largest = std::max(largest, std::abs(P(i, j)) / std::sqrt(P(i, i) * P(j, j)));
    }
  }
  return largest;
}

/// Publishes @p frame and waits for the node's calibration message of that stamp.
bool feed(osc_test::RenderedDrive& drive, const osc_test::CalibrationCollector& out, int frame) {
  drive.publish(frame);
  return osc_test::spinUntil([&]() { return out.has(drive.stamp(frame)); }, 5.0);
}

/// The first pairs after a nodelet subscribed may be lost while its connections come up:
/// publishes frames from *frame on until the node answers one (at most 4); *frame is then
/// the next unused frame. True if the node's first message is of the last frame published.
bool feedUntilAnswered(osc_test::RenderedDrive& drive, const osc_test::CalibrationCollector& out,
                       int* frame) {
  for (int attempt = 0; attempt < 4; ++attempt) {
    drive.publish(*frame);
    const ros::Time stamp = drive.stamp((*frame)++);
    if (osc_test::spinUntil([&]() { return out.size() > 0; }, 3.0)) return out.has(stamp);
  }
  return false;
}

TEST(Restore, SaveRestartRestoreKeepsCalibrationAndFullCovariance) {
  ros::NodeHandle nh;
  std::string file;
  ASSERT_TRUE(ros::param::get("~calibration_file", file));
  ::unlink(file.c_str());
  constexpr int kFramesA = 30;
  osc_test::RenderedDrive drive(nh, "", "/odom", kFramesA + 8, 320, 240, ros::Time::now().toSec());
  osc_test::CalibrationCollector out_a(nh, "/calib_a/calibration");
  osc_test::CalibrationCollector out_b(nh, "/calib_b/calibration");
  osc_test::CalibrationCollector out_c(nh, "/calib_c/calibration");
  osc_test::DiagnosticsCollector diagnostics(nh);
  ASSERT_TRUE(ros::service::waitForService("/manager/load_nodelet", 10000));

  // --- calib_a: calibrate, save on request ---
  ASSERT_TRUE(loadNodelet("/calib_a"));
  ASSERT_TRUE(drive.waitForSubscribers(10.0));
  ASSERT_TRUE(out_a.waitForPublisher(10.0)) << "its first message must not be lost";
  int published = 0;
  for (int k = 0; k < kFramesA; ++k) published += feed(drive, out_a, k);
  EXPECT_GE(published, kFramesA - 2);
  ASSERT_FALSE(out_a.messages().empty());
  const StereoCalibration last_a = out_a.messages().back();
  EXPECT_EQ(last_a.header.stamp, drive.stamp(kFramesA - 1));
  ASSERT_GE(last_a.tracked_points, 10u);

  std_srvs::Trigger trigger;
  ASSERT_TRUE(ros::service::call("/calib_a/save_calibration", trigger));
  ASSERT_TRUE(trigger.response.success) << trigger.response.message;
  const osc::CalibrationFile saved = osc::readCalibrationFile(file);
  const osc::Matrix12d P_a = covarianceOf(last_a);
  const osc::Vector12d p_a = parametersOf(last_a);
  ASSERT_TRUE(saved.covariance.has_value());
  ASSERT_TRUE(saved.sigmas.has_value());
  EXPECT_LE((saved.extrinsics.toParameters() - p_a).cwiseAbs().maxCoeff(), 1e-15)
      << "saved " << saved.extrinsics.toParameters().transpose() << "\npublished "
      << p_a.transpose();
  EXPECT_EQ((*saved.covariance - P_a).cwiseAbs().maxCoeff(), 0.0) << "17 digits round-trip";
  ASSERT_TRUE(saved.stamp.has_value());
  EXPECT_NEAR(*saved.stamp, last_a.header.stamp.toSec(), 1e-6);
  // The point of storing it: after 30 frames the parameters are strongly correlated.
  const double correlation = largestCorrelation(P_a);
  std::printf("  calib_a after %d frames: largest parameter correlation %.3f\n", kFramesA,
              correlation);
  EXPECT_GT(correlation, 0.3);

  // --- shutdown save: unloading calib_a writes the file again ---
  ASSERT_EQ(::unlink(file.c_str()), 0);
  ASSERT_TRUE(unloadNodelet("/calib_a"));
  ASSERT_TRUE(drive.waitForNoSubscribers(10.0));
  ASSERT_TRUE(fileExists(file)) << "the nodelet saves on shutdown";
  const osc::CalibrationFile at_shutdown = osc::readCalibrationFile(file);
  ASSERT_TRUE(at_shutdown.covariance.has_value());
  EXPECT_EQ((*at_shutdown.covariance - P_a).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LE((at_shutdown.extrinsics.toParameters() - p_a).cwiseAbs().maxCoeff(), 1e-15);

  // --- calib_b: a fresh nodelet resumes from the file ---
  ASSERT_TRUE(loadNodelet("/calib_b"));
  ASSERT_TRUE(drive.waitForSubscribers(10.0));
  ASSERT_TRUE(out_b.waitForPublisher(10.0)) << "its first message must not be lost";
  int next_frame = kFramesA;
  ASSERT_TRUE(feedUntilAnswered(drive, out_b, &next_frame));
  const StereoCalibration first_b = out_b.messages().front();
  const osc::Matrix12d P_b = covarianceOf(first_b);
  const double scale = P_a.cwiseAbs().maxCoeff();
  EXPECT_LE((parametersOf(first_b) - p_a).cwiseAbs().maxCoeff(), 1e-12)
      << "restored " << parametersOf(first_b).transpose() << "\nsaved " << p_a.transpose();
  EXPECT_LE((P_b - P_a).cwiseAbs().maxCoeff(), 1e-9 * scale)
      << "restored covariance differs from the saved one by " << (P_b - P_a).cwiseAbs().maxCoeff()
      << " (largest entry " << scale << ")";
  EXPECT_NEAR(largestCorrelation(P_b), correlation, 1e-6);
  EXPECT_TRUE(osc_test::spinUntil(
      [&]() { return diagnostics.sawValue("initial guess", "full 12x12 covariance"); }, 3.0))
      << diagnostics.describe();
  ASSERT_TRUE(unloadNodelet("/calib_b"));
  ASSERT_TRUE(drive.waitForNoSubscribers(10.0));

  // --- calib_c: the same file without `covariance` (an older file): sigmas only ---
  osc::CalibrationFile old_format = osc::readCalibrationFile(file);
  old_format.covariance.reset();
  osc::writeCalibrationFileAtomic(file, old_format);
  ASSERT_TRUE(loadNodelet("/calib_c"));
  ASSERT_TRUE(drive.waitForSubscribers(10.0));
  ASSERT_TRUE(out_c.waitForPublisher(10.0)) << "its first message must not be lost";
  ASSERT_TRUE(feedUntilAnswered(drive, out_c, &next_frame));
  const osc::Matrix12d P_c = covarianceOf(out_c.messages().front());
  for (int i = 0; i < 12; ++i) {
    const double variance = (*old_format.sigmas)(i) * (*old_format.sigmas)(i);
    EXPECT_NEAR(P_c(i, i), variance, 1e-9 * variance) << "parameter " << i;
  }
  EXPECT_LE(largestCorrelation(P_c), 1e-6) << "no cross-covariance without the key";
  EXPECT_TRUE(osc_test::spinUntil(
      [&]() {
        return diagnostics.sawValue("initial guess", "diagonal covariance from its sigmas");
      },
      3.0))
      << diagnostics.describe();
  ASSERT_TRUE(unloadNodelet("/calib_c"));
  ::unlink(file.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "restore_test");
  return RUN_ALL_TESTS();
}
