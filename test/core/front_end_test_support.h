/// @file front_end_test_support.h
/// @brief Helpers of the front end's tests (test_front_end*): a short drive of the paper
/// scenario from the true calibration, a filter nearly sure of it, and the figures of a
/// rendered drive.
#pragma once

#include <cmath>

#include "online_stereo_calibration/core/config/filter_config.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"

namespace osc {

inline constexpr double kDeg = M_PI / 180.0;

/// A short drive of the paper scenario from the true calibration.
inline MeasurementScenario shortDrive(int frames) {
  MeasurementScenario s = paperOffroadScenario();
  s.frames = frames;
  s.initial_error.setZero();
  s.step_frame = -1;
  return s;
}

/// A filter that is nearly sure of its (true) calibration.
inline FilterConfig confidentConfig() {
  FilterConfig c;
  c.initial_caml_translation_sigma = 0.01;
  c.initial_caml_rotation_sigma = 0.2 * kDeg;
  c.initial_camr_translation_sigma = 0.002;
  c.initial_camr_rotation_sigma = 0.05 * kDeg;
  return c;
}

struct DriveFigures {
  int matches = 0, matches_correct = 0;
  int tracks = 0, tracks_correct = 0;
  int tracks_reported = 0, tracks_stereo_correct = 0;
  int new_points = 0, new_correct = 0;
  int matches_at_pixel = 0, new_at_pixel = 0, tracks_stereo_at_pixel = 0;
  int tracks_at_birth_pixel = 0;
  int final_points = 0;
  int processed = 0;
};

}  // namespace osc
