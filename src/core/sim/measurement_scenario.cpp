#include "online_stereo_calibration/core/sim/measurement_scenario.h"

#include <sstream>
#include <stdexcept>

namespace osc {

namespace {

constexpr double kDeg = M_PI / 180.0;

CameraIntrinsics defaultIntrinsics() {
  CameraIntrinsics intrinsics;
  intrinsics.width = 640;
  intrinsics.height = 480;
  intrinsics.fx = intrinsics.fy = 600.0;
  intrinsics.cx = 319.5;
  intrinsics.cy = 239.5;
  return intrinsics;
}

/// Collects "field must be ... (got value)" messages.
class Problems {
 public:
  void require(bool ok, const std::string& field, const std::string& range, double value) {
    if (ok) return;
    std::ostringstream message;
    message << field << " must be " << range << " (got " << value << ")";
    list_.push_back(message.str());
  }
  void requireFinite(const Vector12d& vector, const std::string& field) {
    if (!vector.allFinite()) list_.push_back(field + " must be finite (12 values)");
  }
  void add(const std::string& message) { list_.push_back(message); }
  std::vector<std::string> take() { return std::move(list_); }

 private:
  std::vector<std::string> list_;
};

/// The comparisons are written so that NaN always fails them.
void validateMotion(const VehicleMotionProfile& m, Problems* p) {
  const auto nonNegative = [p](double v, const std::string& field) {
    p->require(v >= 0.0 && std::isfinite(v), field, ">= 0 and finite", v);
  };
  const auto positive = [p](double v, const std::string& field) {
    p->require(v > 0.0 && std::isfinite(v), field, "> 0 and finite", v);
  };
  nonNegative(m.speed, "motion.speed");
  nonNegative(m.roll_amplitude, "motion.roll_amplitude");
  nonNegative(m.pitch_amplitude, "motion.pitch_amplitude");
  nonNegative(m.yaw_rate_amplitude, "motion.yaw_rate_amplitude");
  nonNegative(m.heave_amplitude, "motion.heave_amplitude");
  positive(m.roll_period, "motion.roll_period");
  positive(m.pitch_period, "motion.pitch_period");
  positive(m.yaw_period, "motion.yaw_period");
  positive(m.heave_period, "motion.heave_period");
}

void validateCamera(const CameraIntrinsics& intrinsics, const std::string& field, Problems* p) {
  try {
    CameraModel model(intrinsics);
  } catch (const std::invalid_argument& e) {
    p->add(field + ": " + e.what());
  }
}

}  // namespace

MeasurementScenario::MeasurementScenario() : left(defaultIntrinsics()), right(defaultIntrinsics()) {
  truth << 1.5, 0.15, 1.3, 0.0, 0.05, 0.0, 0.0, -0.30, 0.0, 0.0, 0.0, 0.0;
  initial_error << 0.5, 0.5, 0.5, 10 * kDeg, 10 * kDeg, 10 * kDeg, 0.0, 0.1, 0.0, 0.0, 0.0, 0.0;
  step.setZero();
  step(5) = 10.0 * kDeg;
  drift_per_second.setZero();
}

std::vector<std::string> MeasurementScenario::validate() const {
  Problems p;
  p.require(frames > 0, "frames", "> 0", frames);
  p.require(rate_hz > 0.0 && std::isfinite(rate_hz), "rate_hz", "> 0 and finite", rate_hz);
  validateCamera(left, "left", &p);
  validateCamera(right, "right", &p);
  p.requireFinite(truth, "truth");
  p.requireFinite(initial_error, "initial_error");
  p.requireFinite(step, "step");
  p.requireFinite(drift_per_second, "drift_per_second");
  validateMotion(motion, &p);
  p.require(motion_rotation_noise >= 0.0 && std::isfinite(motion_rotation_noise),
            "motion_rotation_noise", ">= 0 and finite", motion_rotation_noise);
  p.require(motion_translation_noise >= 0.0 && std::isfinite(motion_translation_noise),
            "motion_translation_noise", ">= 0 and finite", motion_translation_noise);
  p.require(pixel_noise >= 0.0 && std::isfinite(pixel_noise), "pixel_noise", ">= 0 and finite",
            pixel_noise);
  p.require(target_points >= 1, "target_points", ">= 1", target_points);
  p.require(max_new_points_per_frame >= 1, "max_new_points_per_frame", ">= 1",
            max_new_points_per_frame);
  p.require(min_depth >= 1.0 && std::isfinite(min_depth), "min_depth",
            ">= 1 m (points closer than 1 m are lost) and finite", min_depth);
  p.require(max_depth > min_depth && std::isfinite(max_depth), "max_depth",
            "> min_depth and finite", max_depth);
  p.require(mean_track_length >= 1.0, "mean_track_length", ">= 1 frame (or +inf)",
            mean_track_length);
  p.require(outlier_fraction >= 0.0 && outlier_fraction <= 1.0, "outlier_fraction", "in [0, 1]",
            outlier_fraction);
  return p.take();
}

Vector12d MeasurementScenario::truthParametersAt(int frame) const {
  const double t = frame / rate_hz;
  Vector12d parameters = truth + drift_per_second * t;
  if (step_frame >= 0 && frame >= step_frame) parameters += step;
  return parameters;
}

Vector12d MeasurementScenario::initialGuessParameters() const {
  return truthParametersAt(0) + initial_error;
}

MeasurementScenario paperOffroadScenario() { return MeasurementScenario(); }

MeasurementScenario urbanPlanarScenario() {
  MeasurementScenario scenario;
  scenario.name = "urban_planar";
  scenario.motion.planar = true;
  scenario.motion.speed = 10.0;
  scenario.step_frame = -1;
  scenario.step.setZero();
  return scenario;
}

MeasurementScenario driftScenario() {
  MeasurementScenario scenario;
  scenario.name = "drift";
  scenario.step_frame = -1;
  scenario.step.setZero();
  // Spread over the default drive of 1500 frames at 10 Hz.
  const double duration = scenario.frames / scenario.rate_hz;
  scenario.drift_per_second(7) = 0.002 / duration;
  scenario.drift_per_second(11) = 0.2 * kDeg / duration;
  return scenario;
}

}  // namespace osc
