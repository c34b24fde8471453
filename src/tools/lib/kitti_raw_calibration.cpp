/// @file kitti_raw_calibration.cpp
/// @brief The KITTI raw reader's calibration: calib_cam_to_cam.txt, calib_imu_to_velo.txt and
/// calib_velo_to_cam.txt into the intrinsics and the chain T_imu_lopt, T_lopt_ropt (raw or
/// rectified images), and KittiRawDrive::truth().
#include "online_stereo_calibration/tools/kitti_raw_drive.h"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/SVD>
#include <opencv2/imgcodecs.hpp>

#include "online_stereo_calibration/tools/output_directory.h"

#include "kitti_raw_drive_internal.h"

namespace osc {
namespace kitti_raw_drive_internal {
namespace {

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

}  // namespace

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

}  // namespace kitti_raw_drive_internal

Vector12d KittiRawDrive::truth() const {
  return StereoExtrinsics::fromOpticalFrames(T_imu_lopt, T_lopt_ropt).toParameters();
}

}  // namespace osc
