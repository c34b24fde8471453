/// @file bad_input.cpp
/// @brief rostest (test/ros/bad_input.test), issue 17: bad input never moves the calibration.
/// The paper's off-road drive rendered at 320x240 goes one pair at a time to two nodes,
/// "clean" and "dirty"; between its frames the dirty node also gets every bad input of
/// docs/ros.md's table (stamps between two frames unless said):
///   3: left image 640x480, its camera_info 320x240     5: 0x0 images
///   7: all-black images (refused inside the pipeline)  9: encodings yuv422, 32FC1, nonsense
///   11: image data half of step x height               13: left camera_info with K = 0
///   15: right camera_info with NaN in D                17: odometry NaN, Inf, zero quaternion
///   19: one odometry message 2 s back                  21: frame 21 again (duplicated stamp)
///   23: frame 3 again, 2 s back (backwards stamp)      30-229: a burst: 200 pairs in 1 s
/// Asserts: the dirty node answers to the end, never reports DIVERGED, every parameter it
/// publishes is within 3 of its sigmas of the clean node's at the same stamp, and every kind
/// of bad input is named in its /diagnostics.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <diagnostic_msgs/DiagnosticStatus.h>
#include <gtest/gtest.h>
#include <std_srvs/Trigger.h>
#include <opencv2/imgproc.hpp>

#include "online_stereo_calibration/core/geometry/rotation.h"
#include "rostest_helpers.h"

namespace {

using online_stereo_calibration::StereoCalibration;
using osc_test::spinUntil;

sensor_msgs::ImagePtr mono8(const cv::Mat& image, const ros::Time& stamp,
                            const std::string& frame) {
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = frame;
  return cv_bridge::CvImage(header, "mono8", image).toImageMsg();
}

class BadInput : public ::testing::Test {
 protected:
  BadInput()
      : clean_nh_("/clean"),
        dirty_nh_("/dirty"),
        frames_(readFrames()),
        start_(std::floor(ros::Time::now().toSec())),
        clean_(nh_, "/clean", "/clean/odom", frames_, 320, 240, start_),
        dirty_(nh_, "/dirty", "/dirty/odom", frames_, 320, 240, start_),
        raw_(dirty_nh_),
        clean_out_(nh_, "/clean/online_stereo_calibration/calibration"),
        dirty_out_(nh_, "/dirty/online_stereo_calibration/calibration"),
        diagnostics_(nh_, "dirty/") {}

  static int readFrames() {
    int frames = 270;
    ros::param::get("~frames", frames);
    return frames;
  }

  /// Publishes frame @p k (rendered once) to both nodes; waits for both answers.
  void publishToBoth(int k) {
    const osc::SimulatedImagePair pair = clean_.simulator().renderFrame(k);
    const ros::Time t = clean_.stamp(k);
    for (osc_test::RenderedDrive* drive : {&clean_, &dirty_}) {
      drive->publishOdometryUntil(t.toSec() + 0.025);
      drive->publishPair(pair, t);
    }
    answered_clean_ += spinUntil([&]() { return clean_out_.has(t); }, 15.0);
    answered_dirty_ += spinUntil([&]() { return dirty_out_.has(t); }, 5.0);
  }

  /// A pair for the dirty node only, stamped @p t, with odometry up to just past it.
  void publishDirty(const sensor_msgs::ImagePtr& left, const sensor_msgs::ImagePtr& right,
                    const sensor_msgs::CameraInfo& left_info,
                    const sensor_msgs::CameraInfo& right_info) {
    dirty_.publishOdometryUntil(left->header.stamp.toSec() + 0.025);
    raw_.left.publish(left);
    raw_.right.publish(right);
    raw_.left_info.publish(left_info);
    raw_.right_info.publish(right_info);
  }

  /// Waits until /diagnostics names @p text under "<kind> (last)" (the detail of a report).
  void expectReported(const std::string& kind, const std::string& text) {
    EXPECT_TRUE(spinUntil([&]() { return diagnostics_.sawValue(kind + " (last)", text); }, 10.0))
        << "'" << kind << "' with '" << text << "' never reported:" << diagnostics_.describe();
  }

