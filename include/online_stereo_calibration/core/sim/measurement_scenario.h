/// @file measurement_scenario.h
/// @brief Configuration of the measurement-level simulator: the vehicle motion, the true
/// calibration and its changes, the noise levels and the feature-tracker statistics of one
/// synthetic drive (the seed's Sec. III experiment and variations of it).
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

class PoseTrajectory;

/// A stretch of drive time (s, 0 at frame 0).
struct TimeSpan {
  double start = 0.0;     ///< s, >= 0
  double duration = 0.0;  ///< s, > 0
};

/// A stretch of frames, both ends included.
struct FrameSpan {
  int first = 0;  ///< >= 0
  int last = 0;   ///< >= first

  bool contains(int frame) const { return frame >= first && frame <= last; }
};

/// Whether @p frame lies in one of @p spans.
bool inFrameSpans(const std::vector<FrameSpan>& spans, int frame);

/// Smooth analytic vehicle motion (see VehicleTrajectory): constant forward speed along a
/// sinusoidally steered path, plus sinusoidal roll, pitch and heave of the body.
struct VehicleMotionProfile {
  /// Forward speed along the path (m/s), >= 0.
  double speed = 3.5;
  /// Roll amplitude (rad), >= 0. The std of a sinusoid is amplitude / sqrt(2), so the default
  /// gives the paper-like off-road roll std of 1.75 deg (algorithm.md, Cramér-Rao section).
  double roll_amplitude = 1.75 * M_PI / 180.0 * M_SQRT2;
  /// Pitch amplitude (rad), >= 0; default std 1.75 deg as for roll.
  double pitch_amplitude = 1.75 * M_PI / 180.0 * M_SQRT2;
  /// Periods of roll and pitch (s), > 0; incommensurate so the excitation never repeats.
  double roll_period = 3.1, pitch_period = 2.3;
  /// Amplitude of the sinusoidal yaw rate (rad/s) of a slow steering, >= 0.
  double yaw_rate_amplitude = 0.15;
  /// Period of the steering (s), > 0.
  double yaw_period = 23.0;
  /// Phase of the steering at t = 0 (rad), finite: the yaw rate is
  /// yaw_rate_amplitude * cos(2 pi t / yaw_period + yaw_phase). 0 starts at the height of a
  /// left turn, pi of a right turn, +-pi/2 driving straight into a right / left turn.
  double yaw_phase = 0.0;
  /// Amplitude of the vertical bump motion (m), >= 0.
  double heave_amplitude = 0.05;
  /// Period of the vertical bump motion (s), > 0.
  double heave_period = 1.7;
  /// True: roll = pitch = heave = 0 (on-road driving; zl is then unobservable).
  bool planar = false;
  /// Stops (traffic lights, queues): over each span the vehicle stands still. It slows down
  /// over stop_ramp seconds before the span and speeds up over stop_ramp after it; the whole
  /// profile (steering, roll, pitch, heave) is frozen with it, as if its clock stood still
  /// (a time warp, see VehicleTrajectory: after a stop the profile lags the drive clock by
  /// duration + stop_ramp). Spans must be in order, start >= 0, end by the last frame's time
  /// and not overlap (ramps included: the gap between two spans >= 2 stop_ramp). A ramp may
  /// reach before t = 0 (a stop at start 0 means standing at frame 0). Not allowed with a
  /// recorded_trajectory (which replaces the whole profile).
  std::vector<TimeSpan> stops;
  /// Length (s) of the smooth slow-down and speed-up around a stop, >= 0 (0: an abrupt stop,
  /// the speed jumps).
  double stop_ramp = 1.0;
};

/// What real odometry gets wrong beyond the white noise of motion_*_noise: every error is 0 by
/// default, so a scenario without them is unchanged (its own random stream, so enabling one
/// does not change the track structure or the pixel noise).
struct OdometryErrorModel {
  /// Clock offset (s) of the odometry against the cameras: the motion reported between two
  /// image pairs stamped t0 and t1 is the true motion between t0 + time_offset and
  /// t1 + time_offset (positive: the odometry runs ahead). |time_offset| <= 0.5. The analytic
  /// profile is defined at negative times too; with a recorded_trajectory the shifted
  /// interval of every frame must lie inside the recording (validate() checks it).
  double time_offset = 0.0;
  /// Scale error of the measured translation: each increment's translation is multiplied by
  /// (1 + scale_error). |scale_error| <= 0.2.
  double scale_error = 0.0;
  /// Steady-state std of a slowly varying bias of the measured angular rate (rad/s, per
  /// axis of the vehicle frame); the bias times dt is added to each increment's rotation
  /// (R * Exp(b dt), boxPlus convention). >= 0. The arithmetic: OdometryErrorProcess.
  double rotation_rate_bias = 0.0;
  /// Steady-state std of a slowly varying bias of the measured velocity (m/s, per axis, in
  /// the vehicle frame); the bias times dt is added to each increment's translation. >= 0.
  double velocity_bias = 0.0;
  /// Correlation time (s) of both biases (first-order Gauss-Markov processes), > 0.
  double bias_correlation_time = 30.0;
};

/// One synthetic drive at the level of pixel measurements. Defaults: the seed's experiment
/// (paperOffroadScenario()).
struct MeasurementScenario {
  /// Sets the defaults documented on each field.
  MeasurementScenario();

