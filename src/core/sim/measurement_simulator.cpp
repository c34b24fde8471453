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
/// Slack (s) at the ends of a recorded trajectory for rounding of the frame times.
constexpr double kRecordedTolerance = 1e-9;
/// Random stream numbers (with the scenario's seed).
constexpr unsigned kTrackStream = 1, kPixelStream = 2, kMotionStream = 3, kMovingStream = 5;

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
      recorded_(scenario_.recorded_trajectory),
      left_(scenario_.left),
      right_(scenario_.right),
      track_rng_(scenario_.seed, kTrackStream),
      pixel_rng_(scenario_.seed, kPixelStream),
      motion_rng_(scenario_.seed, kMotionStream),
      moving_rng_(scenario_.seed, kMovingStream),
      odometry_error_(scenario_.odometry_error, scenario_.seed) {
  if (recorded_) recorded_start_ = recorded_->firstStamp() + scenario_.recorded_start_offset;
}

Eigen::Isometry3d MeasurementSimulator::truePose(double t) const {
  if (!recorded_) return trajectory_.pose(t);
  // C1 through the recorded poses: the odometry's twists are its derivative (issue 15).
  const std::optional<Eigen::Isometry3d> pose =
      recorded_->smoothAt(recorded_start_ + t, kRecordedTolerance);
  if (!pose) {
    throw std::out_of_range("MeasurementSimulator::truePose: t = " + std::to_string(t) +
                            " s lies outside the recorded trajectory");
  }
  return *pose;
}

Eigen::Isometry3d MeasurementSimulator::trueMotion(double t0, double t1) const {
  if (!recorded_) return trajectory_.motionBetween(t0, t1);
  return truePose(t0).inverse() * truePose(t1);
}

std::vector<Eigen::Vector2d> MeasurementSimulator::groundTrack() const {
  const double duration = scenario_.frames / scenario_.rate_hz;
  std::vector<Eigen::Vector2d> track;
  if (!recorded_) {
    // Evenly in time, one sample per metre at the profile speed (never faster: stops only
    // slow it down).
    const double speed = std::max(scenario_.motion.speed, 0.1);
    const int samples = std::max(2, static_cast<int>(std::ceil(duration * speed)) + 1);
    for (int i = 0; i <= samples; ++i) {
      track.push_back(trajectory_.groundPosition(duration * i / samples));
    }
    return track;
  }
  const double end = std::min(recorded_start_ + duration, recorded_->lastStamp());
  track.push_back(truePose(0.0).translation().head<2>());
  for (const StampedPose& p : recorded_->poses()) {
    if (p.stamp > recorded_start_ && p.stamp < end) track.push_back(p.pose.translation().head<2>());
  }
  track.push_back(recorded_->smoothAt(end, kRecordedTolerance)->translation().head<2>());
  return track;
}

StereoExtrinsics MeasurementSimulator::initialGuess() const {
  return StereoExtrinsics::fromParameters(scenario_.initialGuessParameters());
}

StereoExtrinsics MeasurementSimulator::truthAt(int frame) const {
  return StereoExtrinsics::fromParameters(scenario_.truthParametersAt(frame));
}

std::optional<Eigen::Vector3d> MeasurementSimulator::worldPoint(PointId id) const {
  if (id == 0 || id > born_points_.size()) return std::nullopt;
  return born_points_[id - 1].position;
}

