/// @file hand_eye_start.h
/// @brief Start, hand-eye rotation: the fresh start the estimator makes when the left
/// camera's rotation from motion (mounting_from_motion.h) is far from the filter's (a camera
/// mounted backwards or sideways; docs/design.md, "start").
///
/// Everything learned so far was learned with x_caml's rotation far off (x_camr too: in the
/// first frames the filter explains the wrong rotation's mispredictions partly with x_camr, 36
/// sigma off in yr after one frame with a backward camera guessed forward). So the start is
/// the guess again, with the hand-eye rotation for x_caml's; a camera whose rotation was
/// guessed this far off is likely elsewhere too (at the tailgate, under a mirror): its
/// translation starts with at least hand_eye_restart_translation_sigma.
#pragma once

#include <string>

#include <Eigen/Core>

#include "online_stereo_calibration/core/estimator/mounting_from_motion.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

/// The start and its tangent covariance.
struct HandEyeStart {
  StereoExtrinsics extrinsics;
  Matrix12d covariance = Matrix12d::Zero();
  std::string message;  ///< the event's line
};

/// The start for @p restart: @p guess with @p restart's rotation for x_caml's, covariance
/// @p guess_covariance with x_caml's block replaced (translation @p translation_sigma per
/// axis, rotation the hand-eye's) and uncorrelated. @p now: the filter's estimate before, for
/// the message.
HandEyeStart handEyeStart(const MountingRestart& restart, const StereoExtrinsics& now,
                          const StereoExtrinsics& guess, const Matrix12d& guess_covariance,
                          double translation_sigma);

}  // namespace osc