  /// Name used in logs and file names.
  std::string name = "paper_offroad";
  /// Number of stereo frames to produce, > 0.
  int frames = 1500;
  /// Frame rate (Hz), > 0.
  double rate_hz = 10.0;
  /// Intrinsics of the two cameras (the truth; the estimator gets the same ones). Default
  /// 640x480, fx = fy = 600, cx = 319.5, cy = 239.5, no distortion.
  CameraIntrinsics left, right;
  /// Interface parameters [xl..yaw_l, xr..yaw_r] at frame 0. Default x_caml =
  /// [1.5, 0.15, 1.3, 0, 0.05, 0] (behind the windscreen, slightly pitched down), x_camr =
  /// [0, -0.30, 0, 0, 0, 0] (30 cm baseline).
  Vector12d truth;
  /// Added to truth (at frame 0) to give the initial guess. Default: +0.5 m and +10 deg on
  /// every axis of x_caml, +0.1 m on yr, 0 else (the seed's start errors).
  Vector12d initial_error;
  /// From this frame on, truth += step; negative: no step. Default 774 (as in the seed).
  int step_frame = 774;
  /// The sudden calibration change at step_frame. Default: yaw_l += 10 deg.
  Vector12d step;
  /// Linear drift of the parameters (per second of drive time), added to truth. Default 0.
  Vector12d drift_per_second;
  /// The vehicle motion.
  VehicleMotionProfile motion;
  /// Std of the measured motion's rotation error (rad) per axis per 0.1 s step; scales with
  /// sqrt(dt / 0.1). Default 0.02 deg (the seed's sigma_IMU), >= 0.
  double motion_rotation_noise = 0.02 * M_PI / 180.0;
  /// Std of the measured motion's translation error (m) per axis per 0.1 s step; scales with
  /// sqrt(dt / 0.1), >= 0.
  double motion_translation_noise = 0.002;
  /// Std of each pixel coordinate (px) in each image, >= 0.
  double pixel_noise = 0.5;
  /// Number of tracked points per frame the simulator aims for, >= 1.
  int target_points = 100;
  /// At most this many tracks are born per frame, >= 1.
  int max_new_points_per_frame = 40;
  /// Depth range (m, along the left optical axis) of born points; inverse depth is sampled
  /// uniformly. 1 <= min_depth < max_depth (points closer than 1 m are lost).
  double min_depth = 3.0, max_depth = 60.0;
  /// Mean track length (frames): each live track is lost with probability 1 / mean per frame,
  /// besides leaving the view. >= 1; +infinity disables the random loss.
  double mean_track_length = 15.0;
  /// Fraction of observations replaced by gross outliers (one image's pixel moved 10-50 px),
  /// in [0, 1]. For robustness tests.
  double outlier_fraction = 0.0;
  /// Seed of all random streams; the same seed gives identical frames.
  unsigned seed = 1;
  /// Errors of the measured motion beyond white noise (time offset, scale, biases).
  OdometryErrorModel odometry_error;
  /// Frames in which nothing can be tracked (a texture-poor view: sky, a uniform wall,
  /// darkness): no observation, every track is lost, no track is born (the next frame
  /// starts new tracks with new ids). The motion is reported as usual. Spans must be in
  /// order, not overlap and lie within [0, frames - 1]. At image level these frames are
  /// rendered almost black (kBlindFrameExposureGain) so that the front end finds nothing.
  std::vector<FrameSpan> blind_frames;
  /// Fraction of the born points that lie on moving objects, in [0, 1]: each such point
  /// moves at a constant velocity of moving_point_speed (m/s) in a random horizontal (world
  /// x-y) direction from its birth on, and its observations follow it
  /// (SimulatedFrame::moving_ids). The decisions come from their own random stream (5), so a
  /// fraction of 0 leaves the frames unchanged. Measurement level only: the image-level
  /// runners do not render moving objects.
  double moving_point_fraction = 0.0;
  /// Speed (m/s) of the points on moving objects, >= 0.
  double moving_point_speed = 2.0;
  /// A recorded trajectory (T_world_veh over time, e.g. a TUM file read with
  /// tools/tum_trajectory.h) that replaces `motion` when set: frame k is taken at
  /// recorded_start_offset + k / rate_hz after its first stamp, on a C1 curve through the
  /// poses (PoseTrajectory::smoothAt). It must hold >= 2 poses and cover every frame, shifted
  /// by odometry_error.time_offset too (validate() names frames / recorded_start_offset).
  std::shared_ptr<const PoseTrajectory> recorded_trajectory;
  /// s after the recorded trajectory's first stamp at which frame 0 is taken, >= 0.
  double recorded_start_offset = 0.0;

  /// Every problem, each naming the field and the allowed range; empty if valid.
  std::vector<std::string> validate() const;

  /// True if @p frame lies in one of blind_frames.
  bool isBlindFrame(int frame) const;

  /// True parameters at a frame: truth + drift_per_second * t + step (from step_frame on).
  Vector12d truthParametersAt(int frame) const;
  /// Initial guess: truthParametersAt(0) + initial_error.
  Vector12d initialGuessParameters() const;
};

/// The seed's experiment: off-road at 3.5 m/s with roll/pitch motion, 10 deg yaw_l step at
/// frame 774 (the defaults of MeasurementScenario).
MeasurementScenario paperOffroadScenario();

/// On-road driving: planar motion at 10 m/s, no step (zl is unobservable).
MeasurementScenario urbanPlanarScenario();

/// Slow drift of x_camr over the default 150 s drive (yaw_r +0.2 deg, yr +2 mm), no step.
MeasurementScenario driftScenario();

}  // namespace osc
