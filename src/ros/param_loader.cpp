/// @file param_loader.cpp
/// @brief Parameter server -> NodeConfig, every problem collected.
#include "online_stereo_calibration/ros/param_loader.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include <XmlRpcValue.h>

namespace online_stereo_calibration {
namespace {

constexpr double kDegToRad = 0.0174532925199432958;

/// A number (int or double) from an XmlRpc value.
bool toNumber(XmlRpc::XmlRpcValue& value, double* number) {
  if (value.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
    *number = static_cast<double>(value);
    return true;
  }
  if (value.getType() == XmlRpc::XmlRpcValue::TypeInt) {
    *number = static_cast<int>(value);
    return true;
  }
  // rosparam (PyYAML, YAML 1.1) reads "5e-05" without a dot as a string: accept a string
  // that is entirely a number.
  if (value.getType() == XmlRpc::XmlRpcValue::TypeString) {
    const std::string text = static_cast<std::string>(value);
    char* end = nullptr;
    const double parsed = std::strtod(text.c_str(), &end);
    if (!text.empty() && end == text.c_str() + text.size()) {
      *number = parsed;
      return true;
    }
  }
  return false;
}

/// Reads an optional number; a wrong type is a problem.
void readNumber(const ros::NodeHandle& nh, const std::string& name, double* target,
                std::vector<std::string>* problems, double scale = 1.0) {
  XmlRpc::XmlRpcValue value;
  if (!nh.getParam(name, value)) return;
  double number = 0.0;
  if (!toNumber(value, &number)) {
    problems->push_back(name + ": not a number");
    return;
  }
  *target = number * scale;
}

void readInt(const ros::NodeHandle& nh, const std::string& name, int* target,
             std::vector<std::string>* problems) {
  XmlRpc::XmlRpcValue value;
  if (!nh.getParam(name, value)) return;
  if (value.getType() != XmlRpc::XmlRpcValue::TypeInt) {
    problems->push_back(name + ": not an integer");
    return;
  }
  *target = static_cast<int>(value);
}

void readBool(const ros::NodeHandle& nh, const std::string& name, bool* target,
              std::vector<std::string>* problems) {
  XmlRpc::XmlRpcValue value;
  if (!nh.getParam(name, value)) return;
  if (value.getType() != XmlRpc::XmlRpcValue::TypeBoolean) {
    problems->push_back(name + ": not a boolean");
    return;
  }
  *target = static_cast<bool>(value);
}

void readString(const ros::NodeHandle& nh, const std::string& name, std::string* target,
                std::vector<std::string>* problems) {
  XmlRpc::XmlRpcValue value;
  if (!nh.getParam(name, value)) return;
  if (value.getType() != XmlRpc::XmlRpcValue::TypeString) {
    problems->push_back(name + ": not a string");
    return;
  }
  *target = static_cast<std::string>(value);
}

void readVector6(const ros::NodeHandle& nh, const std::string& name, osc::Vector6d* target,
                 std::vector<std::string>* problems) {
  XmlRpc::XmlRpcValue value;
  if (!nh.getParam(name, value)) return;
  if (value.getType() != XmlRpc::XmlRpcValue::TypeArray || value.size() != 6) {
    problems->push_back(name + ": must be a list of 6 numbers [x, y, z, roll, pitch, yaw]");
    return;
  }
  for (int i = 0; i < 6; ++i) {
    double number = 0.0;
    if (!toNumber(value[i], &number) || !std::isfinite(number)) {
      problems->push_back(name + "[" + std::to_string(i) + "]: not a finite number");
      return;
    }
    (*target)(i) = number;
  }
}

}  // namespace

osc::FilterConfig loadFilterConfig(const ros::NodeHandle& nh, std::vector<std::string>* problems) {
  osc::FilterConfig config;
  for (const osc::ParameterSpec& spec : osc::filterParameterTable()) {
    XmlRpc::XmlRpcValue value;
    if (!nh.getParam(spec.name, value)) continue;
    double number = 0.0;
    if (!toNumber(value, &number)) {
      problems->push_back(spec.name + ": not a number (" + spec.doc + ")");
      continue;
    }
    if (spec.is_integer && value.getType() != XmlRpc::XmlRpcValue::TypeInt) {
      problems->push_back(spec.name + ": must be an integer");
      continue;
    }
    spec.set(&config, number);
  }
  std::string model_name;
  if (nh.getParam("motion_noise_model", model_name)) {
    try {
      config.motion_noise_model = osc::motionNoiseModelFromName(model_name);
    } catch (const std::exception& e) {
      problems->push_back(std::string("motion_noise_model: ") + e.what());
    }
  } else if (nh.hasParam("motion_noise_model")) {
    problems->push_back("motion_noise_model: not a string");
  }
  for (const std::string& problem : config.validate()) problems->push_back(problem);
  return config;
}

RosConfig loadRosConfig(const ros::NodeHandle& nh, std::vector<std::string>* problems) {
  RosConfig config;
  readString(nh, "vehicle_frame", &config.vehicle_frame, problems);
  readString(nh, "left_optical_frame", &config.left_optical_frame, problems);
  readString(nh, "right_optical_frame", &config.right_optical_frame, problems);
  readBool(nh, "publish_tf", &config.publish_tf, problems);
  readBool(nh, "approximate_sync", &config.approximate_sync, problems);
  readInt(nh, "queue_size", &config.queue_size, problems);
  readInt(nh, "processing_queue_size", &config.processing_queue_size, problems);
  readNumber(nh, "max_stamp_skew", &config.max_stamp_skew, problems);

  std::string motion_source = "odom";
  readString(nh, "motion_source", &motion_source, problems);
  if (motion_source == "odom") {
    config.motion_source = MotionSourceType::kOdom;
  } else if (motion_source == "tf") {
    config.motion_source = MotionSourceType::kTf;
  } else {
    problems->push_back("motion_source = '" + motion_source + "': must be odom or tf");
  }
  readString(nh, "fixed_frame", &config.fixed_frame, problems);
  readBool(nh, "use_imu", &config.use_imu, problems);
  readBool(nh, "use_odometry_covariance", &config.use_odometry_covariance, problems);
  readNumber(nh, "motion_history", &config.motion_history, problems);
  readNumber(nh, "max_motion_gap", &config.max_motion_gap, problems);
  readNumber(nh, "motion_wait", &config.motion_wait, problems);

  std::string guess_source = "parameters";
  readString(nh, "initial_guess_source", &guess_source, problems);
  if (guess_source == "parameters") {
    config.initial_guess_source = InitialGuessSource::kParameters;
    if (!nh.hasParam("vehicle_to_left") || !nh.hasParam("left_to_right")) {
      problems->push_back(
          "initial_guess_source is parameters but vehicle_to_left or left_to_right is not set");
    }
  } else if (guess_source == "file") {
    config.initial_guess_source = InitialGuessSource::kFile;
  } else if (guess_source == "tf") {
    config.initial_guess_source = InitialGuessSource::kTf;
  } else {
    problems->push_back("initial_guess_source = '" + guess_source +
                        "': must be parameters, file or tf");
  }
  readVector6(nh, "vehicle_to_left", &config.vehicle_to_left, problems);
  readVector6(nh, "left_to_right", &config.left_to_right, problems);
  readString(nh, "initial_guess_file", &config.initial_guess_file, problems);
  readNumber(nh, "tf_guess_timeout", &config.tf_guess_timeout, problems);
  readString(nh, "calibration_file", &config.calibration_file, problems);
  readBool(nh, "resume", &config.resume, problems);
  readNumber(nh, "save_interval", &config.save_interval, problems);

  readInt(nh, "min_tracked_points", &config.min_tracked_points, problems);
  readNumber(nh, "converged_3sigma_caml_translation", &config.converged.caml_translation, problems);
  readNumber(nh, "converged_3sigma_caml_rotation_deg", &config.converged.caml_rotation, problems,
             kDegToRad);
  readNumber(nh, "converged_3sigma_camr_translation", &config.converged.camr_translation, problems);
  readNumber(nh, "converged_3sigma_camr_rotation_deg", &config.converged.camr_rotation, problems,
             kDegToRad);
  for (const char* old : {"converged_translation_3sigma", "converged_rotation_3sigma_deg"}) {
    if (nh.hasParam(old)) {
      problems->push_back(std::string(old) +
                          " was split per block: set converged_3sigma_caml_translation, "
                          "converged_3sigma_caml_rotation_deg, converged_3sigma_camr_translation "
                          "and converged_3sigma_camr_rotation_deg instead (docs/ros.md)");
    }
  }
  readNumber(nh, "min_rate", &config.min_rate, problems);
  readNumber(nh, "max_rate", &config.max_rate, problems);
  readBool(nh, "publish_rectification", &config.publish_rectification, problems);
  readNumber(nh, "rectification_alpha", &config.rectification_alpha, problems);
  readInt(nh, "rectification_width", &config.rectification_width, problems);
  readInt(nh, "rectification_height", &config.rectification_height, problems);
  readNumber(nh, "rectification_update_px", &config.rectification_update_px, problems);
  for (const std::string& problem : config.validate()) problems->push_back(problem);
  return config;
}

osc::FrontEndConfig loadFrontEndConfig(const ros::NodeHandle& nh,
                                       std::vector<std::string>* problems) {
  osc::FrontEndConfig config;
  const ros::NodeHandle fe(nh, "front_end");
  // Every key of frontEndParameterTable(), as ~front_end/<name>.
  using Type = osc::FrontEndParameterSpec::Type;
  for (const osc::FrontEndParameterSpec& spec : osc::frontEndParameterTable()) {
    XmlRpc::XmlRpcValue value;
    if (!fe.getParam(spec.name, value)) continue;
    const std::string key = "front_end/" + spec.name;
    switch (spec.type) {
      case Type::kString:
        if (value.getType() != XmlRpc::XmlRpcValue::TypeString) {
          problems->push_back(key + ": not a string (" + spec.allowedText() + ")");
        } else {
          spec.setString(&config, static_cast<std::string>(value));
        }
        break;
      case Type::kBool:
        if (value.getType() != XmlRpc::XmlRpcValue::TypeBoolean) {
          problems->push_back(key + ": not a boolean (true or false)");
        } else {
          spec.setBool(&config, static_cast<bool>(value));
        }
        break;
      case Type::kInteger:
        if (value.getType() != XmlRpc::XmlRpcValue::TypeInt) {
          problems->push_back(key + ": not an integer (" + spec.doc + ")");
        } else {
          spec.setNumber(&config, static_cast<int>(value));
        }
        break;
      case Type::kReal: {
        double number = 0.0;
        if (!toNumber(value, &number)) {
          problems->push_back(key + ": not a number (" + spec.doc + ")");
        } else {
          spec.setNumber(&config, number);
        }
        break;
      }
    }
  }
  // A misspelt key would otherwise be ignored silently.
  XmlRpc::XmlRpcValue section;
  if (nh.getParam("front_end", section) && section.getType() == XmlRpc::XmlRpcValue::TypeStruct) {
    for (const auto& entry : section) {
      bool known = false;
      for (const osc::FrontEndParameterSpec& spec : osc::frontEndParameterTable()) {
        known |= spec.name == entry.first;
      }
      if (!known) problems->push_back("front_end/" + entry.first + ": unknown parameter");
    }
  }
  for (const std::string& problem : config.validate()) problems->push_back("front_end/" + problem);
  return config;
}

NodeConfig loadNodeConfig(const ros::NodeHandle& nh, std::vector<std::string>* problems) {
  NodeConfig config;
  config.filter = loadFilterConfig(nh, problems);
  config.front_end = loadFrontEndConfig(nh, problems);
  config.ros = loadRosConfig(nh, problems);
  return config;
}

}  // namespace online_stereo_calibration
