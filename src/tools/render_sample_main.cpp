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
#include "online_stereo_calibration/tools/command_line.h"

namespace {

struct Arguments {
  std::string out = ".";
  unsigned seed = 7;
  int width = 640, height = 480;
  bool color = false;
  std::string distortion = "none";
  double x = 0.0, y = 0.0, yaw = 0.0, pitch = 0.05, baseline = 0.5;
};

/// The command line (`--help` prints it); --size WxH is split after parsing.
osc::CommandLine commandLine(Arguments* a, std::string* size, int* seed) {
  osc::CommandLine cli("render_sample",
                       "Writes one rendered stereo pair of the procedural scene as "
                       "DIR/left.png and DIR/right.png.");
  cli.option("--out", &a->out, "DIR", "output directory (must exist)");
  cli.option("--seed", seed, "N", "scene seed").range(0, 2147483647);
  cli.option("--size", size, "WxH", "image size");
  cli.flag("--color", &a->color, "render in colour (bgr8)");
  cli.option("--distortion", &a->distortion, "MODEL", "lens distortion")
      .choices({"none", "plumb_bob", "rational_polynomial", "equidistant"});
  cli.option("--x", &a->x, "X", "camera x (m)");
  cli.option("--y", &a->y, "Y", "camera y (m)");
  cli.option("--yaw", &a->yaw, "RAD", "camera yaw");
  cli.option("--pitch", &a->pitch, "RAD", "camera pitch").range(-1.5, 1.5);
  cli.option("--baseline", &a->baseline, "B", "stereo baseline (m)").range(0.0, 10.0);
  return cli;
}

/// "640x480" -> width, height; throws CommandLineError otherwise.
void parseSize(const std::string& text, Arguments* a) {
  const size_t x = text.find('x');
  const auto number = [&](const std::string& part) {
    if (part.empty() || part.find_first_not_of("0123456789") != std::string::npos ||
        part.size() > 5 || std::stoi(part) < 8 || std::stoi(part) > 10000) {
      throw osc::CommandLineError("--size: '" + text + "' is not WxH with 8 <= W, H <= 10000");
    }
    return std::stoi(part);
  };
  if (x == std::string::npos) number("");
  a->width = number(text.substr(0, x));
  a->height = number(text.substr(x + 1));
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
  Arguments a;
  std::string size = "640x480";
  int seed = static_cast<int>(a.seed);
  osc::CommandLine cli = commandLine(&a, &size, &seed);
  return osc::runTool(
      "render_sample", [&] { return cli.usage(); },
      [&] {
        if (!cli.parse(argc, argv)) return EXIT_SUCCESS;
        parseSize(size, &a);
        a.seed = static_cast<unsigned>(seed);
        osc::SceneConfig config;
        config.seed = a.seed;
        const osc::StereoSceneRenderer renderer(config);
        const osc::CameraModel camera = makeCamera(a);
        osc::Vector6d body;
        body << a.x, a.y, renderer.scene().groundHeight(a.x, a.y) + 1.5, 0.0, a.pitch, a.yaw;
        const Eigen::Isometry3d T_world_left =
            osc::poseFromParameters(body) * osc::bodyFromOptical();
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
      });
}
