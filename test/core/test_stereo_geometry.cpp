// Independent unit tests of stereo_geometry.h: the essential and fundamental matrices, epipolar
// lines, the Sampson distance and midpoint triangulation.
//
// Every expected value comes from a source other than the code under test: epipolar lines
// built from two points on a ray, OpenCV's findFundamentalMat, the gold-standard error by
// Gauss-Newton, closed forms derived in the comments, or brute-force minimisation. All random
// numbers are seeded.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "geometry_test_support.h"
#include "online_stereo_calibration/core/geometry/stereo_geometry.h"

namespace osc {
namespace {

/// Angle between two vectors, well conditioned for small and large angles.
double angleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

Eigen::Matrix3d intrinsicMatrix(double fx, double fy, double cx, double cy) {
  Eigen::Matrix3d K;
  K << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return K;
}

/// A stereo pair with different intrinsics, a small random relative rotation and a baseline of
/// about 12 cm with the right camera at +x of the left one.
struct StereoRig {
  Eigen::Matrix3d K_left = intrinsicMatrix(458.0, 457.0, 367.0, 248.0);
  Eigen::Matrix3d K_right = intrinsicMatrix(462.0, 460.5, 379.0, 255.0);
  Eigen::Isometry3d T_lopt_ropt = Eigen::Isometry3d::Identity();
};

StereoRig randomRig(std::mt19937& rng) {
  StereoRig rig;
  rig.T_lopt_ropt.linear() =
      Eigen::AngleAxisd(uniform(rng, 0, 3 * kDeg), randomUnitVector(rng)).toRotationMatrix();
  rig.T_lopt_ropt.translation() = Eigen::Vector3d(
      uniform(rng, 0.1, 0.15), uniform(rng, -0.01, 0.01), uniform(rng, -0.01, 0.01));
  return rig;
}

Eigen::Vector2d pinholePixel(const Eigen::Matrix3d& K, const Eigen::Vector3d& p) {
  return (K * p).hnormalized();
}

Eigen::Vector3d randomPointInFront(std::mt19937& rng) {
  return Eigen::Vector3d(uniform(rng, -4, 4), uniform(rng, -2.5, 2.5), uniform(rng, 2, 30));
}

struct Correspondence {
  Eigen::Vector3d point_left;
  Eigen::Vector2d left, right;
};

Correspondence observe(const StereoRig& rig, const Eigen::Vector3d& point_left) {
  const Eigen::Vector3d point_right = rig.T_lopt_ropt.inverse() * point_left;
  return {point_left, pinholePixel(rig.K_left, point_left), pinholePixel(rig.K_right, point_right)};
}

/// The epipolar line of a left pixel, built independently of F: the right-image line through
/// the projections of two points on the left pixel's ray. Returns a unit normal n and a point.
std::pair<Eigen::Vector2d, Eigen::Vector2d> independentEpipolarLine(const StereoRig& rig,
                                                                    const Eigen::Vector2d& left) {
  const Eigen::Vector3d ray = rig.K_left.inverse() * left.homogeneous();
  const Eigen::Isometry3d T_ropt_lopt = rig.T_lopt_ropt.inverse();
  const Eigen::Vector2d a = pinholePixel(rig.K_right, T_ropt_lopt * (1.0 * ray));
  const Eigen::Vector2d b = pinholePixel(rig.K_right, T_ropt_lopt * (50.0 * ray));
  const Eigen::Vector2d direction = (b - a).normalized();
  return {Eigen::Vector2d(-direction.y(), direction.x()), a};
}

/// The gold-standard (reprojection) error of a correspondence: min over 3D points X of
/// sqrt(|pi_l(X) - left|^2 + |pi_r(X) - right|^2), by Gauss-Newton from a start point.
double goldStandardError(const StereoRig& rig, const Eigen::Vector2d& left,
                         const Eigen::Vector2d& right, Eigen::Vector3d X) {
  const Eigen::Isometry3d T_ropt_lopt = rig.T_lopt_ropt.inverse();
  auto residual = [&](const Eigen::Vector3d& x) {
    Eigen::Vector4d r;
    r << pinholePixel(rig.K_left, x) - left, pinholePixel(rig.K_right, T_ropt_lopt * x) - right;
    return r;
  };
  for (int iteration = 0; iteration < 50; ++iteration) {
    Eigen::Matrix<double, 4, 3> J;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d h = Eigen::Vector3d::Zero();
      h(k) = 1e-6 * std::max(1.0, X.norm());
      J.col(k) = (residual(X + h) - residual(X - h)) / (2 * h(k));
    }
    X -= (J.transpose() * J).ldlt().solve(J.transpose() * residual(X));
  }
  return residual(X).norm();
}

TEST(StereoGeometry, EssentialMatrixOfAHorizontalRig) {
  // Right camera at (b, 0, 0), no rotation: T_ropt_lopt = (I, (-b, 0, 0)) and
  // E = [(-b,0,0)]x = [[0,0,0],[0,0,b],[0,-b,0]], so x_r^T E x_l = b (y_r - y_l).
  const double b = 0.12;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(b, 0, 0);
  Eigen::Matrix3d expected;
  expected << 0, 0, 0, 0, 0, b, 0, -b, 0;
  EXPECT_TRUE(matrixNear(essentialMatrix(T), expected, 1e-15));
}

TEST(StereoGeometry, FundamentalMatrixSatisfiesTheEpipolarConstraint) {
  std::mt19937 rng(20);
  for (int r = 0; r < 20; ++r) {
    const StereoRig rig = randomRig(rng);
    const Eigen::Matrix3d F = fundamentalMatrix(rig.K_left, rig.K_right, rig.T_lopt_ropt);
    const Eigen::Matrix3d E = essentialMatrix(rig.T_lopt_ropt);
    const Eigen::Vector3d singular_values = Eigen::JacobiSVD<Eigen::Matrix3d>(F).singularValues();
    EXPECT_LT(singular_values(2), 1e-12 * singular_values(0));  // rank 2
    for (int i = 0; i < 50; ++i) {
      const Correspondence c = observe(rig, randomPointInFront(rng));
      const Eigen::Vector3d xl = c.left.homogeneous(), xr = c.right.homogeneous();
      EXPECT_LT(std::abs(xr.dot(F * xl)) / (F.norm() * xl.norm() * xr.norm()), 1e-9);
      // In pixels: the distance of the right pixel from the line F x_l.
      EXPECT_LT(std::abs(xr.dot(F * xl)) / (F * xl).head<2>().norm(), 1e-9);
      // The same for normalized rays under E.
      const Eigen::Vector3d nl = c.point_left / c.point_left.z();
      const Eigen::Vector3d pr = rig.T_lopt_ropt.inverse() * c.point_left;
      EXPECT_LT(std::abs((pr / pr.z()).dot(E * nl)), 1e-12);
      // A wrong correspondence 5 px off the (independently computed) line is 5 px off under F.
      const auto line = independentEpipolarLine(rig, c.left);
      const Eigen::Vector3d off = (c.right + 5.0 * line.first).homogeneous();
      EXPECT_NEAR(std::abs(off.dot(F * xl)) / (F * xl).head<2>().norm(), 5.0, 1e-9);
    }
  }
}

TEST(StereoGeometry, FundamentalMatrixMatchesOpenCvEightPoint) {
  std::mt19937 rng(21);
  for (int r = 0; r < 5; ++r) {
    const StereoRig rig = randomRig(rng);
    std::vector<cv::Point2d> left, right;
    for (int i = 0; i < 60; ++i) {
      const Correspondence c = observe(rig, randomPointInFront(rng));
      left.emplace_back(c.left.x(), c.left.y());
      right.emplace_back(c.right.x(), c.right.y());
    }
    const cv::Mat F_cv = cv::findFundamentalMat(left, right, cv::FM_8POINT);
    ASSERT_EQ(F_cv.rows, 3);
    Eigen::Matrix3d expected;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) expected(i, j) = F_cv.at<double>(i, j);
    }
    Eigen::Matrix3d F = fundamentalMatrix(rig.K_left, rig.K_right, rig.T_lopt_ropt);
    // Equal up to scale and sign. OpenCV's 8-point solves the normal equations (squared
    // condition number), so even on exact data it is only good to ~1e-6 relative.
    F /= F.norm();
    expected /= expected.norm();
    if ((F - expected).norm() > (F + expected).norm()) expected = -expected;
    EXPECT_TRUE(matrixNear(F, expected, 1e-5)) << "rig " << r;
    // Both agree on the correspondences to a small fraction of a pixel.
    for (size_t i = 0; i < left.size(); ++i) {
      const Eigen::Vector3d xl(left[i].x, left[i].y, 1), xr(right[i].x, right[i].y, 1);
      EXPECT_LT(std::abs(xr.dot(expected * xl)) / (expected * xl).head<2>().norm(), 1e-3);
    }
  }
}

