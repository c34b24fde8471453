/// @file measurement_simulator.h
/// @brief Measurement-level simulator of the seed's experiment: 3D points (static, or on moving
/// objects) around a vehicle trajectory (analytic with stops, or recorded), a true (possibly
/// changing) calibration, noisy and biased motion increments and noisy stereo pixel
/// measurements with the births and deaths of a real feature tracker (and blind frames).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "online_stereo_calibration/core/estimator/types.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/geometry/pose_interpolation.h"
#include "online_stereo_calibration/core/sim/measurement_scenario.h"
#include "online_stereo_calibration/core/sim/odometry_error.h"
#include "online_stereo_calibration/core/sim/vehicle_trajectory.h"

namespace osc {

/// Everything the simulator produces for one stereo frame: the estimator's inputs
/// (measured_motion, observations) and the truth to evaluate it against.
struct SimulatedFrame {
  /// Frame number, from 0.
  int index = 0;
  /// Time of the frame (s): index / rate_hz.
  double stamp = 0.0;
  /// Measured motion since the previous frame: the true motion of the interval shifted by
  /// odometry_error.time_offset, with its scale error and biases (OdometryErrorProcess), then
  /// the white motion noise. Frame 0: identity with dt = 1 / rate_hz.
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
  /// Ids of the observations this frame that lie on moving objects
  /// (scenario.moving_point_fraction; ascending, a subset of observations).
  std::vector<PointId> moving_ids;
  /// True calibration at this frame.
  StereoExtrinsics truth;
  /// True vehicle pose T_world_veh (= MeasurementSimulator::truePose(stamp)).
  Eigen::Isometry3d T_world_veh = Eigen::Isometry3d::Identity();
  /// The frame is one of scenario.blind_frames: no observations, every track died.
  bool blind = false;
};

/// Produces the frames of a MeasurementScenario one by one. Deterministic for a given
/// scenario (seed included). The track structure (births, losses), the pixel noise, the
/// motion noise, the odometry biases (stream 4) and the moving-point draws (stream 5) come
/// from separate random streams, so changing a noise level or an odometry error does not
/// change which points exist, and features left at zero leave the frames bit-identical.
class MeasurementSimulator {
 public:
  /// @throws std::invalid_argument listing validate() problems.
  explicit MeasurementSimulator(const MeasurementScenario& scenario);

  /// Fills the next frame; false when all scenario.frames were produced (frame untouched).
  bool nextFrame(SimulatedFrame* frame);

  /// Read the odometry for the next frames at the image stamps minus @p shift (s), as a
  /// caller does with StereoCalibrationEstimator::odometryTimeShift(); the frame's
  /// measured_motion.time_shift says it. 0 (the default) reads at the image stamps. A shifted
  /// read that would leave a recorded trajectory is made unshifted (time_shift 0).
  void setOdometryTimeShift(double shift) { odometry_time_shift_ = shift; }

  /// The estimator lost or rejected these points; like a real tracker, stop reporting them
  /// (they die). Unknown or dead ids are ignored.
  void dropTracks(const std::vector<PointId>& ids);

  const MeasurementScenario& scenario() const { return scenario_; }
  const CameraModel& leftCamera() const { return left_; }
  const CameraModel& rightCamera() const { return right_; }
  /// The analytic profile (scenario.motion, stops included). With a recorded_trajectory it
  /// is NOT the drive: use truePose() and groundTrack(), which follow either.
  const VehicleTrajectory& trajectory() const { return trajectory_; }

  /// True vehicle pose T_world_veh at drive time t (s, 0 at frame 0; any t for the analytic
  /// profile). With a recorded_trajectory: its pose at firstStamp + recorded_start_offset + t
  /// (PoseTrajectory::smoothAt: C1, so that the twists below are the derivative of the pose
  /// over any time offset). @throws std::out_of_range if t lies outside the recording.
  Eigen::Isometry3d truePose(double t) const;
  /// True motion T_veh(t0)_veh(t1) = truePose(t0)^-1 * truePose(t1); exactly the identity
  /// while the vehicle stands in a stop.
  Eigen::Isometry3d trueMotion(double t0, double t1) const;
  /// The body twist [v, w] the odometry reports at its time t (true, times its scale error).
  Vector6d measuredTwist(double t) const;
  /// The shift the odometry of the increment from drive time t0 to t1 is read with:
  /// setOdometryTimeShift's, or 0 if that read would leave the recorded trajectory.
  double odometryReadShift(double t0, double t1) const;
  /// The vehicle's world x-y positions over the drive [0, frames / rate_hz] (clamped to the
  /// recording), for SceneConfig::path of the image-level renderer: at most 1 m apart for
  /// the analytic profile (the scene decimates to 1 m), every recorded pose in between for a
  /// recorded trajectory.
  std::vector<Eigen::Vector2d> groundTrack() const;

  /// Truth at frame 0 + initial_error (parameter space).
  StereoExtrinsics initialGuess() const;
  /// True calibration at any frame (also those not produced yet).
  StereoExtrinsics truthAt(int frame) const;

  /// True world position at its birth of a point ever born (also after it died), for tests.
  /// A static point stays there; see worldPointAt() for points on moving objects.
  std::optional<Eigen::Vector3d> worldPoint(PointId id) const;
  /// True world position of a point ever born at drive time t (s): its birth position plus
  /// its velocity (zero unless on a moving object) times (t - birth time).
  std::optional<Eigen::Vector3d> worldPointAt(PointId id, double t) const;

  /// Number of tracks alive after the last frame (before any later dropTracks()).
  int liveTrackCount() const { return static_cast<int>(live_.size()); }
  /// Number of frames produced so far.
  int framesProduced() const { return next_frame_; }

 private:
  /// A point ever born: where and when, and its velocity (m/s, world; zero if static).
  struct BornPoint {
    Eigen::Vector3d position;
    double birth_time;
    Eigen::Vector3d velocity;
    bool moving;
    Eigen::Vector3d at(double t) const {
      return moving ? Eigen::Vector3d(position + (t - birth_time) * velocity) : position;
    }
  };
  struct Track {
    PointId id;
    BornPoint point;
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
  /// Velocity of a point born now: on a moving object with moving_point_fraction.
  std::optional<Eigen::Vector3d> drawMovingVelocity();
  void birthTracks(const StereoView& view, SimulatedFrame* frame);

  MeasurementScenario scenario_;
  VehicleTrajectory trajectory_;
  /// The recorded drive (scenario.recorded_trajectory) and the stamp of frame 0 in it.
  std::shared_ptr<const PoseTrajectory> recorded_;
  double recorded_start_ = 0.0;
  CameraModel left_, right_;
  RandomStream track_rng_;               ///< births and random losses
  RandomStream pixel_rng_;               ///< pixel noise and outliers
  RandomStream motion_rng_;              ///< motion noise
  RandomStream moving_rng_;              ///< which born points move, and where (stream 5)
  OdometryErrorProcess odometry_error_;  ///< scale error and biases (stream 4)
  int next_frame_ = 0;
  double odometry_time_shift_ = 0.0;  ///< setOdometryTimeShift
  std::vector<Track> live_;
  /// Every point ever born, indexed by id - 1 (ids are 1, 2, 3, ...).
  std::vector<BornPoint> born_points_;
};

}  // namespace osc
