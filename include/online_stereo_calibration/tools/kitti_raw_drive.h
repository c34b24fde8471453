/// @file kitti_raw_drive.h
/// @brief A drive folder of the KITTI raw data (Geiger, Lenz, Stiller, Urtasun, IJRR 2013) in
/// the package's terms: the grey stereo pair image_00 (left) / image_01 (right), the vehicle
/// motion from the OXTS GPS/INS records, and KITTI's calibration chain as the reference.
///
/// The folder (KITTI's layout; docs/evaluation.md "evaluate on a KITTI raw drive"):
/// ```
/// image_00/data/NNNNNNNNNN.png  image_00/timestamps.txt    left grey camera
/// image_01/data/NNNNNNNNNN.png  image_01/timestamps.txt    right grey camera
/// oxts/data/NNNNNNNNNN.txt      oxts/timestamps.txt        one record of 30 values per file
/// calib_cam_to_cam.txt  calib_imu_to_velo.txt  calib_velo_to_cam.txt   (in the folder or,
///                                             as KITTI ships them, in the date folder above)
/// ```
/// - Vehicle frame = the OXTS/IMU frame (x forward, y left, z up), so the reference is
///   T_imu_cam0 = inv(T_velo_imu) * inv(T_cam0_velo) (camera 0's optical frame, turned to its
///   body frame) and x_camr from R_01, T_01 (x_1 = R_01 x_0 + T_01).
/// - Raw or rectified images, told apart by the size of the first left image: S_00 (raw:
///   K_0i, plumb_bob D_0i, the unrectified optical frames) or S_rect_00 (rectified: P_rect_0i
///   without distortion, the rectified frames: cam0's turned by R_rect_00, cam1's shifted by
///   P_rect_01's baseline).
/// - Synced or unsynced layout, told apart by the stamps: synced when oxts/timestamps.txt has
///   one stamp per image frame, each within half a frame period of its image's; unsynced (the
///   OXTS at its own rate and stamps) otherwise. Both are read the same way: the pose is
///   interpolated at each image stamp.
/// - OXTS records missing in oxts/data/ (a stamp without a file) are interpolated from the
///   nearest records on both sides when those are at most KittiRawOptions::max_oxts_gap apart;
///   a longer gap is left open, and frames in it are skipped.
/// - Frames are paired by index; a frame without both images, without both stamps, with
///   stamps further apart than max_stereo_skew or without OXTS records on both sides within
///   the gap limit is skipped and listed with the reason.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "online_stereo_calibration/core/estimator/types.h"
#include "online_stereo_calibration/core/geometry/camera_model.h"
#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/geometry/pose_interpolation.h"

namespace osc {

/// Where the vehicle positions come from; the rotation is always the OXTS roll, pitch, yaw.
enum class OxtsPositionSource {
  /// The OXTS velocity (ve, vn, vu: east, north, up) integrated from record to record
  /// (trapezoid), anchored at the first record's GPS position and again after every gap
  /// longer than max_oxts_gap. The default: the velocities are smooth, where the GPS positions
  /// jitter by 2-3 cm from record to record, ten times the motion noise the filter assumes per
  /// image pair (config/default.yaml motion_translation_noise_m).
  kIntegratedVelocity,
  /// lat, lon, alt in KITTI's local Mercator frame (devkit latToScale, latlonToMercator),
  /// as KITTI's own convertOxtsToPose.
  kGps,
};

/// "velocity" / "gps" (the --oxts-position values). @throws std::invalid_argument otherwise.
OxtsPositionSource oxtsPositionSourceFromName(const std::string& name);
std::string oxtsPositionSourceName(OxtsPositionSource source);

/// How a drive folder is read.
struct KittiRawOptions {
  /// Where the positions come from (OxtsPositionSource).
  OxtsPositionSource position = OxtsPositionSource::kIntegratedVelocity;
  /// s: missing OXTS records are interpolated, and frames placed, only between records at
  /// most this far apart. KITTI's OXTS runs at 100 Hz (10 ms; 0.1 s in the synced layout);
  /// over 0.5 s a car's turn rate changes enough for a straight-line interpolation of the
  /// heading to miss by tenths of a degree.
  double max_oxts_gap = 0.5;
  /// s: a frame whose left and right stamps lie further apart is skipped (KITTI triggers both
  /// cameras together; the stamps carry a few ms of reception jitter).
  double max_stereo_skew = 0.02;
};

/// ns since 1970 -> s, as ros::Time::toSec() computes it (whole seconds + 1e-9 * the rest), so
/// that a drive read here and its bag (kitti_raw_to_bag) carry the same double stamps.
inline double secondsFromNanoseconds(std::int64_t ns) {
  return static_cast<double>(ns / 1000000000) + 1e-9 * static_cast<double>(ns % 1000000000);
}

/// One OXTS record, fields in KITTI's order (dataformat.txt): lat, lon (deg), alt (m),
/// roll, pitch, yaw (rad; yaw 0 = east, counter-clockwise), vn, ve, vf, vl, vu (m/s), ax, ay,
/// az, af, al, au (m/s^2), wx, wy, wz, wf, wl, wu (rad/s), pos_accuracy, vel_accuracy, navstat,
/// numsats, posmode, velmode, orimode. (vf, vl, vu) are parallel and perpendicular to the
/// earth's surface, (wx, wy, wz) in the IMU frame.
struct OxtsRecord {
  int index = 0;              ///< the record's line in oxts/timestamps.txt
  std::int64_t stamp_ns = 0;  ///< ns since 1970 (UTC)
  std::array<double, 30> values{};
  bool interpolated = false;  ///< not in oxts/data/: interpolated from its neighbours

