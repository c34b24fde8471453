#include "online_stereo_calibration/core/geometry/pose.h"

#include <cmath>

#include <Eigen/LU>

#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {

Eigen::Isometry3d poseFromParameters(const Vector6d& parameters) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotationFromRpy(parameters.tail<3>());
  pose.translation() = parameters.head<3>();
  return pose;
}

Vector6d parametersFromPose(const Eigen::Isometry3d& pose) {
  Vector6d parameters;
  parameters.head<3>() = pose.translation();
  parameters.tail<3>() = rpyFromRotation(pose.linear());
  return parameters;
}

const Eigen::Matrix3d& rotationBodyOptical() {
  static const Eigen::Matrix3d r = (Eigen::Matrix3d() << 0, 0, 1, -1, 0, 0, 0, -1, 0).finished();
  return r;
}

Eigen::Isometry3d bodyFromOptical() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = rotationBodyOptical();
  return t;
}

Eigen::Isometry3d boxPlus(const Eigen::Isometry3d& pose, const Vector6d& delta) {
  Eigen::Isometry3d result = Eigen::Isometry3d::Identity();
  result.translation() = pose.translation() + delta.head<3>();
  result.linear() = pose.linear() * expSO3(delta.tail<3>());
  return result;
}

Vector6d boxMinus(const Eigen::Isometry3d& pose, const Eigen::Isometry3d& reference) {
  Vector6d delta;
  delta.head<3>() = pose.translation() - reference.translation();
  delta.tail<3>() = logSO3(reference.linear().transpose() * pose.linear());
  return delta;
}

namespace {

/// Left Jacobian of SO(3): V(w) = I + (1 - cos a) / a^2 [w]x + (a - sin a) / a^3 [w]x^2.
Eigen::Matrix3d leftJacobianSO3(const Eigen::Vector3d& w) {
  const double a = w.norm();
  const Eigen::Matrix3d W = skew(w);
  if (a < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * W + W * W / 6.0;
  return Eigen::Matrix3d::Identity() + (1.0 - std::cos(a)) / (a * a) * W +
         (a - std::sin(a)) / (a * a * a) * W * W;
}

}  // namespace

Eigen::Isometry3d expSE3(const Vector6d& twist) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = expSO3(twist.tail<3>());
  pose.translation() = leftJacobianSO3(twist.tail<3>()) * twist.head<3>();
  return pose;
}

Vector6d logSE3(const Eigen::Isometry3d& pose) {
  Vector6d twist;
  twist.tail<3>() = logSO3(pose.linear());
  twist.head<3>() = leftJacobianSO3(twist.tail<3>()).inverse() * pose.translation();
  return twist;
}

StereoExtrinsics StereoExtrinsics::fromParameters(const Vector12d& parameters) {
  StereoExtrinsics e;
  e.T_veh_caml = poseFromParameters(parameters.head<6>());
  e.T_caml_camr = poseFromParameters(parameters.tail<6>());
  return e;
}

Vector12d StereoExtrinsics::toParameters() const {
  Vector12d p;
  p.head<6>() = parametersFromPose(T_veh_caml);
  p.tail<6>() = parametersFromPose(T_caml_camr);
  return p;
}

StereoExtrinsics StereoExtrinsics::fromOpticalFrames(const Eigen::Isometry3d& T_veh_lopt,
                                                     const Eigen::Isometry3d& T_lopt_ropt) {
  const Eigen::Isometry3d T_body_optical = bodyFromOptical();
  StereoExtrinsics e;
  e.T_veh_caml = T_veh_lopt * T_body_optical.inverse();
  e.T_caml_camr = T_body_optical * T_lopt_ropt * T_body_optical.inverse();
  return e;
}

Eigen::Isometry3d StereoExtrinsics::vehicleToLeftOptical() const {
  return T_veh_caml * bodyFromOptical();
}

Eigen::Isometry3d StereoExtrinsics::leftToRightOptical() const {
  return bodyFromOptical().inverse() * T_caml_camr * bodyFromOptical();
}

Matrix12d parameterJacobian(const StereoExtrinsics& extrinsics) {
  Matrix12d jacobian = Matrix12d::Zero();
  const double h = 1e-6;
  const Eigen::Isometry3d* poses[2] = {&extrinsics.T_veh_caml, &extrinsics.T_caml_camr};
  for (int block = 0; block < 2; ++block) {
    for (int k = 0; k < 6; ++k) {
      Vector6d delta = Vector6d::Zero();
      delta(k) = h;
      Vector6d diff = parametersFromPose(boxPlus(*poses[block], delta)) -
                      parametersFromPose(boxPlus(*poses[block], -delta));
      for (int a = 3; a < 6; ++a) diff(a) = wrapAngle(diff(a));
      jacobian.block<6, 1>(6 * block, 6 * block + k) = diff / (2.0 * h);
    }
  }
  return jacobian;
}

}  // namespace osc
