/// @file test_hand_eye_start.cpp
/// @brief The fresh start the hand-eye rotation asks for (hand_eye_start.h): the guess again
/// with x_caml's rotation from motion, its covariance rebuilt around it.
#include <gtest/gtest.h>

#include <cmath>

#include "online_stereo_calibration/core/estimator/hand_eye_start.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(HandEyeStart, IsTheGuessWithTheRotationFromMotionAndItsOwnCovariance) {
  StereoExtrinsics guess;
  guess.T_veh_caml.translation() = Eigen::Vector3d(1.5, 0.2, 1.3);
  guess.T_caml_camr.translation() = Eigen::Vector3d(0.0, -0.3, 0.0);
  Matrix12d guess_covariance = Matrix12d::Identity() * 1e-4;
  guess_covariance(0, 7) = guess_covariance(7, 0) = 2e-5;  // x_caml-x_camr: dropped
  guess_covariance(6, 7) = guess_covariance(7, 6) = 3e-5;  // within x_camr: kept
  StereoExtrinsics now = guess;
  now.T_veh_caml.translation() = Eigen::Vector3d(1.0, 0.0, 1.0);  // learned: forgotten
  MountingRestart restart;
  restart.R_veh_caml = rotationFromRpy(Eigen::Vector3d(0.0, 0.0, 90.0 * kDeg));  // sideways
  restart.covariance = Eigen::Matrix3d::Identity() * std::pow(2.0 * kDeg, 2);
  restart.distance = 40.0;

  const HandEyeStart start = handEyeStart(restart, now, guess, guess_covariance, 0.5);
  EXPECT_TRUE(start.extrinsics.T_veh_caml.linear().isApprox(restart.R_veh_caml, 1e-15));
  EXPECT_TRUE(
      start.extrinsics.T_veh_caml.translation().isApprox(guess.T_veh_caml.translation(), 1e-15));
  EXPECT_TRUE(start.extrinsics.T_caml_camr.isApprox(guess.T_caml_camr, 1e-15));
  const Matrix12d& P = start.covariance;
  const Eigen::Matrix3d caml_translation = P.block<3, 3>(0, 0), caml_rotation = P.block<3, 3>(3, 3);
  const Matrix6d camr = P.block<6, 6>(6, 6), guess_camr = guess_covariance.block<6, 6>(6, 6);
  EXPECT_TRUE(caml_translation.isApprox(Eigen::Matrix3d::Identity() * 0.25, 1e-15));
  EXPECT_TRUE(caml_rotation.isApprox(restart.covariance, 1e-15));
  EXPECT_TRUE(camr.isApprox(guess_camr, 1e-15));
  const double across = P.topRightCorner<6, 6>().norm() + P.bottomLeftCorner<6, 6>().norm();
  EXPECT_EQ(across, 0.0);
  EXPECT_NE(start.message.find("/90 deg (was 0/"), std::string::npos) << start.message;
  EXPECT_NE(start.message.find("40 sigmas apart"), std::string::npos) << start.message;
}

}  // namespace
}  // namespace osc
