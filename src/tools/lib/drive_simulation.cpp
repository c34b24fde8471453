/// @file drive_simulation.cpp
/// @brief The image-level simulated drive (see drive_simulation.h).
#include "online_stereo_calibration/tools/drive_simulation.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <stdexcept>

#include "online_stereo_calibration/core/sim/odometry_error.h"
#include "online_stereo_calibration/core/sim/room_walls.h"
#include "online_stereo_calibration/tools/tum_trajectory.h"

namespace osc {
namespace {

/// The scenario's motion noise sigmas refer to steps of this length (s).
constexpr double kNoiseReferenceStep = 0.1;
/// Spacing of the ground-track polyline handed to the scene (m).
constexpr double kPathSpacing = 1.0;

}  // namespace

DriveSimulator::DriveSimulator(const SimulationScenario& scenario, int frames)
    : scenario_(scenario),
      frames_(frames > 0 ? frames : scenario.measurement.frames),
      left_(scenario.measurement.left),
      right_(scenario.measurement.right) {
  scenario_.measurement.frames = frames_;
  const double time_offset = scenario_.measurement.odometry_error.time_offset;
  const double duration = (frames_ - 1) / scenario_.measurement.rate_hz +
                          2.0 / scenario_.rendering.odom_rate_hz + std::max(0.0, time_offset);
  recorded_ = scenario_.measurement.recorded_trajectory;
  double start_offset = scenario_.measurement.recorded_start_offset;
  if (!recorded_ && scenario_.trajectory) {
    recorded_ =
        std::make_shared<const PoseTrajectory>(readTumTrajectory(scenario_.trajectory->file));
    start_offset = scenario_.trajectory->start_offset;
  }
  if (recorded_) {
    if (recorded_->size() < 2) throw std::invalid_argument("trajectory: fewer than 2 poses");
    recorded_start_ = recorded_->firstStamp() + start_offset;
    if (recorded_start_ + duration > recorded_->lastStamp() ||
        recorded_start_ + std::min(0.0, time_offset) < recorded_->firstStamp()) {
      throw std::invalid_argument("frames: " + std::to_string(frames_) + " frames at " +
                                  std::to_string(scenario_.measurement.rate_hz) + " Hz need " +
                                  std::to_string(duration) + " s (odometry_error.time_offset " +
                                  std::to_string(time_offset) +
                                  " s included) but trajectory.tum_file covers only " +
                                  std::to_string(recorded_->lastStamp() - recorded_start_) +
                                  " s after start_offset " + std::to_string(start_offset) + " s");
    }
  } else {
    analytic_ = std::make_unique<VehicleTrajectory>(scenario_.measurement.motion);
  }
  SceneConfig scene;
  scene.seed = scenario_.rendering.scene_seed;
  scene.ground_undulation = scenario_.rendering.ground_undulation;
  scene.structure_density = scenario_.rendering.structure_density;
  // The scene is laid along the scenario's whole drive, not only the frames rendered: a drive
  // cut short with `frames` is then the beginning of the full one (same structures), which is
  // what scripts/demo.sh and `simulate --frames` promise.
  const int scenario_frames = std::max(frames_, scenario.measurement.frames);
  double scene_duration = (scenario_frames - 1) / scenario_.measurement.rate_hz +
                          2.0 / scenario_.rendering.odom_rate_hz;
  if (scenario_.trajectory) {
    scene_duration = std::min(scene_duration, recorded_->lastStamp() - recorded_start_);
  }
  Eigen::Vector2d last = truePose(0.0).translation().head<2>();
  scene.path.push_back(last);
  for (double t = 0.0; t <= scene_duration; t += 0.05) {
    const Eigen::Vector2d p = truePose(t).translation().head<2>();
    if ((p - last).norm() >= kPathSpacing) {
      scene.path.push_back(p);
      last = p;
    }
  }
  if (scenario_.rendering.room_margin > 0.0) {  // indoors: walls instead of structures
    scene.generate_structures = false;
    scene.extra_primitives = roomWalls(scene.path, scenario_.rendering.room_margin,
                                       scenario_.rendering.room_height, scene.seed);
  }
  renderer_ = std::make_unique<StereoSceneRenderer>(scene);
}

DriveSimulator::~DriveSimulator() = default;

double DriveSimulator::frameStamp(int frame) const {
  return scenario_.rendering.start_stamp + frame / scenario_.measurement.rate_hz;
}

Eigen::Isometry3d DriveSimulator::truePose(double t) const {
  if (analytic_) return analytic_->pose(t);
  const auto pose = recorded_->smoothAt(recorded_start_ + t, 1e-9);  // as MeasurementSimulator
  if (!pose) throw std::out_of_range("DriveSimulator: time outside the recorded trajectory");
  return *pose;
}

SimulatedImagePair DriveSimulator::renderFrame(int frame) const {
  SimulatedImagePair out;
  out.frame = frame;
  out.stamp = frameStamp(frame);
  out.truth = truthAt(frame);
  out.T_world_veh = truePose(frame / scenario_.measurement.rate_hz);
  const StereoExtrinsics truth = StereoExtrinsics::fromParameters(out.truth);
  const Eigen::Isometry3d T_world_lopt = out.T_world_veh * truth.vehicleToLeftOptical();
  const Eigen::Isometry3d T_world_ropt = T_world_lopt * truth.leftToRightOptical();
  RenderOptions options;
  options.noise_sigma = scenario_.rendering.image_noise;
  options.blur_sigma = scenario_.rendering.blur_sigma;
  options.supersampling = scenario_.rendering.supersampling;
  options.noise_seed = 2u * static_cast<unsigned>(frame) + 1u;
  if (scenario_.measurement.isBlindFrame(frame)) options.exposure_gain = kBlindFrameExposureGain;
  out.left = renderer_->render(left_, T_world_lopt, options);
  options.noise_seed += 1u;
  out.right = renderer_->render(right_, T_world_ropt, options);
  return out;
}

Vector6d DriveSimulator::odometryTwist(double stamp) const {
  const double t =
      stamp - scenario_.rendering.start_stamp + scenario_.measurement.odometry_error.time_offset;
  constexpr double h = 1e-3;  // s, central difference of the true pose
  double from = t - h, to = t + h;
  if (recorded_) {  // one-sided at the ends of the recording
    from = std::max(from, recorded_->firstStamp() - recorded_start_);
    to = std::min(to, recorded_->lastStamp() - recorded_start_);
  }
  const Eigen::Isometry3d motion =
      analytic_ ? analytic_->motionBetween(from, to) : truePose(from).inverse() * truePose(to);
  Vector6d twist = logSE3(motion) / (to - from);
  twist.head<3>() *= 1.0 + scenario_.measurement.odometry_error.scale_error;
  return twist;
}

std::vector<StampedPose> DriveSimulator::odometry() const {
  const double period = 1.0 / scenario_.rendering.odom_rate_hz;
  const double end = (frames_ - 1) / scenario_.measurement.rate_hz + period;
  const int samples = static_cast<int>(std::ceil(end / period - 1e-9)) + 1;
  const double scale = std::sqrt(period / kNoiseReferenceStep);
  std::mt19937_64 engine(0x5eedULL * (scenario_.measurement.seed + 1ULL) + 17ULL);
  std::normal_distribution<double> normal(0.0, 1.0);
  OdometryErrorProcess errors(scenario_.measurement.odometry_error, scenario_.measurement.seed);
  // The camera clock minus the odometry's is time_offset: the sample stamped start_stamp + k *
  // period holds the true motion up to drive time k * period + time_offset.
  const double offset = scenario_.measurement.odometry_error.time_offset;
  std::vector<StampedPose> out;
  out.reserve(samples);
  Eigen::Isometry3d pose = truePose(offset);
  double previous_t = offset;
  for (int k = 0; k < samples; ++k) {
    const double t = k * period + offset;
    if (k > 0) {
      Vector6d delta;
      for (int i = 0; i < 3; ++i) {
        delta(i) = scale * scenario_.measurement.motion_translation_noise * normal(engine);
      }
      for (int i = 3; i < 6; ++i) {
        delta(i) = scale * scenario_.measurement.motion_rotation_noise * normal(engine);
      }
      MotionIncrement increment;
      increment.dt = t - previous_t;
      // Exactly the identity while standing in a stop.
      increment.T_prev_curr = analytic_ ? analytic_->motionBetween(previous_t, t)
                                        : truePose(previous_t).inverse() * truePose(t);
      pose = pose * boxPlus(errors.apply(increment).T_prev_curr, delta);
      previous_t = t;
    }
    out.push_back({scenario_.rendering.start_stamp + k * period, pose});
  }
  return out;
}

}  // namespace osc
