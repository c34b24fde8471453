/// @file kitti_raw_drive.cpp
/// @brief readKittiRawDrive: a KITTI raw drive folder's timestamps, OXTS records and images,
/// the frames paired and sorted into usable and skipped; KittiRawDrive's summary. (The
/// calibration files: kitti_raw_calibration.cpp; the OXTS poses and motion: kitti_raw_oxts.cpp.)
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

#include "online_stereo_calibration/tools/output_directory.h"

#include "kitti_raw_drive_internal.h"

namespace osc {

using namespace kitti_raw_drive_internal;

namespace {

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

}  // namespace

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
