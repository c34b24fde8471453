/// @file kitti_raw_drive.cpp
/// @brief readKittiRawDrive: KITTI's calibration files, timestamps, OXTS records and image
/// folders; the OXTS poses and the drive's motion and truth.
#include "online_stereo_calibration/tools/kitti_raw_drive.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include <Eigen/SVD>
#include <opencv2/imgcodecs.hpp>

#include "online_stereo_calibration/core/geometry/rotation.h"
#include "online_stereo_calibration/tools/output_directory.h"

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

std::string errorPrefix(const std::string& path) { return "KITTI raw: " + path + ": "; }

/// A KITTI calibration file: one `key: values` per line.
class CalibrationText {
 public:
  explicit CalibrationText(std::string path) : path_(std::move(path)) {
    std::ifstream in(path_);
    if (!in) throw std::runtime_error("KITTI raw: cannot open " + path_);
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      const auto colon = line.find(':');
      if (colon == std::string::npos) continue;
      entries_[line.substr(0, colon)] = {number, line.substr(colon + 1)};
    }
  }

  /// Exactly @p count numbers under @p key.
  std::vector<double> numbers(const std::string& key, std::size_t count) const {
    const auto found = entries_.find(key);
    if (found == entries_.end()) throw std::runtime_error(errorPrefix(path_) + "no " + key);
    std::istringstream fields(found->second.second);
    std::vector<double> values;
    double v = 0;
    while (fields >> v) values.push_back(v);
    const std::string where =
        errorPrefix(path_) + "line " + std::to_string(found->second.first) + ": " + key;
    if (!fields.eof())
      throw std::runtime_error(where + ": not a number after " + std::to_string(values.size()) +
                               " numbers");
    if (values.size() != count) {
      throw std::runtime_error(where + " has " + std::to_string(values.size()) +
                               " numbers, expected " + std::to_string(count));
    }
    for (double x : values) {
      if (!std::isfinite(x)) throw std::runtime_error(where + ": not finite");
    }
    return values;
  }

  /// x_to = R x_from + T of keys @p r_key (9, row-major) and @p t_key (3): T_to_from. R is
  /// projected onto the nearest rotation (the files print 7 digits).
  Eigen::Isometry3d transform(const std::string& r_key, const std::string& t_key) const {
    const std::vector<double> r = numbers(r_key, 9);
    const std::vector<double> t = numbers(t_key, 3);
    Eigen::Matrix3d R;
    R << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Matrix3d nearest = svd.matrixU() * svd.matrixV().transpose();
    if (!(nearest.determinant() > 0) || !(R - nearest).isZero(1e-4)) {
      throw std::runtime_error(errorPrefix(path_) + r_key + " is not a rotation matrix");
    }
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = nearest;
    T.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
    return T;
  }

  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::map<std::string, std::pair<int, std::string>> entries_;  ///< key -> (line, values)
};

/// @p name in @p folder, or in its parent (KITTI ships the calibration per day, beside the
/// drive folders).
std::string calibrationPath(const std::string& folder, const std::string& name) {
  for (const std::string& candidate : {folder + "/" + name, folder + "/../" + name}) {
    if (isRegularFile(candidate)) return candidate;
  }
  throw std::runtime_error("KITTI raw: cannot open " + folder + "/" + name + " (nor ../" + name +
                           ")");
}

/// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's days_from_civil).
std::int64_t daysFromCivil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const unsigned yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

std::vector<std::int64_t> readStamps(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("KITTI raw: cannot open " + path);
  std::vector<std::int64_t> stamps;
  std::string line;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) {
      // Only trailing blank lines are allowed: a blank line inside would shift the indices.
      stamps.push_back(-1);
      continue;
    }
    if (!stamps.empty() && stamps.back() == -1) {
      throw std::runtime_error(errorPrefix(path) + "line " + std::to_string(stamps.size()) +
                               ": empty");
    }
    try {
      stamps.push_back(parseKittiTimestamp(line));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(errorPrefix(path) + "line " + std::to_string(stamps.size() + 1) +
                               ": " + e.what());
    }
  }
  while (!stamps.empty() && stamps.back() == -1) stamps.pop_back();
  if (stamps.empty()) throw std::runtime_error(errorPrefix(path) + "no timestamps");
  return stamps;
}

std::string indexedName(const std::string& folder, int index, const char* extension) {
  char name[32];
  std::snprintf(name, sizeof name, "/%010d.%s", index, extension);
  return folder + name;
}