TEST(StereoGeometry, EpipolarLineGivesSignedPixelDistances) {
  std::mt19937 rng(22);
  for (int r = 0; r < 10; ++r) {
    const StereoRig rig = randomRig(rng);
    const Eigen::Matrix3d F = fundamentalMatrix(rig.K_left, rig.K_right, rig.T_lopt_ropt);
    for (int i = 0; i < 30; ++i) {
      const Correspondence c = observe(rig, randomPointInFront(rng));
      const Eigen::Vector3d line = epipolarLine(F, c.left);
      EXPECT_NEAR(line.head<2>().norm(), 1.0, 1e-12);
      EXPECT_NEAR(line.dot(c.right.homogeneous()), 0.0, 1e-9);
      // 3 px off along the independently computed normal: |distance| = 3, sign flips.
      const auto reference = independentEpipolarLine(rig, c.left);
      const double plus = line.dot((c.right + 3.0 * reference.first).homogeneous());
      const double minus = line.dot((c.right - 3.0 * reference.first).homogeneous());
      EXPECT_NEAR(std::abs(plus), 3.0, 1e-9);
      EXPECT_NEAR(plus, -minus, 1e-9);
      // Sliding along the line keeps the distance at 0.
      const Eigen::Vector2d along(reference.first.y(), -reference.first.x());
      EXPECT_NEAR(line.dot((c.right + 40.0 * along).homogeneous()), 0.0, 1e-9);
    }
  }
}

