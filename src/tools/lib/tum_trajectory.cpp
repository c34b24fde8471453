/// @file tum_trajectory.cpp
/// @brief Reader and writer of TUM trajectory files (see tum_trajectory.h).
#include "online_stereo_calibration/tools/tum_trajectory.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace osc {

PoseTrajectory readTumTrajectory(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open TUM trajectory '" + path + "'");
  PoseTrajectory trajectory;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    double v[8];
    for (double& x : v) {
      if (!(fields >> x) || !std::isfinite(x)) {
        throw std::runtime_error(path + ":" + std::to_string(number) +
                                 ": expected 8 numbers 't x y z qx qy qz qw'");
      }
    }
    std::string extra;
    if (fields >> extra) {
      throw std::runtime_error(path + ":" + std::to_string(number) + ": more than 8 fields");
    }
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (q.norm() < 1e-9) {
      throw std::runtime_error(path + ":" + std::to_string(number) + ": zero quaternion");
    }
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = q.normalized().toRotationMatrix();
    pose.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    if (!trajectory.empty() && !(v[0] > trajectory.lastStamp())) {
      throw std::runtime_error(path + ":" + std::to_string(number) + ": stamp not increasing");
    }
    trajectory.append(v[0], pose);
  }
  if (trajectory.size() < 2) throw std::runtime_error(path + ": fewer than 2 poses");
  return trajectory;
}

std::string formatTumTrajectory(const std::vector<StampedPose>& poses, const std::string& comment) {
  std::ostringstream out;
  std::istringstream lines(comment);
  std::string line;
  while (std::getline(lines, line)) out << "# " << line << "\n";
  for (const StampedPose& p : poses) {
    const Eigen::Quaterniond q(p.pose.linear());
    const Eigen::Vector3d& t = p.pose.translation();
    char text[256];
    std::snprintf(text, sizeof text, "%.9f %.4f %.4f %.4f %.9f %.9f %.9f %.9f\n", p.stamp, t.x(),
                  t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
    out << text;
  }
  return out.str();
}

}  // namespace osc