  /// The bad input sent between frames @p k and k + 1 (none for most k).
  void injectAfter(int k) {
    const ros::Time t = clean_.stamp(k) + ros::Duration(0.05);
    const osc::SimulatedImagePair pair = clean_.simulator().renderFrame(k);
    const std::string lf = clean_.names().left_frame, rf = clean_.names().right_frame;
    const auto good = [&](const cv::Mat& image, const std::string& frame) {
      return mono8(image, t, frame);
    };
    switch (k) {
      case 3: {
        cv::Mat big;
        cv::resize(pair.left, big, cv::Size(640, 480));
        publishDirty(good(big, lf), good(pair.right, rf), dirty_.leftInfo(t), dirty_.rightInfo(t));
        expectReported("rejected images", "left image 640x480 does not match its camera_info");
        break;
      }
      case 5:
        publishDirty(good(cv::Mat(), lf), good(cv::Mat(), rf), dirty_.leftInfo(t),
                     dirty_.rightInfo(t));
        expectReported("rejected images", "left image 0x0 does not match");
        break;
      case 7: {
        const cv::Mat black = cv::Mat::zeros(pair.left.size(), CV_8UC1);
        publishDirty(good(black, lf), good(black, rf), dirty_.leftInfo(t), dirty_.rightInfo(t));
        expectReported("rejected images", "all black");
        break;
      }
      case 9: {
        int i = 0;
        for (const std::string encoding : {"yuv422", "32FC1", "nonsense"}) {
          const ros::Time ti = t + ros::Duration(0.01 * i++);
          sensor_msgs::ImagePtr left = mono8(pair.left, ti, lf), right = mono8(pair.right, ti, rf);
          left->encoding = right->encoding = encoding;
          publishDirty(left, right, dirty_.leftInfo(ti), dirty_.rightInfo(ti));
          expectReported("rejected images", "unsupported image encoding '" + encoding + "'");
        }
        break;
      }
      case 11: {
        sensor_msgs::ImagePtr left = good(pair.left, lf);
        left->data.resize(left->data.size() / 2);
        publishDirty(left, good(pair.right, rf), dirty_.leftInfo(t), dirty_.rightInfo(t));
        expectReported("rejected images", "shorter than step x height");
        break;
      }
      case 13: {
        sensor_msgs::CameraInfo info = dirty_.leftInfo(t);
        std::fill(info.K.begin(), info.K.end(), 0.0);
        publishDirty(good(pair.left, lf), good(pair.right, rf), info, dirty_.rightInfo(t));
        expectReported("bad camera_info", "uncalibrated");
        break;
      }
      case 15: {
        sensor_msgs::CameraInfo info = dirty_.rightInfo(t);
        info.D.assign(5, 0.0);
        info.D[0] = std::nan("");
        publishDirty(good(pair.left, lf), good(pair.right, rf), dirty_.leftInfo(t), info);
        expectReported("bad camera_info", "distortion coefficients (D) must be finite");
        break;
      }
      case 17: {
        const double inf = std::numeric_limits<double>::infinity();
        for (int i = 0; i < 3; ++i) {
          nav_msgs::Odometry o =
              osc_test::straightDriveOdometry(start_, t.toSec() - 0.02 + 1e-4 * i);
          if (i == 0) o.pose.pose.position.x = std::nan("");
          if (i == 1) o.pose.pose.orientation.z = inf;
          if (i == 2) o.pose.pose.orientation.w = 0.0;
          raw_.odom.publish(o);
        }
        expectReported("rejected odometry", "a non-finite pose");
        expectReported("rejected odometry", "quaternion of norm 0.0");
        break;
      }
      case 19:
        raw_.odom.publish(osc_test::straightDriveOdometry(start_, t.toSec() - 2.0));
        expectReported("rejected odometry", "behind the newest");
        break;
      case 21: {
        const ros::Time same = clean_.stamp(k);
        dirty_.publishPair(pair, same);
        expectReported("duplicated stamps", "the stamp of the previous one");
        break;
      }
      case 23:
        dirty_.publishPair(clean_.simulator().renderFrame(3), clean_.stamp(3));
        expectReported("time went backwards", "pair stamp");
        break;
      default:
        break;
    }
  }

  /// The burst: frames [first, first + count) to the dirty node within about 1 s (with their
  /// odometry), and one at a time to the clean node.
  void burst(int first, int count) {
    std::vector<osc::SimulatedImagePair> pairs;
    for (int k = first; k < first + count; ++k) {
      pairs.push_back(clean_.simulator().renderFrame(k));
      const ros::Time t = clean_.stamp(k);
      clean_.publishOdometryUntil(t.toSec() + 0.025);
      clean_.publishPair(pairs.back(), t);
      answered_clean_ += spinUntil([&]() { return clean_out_.has(t); }, 15.0);
    }
    const ros::WallTime start = ros::WallTime::now();
    for (int i = 0; i < count; ++i) {
      const ros::Time t = clean_.stamp(first + i);
      dirty_.publishOdometryUntil(t.toSec() + 0.025);
      dirty_.publishPair(pairs[i], t);
      ros::WallDuration(1.0 / count).sleep();
      ros::spinOnce();
    }
    burst_seconds_ = (ros::WallTime::now() - start).toSec();
    // The worker catches up with what it kept: the last pair is answered or dropped.
    spinUntil([]() { return false; }, 2.0);
  }