TEST(StereoGeometry, SampsonDistanceIsZeroForExactCorrespondences) {
  std::mt19937 rng(23);
  for (int r = 0; r < 10; ++r) {
    const StereoRig rig = randomRig(rng);
    const Eigen::Matrix3d F = fundamentalMatrix(rig.K_left, rig.K_right, rig.T_lopt_ropt);
    for (int i = 0; i < 30; ++i) {
      const Correspondence c = observe(rig, randomPointInFront(rng));
      EXPECT_NEAR(sampsonDistance(F, c.left, c.right), 0.0, 1e-9);
    }
  }
}

TEST(StereoGeometry, SampsonDistanceOfARectifiedPairIsHalfTheOffsetInEachImage) {
  // Identical K, pure x baseline: epipolar lines are rows. A right pixel d rows off is best
  // explained by moving each pixel d/2 towards the other: gold-standard error sqrt(2) d / 2, and
  // Sampson is exact here (the constraint is linear in y_l, y_r).
  StereoRig rig;
  rig.K_right = rig.K_left;
  rig.T_lopt_ropt.translation() = Eigen::Vector3d(0.12, 0, 0);
  const Eigen::Matrix3d F = fundamentalMatrix(rig.K_left, rig.K_right, rig.T_lopt_ropt);
  std::mt19937 rng(24);
  for (int i = 0; i < 30; ++i) {
    const Correspondence c = observe(rig, randomPointInFront(rng));
    for (double d : {0.5, 3.0, -3.0}) {
      const Eigen::Vector2d moved = c.right + Eigen::Vector2d(0, d);
      EXPECT_NEAR(sampsonDistance(F, c.left, moved), std::abs(d) / std::sqrt(2.0), 1e-9);
      EXPECT_NEAR(std::abs(epipolarLine(F, c.left).dot(moved.homogeneous())), std::abs(d), 1e-9);
    }
  }
}

TEST(StereoGeometry, SampsonDistanceApproximatesTheGoldStandardError) {
  // For a general rig the Sampson distance is the first-order approximation of the reprojection
  // error minimised over the 3D point (brute force here), for a right pixel moved perpendicular
  // to its epipolar line.
  std::mt19937 rng(25);
  for (int r = 0; r < 5; ++r) {
    const StereoRig rig = randomRig(rng);
    const Eigen::Matrix3d F = fundamentalMatrix(rig.K_left, rig.K_right, rig.T_lopt_ropt);
    for (int i = 0; i < 10; ++i) {
      const Correspondence c = observe(rig, randomPointInFront(rng));
      const Eigen::Vector2d normal = independentEpipolarLine(rig, c.left).first;
      for (double d : {0.3, 3.0}) {
        const Eigen::Vector2d moved = c.right + d * normal;
        const double gold = goldStandardError(rig, c.left, moved, c.point_left);
        EXPECT_NEAR(sampsonDistance(F, c.left, moved), gold, 2e-3 * d) << "d=" << d;
        // Both lie between d / sqrt(2) (equal share) and d (one image only), for similar K.
        EXPECT_GT(gold, 0.6 * d);
        EXPECT_LT(gold, 0.8 * d);
      }
    }
  }
}

