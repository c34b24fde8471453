#include "online_stereo_calibration/core/estimator/hand_eye_start.h"

#include <cmath>
#include <sstream>

#include "online_stereo_calibration/core/filter/state_layout.h"
#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {

HandEyeStart handEyeStart(const MountingRestart& restart, const StereoExtrinsics& now,
                          const StereoExtrinsics& guess, const Matrix12d& guess_covariance,
                          double translation_sigma) {
  using namespace layout;
  HandEyeStart start;
  start.extrinsics = guess;
  start.extrinsics.T_veh_caml.linear() = restart.R_veh_caml;
  // x_camr: the guess's covariance (the config's start sigmas, or a saved calibration's).
  Matrix12d& covariance = start.covariance;
  covariance = guess_covariance;
  covariance.middleRows<kPoseDim>(kCaml).setZero();
  covariance.middleCols<kPoseDim>(kCaml).setZero();
  covariance.block<3, 3>(kCaml + kTranslation, kCaml + kTranslation) =
      Eigen::Matrix3d::Identity() * translation_sigma * translation_sigma;
  covariance.block<3, 3>(kCaml + kRotation, kCaml + kRotation) = restart.covariance;
  const Eigen::Vector3d before = rpyFromRotation(now.T_veh_caml.linear()) * 180.0 / M_PI;
  const Eigen::Vector3d after = rpyFromRotation(restart.R_veh_caml) * 180.0 / M_PI;
  std::ostringstream message;
  message.precision(4);
  message << "mounting rotation from motion: x_caml restarted from roll/pitch/yaw " << after(0)
          << "/" << after(1) << "/" << after(2) << " deg (was " << before(0) << "/" << before(1)
          << "/" << before(2) << " deg, " << restart.distance << " sigmas apart; hand-eye "
          << restart.hand_eye.reason
          << "); everything else from the guess again, translation 1 sigma " << translation_sigma
          << " m; tracks reset";
  start.message = message.str();
  return start;
}

}  // namespace osc