  ros::NodeHandle nh_, clean_nh_, dirty_nh_;
  int frames_;
  double start_;
  osc_test::RenderedDrive clean_, dirty_;
  osc_test::StereoInputs raw_;
  osc_test::CalibrationCollector clean_out_, dirty_out_;
  osc_test::DiagnosticsCollector diagnostics_;
  int answered_clean_ = 0, answered_dirty_ = 0;
  double burst_seconds_ = 0.0;
};

TEST_F(BadInput, NeverMovesTheCalibrationAndIsNamedInDiagnostics) {
  constexpr int kBurstFirst = 30, kBurstPairs = 200;
  ASSERT_GE(frames_, kBurstFirst + kBurstPairs + 20);
  ASSERT_TRUE(clean_.waitForSubscribers(20.0));
  ASSERT_TRUE(dirty_.waitForSubscribers(20.0));
  ASSERT_TRUE(clean_out_.waitForPublisher(20.0));
  ASSERT_TRUE(dirty_out_.waitForPublisher(20.0));
  for (int k = 0; k < kBurstFirst; ++k) {
    publishToBoth(k);
    injectAfter(k);
  }
  burst(kBurstFirst, kBurstPairs);
  const int dirty_before_tail = answered_dirty_;
  for (int k = kBurstFirst + kBurstPairs; k < frames_; ++k) publishToBoth(k);
  const int tail = frames_ - kBurstFirst - kBurstPairs;

  // Alive and answering: every clean pair, and the dirty node's tail after the burst.
  EXPECT_EQ(answered_clean_, frames_);
  EXPECT_GE(answered_dirty_ - dirty_before_tail, tail - 2) << "of the " << tail << " last pairs";
  std_srvs::Trigger trigger;
  EXPECT_TRUE(ros::service::call("/dirty/online_stereo_calibration/save_calibration", trigger));

  std::map<ros::Time, StereoCalibration> clean;
  for (const StereoCalibration& m : clean_out_.messages()) clean[m.header.stamp] = m;
  int compared = 0, beyond = 0, diverged = 0, clean_diverged = 0;
  double worst_z = 0.0;
  std::string worst;
  for (const StereoCalibration& c : clean_out_.messages()) {
    clean_diverged += c.state == StereoCalibration::STATE_DIVERGED;
  }
  ros::Time newest;
  for (const StereoCalibration& d : dirty_out_.messages()) {
    diverged += d.state == StereoCalibration::STATE_DIVERGED;
    // The pair sent 2 s back is processed (as after a bag loop) but has no clean twin.
    if (d.header.stamp <= newest) continue;
    newest = d.header.stamp;
    const auto c = clean.find(d.header.stamp);
    if (c == clean.end()) continue;
    ++compared;
    bool out = false;
    for (int i = 0; i < 12; ++i) {
      double error = d.parameters[i] - c->second.parameters[i];
      if (i % 6 >= 3) error = osc::wrapAngle(error);
      const double z = std::abs(error) / d.sigma[i];
      out = out || !(z <= 3.0);
      if (!(z <= worst_z)) {
        worst_z = z;
        worst = "parameter " + std::to_string(i) + " at " + std::to_string(d.header.stamp.toSec());
      }
    }
    beyond += out;
  }
  std::printf(
      "  clean %d/%d answered, dirty %zu messages (%d compared), burst of %d pairs in %.2f s; "
      "largest |dirty - clean| %.2f sigma (%s); DIVERGED: dirty %d, clean %d\n",
      answered_clean_, frames_, dirty_out_.size(), compared, kBurstPairs, burst_seconds_, worst_z,
      worst.c_str(), diverged, clean_diverged);
  EXPECT_GE(compared, 60);
  EXPECT_EQ(beyond, 0) << "dirty messages further than 3 sigma from the clean run";
  EXPECT_EQ(diverged, 0) << "DIVERGED states published by the dirty node";
  EXPECT_FALSE(dirty_out_.anyNonFinite());

  // Each kind also made the status WARN with its name as a reason.
  const uint8_t warn = diagnostic_msgs::DiagnosticStatus::WARN;
  for (const std::string kind : {"rejected images", "bad camera_info", "rejected odometry",
                                 "duplicated stamps", "time went backwards", "dropped pairs"}) {
    EXPECT_TRUE(diagnostics_.sawReason(warn, kind)) << kind << diagnostics_.describe();
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "bad_input_test");
  return RUN_ALL_TESTS();
}