TEST(StereoGeometry, TriangulateMidpointRecoversTheExactPoint) {
  std::mt19937 rng(26);
  for (int r = 0; r < 10; ++r) {
    const StereoRig rig = randomRig(rng);
    const Eigen::Isometry3d T_ropt_lopt = rig.T_lopt_ropt.inverse();
    for (int i = 0; i < 50; ++i) {
      const Eigen::Vector3d p = randomPointInFront(rng);
      // Rays of arbitrary length.
      const Eigen::Vector3d ray_left = uniform(rng, 0.1, 10) * p;
      const Eigen::Vector3d ray_right = uniform(rng, 0.1, 10) * (T_ropt_lopt * p);
      const auto result = triangulateMidpoint(ray_left, ray_right, rig.T_lopt_ropt);
      ASSERT_TRUE(result.has_value()) << p.transpose();
      EXPECT_TRUE(matrixNear(result->point_left, p, 1e-9)) << p.transpose();
      EXPECT_NEAR(result->ray_gap, 0.0, 1e-9);
      // Parallax: the angle at the point between the directions to the two camera centres.
      const double parallax = angleBetween(p, p - rig.T_lopt_ropt.translation());
      EXPECT_NEAR(result->parallax, parallax, 1e-9);
    }
  }
}

/// Brute force: minimise |s d_l - (c_r + t d_r)| over s, t >= 0 by nested ternary search (the
/// objective is jointly convex). Returns the midpoint and writes the gap.
Eigen::Vector3d bruteForceMidpoint(const Eigen::Vector3d& d_l, const Eigen::Vector3d& c_r,
                                   const Eigen::Vector3d& d_r, double max_range, double* gap) {
  auto distance = [&](double s, double t) { return (s * d_l - c_r - t * d_r).norm(); };
  auto ternary_search = [max_range](const std::function<double(double)>& f) {
    double lo = 0.0, hi = max_range;
    for (int i = 0; i < 200; ++i) {
      const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
      if (f(m1) < f(m2)) {
        hi = m2;
      } else {
        lo = m1;
      }
    }
    return 0.5 * (lo + hi);
  };
  auto best_t = [&](double s) { return ternary_search([&](double t) { return distance(s, t); }); };
  const double s = ternary_search([&](double s) { return distance(s, best_t(s)); });
  const double t = best_t(s);
  *gap = distance(s, t);
  return 0.5 * (s * d_l + c_r + t * d_r);
}

TEST(StereoGeometry, TriangulateMidpointOfSkewRaysByConstruction) {
  // Build two skew rays whose common perpendicular is known: closest points P_l = s0 d_l and
  // P_r = P_l + g n with n perpendicular to both directions; place the right centre on the line
  // through P_r along d_r. The midpoint is P_l + g n / 2 and the gap is g.
  std::mt19937 rng(27);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d d_l =
        Eigen::Vector3d(uniform(rng, -0.5, 0.5), uniform(rng, -0.3, 0.3), 1).normalized();
    const Eigen::Vector3d d_r =
        (d_l + Eigen::Vector3d(uniform(rng, -0.2, 0.2), uniform(rng, -0.1, 0.1), 0)).normalized();
    const Eigen::Vector3d n = d_l.cross(d_r).normalized();
    const double s0 = uniform(rng, 2, 30), t0 = uniform(rng, 2, 30), g = uniform(rng, 0.001, 0.2);
    const Eigen::Vector3d P_l = s0 * d_l, P_r = P_l + g * n, c_r = P_r - t0 * d_r;
    Eigen::Isometry3d T_lopt_ropt = Eigen::Isometry3d::Identity();
    T_lopt_ropt.linear() =
        Eigen::AngleAxisd(uniform(rng, 0, 0.1), randomUnitVector(rng)).toRotationMatrix();
    T_lopt_ropt.translation() = c_r;
    const Eigen::Vector3d ray_right = T_lopt_ropt.linear().transpose() * d_r * 3.7;
    const auto result = triangulateMidpoint(2.0 * d_l, ray_right, T_lopt_ropt);
    ASSERT_TRUE(result.has_value()) << "i=" << i;
    EXPECT_TRUE(matrixNear(result->point_left, P_l + 0.5 * g * n, 1e-8)) << "i=" << i;
    EXPECT_NEAR(result->ray_gap, g, 1e-8) << "i=" << i;
    EXPECT_NEAR(result->parallax, angleBetween(d_l, d_r), 1e-9) << "i=" << i;
  }
}