/// The records of oxts/data, by index; a file must parse to 30 numbers and have a stamp.
std::map<int, std::array<double, 30>> readOxtsFiles(const std::string& folder, std::size_t stamps) {
  const std::string data = folder + "/oxts/data";
  std::error_code error;
  std::filesystem::directory_iterator it(data, error);
  if (error) throw std::runtime_error("KITTI raw: cannot open " + data + ": " + error.message());
  std::map<int, std::array<double, 30>> records;
  for (const auto& entry : it) {
    const std::string name = entry.path().filename().string();
    if (name.size() != 14 || name.substr(10) != ".txt" ||
        name.find_first_not_of("0123456789") != 10) {
      continue;
    }
    const int index = std::stoi(name.substr(0, 10));
    const std::string path = data + "/" + name;
    if (static_cast<std::size_t>(index) >= stamps) {
      throw std::runtime_error(errorPrefix(path) + "no line " + std::to_string(index + 1) +
                               " in oxts/timestamps.txt (" + std::to_string(stamps) + " lines)");
    }
    std::ifstream in(path);
    if (!in) throw std::runtime_error("KITTI raw: cannot open " + path);
    std::array<double, 30> values{};
    for (std::size_t k = 0; k < values.size(); ++k) {
      if (!(in >> values[k]) || !std::isfinite(values[k])) {
        throw std::runtime_error(errorPrefix(path) + "expected 30 numbers, read " +
                                 std::to_string(k));
      }
    }
    records[index] = values;
  }
  if (records.empty()) throw std::runtime_error(errorPrefix(data) + "no records");
  return records;
}

/// Records in index order: every file, and the missing ones between two files at most
/// @p max_gap apart, interpolated.
std::vector<OxtsRecord> oxtsRecords(const std::map<int, std::array<double, 30>>& files,
                                    const std::vector<std::int64_t>& stamps, double max_gap,
                                    int* interpolated) {
  std::vector<OxtsRecord> records;
  *interpolated = 0;
  for (auto it = files.begin(); it != files.end(); ++it) {
    OxtsRecord r;
    r.index = it->first;
    r.stamp_ns = stamps[static_cast<std::size_t>(it->first)];
    r.values = it->second;
    records.push_back(r);
    const auto next = std::next(it);
    if (next == files.end()) break;
    const std::int64_t t0 = stamps[static_cast<std::size_t>(it->first)];
    const std::int64_t t1 = stamps[static_cast<std::size_t>(next->first)];
    if (1e-9 * static_cast<double>(t1 - t0) > max_gap) continue;
    for (int index = it->first + 1; index < next->first; ++index) {
      OxtsRecord m;
      m.index = index;
      m.stamp_ns = stamps[static_cast<std::size_t>(index)];
      m.values =
          interpolateOxts(it->second, next->second,
                          static_cast<double>(m.stamp_ns - t0) / static_cast<double>(t1 - t0));
      m.interpolated = true;
      records.push_back(m);
      ++*interpolated;
    }
  }
  return records;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? 0.0 : values[values.size() / 2];
}

std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

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

