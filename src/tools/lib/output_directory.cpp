#include "online_stereo_calibration/tools/output_directory.h"

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace osc {

namespace {

std::string errnoText() { return std::strerror(errno); }

/// Writes all of @p data to @p fd; false on error (errno set).
bool writeAll(int fd, const std::string& data) {
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

void makeDirectories(const std::string& path) {
  std::string partial;
  for (size_t i = 0; i <= path.size(); ++i) {
    if ((i == path.size() || path[i] == '/') && !partial.empty()) mkdir(partial.c_str(), 0755);
    if (i < path.size()) partial += path[i];
  }
  struct stat st;
  if (stat(path.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    throw std::runtime_error("cannot create output directory '" + path + "'");
  }
}

std::string directoryOf(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

bool isRegularFile(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

void writeTextFileAtomic(const std::string& path, const std::string& text) {
  std::string temp = path + ".tmp.XXXXXX";
  std::vector<char> temp_buffer(temp.begin(), temp.end());
  temp_buffer.push_back('\0');
  const int fd = ::mkstemp(temp_buffer.data());
  if (fd < 0) throw std::runtime_error("cannot create a temporary file: " + errnoText());
  temp.assign(temp_buffer.data());

  std::string error;
  if (::fchmod(fd, 0644) != 0) {
    error = "chmod: " + errnoText();
  } else if (!writeAll(fd, text)) {
    error = "write: " + errnoText();
  } else if (::fsync(fd) != 0) {
    error = "fsync: " + errnoText();
  }
  if (::close(fd) != 0 && error.empty()) error = "close: " + errnoText();
  if (error.empty() && ::rename(temp.c_str(), path.c_str()) != 0) {
    error = "rename: " + errnoText();
  }
  if (!error.empty()) {
    ::unlink(temp.c_str());
    throw std::runtime_error(error + " (old file, if any, kept)");
  }

  // Make the rename itself durable. Failure here leaves a complete file in place.
  const int dir_fd = ::open(directoryOf(path).c_str(), O_RDONLY | O_DIRECTORY);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
}

}  // namespace osc
