/// @file tool_test_helpers.h
/// @brief For tests that run the built tools (evaluate, simulate, kitti_raw_to_bag): where a
/// tool is, and a file's text.
#pragma once

#include <unistd.h>

#include <fstream>
#include <sstream>
#include <string>

namespace osc_test {

/// Directory of the running test binary (catkin puts the executables next to it).
inline std::string executableDirectory() {
  char buffer[4096];
  const ssize_t n = readlink("/proc/self/exe", buffer, sizeof buffer - 1);
  if (n <= 0) return ".";
  const std::string path(buffer, static_cast<std::size_t>(n));
  return path.substr(0, path.find_last_of('/'));
}

/// Path of a built tool: next to the test binary or in the catkin devel lib folder; "" if none.
inline std::string findTool(const std::string& name) {
  const std::string dir = executableDirectory();
  for (const std::string& c : {dir + "/" + name, dir + "/../lib/online_stereo_calibration/" + name,
                               dir + "/devel/lib/online_stereo_calibration/" + name,
                               dir + "/../devel/lib/online_stereo_calibration/" + name}) {
    if (access(c.c_str(), X_OK) == 0) return c;
  }
  return "";
}

/// The whole text of a file ("" if it cannot be read).
inline std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace osc_test
