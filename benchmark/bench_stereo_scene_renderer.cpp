/// @file bench_stereo_scene_renderer.cpp
/// @brief Time of StereoSceneRenderer::render() on one thread (cv::setNumThreads(1)):
/// mono8, default options (2x2 supersampling at edges), camera 1.5 m above the ground
/// looking along the path, at 640x480 and 1280x960; also one ground-truth query.
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>

#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/sim/stereo_scene_renderer.h"

namespace {

osc::CameraModel camera(int width, int height) {
  osc::CameraIntrinsics in;
  in.width = width;
  in.height = height;
  in.fx = in.fy = 0.78 * width;
  in.cx = 0.5 * (width - 1);
  in.cy = 0.5 * (height - 1);
  return osc::CameraModel(in);
}

/// A straight 300 m drive along x; the camera is 100 m into it.
const osc::StereoSceneRenderer& renderer() {
  static const osc::StereoSceneRenderer instance([] {
    osc::SceneConfig config;
    for (int k = 0; k <= 300; ++k) config.path.emplace_back(static_cast<double>(k), 0.0);
    return config;
  }());
  return instance;
}

Eigen::Isometry3d pose(double x) {
  osc::Vector6d body;
  body << x, 0.0, renderer().scene().groundHeight(x, 0.0) + 1.5, 0.0, 0.05, 0.0;
  return osc::poseFromParameters(body) * osc::bodyFromOptical();
}

void BM_Render(benchmark::State& state) {
  cv::setNumThreads(1);
  const osc::CameraModel cam =
      camera(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const osc::RenderOptions options;
  renderer().render(cam, pose(100.0), options);  // fills the per-camera ray cache
  // The same ten frames of a 3.5 m/s drive at 10 Hz over and over, so every run and every
  // image size sees the same views.
  int frame = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(renderer().render(cam, pose(100.0 + 0.35 * (frame++ % 10)), options));
  }
  state.SetLabel("mono8, supersampling 2, 1 thread");
}
BENCHMARK(BM_Render)->Args({640, 480})->Args({1280, 960})->Unit(benchmark::kMillisecond);

void BM_ProjectVisible(benchmark::State& state) {
  const osc::CameraModel cam = camera(640, 480);
  const Eigen::Isometry3d T = pose(100.0);
  const Eigen::Vector3d p = *renderer().surfacePoint(cam, T, Eigen::Vector2d(320.0, 400.0));
  Eigen::Vector2d pixel;
  for (auto _ : state) benchmark::DoNotOptimize(renderer().projectVisible(cam, T, p, &pixel));
}
BENCHMARK(BM_ProjectVisible)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
