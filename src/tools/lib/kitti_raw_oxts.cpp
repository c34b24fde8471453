/// @file kitti_raw_oxts.cpp
/// @brief The KITTI raw reader's motion: OXTS records (fields, interpolation), their poses
/// (Mercator GPS or the integrated velocity) and the drive's motion and twists between stamps.
#include "online_stereo_calibration/tools/kitti_raw_drive.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "online_stereo_calibration/core/geometry/rotation.h"

namespace osc {
namespace {

constexpr double kEarthRadius = 6378137.0;  ///< m, KITTI devkit latlonToMercator
constexpr double kDeg = M_PI / 180.0;

/// Field positions in an OXTS record.
enum OxtsField {
  kLat = 0,
  kLon = 1,
  kAlt = 2,
  kRoll = 3,
  kPitch = 4,
  kYaw = 5,
  kVn = 6,
  kVe = 7,
  kVu = 10,
  kWx = 17,
  kNavstat = 25
};

}  // namespace

OxtsPositionSource oxtsPositionSourceFromName(const std::string& name) {
  if (name == "velocity") return OxtsPositionSource::kIntegratedVelocity;
  if (name == "gps") return OxtsPositionSource::kGps;
  throw std::invalid_argument("unknown OXTS position source '" + name + "' (velocity or gps)");
}

std::string oxtsPositionSourceName(OxtsPositionSource source) {
  return source == OxtsPositionSource::kGps ? "gps" : "velocity";
}

Eigen::Matrix3d OxtsRecord::rotation() const {
  return rotationFromRpy(Eigen::Vector3d(values[kRoll], values[kPitch], values[kYaw]));
}

Eigen::Vector3d OxtsRecord::worldVelocity() const {
  return Eigen::Vector3d(values[kVe], values[kVn], values[kVu]);
}

Vector6d OxtsRecord::bodyTwist() const {
  Vector6d twist;
  twist.head<3>() = rotation().transpose() * worldVelocity();
  twist.tail<3>() = Eigen::Vector3d(values[kWx], values[kWx + 1], values[kWx + 2]);
  return twist;
}

std::array<double, 30> interpolateOxts(const std::array<double, 30>& a,
                                       const std::array<double, 30>& b, double fraction) {
  std::array<double, 30> out = a;
  for (int k = 0; k < kNavstat; ++k) {
    double difference = b[k] - a[k];
    if (k == kRoll || k == kPitch || k == kYaw) difference = wrapAngle(difference);
    out[k] = a[k] + fraction * difference;
    if (k == kRoll || k == kPitch || k == kYaw) out[k] = wrapAngle(out[k]);
  }
  return out;
}

double mercatorScale(double latitude_deg) { return std::cos(latitude_deg * kDeg); }

Eigen::Vector3d mercatorPosition(double latitude_deg, double longitude_deg, double altitude,
                                 double scale) {
  return Eigen::Vector3d(
      scale * kEarthRadius * longitude_deg * kDeg,
      scale * kEarthRadius * std::log(std::tan(M_PI / 4 + latitude_deg * kDeg / 2)), altitude);
}

std::vector<StampedPose> oxtsPoses(const std::vector<OxtsRecord>& records,
                                   OxtsPositionSource source, double max_gap) {
  std::vector<StampedPose> poses;
  if (records.empty()) return poses;
  const double scale = mercatorScale(records.front().values[kLat]);
  const auto gps = [&](const OxtsRecord& r) {
    return mercatorPosition(r.values[kLat], r.values[kLon], r.values[kAlt], scale);
  };
  const Eigen::Vector3d origin = gps(records.front());
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < records.size(); ++i) {
    const OxtsRecord& r = records[i];
    if (i > 0) {
      const OxtsRecord& previous = records[i - 1];
      const double dt = r.stamp() - previous.stamp();
      if (!(r.stamp_ns > previous.stamp_ns)) {
        throw std::invalid_argument("OXTS record " + std::to_string(r.index) +
                                    ": stamp not after record " + std::to_string(previous.index) +
                                    "'s");
      }
      if (source == OxtsPositionSource::kGps || dt > max_gap) {
        position = gps(r) - origin;
      } else {
        position += 0.5 * dt * (previous.worldVelocity() + r.worldVelocity());
      }
    }
    StampedPose pose;
    pose.stamp = r.stamp();
    pose.pose.linear() = r.rotation();
    pose.pose.translation() = position;
    poses.push_back(pose);
  }
  return poses;
}

std::optional<MotionIncrement> KittiRawDrive::motionBetween(double from, double to) const {
  if (!(to > from)) return std::nullopt;
  for (const auto& [gap_start, gap_end] : oxts_gaps) {
    if (gap_start < to && gap_end > from) return std::nullopt;
  }
  std::optional<MotionIncrement> motion = imu_poses.motionBetween(from, to);
  if (!motion) return std::nullopt;
  motion->has_twists = twistAt(from, &motion->twist_start) && twistAt(to, &motion->twist_end);
  return motion;
}

std::optional<MotionIncrement> KittiRawDrive::motion(std::size_t k, double time_shift) const {
  if (k == 0 || k >= frames.size()) return std::nullopt;
  std::optional<MotionIncrement> m =
      motionBetween(frames[k - 1].stamp() - time_shift, frames[k].stamp() - time_shift);
  if (m) m->time_shift = time_shift;
  return m;
}

bool KittiRawDrive::twistAt(double stamp, Vector6d* twist) const {
  const std::vector<StampedPose>& poses = imu_poses.poses();
  if (poses.empty() || !(stamp >= poses.front().stamp && stamp <= poses.back().stamp)) {
    return false;
  }
  const auto after = std::lower_bound(poses.begin(), poses.end(), stamp,
                                      [](const StampedPose& p, double t) { return p.stamp < t; });
  const std::size_t j = static_cast<std::size_t>(after - poses.begin());
  if (after->stamp == stamp) {
    *twist = imu_twists[j];
    return true;
  }
  const double span = poses[j].stamp - poses[j - 1].stamp;
  if (span > options.max_oxts_gap) return false;
  const double s = (stamp - poses[j - 1].stamp) / span;
  *twist = (1.0 - s) * imu_twists[j - 1] + s * imu_twists[j];
  return true;
}

}  // namespace osc