TEST(StereoGeometry, TriangulateMidpointOfSkewRaysAgreesWithBruteForce) {
  std::mt19937 rng(28);
  for (int r = 0; r < 10; ++r) {
    const StereoRig rig = randomRig(rng);
    for (int i = 0; i < 5; ++i) {
      const Correspondence c = observe(rig, randomPointInFront(rng));
      // Perturb both pixels so the back-projected rays are skew.
      const Eigen::Vector2d left =
          c.left + Eigen::Vector2d(uniform(rng, -2, 2), uniform(rng, -2, 2));
      const Eigen::Vector2d right =
          c.right + Eigen::Vector2d(uniform(rng, -2, 2), uniform(rng, -2, 2));
      const Eigen::Vector3d ray_left = rig.K_left.inverse() * left.homogeneous();
      const Eigen::Vector3d ray_right = rig.K_right.inverse() * right.homogeneous();
      const auto result = triangulateMidpoint(ray_left, ray_right, rig.T_lopt_ropt);
      if (!result) continue;  // the perturbation may make a far point diverge: checked elsewhere
      double gap = 0.0;
      const Eigen::Vector3d expected =
          bruteForceMidpoint(ray_left.normalized(), rig.T_lopt_ropt.translation(),
                             (rig.T_lopt_ropt.linear() * ray_right).normalized(), 2000.0, &gap);
      EXPECT_TRUE(matrixNear(result->point_left, expected, 1e-6 * expected.norm()));
      EXPECT_NEAR(result->ray_gap, gap, 1e-7);
    }
  }
}

TEST(StereoGeometry, TriangulateMidpointRejectsParallelRays) {
  std::mt19937 rng(29);
  const StereoRig rig = randomRig(rng);
  const Eigen::Matrix3d R_ropt_lopt = rig.T_lopt_ropt.linear().transpose();
  for (const Eigen::Vector3d& direction :
       {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.3, -0.2, 1), Eigen::Vector3d(-1, 0, 0.2)}) {
    // Same direction in the left frame, expressed in the right frame: parallel.
    EXPECT_FALSE(triangulateMidpoint(direction, R_ropt_lopt * direction, rig.T_lopt_ropt));
    EXPECT_FALSE(triangulateMidpoint(direction, 5.0 * R_ropt_lopt * direction, rig.T_lopt_ropt));
    // Nearly parallel (1e-9 rad): a point ~1e8 m away is no measurement either.
    const Eigen::Vector3d tilted = Eigen::AngleAxisd(1e-9, direction.unitOrthogonal()) * direction;
    EXPECT_FALSE(triangulateMidpoint(direction, R_ropt_lopt * tilted, rig.T_lopt_ropt));
  }
  EXPECT_FALSE(
      triangulateMidpoint(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1), rig.T_lopt_ropt));
  // Converging but only 1e-7 rad apart (a point ~1200 km away with a 12 cm baseline): nearly
  // parallel, rejected; 1e-4 rad apart (1.2 km) is still a valid point.
  StereoRig horizontal;
  horizontal.T_lopt_ropt.translation() = Eigen::Vector3d(0.12, 0, 0);
  EXPECT_FALSE(triangulateMidpoint(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(-1e-7, 0, 1),
                                   horizontal.T_lopt_ropt));
  const auto far = triangulateMidpoint(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(-1e-4, 0, 1),
                                       horizontal.T_lopt_ropt);
  ASSERT_TRUE(far.has_value());
  EXPECT_NEAR(far->point_left.z(), 0.12 / 1e-4, 1e-6 * 1200);
  EXPECT_NEAR(far->parallax, 1e-4, 1e-10);
}

