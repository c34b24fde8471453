/// @file rectify.cpp
/// @brief rostest (test/ros/rectify.test): launch/calibrate.launch with rectify:=true on the
/// paper's off-road drive rendered at 320x240 (as convergence.cpp), whose camera_info
/// carries R and P computed from a left->right transform 0.5 deg off the truth (the right
/// camera pitched: what a stereo camera's stale factory calibration looks like). After
/// convergence the images stereo_image_proc rectifies with the calibration's camera_info
/// must be row-aligned (median vertical disparity of matched features < 0.2 px), while
/// those it rectifies with the drive's own camera_info are not (> 2 px). The valid share of
/// both disparity images is printed, the ~calibration quality figures are checked against
/// the truth: the rectification error against the truth's (the pairs are the renderer's),
/// and the depth sigmas against the estimate's covariance (the core computes them;
/// test/core/test_stereo_rectification.cpp checks them against a Monte-Carlo).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include <gtest/gtest.h>
#include <message_filters/subscriber.h>
#include <message_filters/time_synchronizer.h>
#include <sensor_msgs/PointCloud2.h>
#include <stereo_msgs/DisparityImage.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "online_stereo_calibration/core/geometry/stereo_rectification.h"
#include "rostest_helpers.h"

namespace {

using osc_test::StereoCalibration;
constexpr double kDeg = M_PI / 180.0;

double median(std::vector<double> values) {
  if (values.empty()) return std::nan("");
  const size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + middle, values.end());
  return values[middle];
}

/// Median |v_left - v_right| (px) of features tracked from the left into the right rectified
/// image (Shi-Tomasi corners, pyramidal Lucas-Kanade with a forward-backward check); NaN
/// with fewer than 20 matches.
double verticalDisparity(const cv::Mat& left, const cv::Mat& right, int* matches) {
  std::vector<cv::Point2f> corners, in_right, back;
  cv::goodFeaturesToTrack(left, corners, 400, 0.01, 6.0);
  *matches = 0;
  if (corners.size() < 20) return std::nan("");
  std::vector<uchar> status, status_back;
  std::vector<float> error;
  const cv::Size window(21, 21);
  cv::calcOpticalFlowPyrLK(left, right, corners, in_right, status, error, window, 3);
  cv::calcOpticalFlowPyrLK(right, left, in_right, back, status_back, error, window, 3);
  std::vector<double> vertical;
  for (size_t i = 0; i < corners.size(); ++i) {
    if (!status[i] || !status_back[i]) continue;
    if (std::hypot(back[i].x - corners[i].x, back[i].y - corners[i].y) > 0.2) continue;
    const double disparity = corners[i].x - in_right[i].x;
    if (disparity < -0.5 || disparity > 60.0) continue;  // not a plausible stereo match
    vertical.push_back(std::abs(in_right[i].y - corners[i].y));
  }
  *matches = static_cast<int>(vertical.size());
  return vertical.size() >= 20 ? median(vertical) : std::nan("");
}

/// Per stamp: the vertical disparity of a rectified pair and the valid share of a disparity
/// image, from one stereo_image_proc chain (namespace @p ns).
class RectifiedOutput {
 public:
  RectifiedOutput(ros::NodeHandle& nh, const std::string& ns)
      : left_(nh, ns + "/left/image_rect", 5),
        right_(nh, ns + "/right/image_rect", 5),
        sync_(left_, right_, 10) {
    sync_.registerCallback(boost::bind(&RectifiedOutput::pair, this, boost::placeholders::_1,
                                       boost::placeholders::_2));
    disparity_sub_ = nh.subscribe<stereo_msgs::DisparityImage>(
        ns + "/disparity", 5, [this](const stereo_msgs::DisparityImage::ConstPtr& d) {
          const cv::Mat image = cv_bridge::toCvCopy(d->image, "32FC1")->image;
          int valid = 0;
          for (int r = 0; r < image.rows; ++r) {
            for (int c = 0; c < image.cols; ++c) {
              const float v = image.at<float>(r, c);
              valid += std::isfinite(v) && v >= d->min_disparity && v <= d->max_disparity;
            }
          }
          valid_share_[d->header.stamp] = static_cast<double>(valid) / image.total();
        });
  }
  void pair(const sensor_msgs::ImageConstPtr& left, const sensor_msgs::ImageConstPtr& right) {
    int matches = 0;
    const double v = verticalDisparity(cv_bridge::toCvShare(left, "mono8")->image,
                                       cv_bridge::toCvShare(right, "mono8")->image, &matches);
    vertical_[left->header.stamp] = v;
    EXPECT_EQ(left->encoding, "mono8");
  }
  bool has(const ros::Time& t) const { return vertical_.count(t) && valid_share_.count(t); }
  /// Medians over the stamps from @p from on.
  double medianVertical(const ros::Time& from) const { return medianFrom(vertical_, from); }
  double medianValidShare(const ros::Time& from) const { return medianFrom(valid_share_, from); }
  size_t pairs() const { return vertical_.size(); }
  size_t disparities() const { return valid_share_.size(); }

 private:
  static double medianFrom(const std::map<ros::Time, double>& values, const ros::Time& from) {
    std::vector<double> v;
    for (const auto& [t, x] : values) {
      if (t >= from && std::isfinite(x)) v.push_back(x);
    }
    return median(v);
  }
  message_filters::Subscriber<sensor_msgs::Image> left_, right_;
  message_filters::TimeSynchronizer<sensor_msgs::Image, sensor_msgs::Image> sync_;
  ros::Subscriber disparity_sub_;
  std::map<ros::Time, double> vertical_, valid_share_;
};