std::optional<Eigen::Vector3d> MeasurementSimulator::worldPointAt(PointId id, double t) const {
  if (id == 0 || id > born_points_.size()) return std::nullopt;
  return born_points_[id - 1].at(t);
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
  out.T_world_veh = truePose(out.stamp);
  out.truth = truthAt(out.index);
  out.true_motion.dt = out.measured_motion.dt = dt;
  if (out.index > 0) {
    const double previous = (out.index - 1) * dt;
    out.true_motion.T_prev_curr = trueMotion(previous, out.stamp);
    // The odometry's sample stamped t holds the vehicle at camera time t + time_offset; read
    // at the image stamps minus the shift, it gives the motion time_offset - shift later than
    // the cameras saw it.
    MotionIncrement reported = out.true_motion;
    const double shift = odometryReadShift(previous, out.stamp);
    const double offset = scenario_.odometry_error.time_offset - shift;
    if (offset != 0.0) reported.T_prev_curr = trueMotion(previous + offset, out.stamp + offset);
    out.measured_motion = perturbMotion(odometry_error_.apply(reported));
    // The odometry's twists at both ends, on its clock and in its scale (exact derivatives:
    // their noise matters to the time-offset model only times the offset).
    out.measured_motion.has_twists = true;
    out.measured_motion.twist_start = measuredTwist(previous + offset);
    out.measured_motion.twist_end = measuredTwist(out.stamp + offset);
    out.measured_motion.time_shift = shift;
  }
  if (scenario_.isBlindFrame(out.index)) {
    // Nothing can be tracked: every track is lost, none is born (no random draws either).
    out.blind = true;
    live_.clear();
    *frame = std::move(out);
    return true;
  }

  StereoView view;
  view.T_lopt_world = (out.T_world_veh * out.truth.vehicleToLeftOptical()).inverse();
  view.T_ropt_lopt = out.truth.leftToRightOptical().inverse();
  advanceTracks(view, &out);
  birthTracks(view, &out);
  *frame = std::move(out);
  return true;
}

double MeasurementSimulator::odometryReadShift(double t0, double t1) const {
  if (odometry_time_shift_ == 0.0 || !recorded_) return odometry_time_shift_;
  constexpr double kTwistStep = 1e-3;  // measuredTwist's central difference
  const double offset = scenario_.odometry_error.time_offset - odometry_time_shift_;
  const bool recorded = recorded_start_ + t0 + offset - kTwistStep >= recorded_->firstStamp() &&
                        recorded_start_ + t1 + offset + kTwistStep <= recorded_->lastStamp();
  return recorded ? odometry_time_shift_ : 0.0;
}

Vector6d MeasurementSimulator::measuredTwist(double t) const {
  constexpr double h = 1e-3;  // s, central difference of the true pose (odometryReadShift)
  Vector6d twist = logSE3(trueMotion(t - h, t + h)) / (2.0 * h);
  twist.head<3>() *= 1.0 + scenario_.odometry_error.scale_error;
  return twist;
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
    const std::optional<StereoPixels> pixels = projectBoth(track.point.at(frame->stamp), view);
    if (!pixels) continue;
    frame->observations.push_back(observe(track.id, *pixels, frame));
    if (track.point.moving) frame->moving_ids.push_back(track.id);
    survivors.push_back(track);
  }
  live_.swap(survivors);
}

std::optional<Eigen::Vector3d> MeasurementSimulator::drawMovingVelocity() {
  // Drawn only when enabled, so a scenario without moving points is unchanged.
  if (!(scenario_.moving_point_fraction > 0.0)) return std::nullopt;
  if (!(moving_rng_.uniform(0.0, 1.0) < scenario_.moving_point_fraction)) return std::nullopt;
  const double heading = moving_rng_.uniform(0.0, 2.0 * M_PI);
  return Eigen::Vector3d(scenario_.moving_point_speed * std::cos(heading),
                         scenario_.moving_point_speed * std::sin(heading), 0.0);
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
    BornPoint born{point_world, frame->stamp, Eigen::Vector3d::Zero(), false};
    if (const std::optional<Eigen::Vector3d> velocity = drawMovingVelocity()) {
      born.velocity = *velocity;
      born.moving = true;
    }
    born_points_.push_back(born);
    const PointId id = born_points_.size();
    live_.push_back(Track{id, born});
    frame->observations.push_back(observe(id, *pixels, frame));
    frame->new_point_ids.push_back(id);
    if (born.moving) frame->moving_ids.push_back(id);
    ++births;
  }
}

}  // namespace osc
