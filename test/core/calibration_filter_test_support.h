/// @file calibration_filter_test_support.h
/// @brief The small problem the structured filter's tests (test_calibration_filter*) run on: a
/// few static world points, a true calibration, a wrong guess and a short drive, and the
/// guess's covariance.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "online_stereo_calibration/core/estimator/types.h"
#include "online_stereo_calibration/core/filter/calibration_filter.h"
#include "online_stereo_calibration/core/filter/measurement_model.h"
#include "online_stereo_calibration/core/geometry/pose.h"

namespace osc {

inline constexpr double kDeg = M_PI / 180.0;

/// A few static world points, a true calibration, a wrong guess and a short drive.
struct SmallProblem {
  StereoIntrinsics K;
  StereoExtrinsics truth, guess;
  std::vector<Eigen::Vector3d> world;
  std::vector<Eigen::Isometry3d> T_world_veh;
  std::mt19937_64 rng{3};

  SmallProblem(int points, int frames) {
    K.K_left << 600, 0, 320, 0, 600, 240, 0, 0, 1;
    K.K_right = K.K_left;
    Vector12d p;
    p << 1.5, 0.15, 1.3, 0.0, 0.05, 0.0, 0.0, -0.3, 0.0, 0.0, 0.0, 0.0;
    truth = StereoExtrinsics::fromParameters(p);
    Vector12d err;
    err << 0.05, -0.05, 0.05, 1 * kDeg, -1 * kDeg, 1 * kDeg, 0.0, 0.01, 0.0, 0.1 * kDeg, 0.0, 0.0;
    guess = StereoExtrinsics::fromParameters(p + err);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int i = 0; i < points; ++i) {
      world.emplace_back(12 + 8 * u(rng), 4 * u(rng), 1.3 + 1.5 * u(rng));
    }
    for (int k = 0; k < frames; ++k) {
      Vector6d w;
      w << 0.35 * k, 0.0, 0.02 * std::sin(k), 0.03 * std::sin(0.7 * k), 0.03 * std::cos(0.9 * k),
          0.02 * k;
      T_world_veh.push_back(poseFromParameters(w));
    }
  }

  MotionIncrement motion(int k) const {
    MotionIncrement m;
    m.T_prev_curr = T_world_veh[k - 1].inverse() * T_world_veh[k];
    m.dt = 0.1;
    return m;
  }

  std::vector<PointMeasurement> measure(int k, double pixel_noise) {
    std::normal_distribution<double> n(0.0, pixel_noise);
    const Eigen::Isometry3d T_lopt_world =
        (T_world_veh[k] * truth.vehicleToLeftOptical()).inverse();
    const Eigen::Isometry3d T_ropt_lopt = truth.leftToRightOptical().inverse();
    std::vector<PointMeasurement> out;
    for (size_t i = 0; i < world.size(); ++i) {
      PointMeasurement m;
      m.id = i + 1;
      EXPECT_TRUE(projectStereo(T_lopt_world * world[i], T_ropt_lopt, K, 0.1, &m.z));
      for (int c = 0; c < 4; ++c) m.z(c) += n(rng);
      m.variance.setConstant(std::max(pixel_noise, 0.3) * std::max(pixel_noise, 0.3));
      out.push_back(m);
    }
    return out;
  }
};

inline Matrix12d guessCovariance(double scale = 1.0) {
  Vector12d sigma;
  sigma << 0.1, 0.1, 0.1, 2 * kDeg, 2 * kDeg, 2 * kDeg, 0.02, 0.02, 0.02, 0.3 * kDeg, 0.3 * kDeg,
      0.3 * kDeg;
  return (scale * sigma).array().square().matrix().asDiagonal();
}

}  // namespace osc
