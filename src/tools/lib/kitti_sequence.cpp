/// @file kitti_sequence.cpp
/// @brief readKittiSequence and the sequence's truth and motion.
#include "online_stereo_calibration/tools/kitti_sequence.h"

#include <algorithm>
#include <array>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

namespace osc {
namespace {

/// The 3x4 row-major matrices of a text file, one per non-empty line.
std::vector<std::array<double, 12>> readMatrices(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("KITTI: cannot open " + path);
  std::vector<std::array<double, 12>> rows;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream fields(line);
    std::array<double, 12> m{};
    for (double& v : m) {
      if (!(fields >> v)) {
        throw std::runtime_error("KITTI: " + path + " line " + std::to_string(number) +
                                 ": expected 12 numbers (a 3x4 matrix)");
      }
    }
    rows.push_back(m);
  }
  return rows;
}

}  // namespace

std::vector<std::string> sortedPngs(const std::string& folder) {
  std::vector<cv::String> files;
  cv::glob(folder + "/*.png", files, false);
  std::vector<std::string> out(files.begin(), files.end());
  std::sort(out.begin(), out.end());
  return out;
}

Vector12d KittiSequence::truth() const {
  Vector12d p = Vector12d::Zero();
  p(7) = -baseline;
  return p;
}

MotionIncrement KittiSequence::motion(int k) const {
  const Eigen::Isometry3d T_lopt_body = bodyFromOptical().inverse();
  MotionIncrement m;
  m.T_prev_curr = (T_first_lopt.at(static_cast<size_t>(k - 1)) * T_lopt_body).inverse() *
                  (T_first_lopt.at(static_cast<size_t>(k)) * T_lopt_body);
  m.dt = frame_interval;
  return m;
}

KittiSequence readKittiSequence(const std::string& folder) {
  KittiSequence s;
  const std::vector<std::array<double, 12>> P = readMatrices(folder + "/calib.txt");
  if (P.size() < 2) throw std::runtime_error("KITTI: " + folder + "/calib.txt needs P0 and P1");
  for (const std::array<double, 12>& m : readMatrices(folder + "/poses.txt")) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) T.matrix()(r, c) = m[static_cast<size_t>(4 * r + c)];
    }
    s.T_first_lopt.push_back(T);
  }
  s.left_images = sortedPngs(folder + "/image_l");
  s.right_images = sortedPngs(folder + "/image_r");
  if (s.left_images.size() != s.T_first_lopt.size() ||
      s.right_images.size() != s.T_first_lopt.size()) {
    throw std::runtime_error("KITTI: " + folder + ": " + std::to_string(s.left_images.size()) +
                             " left and " + std::to_string(s.right_images.size()) +
                             " right images for " + std::to_string(s.T_first_lopt.size()) +
                             " poses");
  }
  const cv::Mat first = cv::imread(s.left_images.front(), cv::IMREAD_GRAYSCALE);
  if (first.empty()) throw std::runtime_error("KITTI: cannot read " + s.left_images.front());
  for (int side = 0; side < 2; ++side) {
    const std::array<double, 12>& p = P[static_cast<size_t>(side)];
    CameraIntrinsics& c = side == 0 ? s.left : s.right;
    c.width = first.cols;
    c.height = first.rows;
    c.fx = p[0];
    c.fy = p[5];
    c.cx = p[2];
    c.cy = p[6];
    c.model = DistortionModel::kNone;
  }
  s.baseline = -P[1][3] / P[1][0];
  return s;
}

}  // namespace osc
