#include "online_stereo_calibration/tools/campaign_draw.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <random>
#include <stdexcept>

#include "online_stereo_calibration/core/geometry/pose_interpolation.h"
#include "online_stereo_calibration/tools/tum_trajectory.h"

namespace osc {

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kRateHz = 10.0;
/// Draw's stream of the steering phase (see Draw(seed, stream)).
constexpr std::uint64_t kYawPhaseStream = 1;

/// Draws from a fully specified generator (std::mt19937_64) with our own conversions, so that
/// a seed gives the same values with any standard library.
class Draw {
 public:
  static std::uint64_t splitMix64(std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  }
  /// The seed goes through SplitMix64 first, so that neighbouring seeds (S + k) start the
  /// Mersenne Twister from unrelated states.
  explicit Draw(unsigned seed) : rng_(splitMix64(seed)) {}
  /// Stream @p stream (> 0) of @p seed: unrelated to Draw(seed), so that a value added to the
  /// campaign later leaves every value drawn before it unchanged.
  Draw(unsigned seed, std::uint64_t stream) : rng_(splitMix64(splitMix64(seed) + stream)) {}
  /// Uniform in [0, 1).
  double unit() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }
  double uniform(const DrawRange& r) { return r.min + (r.max - r.min) * unit(); }
  /// An integer uniform in [min, max] (both integers).
  int integer(const DrawRange& r) {
    const int low = static_cast<int>(r.min), high = static_cast<int>(r.max);
    return std::min(high, low + static_cast<int>(unit() * (high - low + 1)));
  }
  double sign() { return unit() < 0.5 ? -1.0 : 1.0; }
  /// A kind by weight.
  std::string kind(const KindChoice& choice) {
    double sum = 0.0;
    for (const auto& kw : choice.weights) sum += kw.second;
    double x = unit() * sum;
    for (const auto& kw : choice.weights) {
      if (kw.second > 0.0 && x < kw.second) return kw.first;
      x -= kw.second;
    }
    for (auto it = choice.weights.rbegin(); it != choice.weights.rend(); ++it) {
      if (it->second > 0.0) return it->first;
    }
    return choice.weights.front().first;
  }
  /// A unit vector, uniform on the sphere.
  Eigen::Vector3d direction() {
    const double z = 2.0 * unit() - 1.0, phi = 2.0 * M_PI * unit();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z);
  }

 private:
  std::mt19937_64 rng_;
};

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g", value);
  return text;
}

std::string stem(const std::string& path) {
  const auto slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const auto dot = name.find_last_of('.');
  return dot == std::string::npos ? name : name.substr(0, dot);
}

}  // namespace

std::vector<std::string> campaignSettingNames(bool images) {
  std::vector<std::string> names = {"baseline_m",
                                    "image_width",
                                    "image_height",
                                    "focal_px",
                                    "lens",
                                    "k1",
                                    "mounting",
                                    "pitch_down_deg",
                                    "motion",
                                    "trajectory",
                                    "trajectory_start_s",
                                    "speed_mps",
                                    "roll_pitch_std_deg",
                                    "heave_m",
                                    "yaw_rate_deg_s",
                                    "yaw_phase_deg",
                                    "stops",
                                    "stop_s",
                                    "start_caml_m",
                                    "start_caml_deg",
                                    "start_baseline_percent",
                                    "start_camr_m",
                                    "start_camr_deg",
                                    "event",
                                    "event_frame",
                                    "event_deg",
                                    "event_mm_per_min",
                                    "odo_time_offset_ms",
                                    "odo_scale_percent",
                                    "odo_rotation_bias_deg_s",
                                    "odo_velocity_bias_mps",
                                    "blind_s",
                                    "moving_fraction",
                                    "moving_speed_mps"};
  if (images) {
    for (const char* name : {"image_noise", "image_blur_px", "image_flicker"}) {
      names.push_back(name);
    }
  }
  names.push_back("odo_white_noise_factor");  // drawn last
  return names;
}