  double stamp() const { return secondsFromNanoseconds(stamp_ns); }
  /// R_world_imu = Rz(yaw) Ry(pitch) Rx(roll) (world: x east, y north, z up).
  Eigen::Matrix3d rotation() const;
  /// (ve, vn, vu): the velocity in the world frame (m/s).
  Eigen::Vector3d worldVelocity() const;
  /// The body twist [v, w] in the IMU frame: R^T (ve, vn, vu) and (wx, wy, wz).
  Vector6d bodyTwist() const;
};

/// Linear interpolation of two records at @p fraction in [0, 1]: angles along the shorter arc,
/// the status fields (navstat ... orimode) from @p a.
std::array<double, 30> interpolateOxts(const std::array<double, 30>& a,
                                       const std::array<double, 30>& b, double fraction);

/// KITTI devkit latToScale: the Mercator scale cos(lat) of the reference latitude (deg).
double mercatorScale(double latitude_deg);
/// KITTI devkit latlonToMercator (radius 6378137 m) and the altitude: (x east, y north, z up)
/// in m, metric near the latitude whose @p scale it is.
Eigen::Vector3d mercatorPosition(double latitude_deg, double longitude_deg, double altitude,
                                 double scale);

/// The IMU pose T_world_imu at each record (world: x east, y north, z up, origin at the first
/// record's position), records in stamp order. Consecutive records more than @p max_gap apart
/// start a new stretch: with kIntegratedVelocity its positions are anchored at its first
/// record's GPS position again. @throws std::invalid_argument if the stamps do not increase.
std::vector<StampedPose> oxtsPoses(const std::vector<OxtsRecord>& records,
                                   OxtsPositionSource source, double max_gap);

/// One usable stereo frame.
struct KittiRawFrame {
  int index = 0;                        ///< the frame's number in image_00/data (NNNNNNNNNN)
  std::int64_t stamp_ns = 0;            ///< the left image's stamp, ns since 1970 (UTC)
  std::string left_image, right_image;  ///< paths

  double stamp() const { return secondsFromNanoseconds(stamp_ns); }
};

/// A frame left out, and why.
struct KittiRawSkippedFrame {
  int index = 0;
  std::string reason;  ///< e.g. "no left image (image_00/data/0000000023.png)"
};

/// A drive folder, read.
struct KittiRawDrive {
  std::string folder;
  KittiRawOptions options;
  bool rectified = false;  ///< images rectified (P_rect, no distortion) rather than raw
  bool synced = false;     ///< KITTI's synced layout (one OXTS record per image frame)
  CameraIntrinsics left, right;
  /// The left optical frame in the vehicle (IMU) frame, and the right optical frame in the
  /// left one (KITTI's chain; the rectified frames for rectified images).
  Eigen::Isometry3d T_imu_lopt = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_lopt_ropt = Eigen::Isometry3d::Identity();
  /// Every record used, in index order: those in oxts/data/ and those interpolated.
  std::vector<OxtsRecord> oxts;
  int oxts_stamps = 0;        ///< lines of oxts/timestamps.txt
  int oxts_interpolated = 0;  ///< records of oxts that were interpolated
  /// T_world_imu at the OXTS records (oxtsPoses) and their body twists.
  PoseTrajectory imu_poses;
  std::vector<Vector6d> imu_twists;
  /// Stretches (from, to; s) between consecutive OXTS records further apart than
  /// options.max_oxts_gap: no motion is read across them.
  std::vector<std::pair<double, double>> oxts_gaps;
  std::vector<KittiRawFrame> frames;  ///< usable frames, in index order
  std::vector<KittiRawSkippedFrame> skipped;

  /// The reference in the interface's 12 parameters (StereoExtrinsics::fromOpticalFrames).
  Vector12d truth() const;
  /// The vehicle motion from @p from to @p to (s), read at those times: T_prev_curr in the
  /// IMU frame, dt, and the OXTS body twists at both ends (has_twists). Nothing if either
  /// time lies outside the records, to <= from, or a gap of the records lies in between.
  std::optional<MotionIncrement> motionBetween(double from, double to) const;
  /// The motion from usable frame k - 1 to frame k (k >= 1), read @p time_shift (s) earlier
  /// (MotionIncrement::time_shift).
  std::optional<MotionIncrement> motion(std::size_t k, double time_shift = 0.0) const;
  /// The body twist at @p stamp, interpolated between the records around it; false outside
  /// them or in a gap.
  bool twistAt(double stamp, Vector6d* twist) const;
  /// One line per skipped frame ("frame 23: no left image (...)").
  std::vector<std::string> skippedLines() const;
  /// What was read, in a few lines: layout, images, OXTS records (interpolated, gaps), frames.
  std::string summary() const;
};

/// `YYYY-MM-DD hh:mm:ss.fffffffff` (UTC, 0-9 decimals) -> ns since 1970.
/// @throws std::invalid_argument naming the text.
std::int64_t parseKittiTimestamp(const std::string& text);

/// Reads a drive folder. @throws std::runtime_error naming the file and what is wrong: a
/// missing or unreadable file, a calibration key missing or with too few numbers, a line of
/// a timestamps file or an OXTS record that does not parse, an OXTS file without a stamp,
/// an image of neither the raw nor the rectified size, no usable frame.
KittiRawDrive readKittiRawDrive(const std::string& folder,
                                const KittiRawOptions& options = KittiRawOptions());

}  // namespace osc
