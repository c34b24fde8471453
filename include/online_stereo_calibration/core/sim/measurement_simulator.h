/// @file measurement_simulator.h
/// @brief Measurement-level simulator of the seed's experiment: static 3D points around a
/// vehicle trajectory, a true (possibly changing) calibration, noisy motion increments and
/// noisy stereo pixel measurements with the births and deaths of a real feature tracker.
#pragma once

#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "online_stereo_calibration/core/estimator/types.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/sim/measurement_scenario.h"
#include "online_stereo_calibration/core/sim/vehicle_trajectory.h"

namespace osc {

/// Everything the simulator produces for one stereo frame: the estimator's inputs
/// (measured_motion, observations) and the truth to evaluate it against.
struct SimulatedFrame {
  /// Frame number, from 0.
  int index = 0;
  /// Time of the frame (s): index / rate_hz.
  double stamp = 0.0;
  /// Noisy motion since the previous frame; frame 0: identity with dt = 1 / rate_hz.
  MotionIncrement measured_motion;
  /// Exact motion since the previous frame; frame 0: identity with dt = 1 / rate_hz.
  MotionIncrement true_motion;
  /// Raw (distorted) pixels of the points visible in both images, sorted by id; sigma_left
  /// and sigma_right are scenario.pixel_noise.
  std::vector<StereoObservation> observations;
  /// Ids born this frame (a subset of observations, ascending).
  std::vector<PointId> new_point_ids;
  /// Ids whose observation this frame is a gross outlier (scenario.outlier_fraction).
  std::vector<PointId> outlier_ids;
  /// True calibration at this frame.
  StereoExtrinsics truth;
  /// True vehicle pose T_world_veh.
  Eigen::Isometry3d T_world_veh = Eigen::Isometry3d::Identity();
};

/// Produces the frames of a MeasurementScenario one by one. Deterministic for a given
/// scenario (seed included). The track structure (births, losses), the pixel noise and the
/// motion noise come from separate random streams, so changing a noise level does not change
/// which points exist.
class MeasurementSimulator {
 public:
  /// @throws std::invalid_argument listing validate() problems.
  explicit MeasurementSimulator(const MeasurementScenario& scenario);

  /// Fills the next frame; false when all scenario.frames were produced (frame untouched).
  bool nextFrame(SimulatedFrame* frame);

  /// The estimator lost or rejected these points; like a real tracker, stop reporting them
  /// (they die). Unknown or dead ids are ignored.
  void dropTracks(const std::vector<PointId>& ids);

  const MeasurementScenario& scenario() const { return scenario_; }
  const CameraModel& leftCamera() const { return left_; }
  const CameraModel& rightCamera() const { return right_; }
  const VehicleTrajectory& trajectory() const { return trajectory_; }

  /// Truth at frame 0 + initial_error (parameter space).
  StereoExtrinsics initialGuess() const;
  /// True calibration at any frame (also those not produced yet).
  StereoExtrinsics truthAt(int frame) const;

  /// True world position of a point ever born (also after it died), for tests.
  std::optional<Eigen::Vector3d> worldPoint(PointId id) const;

  /// Number of tracks alive after the last frame (before any later dropTracks()).
  int liveTrackCount() const { return static_cast<int>(live_.size()); }
  /// Number of frames produced so far.
  int framesProduced() const { return next_frame_; }

 private:
  struct Track {
    PointId id;
    Eigen::Vector3d point_world;
  };
  /// The transforms that map world points into both optical frames at one frame.
  struct StereoView {
    Eigen::Isometry3d T_lopt_world;
    Eigen::Isometry3d T_ropt_lopt;
  };
  /// One independent random stream (its own engine and normal-distribution cache).
  struct RandomStream {
    RandomStream(unsigned seed, unsigned stream);
    double gaussian() { return normal(engine); }
    double uniform(double low, double high) {
      return low + (high - low) * std::generate_canonical<double, 53>(engine);
    }
    std::mt19937_64 engine;
    std::normal_distribution<double> normal{0.0, 1.0};
  };
  /// True pixels of a world point if it is visible in both images.
  struct StereoPixels {
    Eigen::Vector2d left, right;
  };

  std::optional<StereoPixels> projectBoth(const Eigen::Vector3d& point_world,
                                          const StereoView& view) const;
  MotionIncrement perturbMotion(const MotionIncrement& truth);
  StereoObservation observe(PointId id, const StereoPixels& pixels, SimulatedFrame* frame);
  Eigen::Vector2d outlierPixel(const Eigen::Vector2d& pixel, const CameraModel& camera);
  void advanceTracks(const StereoView& view, SimulatedFrame* frame);
  void birthTracks(const StereoView& view, SimulatedFrame* frame);

  MeasurementScenario scenario_;
  VehicleTrajectory trajectory_;
  CameraModel left_, right_;
  RandomStream track_rng_;   ///< births and random losses
  RandomStream pixel_rng_;   ///< pixel noise and outliers
  RandomStream motion_rng_;  ///< motion noise
  int next_frame_ = 0;
  Eigen::Isometry3d previous_pose_ = Eigen::Isometry3d::Identity();
  std::vector<Track> live_;
  /// World point of every track ever born, indexed by id - 1 (ids are 1, 2, 3, ...).
  std::vector<Eigen::Vector3d> born_points_;
};

}  // namespace osc
