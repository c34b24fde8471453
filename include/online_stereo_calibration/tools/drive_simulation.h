/// @file drive_simulation.h
/// @brief The image-level simulated drive behind `simulate`: the true vehicle motion (analytic
/// or a TUM recording), the true calibration per frame, rendered raw stereo images of the
/// procedural scene and INS-like noisy odometry. No ROS: `simulate` only writes it to a bag.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include "online_stereo_calibration/core/geometry/pose_interpolation.h"
#include "online_stereo_calibration/core/sim/stereo_scene_renderer.h"
#include "online_stereo_calibration/core/sim/vehicle_trajectory.h"
#include "online_stereo_calibration/tools/scenario_file.h"

namespace osc {

/// One rendered stereo frame with its truth.
struct SimulatedImagePair {
  int frame = 0;
  double stamp = 0.0;   ///< ROS time (s): rendering.start_stamp + frame / rate_hz
  cv::Mat left, right;  ///< raw (distorted) mono8 images
  Vector12d truth;      ///< true interface parameters at this frame
  Eigen::Isometry3d T_world_veh = Eigen::Isometry3d::Identity();  ///< true vehicle pose
};

/// Produces the frames and the odometry of a SimulationScenario. Deterministic.
class DriveSimulator {
 public:
  /// @p frames overrides scenario.measurement.frames when > 0. The recorded trajectory is
  /// scenario.measurement.recorded_trajectory (parseScenarioYaml fills it), else the file of
  /// scenario.trajectory.
  /// @throws std::invalid_argument (bad cameras, a TUM file too short for the frames and the
  /// odometry's time offset: the message names `frames`) or std::runtime_error (unreadable
  /// TUM file).
  DriveSimulator(const SimulationScenario& scenario, int frames = -1);
  ~DriveSimulator();

  int frames() const { return frames_; }
  /// ROS time (s) of a frame.
  double frameStamp(int frame) const;
  /// True vehicle pose T_world_veh at drive time t (s, 0 at frame 0).
  Eigen::Isometry3d truePose(double t) const;
  /// True parameters at a frame (scenario truth, drift, step).
  Vector12d truthAt(int frame) const { return scenario_.measurement.truthParametersAt(frame); }
  /// Initial guess: truth at frame 0 + scenario.initial_error.
  Vector12d initialGuess() const { return scenario_.measurement.initialGuessParameters(); }
  /// Renders one frame (thread-safe). A blind frame (scenario blind_frames) is rendered at
  /// kBlindFrameExposureGain times the exposure.
  SimulatedImagePair renderFrame(int frame) const;

  /// Noisy odometry T_odom_veh at odom_rate_hz (ROS stamps) from frame 0's stamp to one odom
  /// period past the last frame, dead-reckoned: each true increment between two samples gets
  /// an independent error of the scenario's motion_rotation_noise / motion_translation_noise
  /// per 0.1 s (scaled by sqrt(dt / 0.1)) and the noisy increments are chained. So the motion
  /// between two image pairs has independent noise, as the filter's model (eq. 15) and the
  /// measurement-level simulator assume, while the absolute pose drifts. (Multiplying the true
  /// pose by an accumulated body-frame error instead would rotate every later increment by
  /// that error, ~0.7 deg after 1000 frames: a systematic error that biased x_caml.)
  /// The scenario's odometry_error applies too: the sample stamped start_stamp + t holds the
  /// true motion up to drive time t + time_offset (the stamps are shifted by -time_offset
  /// against the truth), and each true increment gets the scale error and the Gauss-Markov
  /// biases (OdometryErrorProcess, seeded with the scenario seed) before the white noise.
  std::vector<StampedPose> odometry() const;
  /// The body twist [v (m/s), w (rad/s)] (vehicle frame) the odometry reports with its
  /// sample stamped @p stamp (ROS): the true twist at drive time
  /// stamp - start_stamp + time_offset, the translation times 1 + scale_error, as
  /// MeasurementSimulator::measuredTwist. For nav_msgs/Odometry twist.twist.
  Vector6d odometryTwist(double stamp) const;

  const SimulationScenario& scenario() const { return scenario_; }
  const CameraModel& leftCamera() const { return left_; }
  const CameraModel& rightCamera() const { return right_; }

 private:
  SimulationScenario scenario_;
  int frames_;
  CameraModel left_, right_;
  std::unique_ptr<VehicleTrajectory> analytic_;
  std::shared_ptr<const PoseTrajectory> recorded_;
  double recorded_start_ = 0.0;
  std::unique_ptr<StereoSceneRenderer> renderer_;
};

}  // namespace osc
