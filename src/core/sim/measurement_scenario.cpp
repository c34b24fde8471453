#include "online_stereo_calibration/core/sim/measurement_scenario.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "online_stereo_calibration/core/geometry/pose_interpolation.h"

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
  nonNegative(m.stop_ramp, "motion.stop_ramp");
  p->require(std::isfinite(m.yaw_phase), "motion.yaw_phase", "finite", m.yaw_phase);
}

/// Stops: each inside the drive [0, drive_end], in order, the gaps leaving room for the ramps.
void validateStops(const VehicleMotionProfile& m, double drive_end, Problems* p) {
  const double ramp = std::isfinite(m.stop_ramp) && m.stop_ramp >= 0.0 ? m.stop_ramp : 0.0;
  for (std::size_t i = 0; i < m.stops.size(); ++i) {
    const TimeSpan& stop = m.stops[i];
    const std::string field = "motion.stops[" + std::to_string(i) + "]";
    p->require(stop.start >= 0.0 && std::isfinite(stop.start), field + ".start",
               ">= 0 s and finite", stop.start);
    p->require(stop.duration > 0.0 && std::isfinite(stop.duration), field + ".duration",
               "> 0 s and finite", stop.duration);
    const double end = stop.start + stop.duration;
    std::ostringstream drive;
    drive << "<= the last frame's time " << drive_end << " s (start + duration)";
    p->require(end <= drive_end, field, drive.str(), end);
    if (i > 0) {
      const TimeSpan& before = m.stops[i - 1];
      const double gap = stop.start - (before.start + before.duration);
      p->require(gap >= 2.0 * ramp, field,
                 "after motion.stops[" + std::to_string(i - 1) +
                     "] with a gap >= 2 * motion.stop_ramp (in order, ramps not overlapping); "
                     "gap in s",
                 gap);
    }
  }
}

void validateOdometryError(const OdometryErrorModel& e, Problems* p) {
  p->require(std::abs(e.time_offset) <= 0.5, "odometry_error.time_offset", "in [-0.5, 0.5] s",
             e.time_offset);
  p->require(std::abs(e.scale_error) <= 0.2, "odometry_error.scale_error", "in [-0.2, 0.2]",
             e.scale_error);
  p->require(e.rotation_rate_bias >= 0.0 && std::isfinite(e.rotation_rate_bias),
             "odometry_error.rotation_rate_bias", ">= 0 rad/s and finite", e.rotation_rate_bias);
  p->require(e.velocity_bias >= 0.0 && std::isfinite(e.velocity_bias),
             "odometry_error.velocity_bias", ">= 0 m/s and finite", e.velocity_bias);
  p->require(e.bias_correlation_time > 0.0 && std::isfinite(e.bias_correlation_time),
             "odometry_error.bias_correlation_time", "> 0 s and finite", e.bias_correlation_time);
}

void validateBlindFrames(const std::vector<FrameSpan>& spans, int frames, Problems* p) {
  for (std::size_t i = 0; i < spans.size(); ++i) {
    const FrameSpan& span = spans[i];
    const std::string field = "blind_frames[" + std::to_string(i) + "]";
    p->require(span.first >= 0, field + ".first", ">= 0", span.first);
    p->require(span.last >= span.first, field + ".last", ">= first", span.last);
    p->require(span.last < frames, field + ".last", "< frames (inside the drive)", span.last);
    if (i > 0) {
      p->require(span.first > spans[i - 1].last, field + ".first",
                 "> blind_frames[" + std::to_string(i - 1) + "].last (in order, not overlapping)",
                 span.first);
    }
  }
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
  validateOdometryError(odometry_error, &p);
  validateBlindFrames(blind_frames, frames, &p);
  p.require(moving_point_fraction >= 0.0 && moving_point_fraction <= 1.0, "moving_point_fraction",
            "in [0, 1]", moving_point_fraction);
  p.require(moving_point_speed >= 0.0 && std::isfinite(moving_point_speed), "moving_point_speed",
            ">= 0 m/s and finite", moving_point_speed);
  p.require(recorded_start_offset >= 0.0 && std::isfinite(recorded_start_offset),
            "recorded_start_offset", ">= 0 s and finite", recorded_start_offset);
  const double last_frame_time = frames > 0 && rate_hz > 0.0 ? (frames - 1) / rate_hz : 0.0;
  if (!recorded_trajectory) {
    validateStops(motion, last_frame_time, &p);
  } else {
    if (!motion.stops.empty()) {
      p.add("motion.stops must be empty with a recorded_trajectory (it replaces the motion)");
    }
    if (recorded_trajectory->size() < 2) {
      p.add("recorded_trajectory must hold at least 2 poses");
    } else if (std::isfinite(recorded_start_offset) && recorded_start_offset >= 0.0) {
      // Every frame's pose and every measured increment's shifted interval must be recorded.
      const double offset =
          std::isfinite(odometry_error.time_offset) ? odometry_error.time_offset : 0.0;
      const double span = recorded_trajectory->lastStamp() - recorded_trajectory->firstStamp();
      const double first_needed = recorded_start_offset + std::min(0.0, offset);
      const double last_needed = recorded_start_offset + last_frame_time + std::max(0.0, offset);
      p.require(first_needed >= 0.0, "recorded_start_offset",
                ">= -odometry_error.time_offset (the shifted first frame must be recorded); "
                "recorded_start_offset + time_offset in s",
                first_needed);
      if (last_needed > span + 1e-9) {
        std::ostringstream message;
        message << "frames / recorded_start_offset: " << frames << " frames at " << rate_hz
                << " Hz from recorded_start_offset " << recorded_start_offset
                << " s (odometry_error.time_offset " << offset << " s) need the recording up to "
                << last_needed << " s after its first stamp, but it spans only " << span << " s";
        p.add(message.str());
      }
    }
  }
  return p.take();
}

bool inFrameSpans(const std::vector<FrameSpan>& spans, int frame) {
  return std::any_of(spans.begin(), spans.end(),
                     [frame](const FrameSpan& span) { return span.contains(frame); });
}

bool MeasurementScenario::isBlindFrame(int frame) const {
  return inFrameSpans(blind_frames, frame);
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
