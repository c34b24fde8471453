#include "online_stereo_calibration/core/sim/measurement_simulator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_set>

namespace osc {

namespace {

/// Tracks whose true projection comes closer than this to an image border are lost, as a
/// feature tracker loses a patch that no longer fits into the image.
constexpr double kImageMarginPx = 2.0;
/// Points closer than this (m, along either optical axis) are lost.
constexpr double kMinTrackDepth = 1.0;
/// Motion noise is specified per step of this length (s); it scales with sqrt(dt / this).
constexpr double kMotionNoiseStep = 0.1;
/// Range of the offset (px) of a gross outlier.
constexpr double kOutlierMinPx = 10.0, kOutlierMaxPx = 50.0;
/// Births give up after this many rejected samples per allowed birth (e.g. cameras whose
/// fields of view barely overlap), so a frame never loops for long.
constexpr int kBirthAttemptsPerPoint = 20;

MeasurementScenario validated(const MeasurementScenario& scenario) {
  const std::vector<std::string> problems = scenario.validate();
  if (problems.empty()) return scenario;
  std::string message = "invalid MeasurementScenario '" + scenario.name + "':";
  for (const std::string& problem : problems) message += "\n  - " + problem;
  throw std::invalid_argument(message);
}

}  // namespace

MeasurementSimulator::RandomStream::RandomStream(unsigned seed, unsigned stream) {
  std::seed_seq sequence{seed, stream};
  engine.seed(sequence);
}

MeasurementSimulator::MeasurementSimulator(const MeasurementScenario& scenario)
    : scenario_(validated(scenario)),
      trajectory_(scenario_.motion),
      left_(scenario_.left),
      right_(scenario_.right),
      track_rng_(scenario_.seed, 1),
      pixel_rng_(scenario_.seed, 2),
      motion_rng_(scenario_.seed, 3) {}

StereoExtrinsics MeasurementSimulator::initialGuess() const {
  return StereoExtrinsics::fromParameters(scenario_.initialGuessParameters());
}

StereoExtrinsics MeasurementSimulator::truthAt(int frame) const {
  return StereoExtrinsics::fromParameters(scenario_.truthParametersAt(frame));
}

std::optional<Eigen::Vector3d> MeasurementSimulator::worldPoint(PointId id) const {
  if (id == 0 || id > born_points_.size()) return std::nullopt;
  return born_points_[id - 1];
}

void MeasurementSimulator::dropTracks(const std::vector<PointId>& ids) {
  if (ids.empty()) return;
  const std::unordered_set<PointId> drop(ids.begin(), ids.end());
  live_.erase(std::remove_if(live_.begin(), live_.end(),
                             [&drop](const Track& track) { return drop.count(track.id) > 0; }),
              live_.end());
}

bool MeasurementSimulator::nextFrame(SimulatedFrame* frame) {
  if (next_frame_ >= scenario_.frames) return false;
  SimulatedFrame out;
  out.index = next_frame_++;
  const double dt = 1.0 / scenario_.rate_hz;
  out.stamp = out.index * dt;
  out.T_world_veh = trajectory_.pose(out.stamp);
  out.truth = truthAt(out.index);
  out.true_motion.dt = out.measured_motion.dt = dt;
  if (out.index > 0) {
    out.true_motion.T_prev_curr = previous_pose_.inverse() * out.T_world_veh;
    out.measured_motion = perturbMotion(out.true_motion);
  }
  previous_pose_ = out.T_world_veh;

  StereoView view;
  view.T_lopt_world = (out.T_world_veh * out.truth.vehicleToLeftOptical()).inverse();
  view.T_ropt_lopt = out.truth.leftToRightOptical().inverse();
  advanceTracks(view, &out);
  birthTracks(view, &out);
  *frame = std::move(out);
  return true;
}

MotionIncrement MeasurementSimulator::perturbMotion(const MotionIncrement& truth) {
  // Independent errors per step, like integrated IMU/odometry noise: the std grows with
  // the square root of the step length.
  const double scale = std::sqrt(truth.dt / kMotionNoiseStep);
  Vector6d delta;
  for (int axis = 0; axis < 3; ++axis) {
    delta(axis) = scale * scenario_.motion_translation_noise * motion_rng_.gaussian();
  }
  for (int axis = 3; axis < 6; ++axis) {
    delta(axis) = scale * scenario_.motion_rotation_noise * motion_rng_.gaussian();
  }
  MotionIncrement measured = truth;
  measured.T_prev_curr = boxPlus(truth.T_prev_curr, delta);
  return measured;
}

std::optional<MeasurementSimulator::StereoPixels> MeasurementSimulator::projectBoth(
    const Eigen::Vector3d& point_world, const StereoView& view) const {
  const Eigen::Vector3d in_left = view.T_lopt_world * point_world;
  if (!(in_left.z() >= kMinTrackDepth)) return std::nullopt;
  const Eigen::Vector3d in_right = view.T_ropt_lopt * in_left;
  if (!(in_right.z() >= kMinTrackDepth)) return std::nullopt;
  StereoPixels pixels;
  if (!left_.project(in_left, &pixels.left) || !left_.isInImage(pixels.left, kImageMarginPx) ||
      !right_.project(in_right, &pixels.right) || !right_.isInImage(pixels.right, kImageMarginPx)) {
    return std::nullopt;
  }
  return pixels;
}

Eigen::Vector2d MeasurementSimulator::outlierPixel(const Eigen::Vector2d& pixel,
                                                   const CameraModel& camera) {
  const double distance = pixel_rng_.uniform(kOutlierMinPx, kOutlierMaxPx);
  const double angle = pixel_rng_.uniform(0.0, 2.0 * M_PI);
  const Eigen::Vector2d offset = distance * Eigen::Vector2d(std::cos(angle), std::sin(angle));
  // A wrong match still lies in the image: mirror an offset component that would leave it
  // (clamping is only a last resort for images smaller than the offsets).
  const Eigen::Vector2d upper(camera.intrinsics().width - 1, camera.intrinsics().height - 1);
  Eigen::Vector2d moved = pixel + offset;
  for (int axis = 0; axis < 2; ++axis) {
    if (moved(axis) < 0.0 || moved(axis) > upper(axis)) moved(axis) = pixel(axis) - offset(axis);
    moved(axis) = std::clamp(moved(axis), 0.0, upper(axis));
  }
  return moved;
}

StereoObservation MeasurementSimulator::observe(PointId id, const StereoPixels& pixels,
                                                SimulatedFrame* frame) {
  StereoObservation observation;
  observation.id = id;
  observation.sigma_left = observation.sigma_right = scenario_.pixel_noise;
  const double sigma = scenario_.pixel_noise;
  observation.left_pixel =
      pixels.left + sigma * Eigen::Vector2d(pixel_rng_.gaussian(), pixel_rng_.gaussian());
  observation.right_pixel =
      pixels.right + sigma * Eigen::Vector2d(pixel_rng_.gaussian(), pixel_rng_.gaussian());
  // Only draw for outliers when they are enabled, so the noise of an outlier-free scenario
  // does not depend on this feature.
  if (scenario_.outlier_fraction > 0.0 &&
      pixel_rng_.uniform(0.0, 1.0) < scenario_.outlier_fraction) {
    // A mismatch in one of the two images (which one at random).
    if (pixel_rng_.uniform(0.0, 1.0) < 0.5) {
      observation.left_pixel = outlierPixel(observation.left_pixel, left_);
    } else {
      observation.right_pixel = outlierPixel(observation.right_pixel, right_);
    }
    frame->outlier_ids.push_back(id);
  }
  return observation;
}

void MeasurementSimulator::advanceTracks(const StereoView& view, SimulatedFrame* frame) {
  const double loss_probability = 1.0 / scenario_.mean_track_length;
  std::vector<Track> survivors;
  survivors.reserve(live_.size());
  for (const Track& track : live_) {
    // Drawn for every track, so the loss of one track does not shift the others' draws.
    const bool lost = track_rng_.uniform(0.0, 1.0) < loss_probability;
    if (lost) continue;
    const std::optional<StereoPixels> pixels = projectBoth(track.point_world, view);
    if (!pixels) continue;
    frame->observations.push_back(observe(track.id, *pixels, frame));
    survivors.push_back(track);
  }
  live_.swap(survivors);
}

void MeasurementSimulator::birthTracks(const StereoView& view, SimulatedFrame* frame) {
  const CameraIntrinsics& in = left_.intrinsics();
  // Sample strictly inside the margin so the round trip pixel -> ray -> pixel passes.
  const double margin = kImageMarginPx + 0.5;
  const Eigen::Isometry3d T_world_lopt = view.T_lopt_world.inverse();
  const int max_attempts = kBirthAttemptsPerPoint * scenario_.max_new_points_per_frame;
  int births = 0;
  for (int attempt = 0;
       attempt < max_attempts && static_cast<int>(live_.size()) < scenario_.target_points &&
       births < scenario_.max_new_points_per_frame;
       ++attempt) {
    // Sampling the left image and the inverse depth covers the camera's frustum whatever
    // the mounting, and gives the many-near, few-far depths of a real scene.
    const Eigen::Vector2d pixel(track_rng_.uniform(margin, in.width - 1 - margin),
                                track_rng_.uniform(margin, in.height - 1 - margin));
    const double inverse_depth =
        track_rng_.uniform(1.0 / scenario_.max_depth, 1.0 / scenario_.min_depth);
    const Eigen::Vector3d in_left = left_.pixelToNormalized(pixel).homogeneous() / inverse_depth;
    const Eigen::Vector3d point_world = T_world_lopt * in_left;
    const std::optional<StereoPixels> pixels = projectBoth(point_world, view);
    if (!pixels) continue;
    born_points_.push_back(point_world);
    const PointId id = born_points_.size();
    live_.push_back(Track{id, point_world});
    frame->observations.push_back(observe(id, *pixels, frame));
    frame->new_point_ids.push_back(id);
    ++births;
  }
}

}  // namespace osc