CampaignRunSpec drawCampaignRun(const CampaignRanges& ranges, int run, unsigned seed, int frames,
                                bool images) {
  CampaignRunSpec spec;
  spec.run = run;
  spec.seed = seed;
  Draw draw(seed);
  MeasurementScenario& s = spec.scenario;
  s.name = "campaign_run_" + std::to_string(run);
  s.frames = frames;
  s.rate_hz = kRateHz;
  s.seed = seed;
  const double duration = frames / kRateHz;
  CampaignSettings& out = spec.settings;
  const auto set = [&out](const std::string& name, const std::string& value) {
    out.emplace_back(name, value);
  };

  // --- rig ---
  const double baseline = draw.uniform(ranges.baseline_m);
  const int width = 8 * static_cast<int>(std::lround(draw.uniform(ranges.image_width_px) / 8.0));
  const int height = width * 3 / 4;
  const double focal = draw.uniform(ranges.focal_px);
  const std::string lens = draw.kind(ranges.lens);
  const double plumb_k1 = draw.uniform(ranges.plumb_bob_k1);
  const double equidistant_k1 = draw.uniform(ranges.equidistant_k1);
  const std::string mounting = draw.kind(ranges.mounting);
  const double pitch_down = draw.uniform(ranges.forward_pitch_down_deg);
  const double side = draw.sign();
  CameraIntrinsics camera;
  camera.width = width;
  camera.height = height;
  camera.fx = camera.fy = focal;
  camera.cx = (width - 1) / 2.0;
  camera.cy = (height - 1) / 2.0;
  double k1 = 0.0;
  if (lens == "plumb_bob") {
    // The polynomial r (1 + k1 r^2) folds back at r = 1 / sqrt(3 |k1|); keep that beyond twice
    // the image corner's normalized radius, or rays beyond the fold would map into the image.
    const double corner = std::hypot(width / 2.0, height / 2.0) / focal;
    const double limit = 1.0 / (12.0 * corner * corner);
    k1 = std::clamp(plumb_k1, -limit, limit);
    camera.model = DistortionModel::kPlumbBob;
    camera.distortion = {k1, 0.0, 0.0, 0.0, 0.0};
  } else if (lens == "equidistant") {
    k1 = equidistant_k1;
    camera.model = DistortionModel::kEquidistant;
    camera.distortion = {k1, 0.0, 0.0, 0.0};
  }
  s.left = s.right = camera;
  double pitch = 0.0;
  s.truth.setZero();
  if (mounting == "forward") {  // behind the windscreen
    pitch = pitch_down;
    s.truth.head<6>() << 1.5, 0.15, 1.3, 0.0, pitch * kDeg, 0.0;
  } else if (mounting == "backward") {  // at the top of the tailgate
    s.truth.head<6>() << -0.8, 0.0, 1.4, 0.0, 0.0, M_PI;
  } else {  // under a side mirror, looking left (+90 deg) or right (-90 deg)
    s.truth.head<6>() << 1.0, side * 0.9, 1.1, 0.0, 0.0, side * M_PI / 2.0;
  }
  s.truth(7) = -baseline;  // the right camera to the right of the left one
  set("baseline_m", number(baseline));
  set("image_width", std::to_string(width));
  set("image_height", std::to_string(height));
  set("focal_px", number(focal));
  set("lens", lens);
  set("k1", number(k1));
  set("mounting",
      mounting == "sideways" ? (side > 0 ? "sideways_left" : "sideways_right") : mounting);
  set("pitch_down_deg", number(pitch));

  // --- motion ---
  const std::string motion = draw.kind(ranges.motion);
  const double offroad_speed = draw.uniform(ranges.offroad_speed_mps);
  const double roll_pitch_std = draw.uniform(ranges.offroad_roll_pitch_std_deg);
  const double heave = draw.uniform(ranges.offroad_heave_m);
  const double yaw_rate = draw.uniform(ranges.offroad_yaw_rate_deg_s);
  const double urban_speed = draw.uniform(ranges.urban_speed_mps);
  const int stops = draw.integer(ranges.urban_stops);
  const double ramp = draw.uniform(ranges.urban_stop_ramp_s);
  const double trajectory_pick = draw.unit(), trajectory_start = draw.unit();
  std::string trajectory = "-", trajectory_start_text = "-";
  double stop_total = 0.0;
  int stops_made = 0;
  if (motion == "offroad") {
    s.motion.speed = offroad_speed;
    s.motion.roll_amplitude = s.motion.pitch_amplitude = roll_pitch_std * M_SQRT2 * kDeg;
    s.motion.heave_amplitude = heave;
    s.motion.yaw_rate_amplitude = yaw_rate * kDeg;
  } else if (motion == "urban") {
    s.motion.planar = true;
    s.motion.speed = urban_speed;
    s.motion.stop_ramp = ramp;
    // One slot of the drive per stop; each stop with its ramps inside its slot, shortened to
    // fit a short drive (and left out if less than 0.5 s would remain).
    const double slot = duration / std::max(stops, 1);
    for (int i = 0; i < stops; ++i) {
      const double wanted = draw.uniform(ranges.urban_stop_duration_s);
      const double where = draw.unit();
      const double room = slot - 2.0 * ramp - 1.0;
      const double length = std::min(wanted, room);
      if (length < 0.5) continue;
      TimeSpan span;
      span.duration = length;
      span.start = i * slot + ramp + 0.5 + where * (room - length);
      s.motion.stops.push_back(span);
      stop_total += length;
      ++stops_made;
    }
  } else {  // recorded
    const auto& files = ranges.trajectory_files;
    if (files.empty()) throw std::invalid_argument("motion 'recorded': no trajectory files");
    const std::string& file =
        files[std::min(files.size() - 1, static_cast<size_t>(trajectory_pick * files.size()))];
    trajectory = stem(file);
    try {
      auto recorded = std::make_shared<PoseTrajectory>(readTumTrajectory(file));
      const double length = recorded->lastStamp() - recorded->firstStamp();
      if (length < duration + 0.2) {
        spec.error = "trajectory '" + file + "' lasts " + number(length) +
                     " s, shorter than the drive of " + number(duration) + " s";
      } else {
        s.recorded_trajectory = recorded;
        s.recorded_start_offset = trajectory_start * (length - duration - 0.2);
      }
    } catch (const std::exception& e) {
      spec.error = e.what();
    }
    trajectory_start_text = number(s.recorded_start_offset);
  }
  set("motion", motion);
  set("trajectory", trajectory);
  set("trajectory_start_s", trajectory_start_text);
  set("speed_mps", motion == "recorded" ? "-" : number(s.motion.speed));
  set("roll_pitch_std_deg", motion == "offroad" ? number(roll_pitch_std) : "-");
  set("heave_m", motion == "offroad" ? number(heave) : "-");
  set("yaw_rate_deg_s", motion == "offroad" ? number(yaw_rate) : "-");
  // The steering's phase (added in session 34, when every drawn drive had started at the
  // height of a left turn), from a stream of its own: the runs' other values stay as before.
  const double yaw_phase_deg = Draw(seed, kYawPhaseStream).uniform(ranges.yaw_phase_deg);
  if (motion != "recorded") s.motion.yaw_phase = yaw_phase_deg * kDeg;
  set("yaw_phase_deg", motion == "recorded" ? "-" : number(yaw_phase_deg));
  set("stops", std::to_string(stops_made));
  set("stop_s", number(stop_total));

  // --- start errors ---
  Vector12d error = Vector12d::Zero();
  double caml_m = 0.0, caml_deg = 0.0, camr_m = 0.0, camr_deg = 0.0;
  for (int i = 0; i < 3; ++i) {
    error(i) = draw.sign() * draw.uniform(ranges.caml_translation_error_m);
    caml_m = std::max(caml_m, std::abs(error(i)));
  }
  for (int i = 3; i < 6; ++i) {
    const double deg = draw.uniform(ranges.caml_angle_error_deg);
    error(i) = draw.sign() * deg * kDeg;
    caml_deg = std::max(caml_deg, deg);
  }
  const double baseline_percent = draw.uniform(ranges.camr_baseline_error_percent);
  error(7) = -baseline * baseline_percent / 100.0;  // the guessed baseline is that much longer
  for (int i : {6, 8}) {
    error(i) = draw.sign() * draw.uniform(ranges.camr_translation_error_m);
    camr_m = std::max(camr_m, std::abs(error(i)));
  }
  for (int i = 9; i < 12; ++i) {
    const double deg = draw.uniform(ranges.camr_angle_error_deg);
    error(i) = draw.sign() * deg * kDeg;
    camr_deg = std::max(camr_deg, deg);
  }
  s.initial_error = error;
  set("start_caml_m", number(caml_m));
  set("start_caml_deg", number(caml_deg));
  set("start_baseline_percent", number(baseline_percent));
  set("start_camr_m", number(camr_m));
  set("start_camr_deg", number(camr_deg));

  // --- events ---
  const std::string event = draw.kind(ranges.event);
  const int event_frame =
      static_cast<int>(std::lround(draw.uniform(ranges.event_at_fraction) * frames));
  const double yaw_step = draw.sign() * draw.uniform(ranges.caml_yaw_step_deg);
  const double knock = draw.uniform(ranges.camr_knock_deg);
  const Eigen::Vector3d knock_axis = draw.direction();
  const double drift_deg = draw.uniform(ranges.camr_drift_deg_per_min);
  const Eigen::Vector3d drift_axis = draw.direction();
  const double drift_mm = draw.uniform(ranges.camr_drift_mm_per_min);
  const Eigen::Vector3d drift_direction = draw.direction();
  s.step.setZero();
  s.step_frame = -1;
  s.drift_per_second.setZero();
  double event_deg = 0.0, event_mm = 0.0;
  if (event == "caml_yaw_step") {
    s.step_frame = event_frame;
    s.step(5) = yaw_step * kDeg;
    event_deg = yaw_step;
  } else if (event == "camr_knock") {
    s.step_frame = event_frame;
    s.step.segment<3>(9) = knock * kDeg * knock_axis;  // small angles: RPY ~ rotation vector
    event_deg = knock;
  } else if (event == "camr_drift") {
    s.drift_per_second.segment<3>(9) = drift_deg * kDeg / 60.0 * drift_axis;
    s.drift_per_second.segment<3>(6) = drift_mm * 1e-3 / 60.0 * drift_direction;
    event_deg = drift_deg;
    event_mm = drift_mm;
  }
  set("event", event);
  set("event_frame", std::to_string(s.step_frame));
  set("event_deg", number(event_deg));
  set("event_mm_per_min", number(event_mm));

  // --- odometry ---
  s.odometry_error.time_offset = draw.uniform(ranges.time_offset_ms) * 1e-3;
  s.odometry_error.scale_error = draw.uniform(ranges.scale_error_percent) * 1e-2;
  s.odometry_error.rotation_rate_bias = draw.uniform(ranges.rotation_rate_bias_deg_s) * kDeg;
  s.odometry_error.velocity_bias = draw.uniform(ranges.velocity_bias_mps);
  s.odometry_error.bias_correlation_time = draw.uniform(ranges.bias_correlation_time_s);
  set("odo_time_offset_ms", number(s.odometry_error.time_offset * 1e3));
  set("odo_scale_percent", number(s.odometry_error.scale_error * 1e2));
  set("odo_rotation_bias_deg_s", number(s.odometry_error.rotation_rate_bias / kDeg));
  set("odo_velocity_bias_mps", number(s.odometry_error.velocity_bias));

  // --- scene: blind stretches after the first 3 s, one slot of the rest each; moving points
  const int blind = draw.integer(ranges.blind_stretches);
  double blind_total = 0.0;
  const double blind_from = 3.0;
  const double blind_slot = (duration - blind_from) / std::max(blind, 1);
  for (int i = 0; i < blind; ++i) {
    const double wanted = draw.uniform(ranges.blind_duration_s);
    const double where = draw.unit();
    const double length = std::min(wanted, 0.8 * blind_slot);
    if (length * kRateHz < 1.0) continue;
    FrameSpan span;
    span.first = static_cast<int>(
        std::lround((blind_from + i * blind_slot + where * (blind_slot - length)) * kRateHz));
    span.last =
        std::min(frames - 1, span.first + static_cast<int>(std::lround(length * kRateHz)) - 1);
    if (span.last < span.first) continue;
    s.blind_frames.push_back(span);
    blind_total += (span.last - span.first + 1) / kRateHz;
  }
  s.moving_point_fraction = draw.uniform(ranges.moving_point_fraction);
  s.moving_point_speed = draw.uniform(ranges.moving_point_speed_mps);
  set("blind_s", number(blind_total));
  set("moving_fraction", number(s.moving_point_fraction));
  set("moving_speed_mps", number(s.moving_point_speed));

  // --- images ---
  ImageScenarioOptions& image = spec.image_options;
  image.scene.seed = seed;
  image.render.noise_sigma = draw.uniform(ranges.image_noise_grey);
  image.render.blur_sigma = draw.uniform(ranges.image_blur_px);
  image.exposure_variation = draw.uniform(ranges.exposure_flicker);
  image.check_all_matches = false;
  if (images) {
    set("image_noise", number(image.render.noise_sigma));
    set("image_blur_px", number(image.render.blur_sigma));
    set("image_flicker", number(image.exposure_variation));
  }

  // --- the odometry's white noise, drawn last (campaign_ranges.h) ---
  const double white = draw.uniform(ranges.white_noise_factor);
  s.motion_translation_noise *= white;
  s.motion_rotation_noise *= white;
  set("odo_white_noise_factor", number(white));
  return spec;
}

}  // namespace osc
