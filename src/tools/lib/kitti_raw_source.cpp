/// @file kitti_raw_source.cpp
/// @brief KittiRawSource::next: the images of the next usable frame.
#include "online_stereo_calibration/tools/kitti_raw_source.h"

#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

namespace osc {

void KittiRawCommandLine::addTo(CommandLine* cli, const std::string& help_prefix) {
  cli->option("--oxts-position", &position_, "SOURCE",
              help_prefix + "positions from the integrated OXTS velocity or from GPS (Mercator)")
      .choices({"velocity", "gps"});
  cli->option("--oxts-max-gap", &max_oxts_gap_, "S",
              help_prefix + "missing OXTS records are interpolated over at most this (s)")
      .range(0.01, 10.0);
}

KittiRawOptions KittiRawCommandLine::options() const {
  KittiRawOptions options;
  options.position = oxtsPositionSourceFromName(position_);
  options.max_oxts_gap = max_oxts_gap_;
  return options;
}

bool KittiRawSource::next(StereoPairInput* pair) {
  if (next_ >= drive_.frames.size()) return false;
  const KittiRawFrame& frame = drive_.frames[next_++];
  pair->stamp = frame.stamp();
  pair->stamp_ns = frame.stamp_ns;
  pair->left = cv::imread(frame.left_image, cv::IMREAD_UNCHANGED);
  pair->right = cv::imread(frame.right_image, cv::IMREAD_UNCHANGED);
  pair->owner.reset();
  for (const auto& [image, path] : {std::make_pair(&pair->left, &frame.left_image),
                                    std::make_pair(&pair->right, &frame.right_image)}) {
    if (image->empty()) throw std::runtime_error("KITTI raw: cannot read " + *path);
  }
  return true;
}

}  // namespace osc
