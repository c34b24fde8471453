/// @file scenario_file.h
/// @brief Scenario files of the image-level simulator (config/scenarios/*.yaml, read by
/// `simulate`): a MeasurementScenario (cameras, truth, its changes, motion and motion noise),
/// how the images are rendered, and optionally a recorded 6-DoF trajectory (TUM file).
///
/// All values SI: metres, seconds, radians (calibration vectors as in interface.md).
/// ```
/// base: paper_offroad            # preset to start from: paper_offroad, urban_planar, drift
/// name: paper_offroad
/// frames: 1500
/// rate_hz: 10
/// seed: 1
/// left_camera:  {width: 640, height: 480, fx: 600, fy: 600, cx: 319.5, cy: 239.5,
///                distortion_model: plumb_bob, distortion: [k1, k2, p1, p2]}
///               # or {euroc_sensor_yaml: path}  (EuRoC cam*/sensor.yaml intrinsics)
/// right_camera: {...}
/// truth:        {vehicle_to_left: [6], left_to_right: [6]}
///               # or {euroc_left: cam0/sensor.yaml, euroc_right: cam1/sensor.yaml,
///               #     R_body_vehicle: [9, row-major]}   (rig pose from the EuRoC T_BS)
/// initial_error:     {vehicle_to_left: [6], left_to_right: [6]}
/// step_frame: 774                # negative: no step
/// step:              {vehicle_to_left: [6], left_to_right: [6]}
/// drift_per_second:  {vehicle_to_left: [6], left_to_right: [6]}
/// motion: {speed, roll_amplitude, pitch_amplitude, roll_period, pitch_period,
///          yaw_rate_amplitude, yaw_period, yaw_phase, heave_amplitude, heave_period, planar,
///          stops: [[start, duration], ...],   # s; the vehicle stands still (in order)
///          stop_ramp: 1.0}                    # s of smooth slow-down / speed-up
/// motion_rotation_noise: 3.49e-4     # rad per axis per 0.1 s (odometry white noise)
/// motion_translation_noise: 0.002    # m per axis per 0.1 s
/// odometry_error: {time_offset: 0,          # s, camera clock minus odometry clock
///                  scale_error: 0,          # translation x (1 + scale_error)
///                  rotation_rate_bias: 0,   # rad/s, steady-state std per axis
///                  velocity_bias: 0,        # m/s, steady-state std per axis
///                  bias_correlation_time: 30}  # s (Gauss-Markov)
/// blind_frames: [[first, last], ...]   # frames (both included) with nothing to track
/// moving_point_fraction: 0             # measurement level only (see below)
/// moving_point_speed: 2.0              # m/s
/// trajectory: {tum_file: path, start_offset: 0}   # optional: replaces `motion` (no stops)
/// rendering: {scene_seed, ground_undulation, structure_density, image_noise, blur_sigma,
///             supersampling, odom_rate_hz, start_stamp, room_margin, room_height}
/// ```
/// Keys left out keep the preset's value. Relative paths are resolved against the scenario
/// file's directory first, then the current directory. The keys map to the
/// MeasurementScenario fields of the same names (their docs give the ranges; `trajectory`
/// is read into recorded_trajectory / recorded_start_offset). In `simulate` (the image-level
/// drive, DriveSimulator) blind frames are rendered almost black and the odometry carries
/// odometry_error; moving points exist only in measurement-level runs (MeasurementSimulator):
/// the rendered scene is static.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "online_stereo_calibration/core/sim/measurement_scenario.h"

namespace osc {

/// How the images and the odometry of a simulated drive are produced.
struct SceneRenderingOptions {
  unsigned scene_seed = 7;          ///< seed of the procedural scene
  double ground_undulation = 0.3;   ///< m, SceneConfig::ground_undulation
  double structure_density = 40.0;  ///< per hectare, SceneConfig::structure_density
  double image_noise = 1.0;         ///< grey levels (0-255), Gaussian, per pixel
  double blur_sigma = 0.5;          ///< px, optics blur
  int supersampling = 2;            ///< RenderOptions::supersampling (1-4)
  double odom_rate_hz = 100.0;      ///< rate of the simulated INS odometry, > 0
  double start_stamp = 1.7e9;       ///< ROS time (s) of frame 0, >= 1
  /// > 0: an indoor drive. Four textured walls stand this far (m) beyond the bounding box of
  /// the path, and no structures are generated (a MAV flying in a room); 0: outdoors.
  double room_margin = 0.0;
  double room_height = 4.0;  ///< m, height of the room's walls
};

/// A recorded trajectory replacing the analytic vehicle motion.
struct TumTrajectoryOption {
  std::string file;           ///< resolved path of the TUM file
  double start_offset = 0.0;  ///< s after the file's first stamp at which frame 0 is taken
};

/// A parsed scenario file.
struct SimulationScenario {
  /// With `trajectory`, measurement.recorded_trajectory holds the TUM file's poses.
  MeasurementScenario measurement;
  SceneRenderingOptions rendering;
  std::optional<TumTrajectoryOption> trajectory;
  /// The file's text (for the cache fingerprint).
  std::string source_text;
};

/// Parses scenario YAML text. @p source_name names it in errors, @p base_directory resolves
/// relative paths. @throws std::runtime_error listing every problem, each naming the key
/// (unknown key, wrong type, invalid value, MeasurementScenario::validate()).
SimulationScenario parseScenarioYaml(const std::string& text, const std::string& source_name,
                                     const std::string& base_directory);

/// Reads and parses a scenario file. @throws std::runtime_error naming the file.
SimulationScenario readScenarioFile(const std::string& path);

/// Reads the intrinsics of an EuRoC `sensor.yaml` (pinhole, radial-tangential = plumb_bob).
CameraIntrinsics readEurocIntrinsics(const std::string& path);

/// 64-bit FNV-1a hash (hex) of the scenario text, the frame count actually simulated and the
/// simulator version: equal fingerprints mean an identical drive.
std::string scenarioFingerprint(const SimulationScenario& scenario, int frames);

}  // namespace osc