TEST(StereoGeometry, TriangulateMidpointRejectsPointsBehindTheCameras) {
  std::mt19937 rng(30);
  const StereoRig rig = randomRig(rng);
  const Eigen::Isometry3d T_ropt_lopt = rig.T_lopt_ropt.inverse();
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d front = randomPointInFront(rng);
    const Eigen::Vector3d behind(front.x(), front.y(), -front.z());
    // Rays pointing at a point behind both cameras.
    EXPECT_FALSE(triangulateMidpoint(behind, T_ropt_lopt * behind, rig.T_lopt_ropt))
        << behind.transpose();
    // Forward-pointing rays whose lines meet behind the cameras.
    EXPECT_FALSE(triangulateMidpoint(-behind, -(T_ropt_lopt * behind), rig.T_lopt_ropt))
        << behind.transpose();
    // Lines meeting at a point in front of the left camera, but against the direction of one
    // ray: the right ray points away from it, or the left one does.
    const Eigen::Vector3d in_right = T_ropt_lopt * front;
    EXPECT_FALSE(triangulateMidpoint(front, -in_right, rig.T_lopt_ropt)) << front.transpose();
    EXPECT_FALSE(triangulateMidpoint(-front, in_right, rig.T_lopt_ropt)) << front.transpose();
  }
  // Diverging rays: left looks slightly left, right slightly right; the lines cross behind.
  StereoRig horizontal;
  horizontal.T_lopt_ropt.translation() = Eigen::Vector3d(0.12, 0, 0);
  EXPECT_FALSE(triangulateMidpoint(Eigen::Vector3d(-0.01, 0, 1), Eigen::Vector3d(0.01, 0, 1),
                                   horizontal.T_lopt_ropt));
  // The same rays converging give a point in front at z = 0.12 / 0.02 = 6 m.
  const auto converging = triangulateMidpoint(Eigen::Vector3d(0.01, 0, 1),
                                              Eigen::Vector3d(-0.01, 0, 1), horizontal.T_lopt_ropt);
  ASSERT_TRUE(converging.has_value());
  EXPECT_TRUE(matrixNear(converging->point_left, Eigen::Vector3d(0.06, 0, 6), 1e-10));
}

// A pair's depth scales with the baseline's length (the rays are fixed by the pixels): the
// triangulation at a 3-sigma longer baseline is the range's `longest` times the current one.
TEST(BaselineDepthScaleRange, IsTheDepthsRatioOverTheLengthsInterval) {
  const Eigen::Vector3d baseline(0.0, -0.01, 0.0);  // 1 cm to the right (camera frame y left)
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity() * 1e-6;
  covariance(1, 1) = 0.1 * 0.1;  // the length's sigma 0.1 m; across it 1 mm
  const DepthScaleRange range = baselineDepthScaleRange(baseline, covariance, 3.0);
  EXPECT_NEAR(range.longest, 1.0 + 0.3 / 0.01, 1e-9);
  EXPECT_EQ(range.shortest, 0.0);  // a length of 0 is within 3 sigma
  // Triangulated: the same pixels with the baseline 31 times as long, 31 times as deep.
  StereoRig rig;
  rig.T_lopt_ropt.translation() = Eigen::Vector3d(0.01, 0, 0);
  const Eigen::Vector3d left_ray(0.02, 0.01, 1), right_ray(0.0175, 0.01, 1);
  const auto at_guess = triangulateMidpoint(left_ray, right_ray, rig.T_lopt_ropt);
  rig.T_lopt_ropt.translation() *= range.longest;
  const auto at_longest = triangulateMidpoint(left_ray, right_ray, rig.T_lopt_ropt);
  ASSERT_TRUE(at_guess && at_longest);
  EXPECT_NEAR(at_longest->point_left.z(), range.longest * at_guess->point_left.z(), 1e-9);
  // A known length (1 mm on 11 cm): within 3 %.
  covariance(1, 1) = 1e-6;
  const DepthScaleRange known =
      baselineDepthScaleRange(Eigen::Vector3d(0, -0.11, 0), covariance, 3.0);
  EXPECT_NEAR(known.shortest, 1.0 - 0.003 / 0.11, 1e-9);
  EXPECT_NEAR(known.longest, 1.0 + 0.003 / 0.11, 1e-9);
  EXPECT_EQ(baselineDepthScaleRange(Eigen::Vector3d::Zero(), covariance, 3.0).longest, 1.0);
}

}  // namespace
}  // namespace osc
