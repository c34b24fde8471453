// OrbDescription must give exactly cv::ORB's descriptors (the front end's results do not
// depend on which of the two computed them).
#include <gtest/gtest.h>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "online_stereo_calibration/core/frontend/orb_description.h"

namespace {

constexpr int kPatchSize = 19, kEdgeThreshold = 19, kFastThreshold = 12, kKeypoints = 3000;

cv::Ptr<cv::ORB> orb() {
  // As FeatureDetector creates it for detector ORB with orb_levels 1.
  return cv::ORB::create(kKeypoints, 1.2f, 1, kEdgeThreshold, 0, 2, cv::ORB::FAST_SCORE, kPatchSize,
                         kFastThreshold);
}

osc::OrbDescription description() {
  return osc::OrbDescription(kPatchSize, kEdgeThreshold, kFastThreshold);
}

/// Smoothed noise: corners everywhere, many ties after ORB's own smoothing.
cv::Mat texture(int width, int height, int seed) {
  cv::Mat noise(height, width, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat image;
  cv::GaussianBlur(noise, image, cv::Size(5, 5), 1.5);
  return image;
}

int differingRows(const cv::Mat& a, const cv::Mat& b) {
  int rows = 0;
  for (int i = 0; i < a.rows; ++i) rows += cv::norm(a.row(i), b.row(i), cv::NORM_HAMMING) > 0;
  return rows;
}

TEST(OrbDescription, DetectAndOrientGiveOpenCvOrbsKeypointsInItsOrder) {
  for (int seed : {1, 2}) {
    const cv::Mat image = texture(640, 480, seed);
    std::vector<cv::KeyPoint> expected, actual;
    orb()->detect(image, expected);
    const osc::OrbDescription orb_description = description();
    orb_description.detect(image, kKeypoints, &actual);
    orb_description.orient(image, &actual);
    ASSERT_GT(expected.size(), 1000u);
    ASSERT_EQ(actual.size(), expected.size());
    int different = 0;
    for (size_t i = 0; i < actual.size(); ++i) {
      const cv::KeyPoint &a = actual[i], &e = expected[i];
      different += a.pt != e.pt || a.response != e.response || a.angle != e.angle ||
                   a.octave != e.octave || a.size != e.size;
    }
    EXPECT_EQ(different, 0) << "seed " << seed;
  }
}

TEST(OrbDescription, SameBitsAsOpenCvOrbOnItsKeypoints) {
  for (int seed : {1, 2}) {
    const cv::Mat image = texture(640, 480, seed);
    std::vector<cv::KeyPoint> keypoints;
    orb()->detect(image, keypoints);
    ASSERT_GT(keypoints.size(), 1000u);
    std::vector<cv::KeyPoint> described = keypoints;
    cv::Mat expected, actual;
    orb()->compute(image, described, expected);
    ASSERT_EQ(described.size(), keypoints.size());  // cv::ORB dropped none

    ASSERT_TRUE(description().compute(image, keypoints, &actual));
    ASSERT_EQ(actual.rows, expected.rows);
    ASSERT_EQ(actual.cols, expected.cols);
    EXPECT_EQ(differingRows(actual, expected), 0) << "seed " << seed;
  }
}

TEST(OrbDescription, SameBitsAtEveryAngle) {
  // Rounding of the rotated pattern is where an implementation can differ: sweep the angle.
  const cv::Mat image = texture(320, 240, 3);
  std::vector<cv::KeyPoint> keypoints;
  for (int k = 0; k < 3600; ++k) {
    cv::KeyPoint p(cv::Point2f(40.0f + (k % 240), 40.0f + (k / 240) * 10.0f), kPatchSize);
    p.angle = 0.1f * static_cast<float>(k);
    p.octave = 0;
    keypoints.push_back(p);
  }
  std::vector<cv::KeyPoint> described = keypoints;
  cv::Mat expected, actual;
  orb()->compute(image, described, expected);
  ASSERT_EQ(described.size(), keypoints.size());
  ASSERT_TRUE(description().compute(image, keypoints, &actual));
  EXPECT_EQ(differingRows(actual, expected), 0);
}

TEST(OrbDescription, RefusesKeypointsTooCloseToTheBorderOrOnAnotherLevel) {
  const cv::Mat image = texture(100, 80, 4);
  const osc::OrbDescription orb_description = description();
  cv::Mat descriptors;
  cv::KeyPoint near_border(cv::Point2f(static_cast<float>(orb_description.border() - 1), 40.0f),
                           kPatchSize);
  near_border.octave = 0;
  EXPECT_FALSE(orb_description.compute(image, {near_border}, &descriptors));
  cv::KeyPoint other_level(cv::Point2f(50.0f, 40.0f), kPatchSize);
  other_level.octave = 1;
  EXPECT_FALSE(orb_description.compute(image, {other_level}, &descriptors));
  cv::KeyPoint inside(cv::Point2f(50.0f, 40.0f), kPatchSize);
  inside.octave = 0;
  EXPECT_TRUE(orb_description.compute(image, {inside}, &descriptors));
  EXPECT_EQ(descriptors.rows, 1);
  EXPECT_THROW(osc::OrbDescription(31, kEdgeThreshold, kFastThreshold), std::invalid_argument);
}

}  // namespace
