/// @file stereo_front_end_debug.cpp
/// @brief StereoFrontEnd's debug image: keypoints, tracks, search windows and the new points'
/// epipolar bands drawn over the last pair.
#include "online_stereo_calibration/core/frontend/stereo_front_end.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace osc {

StereoFrontEnd::EpipolarBand StereoFrontEnd::bandPolylines(const Eigen::Vector2d& left_und,
                                                           const Eigen::Vector2d& right_und) const {
  // The band around the epipolar line of the left pixel near the match (eq. 5-6), +-60 px
  // along the line, in raw right pixels (the line is curved there under distortion).
  EpipolarBand band;
  const EpipolarMatcher::Lines lines = matcher_.lines(left_und);
  const Eigen::Vector3d& l = lines.nominal;
  const double half = matcher_.bandHalfWidth(lines, right_und);
  const Eigen::Vector2d normal(l.x(), l.y()), along(l.y(), -l.x());
  const Eigen::Vector2d foot = right_und - l.dot(right_und.homogeneous()) * normal;
  const Eigen::Matrix3d K_inv = right_camera_.K().inverse();
  for (double t = -60.0; t <= 60.0; t += 10.0) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d u = foot + t * along + (k - 1) * half * normal;
      const Eigen::Vector2d raw =
          right_camera_.normalizedToPixel((K_inv * u.homogeneous()).head<2>());
      band.lines[k].emplace_back(static_cast<float>(raw.x()), static_cast<float>(raw.y()));
    }
  }
  return band;
}

cv::Mat StereoFrontEnd::debugImage() const {
  if (last_left_.empty() || last_right_.empty()) return cv::Mat();
  const int w = last_left_.cols;
  cv::Mat canvas(std::max(last_left_.rows, last_right_.rows), w + last_right_.cols, CV_8UC3,
                 cv::Scalar::all(0));
  cv::Mat left_roi = canvas(cv::Rect(0, 0, w, last_left_.rows));
  cv::Mat right_roi = canvas(cv::Rect(w, 0, last_right_.cols, last_right_.rows));
  cv::cvtColor(last_left_, left_roi, cv::COLOR_GRAY2BGR);
  cv::cvtColor(last_right_, right_roi, cv::COLOR_GRAY2BGR);
  auto pt = [](const Eigen::Vector2d& p, double dx = 0.0) {
    return cv::Point(static_cast<int>(std::lround(p.x() + dx)),
                     static_cast<int>(std::lround(p.y())));
  };
  const cv::Scalar grey(128, 128, 128), green(0, 220, 0), blue(255, 80, 0);
  const cv::Scalar yellow(0, 220, 220), cyan(220, 220, 0);
  for (const StereoObservation& o : last_matches_) {
    cv::circle(canvas, pt(o.left_pixel), 2, grey, 1);
    cv::circle(canvas, pt(o.right_pixel, w), 2, grey, 1);
  }
  for (const TrackWindow& win : last_windows_) {
    cv::rectangle(canvas, pt(win.left_center - win.left_half), pt(win.left_center + win.left_half),
                  yellow, 1);
    cv::rectangle(canvas, pt(win.right_center - win.right_half, w),
                  pt(win.right_center + win.right_half, w), cyan, 1);
  }
  // Epipolar bands (eq. 5-6) of the new points in the right image: centre line and edges.
  const cv::Scalar magenta(200, 0, 200);
  for (const EpipolarBand& band : last_bands_) {
    for (int k = 0; k < 3; ++k) {
      std::vector<cv::Point> poly;
      for (const cv::Point2f& p : band.lines[k]) {
        poly.emplace_back(static_cast<int>(std::lround(p.x + w)),
                          static_cast<int>(std::lround(p.y)));
      }
      cv::polylines(canvas, poly, false, magenta, 1, k == 1 ? cv::LINE_8 : cv::LINE_4);
    }
  }
  for (const StereoObservation& o : last_new_) {
    cv::circle(canvas, pt(o.left_pixel), 4, blue, 2);
    cv::circle(canvas, pt(o.right_pixel, w), 4, blue, 2);
    cv::line(canvas, pt(o.left_pixel), pt(o.right_pixel, w), blue, 1);
  }
  for (const StereoObservation& o : last_tracked_) {
    cv::circle(canvas, pt(o.left_pixel), 4, green, 2);
    cv::circle(canvas, pt(o.right_pixel, w), 4, green, 2);
  }
  const std::string text = "tracked " + std::to_string(last_tracked_.size()) + "  new " +
                           std::to_string(last_new_.size()) + "  matches " +
                           std::to_string(last_matches_.size());
  cv::putText(canvas, text, cv::Point(8, 20), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 255),
              2);
  return canvas;
}

}  // namespace osc
