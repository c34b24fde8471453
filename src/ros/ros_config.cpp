/// @file ros_config.cpp
/// @brief RosConfig::validate.
#include "online_stereo_calibration/ros/ros_config.h"

#include <cmath>
#include <sstream>

namespace online_stereo_calibration {
namespace {

void checkPositive(const char* name, double value, std::vector<std::string>* problems,
                   bool allow_zero = false) {
  if (!std::isfinite(value) || value < 0.0 || (!allow_zero && value == 0.0)) {
    std::ostringstream out;
    out << name << " = " << value << ": must be " << (allow_zero ? ">= 0" : "> 0");
    problems->push_back(out.str());
  }
}

}  // namespace

std::vector<std::string> RosConfig::validate() const {
  std::vector<std::string> problems;
  if (vehicle_frame.empty()) problems.push_back("vehicle_frame is empty");
  if (queue_size < 1)
    problems.push_back("queue_size = " + std::to_string(queue_size) + ": must be >= 1");
  if (processing_queue_size < 1) {
    problems.push_back("processing_queue_size = " + std::to_string(processing_queue_size) +
                       ": must be >= 1");
  }
  checkPositive("max_stamp_skew", max_stamp_skew, &problems, true);
  checkPositive("motion_history", motion_history, &problems);
  checkPositive("max_motion_gap", max_motion_gap, &problems);
  checkPositive("motion_wait", motion_wait, &problems, true);
  checkPositive("tf_guess_timeout", tf_guess_timeout, &problems, true);
  checkPositive("save_interval", save_interval, &problems, true);
  checkPositive("converged_3sigma_caml_translation", converged.caml_translation, &problems);
  checkPositive("converged_3sigma_caml_rotation_deg", converged.caml_rotation, &problems);
  checkPositive("converged_3sigma_camr_translation", converged.camr_translation, &problems);
  checkPositive("converged_3sigma_camr_rotation_deg", converged.camr_rotation, &problems);
  checkPositive("min_rate", min_rate, &problems);
  checkPositive("max_rate", max_rate, &problems);
  if (!(rectification_alpha >= -1.0 && rectification_alpha <= 1.0)) {
    problems.push_back("rectification_alpha = " + std::to_string(rectification_alpha) +
                       ": must be in [-1, 1]");
  }
  if (rectification_width < 0 || rectification_height < 0) {
    problems.push_back("rectification_width / rectification_height must be >= 0 (0 = input size)");
  }
  if ((rectification_width == 0) != (rectification_height == 0)) {
    problems.push_back("rectification_width and rectification_height: set both or neither");
  }
  checkPositive("rectification_update_px", rectification_update_px, &problems, true);
  if (min_rate > max_rate) problems.push_back("min_rate must not exceed max_rate");
  if (min_tracked_points < 0) problems.push_back("min_tracked_points must be >= 0");
  if (motion_source == MotionSourceType::kTf && fixed_frame.empty()) {
    problems.push_back("fixed_frame is empty but motion_source is tf");
  }
  if (!vehicle_to_left.allFinite()) problems.push_back("vehicle_to_left has non-finite values");
  if (!left_to_right.allFinite()) problems.push_back("left_to_right has non-finite values");
  if (initial_guess_source == InitialGuessSource::kFile && initial_guess_file.empty()) {
    problems.push_back("initial_guess_source is file but initial_guess_file is empty");
  }
  if (resume && calibration_file.empty()) {
    problems.push_back("resume is true but calibration_file is empty");
  }
  return problems;
}

}  // namespace online_stereo_calibration
