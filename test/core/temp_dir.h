/// @file temp_dir.h
/// @brief A fresh directory under /tmp for one test, removed with everything in it at the end
/// (shared by the tests that write files: test_calibration_file, test_estimates_csv_and_evaluation,
/// test_scenario_file_and_drive_simulation, test_campaign, test_campaign_ranges_and_draw,
/// test_kitti_raw_drive).
#pragma once

#include <dirent.h>
#include <stdlib.h>
#include <sys/stat.h>

#include <filesystem>
#include <set>
#include <stdexcept>
#include <string>

namespace osc {

class TempDir {
 public:
  /// @p prefix names the test in the directory's name (/tmp/osc_PREFIX_XXXXXX).
  explicit TempDir(const std::string& prefix = "test") {
    std::string name = "/tmp/osc_" + prefix + "_XXXXXX";
    if (::mkdtemp(name.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = name;
  }
  ~TempDir() {
    ::chmod(path_.c_str(), 0755);  // a test may have made it read-only
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  /// Names in the directory, without "." and "..".
  std::set<std::string> entries() const {
    std::set<std::string> names;
    if (DIR* dir = ::opendir(path_.c_str())) {
      while (const dirent* entry = ::readdir(dir)) {
        const std::string name = entry->d_name;
        if (name != "." && name != "..") names.insert(name);
      }
      ::closedir(dir);
    }
    return names;
  }

 private:
  std::string path_;
};

}  // namespace osc
