/// @file test_odometry_interpolation.cpp
/// @brief Pure conversions of the ROS adapter (no master): pose interpolation (linear +
/// SLERP) against a known trajectory, the pose buffer and gyro integrator, CameraInfo ->
/// CameraIntrinsics, and the calibration message's transforms vs. its parameters.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "online_stereo_calibration/ros/conversions.h"
#include "online_stereo_calibration/ros/motion_buffers.h"
#include "online_stereo_calibration/ros/output_publisher.h"
#include "online_stereo_calibration/ros/ros_config.h"

namespace online_stereo_calibration {
namespace {

/// A known trajectory: constant velocity along x and constant yaw rate, so that linear
/// interpolation of the translation along a straight segment and SLERP are exact.
Eigen::Isometry3d truthAt(double t) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(2.0 * t, -0.5 * t, 0.1 * t);
  pose.linear() = (Eigen::AngleAxisd(0.3 * t, Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  return pose;
}

void expectPoseNear(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double tolerance) {
  EXPECT_NEAR((a.translation() - b.translation()).norm(), 0.0, tolerance);
  EXPECT_NEAR(Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle(), 0.0, tolerance);
}

TEST(InterpolatePose, ExactOnConstantRateTrajectoryBetweenSamples) {
  const StampedPose before{10.0, truthAt(10.0)};
  const StampedPose after{10.1, truthAt(10.1)};
  for (double s : {0.0, 0.25, 0.5, 0.73, 1.0}) {
    const double t = 10.0 + 0.1 * s;
    expectPoseNear(interpolatePose(before, after, t), truthAt(t), 1e-12);
  }
}

TEST(InterpolatePose, EqualStampsReturnTheFirst) {
  const StampedPose a{1.0, truthAt(1.0)};
  expectPoseNear(interpolatePose(a, a, 1.0), truthAt(1.0), 1e-15);
}

TEST(PoseBuffer, InterpolatesAtImageStampsAndReportsWhy) {
  PoseBuffer buffer(10.0, 0.5);
  Eigen::Isometry3d pose;
  EXPECT_EQ(buffer.poseAt(1.0, &pose), LookupStatus::kEmpty);
  for (int i = 0; i <= 20; ++i) EXPECT_TRUE(buffer.add({1.0 + 0.02 * i, truthAt(1.0 + 0.02 * i)}));
  ASSERT_EQ(buffer.poseAt(1.0333, &pose), LookupStatus::kOk);
  expectPoseNear(pose, truthAt(1.0333), 1e-12);
  EXPECT_EQ(buffer.poseAt(1.5, &pose), LookupStatus::kNotYet);
  EXPECT_EQ(buffer.poseAt(0.5, &pose), LookupStatus::kTooOld);
  // Duplicated and out-of-order stamps are refused.
  EXPECT_FALSE(buffer.add({1.4, truthAt(1.4)}));
  EXPECT_FALSE(buffer.add({1.2, truthAt(1.2)}));
  // A NaN pose is refused.
  Eigen::Isometry3d nan_pose = truthAt(2.0);
  nan_pose.translation().x() = std::nan("");
  EXPECT_FALSE(buffer.add({2.0, nan_pose}));
  // A gap larger than max_gap is reported, not bridged.
  EXPECT_TRUE(buffer.add({3.0, truthAt(3.0)}));
  EXPECT_EQ(buffer.poseAt(2.0, &pose), LookupStatus::kGap);
}

// Issue 15: the increment's covariance from the odometry's twist covariances.
TEST(PoseBuffer, IncrementCovarianceSumsTheTwistCovariancesOverTheInterval) {
  PoseBuffer buffer(10.0, 0.5);
  Eigen::Matrix<double, 6, 6> twist = Eigen::Matrix<double, 6, 6>::Zero();
  twist.diagonal() << 0.04, 0.01, 0.01, 1e-4, 1e-4, 4e-4;  // (0.2 m/s)^2 ... (0.02 rad/s)^2
  for (int i = 0; i <= 10; ++i) {
    StampedPose sample{1.0 + 0.02 * i, truthAt(1.0 + 0.02 * i)};
    sample.has_twist_covariance = true;
    sample.twist_covariance = twist;
    ASSERT_TRUE(buffer.add(sample));
  }
  Eigen::Matrix<double, 6, 6> covariance;
  // 0.1 s = 5 whole samples of 0.02 s: 5 * C * 0.02^2.
  ASSERT_TRUE(buffer.incrementCovariance(1.02, 1.12, &covariance));
  EXPECT_LT((covariance - 5.0 * 0.0004 * twist).cwiseAbs().maxCoeff(), 1e-15);
  // Partial overlaps count by their length: [1.01, 1.03] = two halves of 0.01 s.
  ASSERT_TRUE(buffer.incrementCovariance(1.01, 1.03, &covariance));
  EXPECT_LT((covariance - 2.0 * 0.0001 * twist).cwiseAbs().maxCoeff(), 1e-15);
  // Beyond the samples, or over a sample without covariance: none.
  EXPECT_FALSE(buffer.incrementCovariance(1.1, 1.3, &covariance));
  StampedPose bare{1.22, truthAt(1.22)};
  ASSERT_TRUE(buffer.add(bare));
  EXPECT_FALSE(buffer.incrementCovariance(1.1, 1.21, &covariance));
  EXPECT_TRUE(buffer.incrementCovariance(1.1, 1.2, &covariance));
}

/// The odometry message of a vehicle that speeds up (2 m/s + 1.5 m/s^2 t) along its x axis
/// while turning at 0.3 rad/s: body twist [2 + 1.5 t, 0, 0, 0, 0, 0.3], linear in t. The pose
/// is truthAt's (only its movement matters here).
nav_msgs::Odometry acceleratingTurn(double t) {
  nav_msgs::Odometry m;
  m.header.stamp.fromSec(t);
  const geometry_msgs::Transform pose = transformFromIsometry(truthAt(t));
  m.pose.pose.position.x = pose.translation.x;
  m.pose.pose.position.y = pose.translation.y;
  m.pose.pose.position.z = pose.translation.z;
  m.pose.pose.orientation = pose.rotation;
  m.twist.twist.linear.x = 2.0 + 1.5 * t;
  m.twist.twist.angular.z = 0.3;
  return m;
}

osc::Vector6d acceleratingTurnTwist(double t) {
  osc::Vector6d twist;
  twist << 2.0 + 1.5 * t, 0.0, 0.0, 0.0, 0.0, 0.3;
  return twist;
}

// Issue 15: the twists of an increment (at both image stamps) come from the odometry's own
// twist.twist, interpolated between the messages around each stamp, as MotionSource does.
TEST(PoseBuffer, IncrementTwistsAreTheOdometrysTwistsAtTheImageStamps) {
  PoseBuffer buffer(10.0, 0.5);
  for (int i = 0; i <= 50; ++i) {  // 50 Hz
    std::string twist_problem, covariance_problem;
    const StampedPose sample =
        odometrySample(acceleratingTurn(1.0 + 0.02 * i), true, &twist_problem, &covariance_problem);
    EXPECT_TRUE(sample.has_twist);
    EXPECT_EQ(twist_problem, "");
    EXPECT_FALSE(sample.has_twist_covariance);  // all zero: not given
    EXPECT_NE(covariance_problem, "");
    if (buffer.newest()) {
      EXPECT_EQ(unsetTwistProblem(sample, *buffer.newest()), "");
    }
    ASSERT_TRUE(buffer.add(sample));
  }
  // Image stamps between odometry stamps, and on one.
  for (double stamp : {1.013, 1.113, 1.6, 1.987}) {
    osc::Vector6d twist;
    ASSERT_TRUE(buffer.twistAt(stamp, &twist)) << stamp;
    EXPECT_LT((twist - acceleratingTurnTwist(stamp)).norm(), 1e-12) << stamp;
  }
  osc::Vector6d twist;
  EXPECT_FALSE(buffer.twistAt(2.01, &twist));  // not yet covered
  EXPECT_FALSE(buffer.twistAt(0.99, &twist));
}

// A twist that is not finite, or all zero while the pose moves (a driver that does not fill
// it), is not used: increments touching it get none (the filter then uses the trend), and the
// reason is said.
TEST(PoseBuffer, UnusableTwistsGiveNoIncrementTwists) {
  PoseBuffer buffer(10.0, 0.5);
  std::string twist_problem, covariance_problem, nan_problem;
  for (int i = 0; i <= 5; ++i) {
    nav_msgs::Odometry m = acceleratingTurn(1.0 + 0.02 * i);
    if (i == 3) m.twist.twist.angular.y = std::numeric_limits<double>::quiet_NaN();
    twist_problem.clear();
    const StampedPose sample = odometrySample(m, false, &twist_problem, &covariance_problem);
    EXPECT_EQ(sample.has_twist, i != 3);
    EXPECT_EQ(twist_problem.empty(), i != 3);
    if (i == 3) nan_problem = twist_problem;
    ASSERT_TRUE(buffer.add(sample));
  }
  EXPECT_EQ(covariance_problem, "");  // not asked for
  EXPECT_NE(nan_problem.find("not finite"), std::string::npos) << nan_problem;
  osc::Vector6d twist;
  EXPECT_TRUE(buffer.twistAt(1.03, &twist));
  EXPECT_FALSE(buffer.twistAt(1.05, &twist));  // between samples 2 and 3
  EXPECT_FALSE(buffer.twistAt(1.06, &twist));  // sample 3 itself
  EXPECT_FALSE(buffer.twistAt(1.07, &twist));
  EXPECT_TRUE(buffer.twistAt(1.09, &twist));
  // All zero: unset while the vehicle moves, a real standstill while it does not.
  nav_msgs::Odometry zero = acceleratingTurn(1.12);
  zero.twist.twist = geometry_msgs::Twist();
  const StampedPose unset = odometrySample(zero, false, &twist_problem, &covariance_problem);
  EXPECT_NE(unsetTwistProblem(unset, *buffer.newest()), "");
  StampedPose standing = unset;
  standing.pose = buffer.newest()->pose;
  EXPECT_EQ(unsetTwistProblem(standing, *buffer.newest()), "");
}

// Issue 17: one stale odometry message must not wipe the history; a time line that really
// went back (a bag loop) is adopted after PoseBuffer::kSamplesToRestart samples.
TEST(PoseBuffer, OneStaleSampleIsRefusedButANewTimeLineIsAdopted) {
  using Offered = PoseBuffer::Offered;
  PoseBuffer buffer(10.0, 0.5);
  for (int i = 0; i <= 100; ++i) {
    ASSERT_EQ(buffer.offer({10.0 + 0.01 * i, truthAt(10.0 + 0.01 * i)}), Offered::kAdded);
  }
  Eigen::Isometry3d pose;
  // A single message 2 s back: held, not used; the history still answers.
  EXPECT_EQ(buffer.offer({9.0, truthAt(9.0)}), Offered::kHeldBack);
  EXPECT_EQ(buffer.poseAt(10.5, &pose), LookupStatus::kOk);
  EXPECT_EQ(buffer.newestStamp(), 11.0);
  // A normal sample forgets it: stale messages interleaved with live ones never restart.
  for (int i = 1; i <= 2 * PoseBuffer::kSamplesToRestart; ++i) {
    EXPECT_EQ(buffer.offer({11.0 + 0.01 * i, truthAt(11.0 + 0.01 * i)}), Offered::kAdded);
    EXPECT_EQ(buffer.offer({9.0 + 0.01 * i, truthAt(9.0 + 0.01 * i)}), Offered::kHeldBack);
  }
  EXPECT_EQ(buffer.poseAt(10.5, &pose), LookupStatus::kOk);
  // Duplicates within max_gap are still refused, not held.
  EXPECT_EQ(buffer.offer({11.05, truthAt(11.05)}), Offered::kRejected);
  // A bag loop: consecutive samples from t = 1 s on.
  for (int i = 0; i + 1 < PoseBuffer::kSamplesToRestart; ++i) {
    EXPECT_EQ(buffer.offer({1.0 + 0.01 * i, truthAt(1.0 + 0.01 * i)}), Offered::kHeldBack);
  }
  const double last = 1.0 + 0.01 * (PoseBuffer::kSamplesToRestart - 1);
  EXPECT_EQ(buffer.offer({last, truthAt(last)}), Offered::kRestarted);
  EXPECT_EQ(buffer.newestStamp(), last);
  ASSERT_EQ(buffer.poseAt(1.015, &pose), LookupStatus::kOk);
  expectPoseNear(pose, truthAt(1.015), 1e-12);
  EXPECT_EQ(buffer.poseAt(10.5, &pose), LookupStatus::kNotYet);
  // The images went back first: restart() adopts what was held back so far.
  EXPECT_EQ(buffer.offer({0.2, truthAt(0.2)}), Offered::kHeldBack);
  EXPECT_EQ(buffer.offer({0.21, truthAt(0.21)}), Offered::kHeldBack);
  buffer.restart();
  EXPECT_EQ(buffer.newestStamp(), 0.21);
  EXPECT_EQ(buffer.poseAt(0.205, &pose), LookupStatus::kOk);
  buffer.restart();  // nothing held: empty
  EXPECT_TRUE(buffer.empty());
}

TEST(PoseProblem, NamesNonFiniteFieldsAndZeroQuaternions) {
  geometry_msgs::Pose pose;
  pose.orientation.w = 1.0;
  EXPECT_EQ(poseProblem(pose), "");
  pose.orientation.w = 1.3;  // unnormalised but a rotation
  EXPECT_EQ(poseProblem(pose), "");
  pose.position.y = std::numeric_limits<double>::infinity();
  EXPECT_EQ(poseProblem(pose), "a non-finite pose");
  pose.position.y = 0.0;
  pose.orientation.x = std::nan("");
  EXPECT_EQ(poseProblem(pose), "a non-finite pose");
  pose.orientation.x = 0.0;
  pose.orientation.w = 0.0;
  EXPECT_NE(poseProblem(pose).find("quaternion of norm 0.0"), std::string::npos);
}

TEST(ImageBuffer, ShortStepOrDataIsNamed) {
  sensor_msgs::Image image;
  image.width = 4;
  image.height = 3;
  image.step = 8;  // mono16
  image.data.resize(24);
  EXPECT_EQ(imageBufferProblem(image, 2), "");
  image.data.resize(23);
  EXPECT_NE(imageBufferProblem(image, 2).find("data of 23 bytes shorter than step x height"),
            std::string::npos);
  image.step = 6;
  EXPECT_NE(imageBufferProblem(image, 2).find("step 6 shorter than a row"), std::string::npos);
  image.width = 0xFFFFFFFFu;  // no overflow into a small product
  image.step = 0xFFFFFFFFu;
  EXPECT_NE(imageBufferProblem(image, 3).find("shorter"), std::string::npos);
}

TEST(GyroIntegrator, IntegratesConstantRate) {
  GyroIntegrator gyro(10.0, 0.5);
  const Eigen::Vector3d rate(0.0, 0.0, 0.3);
  for (int i = 0; i <= 100; ++i) EXPECT_TRUE(gyro.add(0.01 * i, rate));
  Eigen::Matrix3d rotation;
  ASSERT_EQ(gyro.rotationBetween(0.105, 0.555, &rotation), LookupStatus::kOk);
  const Eigen::Matrix3d expected =
      Eigen::AngleAxisd(0.3 * 0.45, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR((rotation - expected).norm(), 0.0, 1e-12);
  EXPECT_EQ(gyro.rotationBetween(0.5, 1.5, &rotation), LookupStatus::kNotYet);
}

TEST(CameraInfo, ConvertsKDAndModel) {
  sensor_msgs::CameraInfo info;
  info.width = 1280;
  info.height = 720;
  info.K = {700.0, 0.0, 640.5, 0.0, 701.0, 360.25, 0.0, 0.0, 1.0};
  info.distortion_model = "plumb_bob";
  info.D = {-0.1, 0.01, 0.001, -0.002, 0.0};
  const osc::CameraIntrinsics intrinsics = intrinsicsFromCameraInfo(info);
  EXPECT_EQ(intrinsics.width, 1280);
  EXPECT_EQ(intrinsics.height, 720);
  EXPECT_DOUBLE_EQ(intrinsics.fx, 700.0);
  EXPECT_DOUBLE_EQ(intrinsics.fy, 701.0);
  EXPECT_DOUBLE_EQ(intrinsics.cx, 640.5);
  EXPECT_DOUBLE_EQ(intrinsics.cy, 360.25);
  EXPECT_EQ(intrinsics.model, osc::DistortionModel::kPlumbBob);
  EXPECT_EQ(intrinsics.distortion, info.D);

  info.distortion_model = "equidistant";
  info.D = {0.1, 0.01, 0.0, 0.0};
  EXPECT_EQ(intrinsicsFromCameraInfo(info).model, osc::DistortionModel::kEquidistant);

  info.distortion_model = "no_such_model";
  EXPECT_THROW(intrinsicsFromCameraInfo(info), std::invalid_argument);
  // Uncalibrated camera (K all zero), as image_proc rejects it.
  sensor_msgs::CameraInfo uncalibrated;
  uncalibrated.width = 640;
  uncalibrated.height = 480;
  EXPECT_THROW(intrinsicsFromCameraInfo(uncalibrated), std::invalid_argument);
}

// The rectified camera_info: the input's header, size, model, K and D with the given R and P;
// an all-zero D gets the k1 that makes image_geometry rectify at all.
TEST(CameraInfo, RectifiedKeepsTheInputAndSetsRAndP) {
  sensor_msgs::CameraInfo input;
  input.header.frame_id = "left_camera_optical";
  input.header.stamp = ros::Time(12, 5);
  input.width = 640;
  input.height = 480;
  input.K = {600.0, 0.0, 319.5, 0.0, 601.0, 239.5, 0.0, 0.0, 1.0};
  input.distortion_model = "plumb_bob";
  input.D = {-0.1, 0.01, 0.001, -0.002, 0.0};
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.01, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::Matrix<double, 3, 4> P;
  P << 610.0, 0.0, 320.0, -183.0, 0.0, 610.0, 240.0, 0.0, 0.0, 0.0, 1.0, 0.0;
  const sensor_msgs::CameraInfo out = rectifiedCameraInfo(input, R, P);
  EXPECT_EQ(out.header.frame_id, input.header.frame_id);
  EXPECT_EQ(out.header.stamp, input.header.stamp);
  EXPECT_EQ(out.width, 640u);
  EXPECT_EQ(out.K, input.K);
  EXPECT_EQ(out.D, input.D);
  EXPECT_EQ(out.distortion_model, "plumb_bob");
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) EXPECT_EQ(out.R[3 * i + j], R(i, j));
    for (int j = 0; j < 4; ++j) EXPECT_EQ(out.P[4 * i + j], P(i, j));
  }
  input.D = {0.0, 0.0, 0.0, 0.0, 0.0};
  EXPECT_EQ(rectifiedCameraInfo(input, R, P).D, (std::vector<double>{1e-12, 0.0, 0.0, 0.0, 0.0}));
  input.D.clear();
  input.distortion_model.clear();
  const sensor_msgs::CameraInfo empty = rectifiedCameraInfo(input, R, P);
  EXPECT_EQ(empty.distortion_model, "plumb_bob");
  EXPECT_EQ(empty.D, (std::vector<double>{1e-12, 0.0, 0.0, 0.0, 0.0}));
}

// The rectification parameters are validated, each problem naming its key.
TEST(RosConfig, RectificationParametersAreValidatedByName) {
  RosConfig config;
  EXPECT_TRUE(config.validate().empty());
  config.rectification_alpha = 1.5;
  config.rectification_width = 640;  // height left at 0
  config.rectification_update_px = -0.1;
  const std::vector<std::string> problems = config.validate();
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_NE(problems[0].find("rectification_alpha"), std::string::npos);
  EXPECT_NE(problems[1].find("rectification_height"), std::string::npos);
  EXPECT_NE(problems[2].find("rectification_update_px"), std::string::npos);
}

// Quality fields: -1 and 0 pairs when the pair had no stereo pair.
TEST(CalibrationMessage, QualityFields) {
  StereoCalibration message;
  osc::CalibrationQuality quality;
  quality.depth_sigma_10m = 0.03;
  quality.depth_sigma_50m = 0.7;
  setQualityFields(quality, &message);
  EXPECT_EQ(message.rectification_error, -1.0);
  EXPECT_EQ(message.rectification_pairs, 0u);
  EXPECT_EQ(message.depth_sigma_10m, 0.03);
  EXPECT_EQ(message.depth_sigma_50m, 0.7);
  quality.rectification_error = osc::RectificationError{0.04, 55};
  setQualityFields(quality, &message);
  EXPECT_EQ(message.rectification_error, 0.04);
  EXPECT_EQ(message.rectification_pairs, 55u);
}

TEST(CalibrationMessage, TransformsEqualParametersUnderInterfaceConventions) {
  osc::CalibrationEstimate estimate;
  estimate.parameters << 1.5, 0.2, 1.3, 0.01, -0.02, 0.03, 0.001, -0.12, 0.002, 0.004, -0.003,
      0.002;
  estimate.extrinsics = osc::StereoExtrinsics::fromParameters(estimate.parameters);
  estimate.parameter_covariance = osc::Matrix12d::Identity() * 1e-4;
  const OutputFrames frames{"base_link", "left_optical", "right_optical"};
  const StereoCalibration message =
      makeCalibrationMessage(estimate, ros::Time(12.5), frames, 1, 0.01);
  EXPECT_EQ(message.header.frame_id, "base_link");
  EXPECT_EQ(message.left_frame_id, "left_optical");
  EXPECT_DOUBLE_EQ(message.header.stamp.toSec(), 12.5);
  // vehicle -> left optical = pose(vehicle_to_left) * R_body_optical.
  const Eigen::Isometry3d T_veh_caml = osc::poseFromParameters(estimate.parameters.head<6>());
  const Eigen::Isometry3d T_caml_camr = osc::poseFromParameters(estimate.parameters.tail<6>());
  const Eigen::Isometry3d B = osc::bodyFromOptical();
  expectPoseNear(isometryFromTransform(message.vehicle_to_left), T_veh_caml * B, 1e-12);
  expectPoseNear(isometryFromTransform(message.left_to_right), B.inverse() * T_caml_camr * B,
                 1e-12);
  for (int i = 0; i < 12; ++i) {
    EXPECT_DOUBLE_EQ(message.parameters[i], estimate.parameters(i));
    EXPECT_NEAR(message.sigma[i], 1e-2, 1e-15);
  }
  // Baseline of -0.12 m along the left body y axis = +0.12 m along the left optical x axis.
  EXPECT_NEAR(message.left_to_right.translation.x, 0.12, 0.01);
}

TEST(RestoredCovariance, TangentCovarianceMapsBackToTheFilesParameterCovariance) {
  // A saved full parameter covariance P (strongly correlated) at a saved calibration: the
  // tangent covariance seeding the filter must give P back through the filter's own map
  // J T J^T (CalibrationFilter::parameterCovariance).
  osc::Vector12d parameters;
  parameters << 1.5, 0.15, 1.3, 0.02, 0.05, -0.03, 0.001, -0.3, 0.002, 0.001, -0.002, 0.003;
  const osc::StereoExtrinsics extrinsics = osc::StereoExtrinsics::fromParameters(parameters);
  osc::Matrix12d A;
  for (int i = 0; i < 144; ++i) A(i / 12, i % 12) = 1e-2 * std::sin(1.0 + 7.0 * i);
  const osc::Matrix12d P = A * A.transpose() + 1e-8 * osc::Matrix12d::Identity();
  const osc::Matrix12d T = tangentCovarianceFromParameterCovariance(extrinsics, P);
  EXPECT_LE((T - T.transpose()).cwiseAbs().maxCoeff(), 0.0);
  const osc::Matrix12d J = osc::parameterJacobian(extrinsics);
  EXPECT_LE((J * T * J.transpose() - P).cwiseAbs().maxCoeff(), 1e-12 * P.cwiseAbs().maxCoeff());
  // Rotations make the tangent and parameter spaces differ: T is not P itself.
  EXPECT_GT((T - P).cwiseAbs().maxCoeff(), 1e-6 * P.cwiseAbs().maxCoeff());
}

TEST(CalibrationState, FollowsPointsAndPerBlockThresholds) {
  osc::CalibrationEstimate estimate;
  estimate.tracked_points = 50;
  estimate.parameter_covariance = osc::Matrix12d::Identity() * 1e-8;  // 3 sigma 0.3 mm / mrad
  osc::ConvergenceThresholds bounds;                                  // the shipped ones
  EXPECT_EQ(calibrationState(estimate, false, 10, bounds), StereoCalibration::STATE_CONVERGED);
  EXPECT_EQ(calibrationState(estimate, true, 10, bounds), StereoCalibration::STATE_DIVERGED);
  estimate.tracked_points = 3;
  EXPECT_EQ(calibrationState(estimate, false, 10, bounds), StereoCalibration::STATE_INITIALIZING);
  estimate.tracked_points = 50;
  // Each block against its own bound: 3 sigma of 4 cm passes for xl (5 cm), not for xr (3 mm).
  estimate.parameter_covariance(0, 0) = std::pow(0.04 / 3.0, 2);
  EXPECT_EQ(calibrationState(estimate, false, 10, bounds), StereoCalibration::STATE_CONVERGED);
  estimate.parameter_covariance(6, 6) = std::pow(0.004 / 3.0, 2);
  EXPECT_EQ(calibrationState(estimate, false, 10, bounds), StereoCalibration::STATE_CONVERGING);
  estimate.parameter_covariance(6, 6) = 1e-8;
  estimate.parameter_covariance(9, 9) = std::pow(0.06 * M_PI / 180.0 / 3.0, 2);  // roll_r
  EXPECT_EQ(calibrationState(estimate, false, 10, bounds), StereoCalibration::STATE_CONVERGING);
}

// Issue 14: what the motion cannot determine is reported and does not block CONVERGED, while
// a wide parameter that the motion does determine still does.
TEST(CalibrationState, UndeterminedTranslationsDoNotBlockConverged) {
  osc::CalibrationEstimate estimate;
  estimate.tracked_points = 50;
  estimate.parameter_covariance = osc::Matrix12d::Identity() * 1e-8;
  estimate.parameter_covariance(2, 2) = 0.5 * 0.5;  // zl still at its start sigma
  osc::ConvergenceThresholds bounds;
  estimate.excitation << 0.0, 0.02, 0.9;  // a car on a flat road: yaw only
  EXPECT_EQ(osc::undeterminedParameters(estimate, bounds), std::vector<int>{2});
  EXPECT_EQ(calibrationState(estimate, false, 10, bounds), StereoCalibration::STATE_CONVERGED);
  estimate.excitation << 0.6, 0.0, 0.9;  // rolling: zl is determined, and not yet learned
  EXPECT_TRUE(osc::undeterminedParameters(estimate, bounds).empty());
  EXPECT_EQ(calibrationState(estimate, false, 10, bounds), StereoCalibration::STATE_CONVERGING);
  // Standing still: nothing rotates, but xl and yl, already learned, are not listed.
  estimate.excitation.setZero();
  EXPECT_EQ(osc::undeterminedParameters(estimate, bounds), std::vector<int>{2});
}

// Issue 15: what only the odometry's scale leaves open (the baseline's metric length) is
// reported and does not block CONVERGED; the same width from the data themselves does.
TEST(CalibrationState, WhatOnlyTheOdometrysScaleLeavesOpenDoesNotBlockConverged) {
  osc::CalibrationEstimate estimate;
  estimate.tracked_points = 50;
  estimate.parameter_covariance = osc::Matrix12d::Identity() * 1e-8;
  osc::ConvergenceThresholds bounds;
  const double scale_variance = std::pow(0.01 * 0.5, 2);  // 1 % of a 0.5 m baseline
  estimate.parameter_covariance(7, 7) += scale_variance;
  estimate.odometry_scale_covariance(7, 7) = scale_variance;
  EXPECT_EQ(osc::scaleLimitedParameters(estimate, bounds), std::vector<int>{7});
  EXPECT_EQ(calibrationState(estimate, false, 10, bounds), StereoCalibration::STATE_CONVERGED);
  estimate.odometry_scale_covariance.setZero();  // the same width, not from the scale
  EXPECT_TRUE(osc::scaleLimitedParameters(estimate, bounds).empty());
  EXPECT_EQ(calibrationState(estimate, false, 10, bounds), StereoCalibration::STATE_CONVERGING);
}

}  // namespace
}  // namespace online_stereo_calibration
