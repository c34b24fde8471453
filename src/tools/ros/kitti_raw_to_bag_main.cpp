/// @file kitti_raw_to_bag_main.cpp
/// @brief Writes a KITTI raw drive folder (tools/kitti_raw_drive.h) into a bag with the
/// interface's topics, for `rosbag play` and the nodelet, or `evaluate --bag`:
///
///   kitti_raw_to_bag --kitti-raw DIR --out OUT.bag [--frames N]
///                    [--oxts-position velocity|gps] [--oxts-max-gap S]
///
/// /stereo/{left,right}/image_raw (the images as stored: mono8 for image_00/01) and
/// camera_info (K, D of the folder's calibration; R = I, P = [K | 0]) of every usable frame,
/// stamped with the left image's stamp; /odom (nav_msgs/Odometry odom -> base_link, base_link =
/// the OXTS/IMU frame) at every OXTS record, measured or interpolated, with its body twist;
/// /ground_truth/calibration (KITTI's chain) per frame. Gaps of the OXTS records longer than
/// the limit are not marked in the bag: a reader of /odom interpolates across them.
#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <string>

#include <cv_bridge/cv_bridge.h>
#include <rosbag/bag.h>
#include <opencv2/imgcodecs.hpp>

#include "bag_io.h"
#include "online_stereo_calibration/tools/bag_evaluation.h"
#include "online_stereo_calibration/tools/command_line.h"
#include "online_stereo_calibration/tools/kitti_raw_drive.h"
#include "online_stereo_calibration/tools/kitti_raw_source.h"
#include "online_stereo_calibration/tools/output_directory.h"
#include "online_stereo_calibration/tools/tum_trajectory.h"

