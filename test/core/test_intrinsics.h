/// @file test_intrinsics.h
/// @brief The 640x480 pinhole pair (600 px focal length, centred) that component tests put
/// a CalibrationFilter on.
#pragma once

#include "online_stereo_calibration/core/estimator/types.h"

namespace osc {

/// Both cameras: focal length 600 px, principal point (320, 240).
inline StereoIntrinsics testIntrinsics() {
  StereoIntrinsics k;
  k.K_left << 600, 0, 320, 0, 600, 240, 0, 0, 1;
  k.K_right = k.K_left;
  return k;
}

}  // namespace osc
