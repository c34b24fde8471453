#include "online_stereo_calibration/tools/package_files.h"
#include "online_stereo_calibration/tools/output_directory.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#ifndef OSC_PACKAGE_SOURCE_DIR
#define OSC_PACKAGE_SOURCE_DIR "."
#endif

namespace osc {

namespace {

constexpr const char* kPackage = "online_stereo_calibration";

std::string baseName(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

bool isThisPackage(const std::string& dir) {
  std::ifstream in(dir + "/package.xml");
  if (!in) return false;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str().find(std::string("<name>") + kPackage + "</name>") != std::string::npos;
}

std::string executableDirectory() {
  char buffer[4096];
  const ssize_t n = readlink("/proc/self/exe", buffer, sizeof(buffer) - 1);
  if (n <= 0) return "";
  return directoryOf(std::string(buffer, static_cast<size_t>(n)));
}

}  // namespace

std::string findPackageFile(const std::string& relative_path, const char* environment_variable) {
  std::vector<std::string> candidates;
  if (environment_variable) {
    if (const char* env = std::getenv(environment_variable)) candidates.push_back(env);
  }
  if (const char* path = std::getenv("ROS_PACKAGE_PATH")) {
    std::istringstream entries(path);
    std::string entry;
    while (std::getline(entries, entry, ':')) {
      if (entry.empty()) continue;
      if (isThisPackage(entry)) candidates.push_back(entry + "/" + relative_path);
      candidates.push_back(entry + "/" + kPackage + "/" + relative_path);
    }
  }
  const std::string exe = executableDirectory();
  if (!exe.empty()) {
    candidates.push_back(exe + "/" + baseName(relative_path));
    candidates.push_back(exe + "/../../share/" + kPackage + "/" + relative_path);
  }
  candidates.push_back(relative_path);
  candidates.push_back(std::string(OSC_PACKAGE_SOURCE_DIR) + "/" + relative_path);
  for (const std::string& c : candidates) {
    if (isRegularFile(c)) return c;
  }
  return "";
}

}  // namespace osc
