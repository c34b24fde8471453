/// @file test_oxts_poses.cpp
/// @brief The KITTI raw reader's OXTS conversions (tools/kitti_raw_drive.h) on synthetic
/// records: Mercator positions in metres east and north, the poses of two records from GPS and
/// from integrated velocity, and the interpolation of the heading.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "online_stereo_calibration/core/geometry/rotation.h"
#include "online_stereo_calibration/tools/kitti_raw_drive.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

// WGS84 at 49 deg north: 100 m along the meridian and along the parallel, by the ellipsoid's
// radii of curvature (not the sphere the Mercator projection uses), come out 100 m +- 0.5 m
// north (+y) and east (+x).
TEST(OxtsPoses, MercatorPositionsAreMetresEastAndNorth) {
  const double a = 6378137.0, e2 = 6.69437999014e-3, lat = 49.0, lon = 8.4;
  const double s2 = std::pow(std::sin(lat * kDeg), 2);
  const double meridian = a * (1 - e2) / std::pow(1 - e2 * s2, 1.5);
  const double normal = a / std::sqrt(1 - e2 * s2);
  const double scale = mercatorScale(lat);
  const Eigen::Vector3d origin = mercatorPosition(lat, lon, 112.0, scale);
  const Eigen::Vector3d north =
      mercatorPosition(lat + 100.0 / meridian / kDeg, lon, 113.5, scale) - origin;
  const Eigen::Vector3d east =
      mercatorPosition(lat, lon + 100.0 / (normal * std::cos(lat * kDeg)) / kDeg, 112.0, scale) -
      origin;
  EXPECT_NEAR(north.y(), 100.0, 0.5);
  EXPECT_NEAR(north.x(), 0.0, 1e-9);
  EXPECT_NEAR(north.z(), 1.5, 1e-12);
  EXPECT_NEAR(east.x(), 100.0, 0.5);
  EXPECT_NEAR(east.y(), 0.0, 1e-9);
}

OxtsRecord syntheticRecord(double stamp, double lat, double lon, double yaw, double ve, double vn) {
  OxtsRecord r;
  r.stamp_ns = static_cast<std::int64_t>(stamp * 1e9);
  r.values[0] = lat;
  r.values[1] = lon;
  r.values[2] = 100.0;
  r.values[5] = yaw;
  r.values[6] = vn;
  r.values[7] = ve;
  r.values[8] = std::hypot(ve, vn);  // vf
  r.values[19] = 0.1;                // wz
  return r;
}

// Heading north (yaw 90 deg) at 10 m/s for 10 s: the GPS and the integrated velocity both put
// the second record 100 m north of the first, and the IMU moved 100 m along its own x.
TEST(OxtsPoses, TwoRecordsHeadingNorthAreOneHundredMetresForward) {
  // 100 m north on the Mercator sphere at the reference latitude.
  const double lat = 49.0, step = 100.0 / 6378137.0 / kDeg;
  const std::vector<OxtsRecord> records = {
      syntheticRecord(0.0, lat, 8.4, M_PI / 2, 0.0, 10.0),
      syntheticRecord(10.0, lat + step, 8.4, M_PI / 2, 0.0, 10.0)};
  for (OxtsPositionSource source :
       {OxtsPositionSource::kGps, OxtsPositionSource::kIntegratedVelocity}) {
    const std::vector<StampedPose> poses = oxtsPoses(records, source, 20.0);
    ASSERT_EQ(poses.size(), 2u);
    EXPECT_TRUE(poses[0].pose.translation().isZero(0.0));
    EXPECT_NEAR(poses[1].pose.translation().y(), 100.0, 0.5) << oxtsPositionSourceName(source);
    EXPECT_NEAR(poses[1].pose.translation().x(), 0.0, 1e-9);
    const Eigen::Vector3d forward = (poses[0].pose.inverse() * poses[1].pose).translation();
    EXPECT_NEAR(forward.x(), 100.0, 0.5);
    EXPECT_NEAR(forward.y(), 0.0, 1e-9);
  }
  // The body twist: 10 m/s forward, the yaw rate about the IMU's z.
  const Vector6d twist = records[0].bodyTwist();
  EXPECT_NEAR(twist(0), 10.0, 1e-12);
  EXPECT_NEAR(twist(1), 0.0, 1e-12);
  EXPECT_NEAR(twist(5), 0.1, 1e-12);
  // A gap longer than the limit: the velocity is not integrated across it (the second record
  // stands at its GPS position, here 100 m although the velocities say 0).
  std::vector<OxtsRecord> stopped = records;
  for (OxtsRecord& r : stopped) r.values[6] = 0.0;
  EXPECT_NEAR(oxtsPoses(stopped, OxtsPositionSource::kIntegratedVelocity, 20.0)[1]
                  .pose.translation()
                  .norm(),
              0.0, 1e-12);
  EXPECT_NEAR(
      oxtsPoses(stopped, OxtsPositionSource::kIntegratedVelocity, 5.0)[1].pose.translation().y(),
      100.0, 0.5);
  // Names of the sources, and a wrong one.
  EXPECT_EQ(oxtsPositionSourceFromName("gps"), OxtsPositionSource::kGps);
  EXPECT_EQ(oxtsPositionSourceFromName("velocity"), OxtsPositionSource::kIntegratedVelocity);
  EXPECT_THROW(oxtsPositionSourceFromName("imu"), std::invalid_argument);
}

TEST(OxtsPoses, InterpolationTakesTheShorterArcOfTheHeading) {
  std::array<double, 30> a{}, b{};
  a[5] = 179.0 * kDeg;
  b[5] = -179.0 * kDeg;
  a[0] = 49.0;
  b[0] = 49.1;
  a[25] = 4;
  b[25] = 5;
  const std::array<double, 30> half = interpolateOxts(a, b, 0.5);
  EXPECT_NEAR(std::abs(half[5]), M_PI, 1e-12);
  EXPECT_NEAR(interpolateOxts(a, b, 0.25)[5], 179.5 * kDeg, 1e-12);
  EXPECT_NEAR(half[0], 49.05, 1e-12);
  EXPECT_EQ(half[25], 4);  // navstat: the earlier record's
}

}  // namespace
}  // namespace osc
