/// @file test_front_end_diagnostics.cpp
/// @brief Diagnostics of the image front end on a rendered drive, not a check (a DISABLED_
/// test, run with --gtest_also_run_disabled_tests): every wrong stereo match and track with
/// its true pixel, depth and depth discontinuity.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "front_end_test_support.h"
#include "online_stereo_calibration/core/frontend/stereo_front_end.h"
#include "online_stereo_calibration/core/sim/image_scenario_runner.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"

namespace osc {
namespace {

// ---- diagnostics (temporary) ----
struct DiagCtx {
  const StereoSceneRenderer* renderer;
  const CameraModel* left;
  const CameraModel* right;
  Eigen::Isometry3d Tl, Tr;
};
// depth (m, along optical z) of the surface seen at a pixel, -1 for sky
double diagDepth(const DiagCtx& c, const CameraModel& cam, const Eigen::Isometry3d& T,
                 const Eigen::Vector2d& px) {
  const auto p = c.renderer->surfacePoint(cam, T, px);
  if (!p) return -1.0;
  return (T.inverse() * *p).z();
}
// largest relative depth change within r px around px
double diagEdge(const DiagCtx& c, const CameraModel& cam, const Eigen::Isometry3d& T,
                const Eigen::Vector2d& px, double r) {
  const double d0 = diagDepth(c, cam, T, px);
  double worst = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const double d = diagDepth(c, cam, T, px + r * Eigen::Vector2d(dx, dy));
      if (d0 < 0 || d < 0) {
        if ((d0 < 0) != (d < 0)) worst = std::max(worst, 10.0);
        continue;
      }
      worst = std::max(worst, std::abs(d - d0) / d0);
    }
  return worst;
}
// prints one line about a pair; returns error (px) or -1 if not visible
double diagPair(const DiagCtx& c, const char* tag, const Eigen::Vector2d& pl,
                const Eigen::Vector2d& pr, bool print_ok) {
  const auto p = c.renderer->surfacePoint(*c.left, c.Tl, pl);
  Eigen::Vector2d proj(-1, -1);
  bool vis = false;
  if (p) vis = c.renderer->projectVisible(*c.right, c.Tr, *p, &proj);
  const double err = p ? (proj - pr).norm() : -1.0;
  const bool ok =
      checkStereoMatch(*c.renderer, *c.left, *c.right, c.Tl, c.Tr, pl, pr, 1.5).point.has_value();
  if (ok && !print_ok) return err;
  const double depth = diagDepth(c, *c.left, c.Tl, pl);
  std::printf(
      "%s %s L(%.0f,%.0f) R(%.1f,%.1f) true(%.1f,%.1f) vis %d err %.2f dx %.2f dy %.2f depth %.1f "
      "edgeL %.2f edgeR %.2f\n",
      tag, ok ? "OK " : "BAD", pl.x(), pl.y(), pr.x(), pr.y(), proj.x(), proj.y(), vis, err,
      pr.x() - proj.x(), pr.y() - proj.y(), depth, diagEdge(c, *c.left, c.Tl, pl, 2.0),
      diagEdge(c, *c.right, c.Tr, pr, 2.0));
  return err;
}

/// Diagnostics, not a check (run with --gtest_also_run_disabled_tests): prints every wrong
/// stereo match (M) and track (T) with its true pixel, error along/across the line, depth
/// and depth discontinuity around the pixel (edgeL/R: largest relative depth change within
/// 2 px; 10 = sky), every track off its birth point (B), and a SUMMARY. Environment:
/// DIAG_FRAMES, DIAG_DISTORT (plumb_bob, or "equidistant"), D_QUIET, D_IMG (debug image of
/// frame 5), D_CROP=id (x8 crops of that point's images from its birth on,
/// /tmp/crop_ID_FRAME.png, and the depths around it), D_INNOV (each track's innovation against
/// the filter's prediction: I lines), D_NOISE, D_BLUR, D_FLICKER (the image options) and D_*
/// overrides of the FrontEndConfig.
TEST(FrontEndDiag, DISABLED_DumpWrongMatchesAndTracks) {
  const int frames = std::getenv("DIAG_FRAMES") ? std::atoi(std::getenv("DIAG_FRAMES")) : 25;
  MeasurementScenario s = shortDrive(frames);
  if (std::getenv("DIAG_DISTORT")) {  // "equidistant", or anything else for plumb_bob
    const bool equidistant = std::string(std::getenv("DIAG_DISTORT")) == "equidistant";
    for (CameraIntrinsics* k : {&s.left, &s.right}) {
      k->model = equidistant ? DistortionModel::kEquidistant : DistortionModel::kPlumbBob;
      k->distortion = equidistant ? std::vector<double>{-0.01, 0.005, -0.002, 0.0}
                                  : std::vector<double>{-0.28, 0.074, 0.0002, 0.00002, 0.0};
      if (std::getenv("D_K")) {  // comma-separated distortion coefficients
        k->distortion.clear();
        std::string list = std::getenv("D_K");
        for (size_t at = 0; at < list.size();) {
          const size_t end = std::min(list.find(',', at), list.size());
          k->distortion.push_back(std::atof(list.substr(at, end - at).c_str()));
          at = end + 1;
        }
      }
    }
  }
  MeasurementSimulator sim(s);
  ImageScenarioOptions options;
  if (std::getenv("D_NOISE")) options.render.noise_sigma = std::atof(std::getenv("D_NOISE"));
  if (std::getenv("D_BLUR")) options.render.blur_sigma = std::atof(std::getenv("D_BLUR"));
  if (std::getenv("D_FLICKER")) options.exposure_variation = std::atof(std::getenv("D_FLICKER"));
  SceneConfig scene = options.scene;
  scene.path = sim.groundTrack();
  const StereoSceneRenderer renderer(scene);
  DiagCtx c{&renderer, &sim.leftCamera(), &sim.rightCamera(), {}, {}};
  FrontEndConfig fe;
  auto envd = [](const char* n, double* v) {
    if (std::getenv(n)) *v = std::atof(std::getenv(n));
  };
  auto envi = [](const char* n, int* v) {
    if (std::getenv(n)) *v = std::atoi(std::getenv(n));
  };
  if (std::getenv("D_DET")) fe.detector = std::getenv("D_DET");
  envi("D_MAXF", &fe.max_features);
  envi("D_FAST", &fe.fast_threshold);
  envd("D_RATIO", &fe.ratio);
  envd("D_TRATIO", &fe.track_ratio);
  envd("D_NCC", &fe.min_patch_ncc);
  if (std::getenv("D_SEARCH")) fe.search_lost_tracks = true;
  envi("D_DISC", &fe.discontinuity_search);
  envd("D_SNCC", &fe.min_search_ncc);
  envd("D_FB", &fe.max_forward_backward);
  envd("D_EIG", &fe.min_patch_eigen_ratio);
  envd("D_RSIG", &fe.refined_pixel_sigma);
  envd("D_ANCHOR", &fe.max_anchor_shift);
  envd("D_TSHIFT", &fe.max_temporal_shift);
  envi("D_CORNER", &fe.corner_half_size);
  envd("D_CORNER_SHIFT", &fe.max_corner_shift);
  envd("D_MAXD", &fe.max_descriptor_distance);
  envd("D_TMAXD", &fe.max_track_descriptor_distance);
  envi("D_HALF", &fe.patch_half_size);
  const bool quiet = std::getenv("D_QUIET") != nullptr;
  // D_CROP=id: x8 crops of that point's left and right images around its pixels
  // (/tmp/crop_ID_FRAME.png; the reported pixel in red, `left_truth` / `right_truth` in green)
  // and the left image's depth (m, -1 sky) every 2 px around it. True if it was that point.
  auto showCrop = [&](int frame, const StereoObservation& o, const Eigen::Vector2d& left_truth,
                      const Eigen::Vector2d& right_truth) {
    if (!std::getenv("D_CROP") || o.id != std::strtoul(std::getenv("D_CROP"), nullptr, 10))
      return false;
    RenderOptions ro = options.render;
    ro.noise_seed = 2u * static_cast<unsigned>(frame) + 1u;
    const cv::Mat li = renderer.render(*c.left, c.Tl, ro);
    ro.noise_seed += 1u;
    const cv::Mat ri = renderer.render(*c.right, c.Tr, ro);
    auto crop = [](const cv::Mat& im, const Eigen::Vector2d& at, const Eigen::Vector2d& truth) {
      const int R = 12, S = 8;
      cv::Mat out;
      cv::Mat patch;
      cv::getRectSubPix(im, cv::Size(2 * R + 1, 2 * R + 1),
                        cv::Point2f(std::round(at.x()), std::round(at.y())), patch);
      cv::resize(patch, out, cv::Size(), S, S, cv::INTER_NEAREST);
      cv::cvtColor(out, out, cv::COLOR_GRAY2BGR);
      auto mark = [&](const Eigen::Vector2d& p, cv::Scalar col) {
        const Eigen::Vector2d q =
            (p - Eigen::Vector2d(std::round(at.x()) - R, std::round(at.y()) - R)) * S +
            Eigen::Vector2d(S / 2, S / 2);
        cv::circle(out, cv::Point(q.x(), q.y()), 5, col, 2);
      };
      mark(at, cv::Scalar(0, 0, 255));
      mark(truth, cv::Scalar(0, 255, 0));
      return out;
    };
    std::printf("DEPTHS id %lu frame %d\n", (unsigned long)o.id, frame);
    for (int dy = -6; dy <= 6; dy += 2) {
      for (int dx = -6; dx <= 6; dx += 2)
        std::printf(" %6.1f", diagDepth(c, *c.left, c.Tl, o.left_pixel + Eigen::Vector2d(dx, dy)));
      std::printf("\n");
    }
    cv::Mat both;
    cv::hconcat(crop(li, o.left_pixel, left_truth), crop(ri, o.right_pixel, right_truth), both);
    cv::imwrite("/tmp/crop_" + std::to_string(o.id) + "_" + std::to_string(frame) + ".png", both);
    return true;
  };
  DriveFigures f;
  std::map<PointId, std::pair<std::vector<Eigen::Vector3d>, int>> births;
  runImageScenario(
      s, confidentConfig(), fe, options,
      [&](const ImageFrameResult& r, const CalibrationPipeline& pipeline) {
        SimulatedFrame frame;
        sim.nextFrame(&frame);
        c.Tl = frame.T_world_veh * frame.truth.vehicleToLeftOptical();
        c.Tr = c.Tl * frame.truth.leftToRightOptical();
        f.matches += r.matches_checked;
        f.matches_correct += r.matches_correct;
        f.tracks += r.tracks_checked;
        f.tracks_correct += r.tracks_correct;
        f.tracks_reported += r.tracks_reported;
        f.tracks_stereo_correct += r.tracks_stereo_correct;
        f.new_points += r.new_checked;
        f.new_correct += r.new_correct;
        f.final_points = r.filter.tracked_points;
        std::printf("FRAME %d matches %d/%d tracks %d/%d birth %d/%d points %d\n", r.filter.frame,
                    r.matches_correct, r.matches_checked, r.tracks_stereo_correct,
                    r.tracks_reported, r.tracks_correct, r.tracks_checked, r.filter.tracked_points);
        for (const auto& o : pipeline.frontEnd().lastTracked()) {
          auto it = births.find(o.id);
          if (it == births.end() || it->second.first.empty()) continue;
          // The birth candidate nearest the pair now.
          Eigen::Vector2d pl, pr;
          bool vl = false, vr = false;
          double el = 1e9, er = 1e9;
          for (const Eigen::Vector3d& p : it->second.first) {
            Eigen::Vector2d ql, qr;
            const bool wl = renderer.projectVisible(*c.left, c.Tl, p, &ql);
            const bool wr = renderer.projectVisible(*c.right, c.Tr, p, &qr);
            const double dl = (ql - o.left_pixel).norm(), dr = (qr - o.right_pixel).norm();
            if (std::max(dl, dr) < std::max(el, er)) {
              pl = ql, pr = qr, vl = wl, vr = wr, el = dl, er = dr;
            }
          }
          showCrop(r.filter.frame, o, pl, pr);
          const bool off_birth = !(vl && vr && el <= 1.5 && er <= 1.5);
          // The track's innovation against the filter's prediction (undistorted pixels: the
          // reported raw ones are the same on the pinhole drives only).
          if (std::getenv("D_INNOV")) {
            for (const TrackWindow& w : pipeline.frontEnd().lastWindows()) {
              if (w.id != o.id) continue;
              const Eigen::Vector4d z(o.left_pixel.x(), o.left_pixel.y(), o.right_pixel.x(),
                                      o.right_pixel.y());
              const Eigen::Vector4d e = z - w.z;
              std::printf(
                  "I id %lu frame %d age %d bad %d e %.2f %.2f %.2f %.2f nis %.2f sd %.2f %.2f "
                  "%.2f %.2f\n",
                  (unsigned long)o.id, r.filter.frame, r.filter.frame - it->second.second,
                  off_birth, e(0), e(1), e(2), e(3), e.dot(w.S.inverse() * e), std::sqrt(w.S(0, 0)),
                  std::sqrt(w.S(1, 1)), std::sqrt(w.S(2, 2)), std::sqrt(w.S(3, 3)));
            }
          }
          if (off_birth && !quiet)
            std::printf(
                "B id %lu age %d vis %d%d L(%.0f,%.0f) errL %.2f (%.2f,%.2f) errR %.2f depth %.1f "
                "edgeL %.2f\n",
                (unsigned long)o.id, r.filter.frame - it->second.second, vl, vr, o.left_pixel.x(),
                o.left_pixel.y(), el, o.left_pixel.x() - pl.x(), o.left_pixel.y() - pl.y(), er,
                diagDepth(c, *c.left, c.Tl, o.left_pixel),
                diagEdge(c, *c.left, c.Tl, o.left_pixel, 2.0));
        }
        for (const auto& o : pipeline.frontEnd().lastNewCandidates()) {
          if (!pipeline.estimator().filter().hasPoint(o.id)) continue;
          births[o.id] = {scenePointsOfStereoMatch(renderer, *c.left, *c.right, c.Tl, c.Tr,
                                                   o.left_pixel, o.right_pixel, 1.5),
                          r.filter.frame};
          if (showCrop(r.filter.frame, o, o.left_pixel, o.right_pixel))
            std::printf("BIRTH of %lu above: disparity %.2f\n", (unsigned long)o.id,
                        o.left_pixel.x() - o.right_pixel.x());
        }
        if (std::getenv("D_IMG") && r.filter.frame == 5)
          cv::imwrite(std::getenv("D_IMG"), pipeline.debugImage());
        if (quiet) return;
        for (const auto& o : pipeline.frontEnd().lastStereoMatches())
          diagPair(c, "M", o.left_pixel, o.right_pixel, false);
        for (const auto& o : pipeline.frontEnd().lastTracked())
          diagPair(c, ("T " + std::to_string(o.id)).c_str(), o.left_pixel, o.right_pixel, false);
      });
  std::printf(
      "SUMMARY matches %d (%.2f %%) new %d (%.2f %%) tracks %d (stereo %.2f %%, birth %.2f %% of "
      "%d) points %d\n",
      f.matches, 100.0 * f.matches_correct / std::max(1, f.matches), f.new_points,
      100.0 * f.new_correct / std::max(1, f.new_points), f.tracks_reported,
      100.0 * f.tracks_stereo_correct / std::max(1, f.tracks_reported),
      100.0 * f.tracks_correct / std::max(1, f.tracks), f.tracks, f.final_points);
}

}  // namespace
}  // namespace osc
