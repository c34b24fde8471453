/// @file motion_buffers.h
/// @brief Time-indexed buffers of vehicle poses (odometry) and angular rates (IMU) that
/// answer "the motion between two image stamps". Pure C++, no ROS: unit-tested without a
/// master.
#pragma once

#include <deque>
#include <string>

#include <Eigen/Geometry>

#include "online_stereo_calibration/ros/conversions.h"

namespace online_stereo_calibration {

/// Why a lookup gave no answer.
enum class LookupStatus {
  kOk,      ///< answered
  kNotYet,  ///< the stamp is newer than the newest sample: wait for more data
  kTooOld,  ///< the stamp is older than the oldest sample kept
  kGap,     ///< the bracketing samples are further apart than the allowed gap
  kEmpty,   ///< no sample at all yet
};

/// Human-readable name of a LookupStatus.
std::string lookupStatusName(LookupStatus status);

/// Vehicle poses in a fixed frame, sorted by stamp, interpolated at arbitrary stamps
/// (linear + SLERP). Not thread-safe.
class PoseBuffer {
 public:
  /// @param history seconds of samples kept behind the newest one.
  /// @param max_gap largest allowed time between two bracketing samples (s).
  PoseBuffer(double history, double max_gap) : history_(history), max_gap_(max_gap) {}

  /// Adds a sample. Returns false (sample ignored) if the pose is not finite or the stamp
  /// is not newer than the newest sample (duplicate or out of order).
  bool add(const StampedPose& sample);

  /// What offer() did with a sample.
  enum class Offered {
    kAdded,      ///< added to the history
    kRejected,   ///< not finite, or not newer than the newest but within max_gap of it
    kHeldBack,   ///< more than max_gap behind the newest: held, not used (see offer())
    kRestarted,  ///< time went back: the history is now the held-back samples
  };
  /// Consecutive held-back samples that make a new time line (offer()).
  static constexpr int kSamplesToRestart = 5;

  /// add() for a live topic whose time may jump back (a looped bag, a restarted player)
  /// while a single stale message (a second publisher, a late retransmission) must not wipe
  /// the history. A sample more than max_gap behind the newest is held back; it becomes
  /// history only with kSamplesToRestart - 1 more held-back samples, each newer than the one
  /// before and within max_gap of it. A sample added normally forgets the held ones.
  Offered offer(const StampedPose& sample);

  /// Starts a new time line (the images jumped back): the history becomes the samples held
  /// back so far (often the first odometry of the new time line), or empty.
  void restart();

  /// The pose at @p stamp, interpolated between the two samples bracketing it.
  LookupStatus poseAt(double stamp, Eigen::Isometry3d* pose) const;

  /// The covariance of the error of the motion increment between @p from and @p to, from
  /// the samples' twist covariances: each sample's twist error is taken as constant over its
  /// interval since the sample before and independent of the others', so an overlap of
  /// length l with [from, to] adds C l^2. False if a sample that overlaps has none (or the
  /// interval is not covered).
  bool incrementCovariance(double from, double to, Eigen::Matrix<double, 6, 6>* covariance) const;

  /// The twist at @p stamp, linear between the two samples bracketing it (a sample's own at
  /// its stamp). False if the stamp is not covered, the samples are further apart than
  /// max_gap, or either has no twist (StampedPose::has_twist).
  bool twistAt(double stamp, osc::Vector6d* twist) const;

  /// The newest sample, or nullptr.
  const StampedPose* newest() const { return samples_.empty() ? nullptr : &samples_.back(); }
  bool empty() const { return samples_.empty(); }
  double newestStamp() const { return samples_.empty() ? 0.0 : samples_.back().stamp; }

 private:
  double history_;
  double max_gap_;
  std::deque<StampedPose> samples_;
  std::deque<StampedPose> held_back_;  ///< offer(): a possible new time line
};

/// Angular rates (rad/s, vehicle frame) integrated into a rotation between two stamps,
/// each rate held constant until the next sample (zero-order hold). Not thread-safe.
class GyroIntegrator {
 public:
  GyroIntegrator(double history, double max_gap) : history_(history), max_gap_(max_gap) {}

  /// Adds a sample; false if not finite or not newer than the newest sample.
  bool add(double stamp, const Eigen::Vector3d& angular_rate);

  /// R_prev_curr: the rotation of the vehicle at @p to expressed in the vehicle frame at
  /// @p from (from < to).
  LookupStatus rotationBetween(double from, double to, Eigen::Matrix3d* rotation) const;

  void clear() { samples_.clear(); }

 private:
  struct Sample {
    double stamp;
    Eigen::Vector3d rate;
  };
  double history_;
  double max_gap_;
  std::deque<Sample> samples_;
};

}  // namespace online_stereo_calibration