namespace {

struct Options {
  std::string kitti_raw, out, tum;
  int frames = -1;
  osc::KittiRawCommandLine reader;
};

osc::CommandLine commandLine(Options* o) {
  osc::CommandLine cli(
      "kitti_raw_to_bag",
      "Writes a KITTI raw drive folder (image_00/01, oxts, calib_*.txt) into a bag with the "
      "interface's\ntopics: stereo images and camera_info, /odom from the OXTS records, KITTI's "
      "calibration on\n/ground_truth/calibration.");
  cli.option("--kitti-raw", &o->kitti_raw, "DIR", "KITTI raw drive folder").required();
  cli.option("--out", &o->out, "OUT.bag", "bag to write (or only --tum)");
  cli.option("--tum", &o->tum, "OUT.tum",
             "also write the OXTS poses (the vehicle = IMU frame in KITTI's world, at the records' "
             "stamps)\nas a TUM trajectory, e.g. for a simulated drive of the same motion");
  cli.option("--frames", &o->frames, "N", "write only the first N usable frames")
      .range(1, 1e9)
      .defaultText("all");
  o->reader.addTo(&cli);
  return cli;
}

/// The cv_bridge encoding of an image as read from a PNG.
std::string encodingOf(const cv::Mat& image) {
  switch (image.type()) {
    case CV_8UC1:
      return "mono8";
    case CV_16UC1:
      return "mono16";
    case CV_8UC3:
      return "bgr8";
    case CV_8UC4:
      return "bgra8";
    default:
      throw std::runtime_error("unsupported image type " + std::to_string(image.type()));
  }
}

int convert(const Options& options) {
  const osc::KittiRawDrive drive =
      osc::readKittiRawDrive(options.kitti_raw, options.reader.options());
  std::cerr << "converting " << drive.summary();
  for (const std::string& line : drive.skippedLines()) std::cerr << "  skipped " << line << "\n";
  if (!options.tum.empty()) {
    osc::makeDirectories(osc::directoryOf(options.tum));
    osc::writeTextFileAtomic(
        options.tum,
        osc::formatTumTrajectory(
            drive.imu_poses.poses(),
            "KITTI raw " + options.kitti_raw + ": the OXTS poses (kitti_raw_to_bag --tum)\n" +
                "vehicle frame = the OXTS/IMU frame (x forward, y left, z up); world x east, y "
                "north, z up"));
    std::cerr << "wrote " << options.tum << ": " << drive.imu_poses.size() << " poses\n";
  }
  if (options.out.empty()) return 0;
  std::size_t frames = drive.frames.size();
  if (options.frames > 0) frames = std::min(frames, static_cast<std::size_t>(options.frames));

  osc::makeDirectories(osc::directoryOf(options.out));
  const std::string partial = options.out + ".partial";
  const osc::bag::DriveTopics names;
  rosbag::Bag bag(partial, rosbag::bagmode::Write);
  // The odometry around the frames written (1 s either side).
  const double first = drive.frames.front().stamp() - 1.0;
  const double last = drive.frames[frames - 1].stamp() + 1.0;
  int odometry = 0;
  for (std::size_t i = 0; i < drive.oxts.size(); ++i) {
    const osc::StampedPose& pose = drive.imu_poses.poses()[i];
    if (pose.stamp < first || pose.stamp > last) continue;
    nav_msgs::Odometry odom = osc::bag::toOdometry(pose, drive.imu_twists[i], names);
    odom.header.stamp.fromNSec(static_cast<std::uint64_t>(drive.oxts[i].stamp_ns));
    bag.write(names.odom, odom.header.stamp, odom);
    ++odometry;
  }
  const osc::Vector12d truth = drive.truth();
  const auto start = std::chrono::steady_clock::now();
  const bool terminal = isatty(STDERR_FILENO) != 0;
  auto last_report = start;
  for (std::size_t k = 0; k < frames; ++k) {
    const osc::KittiRawFrame& frame = drive.frames[k];
    const cv::Mat left = cv::imread(frame.left_image, cv::IMREAD_UNCHANGED);
    const cv::Mat right = cv::imread(frame.right_image, cv::IMREAD_UNCHANGED);
    if (left.empty()) throw std::runtime_error("cannot read " + frame.left_image);
    if (right.empty()) throw std::runtime_error("cannot read " + frame.right_image);
    ros::Time stamp;
    stamp.fromNSec(static_cast<std::uint64_t>(frame.stamp_ns));
    std_msgs::Header header;
    header.stamp = stamp;
    header.seq = static_cast<std::uint32_t>(frame.index);
    header.frame_id = names.left_frame;
    bag.write(names.left_image, stamp,
              cv_bridge::CvImage(header, encodingOf(left), left).toImageMsg());
    bag.write(names.left_info, stamp, osc::bag::toCameraInfo(drive.left, stamp, names.left_frame));
    header.frame_id = names.right_frame;
    bag.write(names.right_image, stamp,
              cv_bridge::CvImage(header, encodingOf(right), right).toImageMsg());
    bag.write(names.right_info, stamp,
              osc::bag::toCameraInfo(drive.right, stamp, names.right_frame));
    bag.write(names.truth, stamp, osc::bag::toCalibrationMessage(truth, stamp, names));
    const auto now = std::chrono::steady_clock::now();
    if (k + 1 == frames || now - last_report > std::chrono::seconds(terminal ? 1 : 10)) {
      last_report = now;
      std::cerr << (terminal ? "\r  " : "  ")
                << osc::progressLine(static_cast<int>(k + 1), static_cast<int>(frames),
                                     std::chrono::duration<double>(now - start).count())
                << (terminal ? "" : "\n") << std::flush;
    }
  }
  if (terminal) std::cerr << "\n";
  bag.close();
  if (std::rename(partial.c_str(), options.out.c_str()) != 0) {
    throw std::runtime_error("cannot rename " + partial + " to " + options.out);
  }
  std::cerr << "wrote " << options.out << ": " << frames << " stereo pairs, " << odometry
            << " odometry messages, KITTI's calibration on " << names.truth << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options parsed;
  osc::CommandLine cli = commandLine(&parsed);
  return osc::runTool(
      "kitti_raw_to_bag", [&] { return cli.usage(); },
      [&] {
        if (!cli.parse(argc, argv)) return 0;
        if (parsed.out.empty() && parsed.tum.empty()) {
          throw osc::CommandLineError("give --out OUT.bag, --tum OUT.tum or both");
        }
        return convert(parsed);
      });
}
