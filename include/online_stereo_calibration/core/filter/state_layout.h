/// @file state_layout.h
/// @brief Where each block lives in the filter's calibration error vector. The filter is an
/// error-state filter: a calibration pose T is T_hat boxPlus [dt, dtheta] (pose.h).
#pragma once

namespace osc {
namespace layout {

constexpr int kPoseDim = 6;      ///< [dt (3), dtheta (3)]
constexpr int kTranslation = 0;  ///< offset of dt inside a pose block
constexpr int kRotation = 3;     ///< offset of dtheta inside a pose block
constexpr int kCaml = 0;         ///< x_caml: vehicle <- left camera body
constexpr int kCamr = 6;         ///< x_camr: left body <- right body
constexpr int kCalibrationDim = 12;
/// The odometry states the config enables (time offset, then the velocity error's axes)
/// follow the calibration, then x_camr's drift rate if enabled; during one step of the shared
/// motion-noise model the motion error of that step is appended after them:
/// [x_caml, x_camr, odometry states, drift rate, motion error].
constexpr int kOdometry = 12;
constexpr int kPointDim = 3;
constexpr int kMeasurementDim = 4;  ///< [u_left, v_left, u_right, v_right]

}  // namespace layout
}  // namespace osc