TEST(Rectify, LiveCalibrationRowAlignsWhatAStaleFactoryCalibrationDoesNot) {
  ros::NodeHandle nh;
  int frames = 200;
  ros::param::get("~frames", frames);
  const std::string node = "/stereo/online_stereo_calibration";
  osc_test::RenderedDrive drive(nh, "/stereo", "/odom", frames, 320, 240,
                                std::floor(ros::Time::now().toSec()));
  // The drive's camera_info: R and P of the true rig with the right camera pitched 0.5 deg.
  const osc::SimulationScenario& scenario = drive.simulator().scenario();
  osc::Vector12d stale = drive.truth(0);
  stale(10) += 0.5 * kDeg;
  const osc::StereoRectification factory = osc::computeStereoRectification(
      scenario.measurement.left, scenario.measurement.right,
      osc::StereoExtrinsics::fromParameters(stale).leftToRightOptical(),
      osc::RectificationSettings());
  drive.setFactoryRectification(factory);

  osc_test::CalibrationCollector calibrations(nh, node + "/calibration");
  RectifiedOutput live(nh, "/stereo/calibrated"), own(nh, "/stereo/factory");
  int clouds = 0;
  ros::Subscriber count_clouds = nh.subscribe<sensor_msgs::PointCloud2>(
      "/stereo/calibrated/points2", 5, [&clouds](const sensor_msgs::PointCloud2::ConstPtr& cloud) {
        clouds += cloud->width * cloud->height > 0;
      });
  std::vector<sensor_msgs::CameraInfo> left_infos;
  ros::Subscriber info_sub = nh.subscribe<sensor_msgs::CameraInfo>(
      node + "/left/camera_info", 10, [&left_infos](const sensor_msgs::CameraInfo::ConstPtr& info) {
        left_infos.push_back(*info);
      });
  ASSERT_TRUE(drive.waitForSubscribers(20.0));
  ASSERT_TRUE(calibrations.waitForPublisher(20.0));
  ASSERT_TRUE(osc_test::spinUntil([&]() { return count_clouds.getNumPublishers() > 0; }, 20.0));

  int answered = 0;
  for (int k = 0; k < frames; ++k) {
    drive.publish(k);
    const ros::Time stamp = drive.stamp(k);
    answered += osc_test::spinUntil([&]() { return calibrations.has(stamp); }, 5.0);
    // Both chains' outputs for this pair before the next (lockstep: nothing queued away).
    osc_test::spinUntil([&]() { return live.has(stamp) && own.has(stamp); }, 2.0);
  }
  EXPECT_GE(answered, frames - 5);
  // After convergence: the last quarter of the drive.
  const ros::Time from = drive.stamp(frames - frames / 4);
  const double v_live = live.medianVertical(from), v_own = own.medianVertical(from);
  const double valid_live = live.medianValidShare(from), valid_own = own.medianValidShare(from);
  std::printf(
      "  vertical disparity of the rectified pairs (median over matched features, frames %d-%d):\n"
      "    live calibration's camera_info: %.3f px, valid disparity share %.1f %%\n"
      "    the drive's own camera_info:    %.3f px, valid disparity share %.1f %%\n"
      "  (%zu/%zu rectified pairs, %zu/%zu disparity images, %d point clouds)\n",
      frames - frames / 4, frames - 1, v_live, 100.0 * valid_live, v_own, 100.0 * valid_own,
      live.pairs(), own.pairs(), live.disparities(), own.disparities(), clouds);
  EXPECT_LT(v_live, 0.2);
  EXPECT_GT(v_own, 2.0);
  EXPECT_GT(clouds, frames / 2);
  // Row-aligned images let block matching find far more of the scene (measured 51 % vs 9 %).
  EXPECT_GT(valid_live, 2.0 * valid_own);

  // The published camera_info: stamped like the images, in the left image's frame (both), the
  // input's K and D.
  ASSERT_FALSE(left_infos.empty());
  const sensor_msgs::CameraInfo& info = left_infos.back();
  EXPECT_EQ(info.header.frame_id, drive.names().left_frame);
  EXPECT_EQ(info.header.stamp, drive.stamp(frames - 1));
  const sensor_msgs::CameraInfo input = drive.leftInfo(drive.stamp(frames - 1));
  for (int i = 0; i < 9; ++i) EXPECT_EQ(info.K[i], input.K[i]);
  EXPECT_EQ(info.D, input.D);

  // Quality figures of the last message: the renderer's pairs rectified with the estimate
  // (truth within 0.02 deg) lie on one row up to the front end's noise; the depth sigmas
  // are those of the estimate's covariance (depthSigmaOnAxis, Monte-Carlo-tested in core).
  const std::vector<StereoCalibration> messages = calibrations.messages();
  ASSERT_FALSE(messages.empty());
  const StereoCalibration& last = messages.back();
  std::printf(
      "  ~calibration: rectification error %.3f px (%u pairs), depth sigma %.3f m at "
      "10 m, %.3f m at 50 m\n",
      last.rectification_error, last.rectification_pairs, last.depth_sigma_10m,
      last.depth_sigma_50m);
  EXPECT_GT(last.rectification_pairs, 20u);
  EXPECT_GE(last.rectification_error, 0.0);
  EXPECT_LT(last.rectification_error, 0.2);
  EXPECT_GT(last.depth_sigma_10m, 0.0);
  // At least linear in depth: Z^2 from x_camr's angles, Z from the baseline's length (the
  // odometry's scale uncertainty, odometry_scale_sigma_percent).
  EXPECT_GT(last.depth_sigma_50m, 5.0 * last.depth_sigma_10m);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rectify_test");
  return RUN_ALL_TESTS();
}
