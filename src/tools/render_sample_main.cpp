/// @file render_sample_main.cpp
/// @brief Writes one rendered stereo pair of the procedural scene as PNGs, to look at.
///
/// Usage: render_sample [--out DIR] [--seed N] [--size WxH] [--color] [--distortion MODEL]
///                      [--x X] [--y Y] [--yaw RAD] [--pitch RAD] [--baseline B]
/// The camera body stands 1.5 m above the ground at (x, y) looking along yaw; the right camera
/// is `baseline` metres to its right. Writes DIR/left.png and DIR/right.png.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "online_stereo_calibration/core/geometry/pose.h"
#include "online_stereo_calibration/core/sim/stereo_scene_renderer.h"

namespace {

struct Arguments {
  std::string out = ".";
  unsigned seed = 7;
  int width = 640, height = 480;
  bool color = false;
  std::string distortion = "none";
  double x = 0.0, y = 0.0, yaw = 0.0, pitch = 0.05, baseline = 0.5;
};

Arguments parse(int argc, char** argv) {
  Arguments a;
  for (int i = 1; i < argc; ++i) {
    const std::string key = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument("missing value after " + key);
      return argv[++i];
    };
    if (key == "--out")
      a.out = value();
    else if (key == "--seed")
      a.seed = static_cast<unsigned>(std::stoul(value()));
    else if (key == "--size") {
      const std::string s = value();
      const size_t x = s.find('x');
      if (x == std::string::npos) throw std::invalid_argument("--size wants WxH");
      a.width = std::stoi(s.substr(0, x));
      a.height = std::stoi(s.substr(x + 1));
    } else if (key == "--color")
      a.color = true;
    else if (key == "--distortion")
      a.distortion = value();
    else if (key == "--x")
      a.x = std::stod(value());
    else if (key == "--y")
      a.y = std::stod(value());
    else if (key == "--yaw")
      a.yaw = std::stod(value());
    else if (key == "--pitch")
      a.pitch = std::stod(value());
    else if (key == "--baseline")
      a.baseline = std::stod(value());
    else
      throw std::invalid_argument("unknown argument " + key);
  }
  return a;
}

osc::CameraModel makeCamera(const Arguments& a) {
  osc::CameraIntrinsics in;
  in.width = a.width;
  in.height = a.height;
  in.fx = in.fy = 0.78 * a.width;
  in.cx = 0.5 * (a.width - 1);
  in.cy = 0.5 * (a.height - 1);
  in.model = osc::distortionModelFromName(a.distortion);
  if (in.model == osc::DistortionModel::kPlumbBob) in.distortion = {-0.28, 0.07, 2e-4, 2e-5};
  if (in.model == osc::DistortionModel::kRationalPolynomial) {
    in.distortion = {-0.2, 0.05, 1e-4, 1e-4, 0.0, 0.05, 0.0, 0.0};
  }
  if (in.model == osc::DistortionModel::kEquidistant) in.distortion = {-0.01, 0.005, -0.002, 0.0};
  return osc::CameraModel(in);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Arguments a = parse(argc, argv);
    osc::SceneConfig config;
    config.seed = a.seed;
    const osc::StereoSceneRenderer renderer(config);
    const osc::CameraModel camera = makeCamera(a);
    osc::Vector6d body;
    body << a.x, a.y, renderer.scene().groundHeight(a.x, a.y) + 1.5, 0.0, a.pitch, a.yaw;
    const Eigen::Isometry3d T_world_left = osc::poseFromParameters(body) * osc::bodyFromOptical();
    Eigen::Isometry3d T_left_right = Eigen::Isometry3d::Identity();
    T_left_right.translation() = Eigen::Vector3d(a.baseline, 0.0, 0.0);  // optical x is right
    osc::RenderOptions options;
    options.color = a.color;
    const auto start = std::chrono::steady_clock::now();
    const cv::Mat left = renderer.render(camera, T_world_left, options);
    const auto middle = std::chrono::steady_clock::now();
    const cv::Mat right = renderer.render(camera, T_world_left * T_left_right, options);
    const auto end = std::chrono::steady_clock::now();
    cv::imwrite(a.out + "/left.png", left);
    cv::imwrite(a.out + "/right.png", right);
    std::cout << "left " << std::chrono::duration<double, std::milli>(middle - start).count()
              << " ms (with the ray cache), right "
              << std::chrono::duration<double, std::milli>(end - middle).count() << " ms; "
              << renderer.scene().primitives().size() << " primitives\n";
    return EXIT_SUCCESS;
  } catch (const std::exception& e) {
    std::cerr << "render_sample: " << e.what() << "\n";
    return EXIT_FAILURE;
  }
}