Vector12d KittiRawDrive::truth() const {
  return StereoExtrinsics::fromOpticalFrames(T_imu_lopt, T_lopt_ropt).toParameters();
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

std::vector<std::string> KittiRawDrive::skippedLines() const {
  std::vector<std::string> lines;
  for (const KittiRawSkippedFrame& s : skipped) {
    lines.push_back("frame " + std::to_string(s.index) + ": " + s.reason);
  }
  return lines;
}

std::string KittiRawDrive::summary() const {
  std::ostringstream text;
  text << "KITTI raw drive " << folder << ": " << (synced ? "synced" : "unsynced") << " layout, "
       << (rectified ? "rectified" : "raw") << " images " << left.width << "x" << left.height
       << (rectified ? " (no distortion)" : " (plumb_bob)") << "\n";
  text << "  OXTS: " << oxts_stamps << " stamps, " << oxts.size() - oxts_interpolated
       << " records in oxts/data, " << oxts_interpolated << " interpolated, " << oxts_gaps.size()
       << " gaps longer than " << options.max_oxts_gap << " s left open; positions from "
       << (options.position == OxtsPositionSource::kGps ? "GPS (Mercator)"
                                                        : "the integrated velocity")
       << "\n";
  text << "  frames: " << frames.size() << " usable, " << skipped.size() << " skipped";
  for (std::size_t i = 0; i < skipped.size(); ++i) {
    text << (i == 0 ? " (" : ", ") << skipped[i].index << (i + 1 == skipped.size() ? ")" : "");
  }
  text << "\n";
  return text.str();
}

std::int64_t parseKittiTimestamp(const std::string& text) {
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0, consumed = 0;
  const bool parsed = std::sscanf(text.c_str(), "%4d-%2d-%2d %2d:%2d:%2d%n", &year, &month, &day,
                                  &hour, &minute, &second, &consumed) == 6;
  if (!parsed || month < 1 || month > 12 || day < 1 || day > 31 || hour > 23 || minute > 59 ||
      second > 60 || hour < 0 || minute < 0 || second < 0) {
    throw std::invalid_argument("not a time 'YYYY-MM-DD hh:mm:ss.nnnnnnnnn': '" + text + "'");
  }
  std::int64_t nanoseconds = 0;
  std::size_t pos = static_cast<std::size_t>(consumed);
  if (pos < text.size() && text[pos] == '.') {
    int digits = 0;
    for (++pos; pos < text.size() && std::isdigit(static_cast<unsigned char>(text[pos])); ++pos) {
      if (++digits > 9) {
        throw std::invalid_argument("more than 9 decimals of a second: '" + text + "'");
      }
      nanoseconds = nanoseconds * 10 + (text[pos] - '0');
    }
    for (; digits < 9; ++digits) nanoseconds *= 10;
  }
  if (text.find_first_not_of(" \t\r", pos) != std::string::npos) {
    throw std::invalid_argument("not a time 'YYYY-MM-DD hh:mm:ss.nnnnnnnnn': '" + text + "'");
  }
  const std::int64_t seconds =
      daysFromCivil(year, static_cast<unsigned>(month), static_cast<unsigned>(day)) * 86400 +
      hour * 3600 + minute * 60 + second;
  return seconds * 1000000000 + nanoseconds;
}

namespace {

/// The calibration: intrinsics and the chain T_imu_lopt, T_lopt_ropt, for raw or rectified
/// images told apart by the size of the first left image.
void readCalibration(const std::string& folder, const std::string& first_left_image,
                     KittiRawDrive* drive) {
  const CalibrationText cam(calibrationPath(folder, "calib_cam_to_cam.txt"));
  const CalibrationText imu_velo(calibrationPath(folder, "calib_imu_to_velo.txt"));
  const CalibrationText velo_cam(calibrationPath(folder, "calib_velo_to_cam.txt"));
  const Eigen::Isometry3d T_imu_cam0 =
      imu_velo.transform("R", "T").inverse() * velo_cam.transform("R", "T").inverse();

  const cv::Mat image = cv::imread(first_left_image, cv::IMREAD_UNCHANGED);
  if (image.empty()) throw std::runtime_error("KITTI raw: cannot read " + first_left_image);
  const std::vector<double> raw_size = cam.numbers("S_00", 2);
  const std::vector<double> rect_size = cam.numbers("S_rect_00", 2);
  const auto is = [&](const std::vector<double>& size) {
    return image.cols == static_cast<int>(std::lround(size[0])) &&
           image.rows == static_cast<int>(std::lround(size[1]));
  };
  if (is(raw_size) == is(rect_size)) {
    throw std::runtime_error("KITTI raw: " + first_left_image + " is " +
                             std::to_string(image.cols) + "x" + std::to_string(image.rows) + ": " +
                             (is(raw_size) ? "both" : "neither") + " the raw size S_00 (" +
                             fixed(raw_size[0], 0) + "x" + fixed(raw_size[1], 0) +
                             ") and the rectified size S_rect_00 (" + fixed(rect_size[0], 0) + "x" +
                             fixed(rect_size[1], 0) + ") of " + cam.path());
  }
  drive->rectified = is(rect_size);

  if (!drive->rectified) {
    for (int side = 0; side < 2; ++side) {
      const std::string i = side == 0 ? "00" : "01";
      const std::vector<double> K = cam.numbers("K_" + i, 9);
      const std::vector<double> S = cam.numbers("S_" + i, 2);
      if (K[1] != 0.0 || K[3] != 0.0 || K[6] != 0.0 || K[7] != 0.0 || K[8] != 1.0) {
        throw std::runtime_error(errorPrefix(cam.path()) + "K_" + i +
                                 " is not [fx 0 cx; 0 fy cy; 0 0 1]");
      }
      CameraIntrinsics& c = side == 0 ? drive->left : drive->right;
      c.width = static_cast<int>(std::lround(S[0]));
      c.height = static_cast<int>(std::lround(S[1]));
      c.fx = K[0];
      c.cx = K[2];
      c.fy = K[4];
      c.cy = K[5];
      c.model = DistortionModel::kPlumbBob;
      c.distortion = cam.numbers("D_" + i, 5);  // k1 k2 p1 p2 k3
    }
    // Camera 0 is the left camera; x_1 = R_01 x_0 + T_01.
    drive->T_imu_lopt = T_imu_cam0;
    drive->T_lopt_ropt = cam.transform("R_01", "T_01").inverse();
    return;
  }
  // Rectified: x_rect0 = R_rect_00 x_cam0; P_rect_0i = K_rect [I | t_i] projects rect0
  // coordinates, so camera i's rectified frame is rect0 shifted by t_i (x_i = x_rect0 + t_i).
  Eigen::Vector3d t[2];
  for (int side = 0; side < 2; ++side) {
    const std::string i = side == 0 ? "00" : "01";
    const std::vector<double> P = cam.numbers("P_rect_" + i, 12);
    const std::vector<double> S = cam.numbers("S_rect_" + i, 2);
    Eigen::Matrix3d K;
    K << P[0], P[1], P[2], P[4], P[5], P[6], P[8], P[9], P[10];
    if (K(0, 1) != 0.0 || K(1, 0) != 0.0 || K(2, 0) != 0.0 || K(2, 1) != 0.0 || K(2, 2) != 1.0) {
      throw std::runtime_error(errorPrefix(cam.path()) + "P_rect_" + i +
                               " is not [fx 0 cx tx; 0 fy cy ty; 0 0 1 tz]");
    }
    t[side] = K.inverse() * Eigen::Vector3d(P[3], P[7], P[11]);
    CameraIntrinsics& c = side == 0 ? drive->left : drive->right;
    c.width = static_cast<int>(std::lround(S[0]));
    c.height = static_cast<int>(std::lround(S[1]));
    c.fx = K(0, 0);
    c.cx = K(0, 2);
    c.fy = K(1, 1);
    c.cy = K(1, 2);
    c.model = DistortionModel::kNone;
    c.distortion.clear();
  }
  const std::vector<double> r = cam.numbers("R_rect_00", 9);
  Eigen::Matrix3d R_rect;
  R_rect << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R_rect, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Isometry3d T_cam0_rect0 = Eigen::Isometry3d::Identity();
  T_cam0_rect0.linear() = (svd.matrixU() * svd.matrixV().transpose()).transpose();
  Eigen::Isometry3d T_rect0_lopt = Eigen::Isometry3d::Identity();
  T_rect0_lopt.translation() = -t[0];
  drive->T_imu_lopt = T_imu_cam0 * T_cam0_rect0 * T_rect0_lopt;
  drive->T_lopt_ropt = Eigen::Isometry3d::Identity();
  drive->T_lopt_ropt.translation() = t[0] - t[1];
}

/// Why the OXTS records cannot give a pose at @p stamp, or "".
std::string oxtsCoverageProblem(const KittiRawDrive& drive, double stamp) {
  const std::vector<StampedPose>& poses = drive.imu_poses.poses();
  if (stamp < poses.front().stamp) {
    return "before the first OXTS record (" + fixed(poses.front().stamp - stamp, 3) + " s later)";
  }
  if (stamp > poses.back().stamp) {
    return "after the last OXTS record (" + fixed(stamp - poses.back().stamp, 3) + " s earlier)";
  }
  for (const auto& [gap_start, gap_end] : drive.oxts_gaps) {
    if (stamp > gap_start && stamp < gap_end) {
      return "in a " + fixed(gap_end - gap_start, 3) + " s gap of the OXTS records (limit " +
             fixed(drive.options.max_oxts_gap, 3) + " s)";
    }
  }
  return "";
}

/// Pairs the frames by index and sorts them into usable and skipped.
void pairFrames(const std::string& folder, const std::vector<std::int64_t>& left_stamps,
                const std::vector<std::int64_t>& right_stamps, KittiRawDrive* drive) {
  const std::size_t count = std::max(left_stamps.size(), right_stamps.size());
  for (std::size_t i = 0; i < count; ++i) {
    const int index = static_cast<int>(i);
    KittiRawFrame frame;
    frame.index = index;
    frame.left_image = indexedName(folder + "/image_00/data", index, "png");
    frame.right_image = indexedName(folder + "/image_01/data", index, "png");
    std::string reason;
    const bool left = isRegularFile(frame.left_image), right = isRegularFile(frame.right_image);
    if (i >= left_stamps.size() || i >= right_stamps.size()) {
      reason = std::string("no line ") + std::to_string(i + 1) + " in image_0" +
               (i >= left_stamps.size() ? "0" : "1") + "/timestamps.txt";
    } else if (!left || !right) {
      reason = std::string("no ") +
               (!left && !right ? "left or right"
                : !left         ? "left"
                                : "right") +
               " image (" + (!left ? frame.left_image : frame.right_image) + ")";
    } else if (std::abs(1e-9 * static_cast<double>(left_stamps[i] - right_stamps[i])) >
               drive->options.max_stereo_skew) {
      reason = "left and right stamps " +
               fixed(1e-6 * static_cast<double>(left_stamps[i] - right_stamps[i]), 1) +
               " ms apart (limit " + fixed(1e3 * drive->options.max_stereo_skew, 1) + " ms)";
    } else if (!drive->frames.empty() && left_stamps[i] <= drive->frames.back().stamp_ns) {
      reason = "stamp not after frame " + std::to_string(drive->frames.back().index) + "'s";
    } else {
      frame.stamp_ns = left_stamps[i];
      reason = oxtsCoverageProblem(*drive, frame.stamp());
    }
    if (reason.empty()) {
      drive->frames.push_back(frame);
    } else {
      drive->skipped.push_back({index, reason});
    }
  }
}

}  // namespace

KittiRawDrive readKittiRawDrive(const std::string& folder, const KittiRawOptions& options) {
  if (!(options.max_oxts_gap > 0) || !(options.max_stereo_skew >= 0)) {
    throw std::invalid_argument("KITTI raw: max_oxts_gap must be > 0, max_stereo_skew >= 0");
  }
  KittiRawDrive drive;
  drive.folder = folder;
  drive.options = options;
  const std::vector<std::int64_t> left_stamps = readStamps(folder + "/image_00/timestamps.txt");
  const std::vector<std::int64_t> right_stamps = readStamps(folder + "/image_01/timestamps.txt");
  const std::string oxts_stamps_path = folder + "/oxts/timestamps.txt";
  const std::vector<std::int64_t> oxts_stamps = readStamps(oxts_stamps_path);
  for (std::size_t i = 1; i < oxts_stamps.size(); ++i) {
    if (oxts_stamps[i] <= oxts_stamps[i - 1]) {
      throw std::runtime_error(errorPrefix(oxts_stamps_path) + "line " + std::to_string(i + 1) +
                               ": not after the line before");
    }
  }
  drive.oxts_stamps = static_cast<int>(oxts_stamps.size());

  // Synced: one OXTS stamp per image frame, each within half a frame period of its image's.
  std::vector<double> periods;
  for (std::size_t i = 1; i < left_stamps.size(); ++i) {
    periods.push_back(1e-9 * static_cast<double>(left_stamps[i] - left_stamps[i - 1]));
  }
  const double half_period = 0.5 * median(periods);
  drive.synced = oxts_stamps.size() == left_stamps.size() && half_period > 0;
  for (std::size_t i = 0; drive.synced && i < oxts_stamps.size(); ++i) {
    drive.synced =
        std::abs(1e-9 * static_cast<double>(oxts_stamps[i] - left_stamps[i])) < half_period;
  }

  // The first left image on disk tells raw from rectified.
  std::string first_left;
  for (std::size_t i = 0; i < left_stamps.size() && first_left.empty(); ++i) {
    const std::string path = indexedName(folder + "/image_00/data", static_cast<int>(i), "png");
    if (isRegularFile(path)) first_left = path;
  }
  if (first_left.empty()) {
    throw std::runtime_error("KITTI raw: " + folder + "/image_00/data: no image of the " +
                             std::to_string(left_stamps.size()) + " stamps");
  }
  readCalibration(folder, first_left, &drive);

  drive.oxts = oxtsRecords(readOxtsFiles(folder, oxts_stamps.size()), oxts_stamps,
                           options.max_oxts_gap, &drive.oxts_interpolated);
  for (std::size_t i = 1; i < drive.oxts.size(); ++i) {
    const double a = drive.oxts[i - 1].stamp(), b = drive.oxts[i].stamp();
    if (b - a > options.max_oxts_gap) drive.oxts_gaps.emplace_back(a, b);
  }
  drive.imu_poses = PoseTrajectory(oxtsPoses(drive.oxts, options.position, options.max_oxts_gap));
  for (const OxtsRecord& r : drive.oxts) drive.imu_twists.push_back(r.bodyTwist());

  pairFrames(folder, left_stamps, right_stamps, &drive);
  if (drive.frames.empty()) {
    throw std::runtime_error("KITTI raw: " + folder + ": no usable frame of " +
                             std::to_string(drive.skipped.size()) +
                             " (first: " + drive.skippedLines().front() + ")");
  }
  return drive;
}

}  // namespace osc
