#include <gtest/gtest.h>
#include "online_stereo_calibration/core/geometry/pose.h"
TEST(Smoke, RoundTrip) {
  osc::Vector6d p; p << 1, 2, 3, 0.1, 0.2, 0.3;
  EXPECT_TRUE(osc::parametersFromPose(osc::poseFromParameters(p)).isApprox(p, 1e-12));
}
