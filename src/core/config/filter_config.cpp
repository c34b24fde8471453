#include "online_stereo_calibration/core/config/filter_config.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace osc {
namespace {

constexpr double kDeg = 0.0174532925199432958;

// The sections, by the component that uses the keys (filterParameterSections() gives their
// order in the files and a line on each).
constexpr const char* kRigAndNoise = "rig and noise";
constexpr const char* kStartPriors = "start priors";
constexpr const char* kOdometryModel = "odometry model";
constexpr const char* kPoints = "points";
constexpr const char* kInputChecks = "input checks";
constexpr const char* kStart = "start";
constexpr const char* kLinearisationGuard = "linearisation guard";
constexpr const char* kChangeDetection = "change detection";
constexpr const char* kConsistencyMonitor = "consistency monitor";
constexpr const char* kUnscentedTransform = "unscented transform";

// The audience: a user's key (rig, noise, priors, what is estimated) or an internal threshold
// tuned on measurements (docs/RESULTS.md).
constexpr bool kUser = false;
constexpr bool kAdvanced = true;

ParameterSpec real(const char* name, double FilterConfig::*field, double scale, double lo,
                   double hi, const char* section, bool advanced, const char* doc) {
  ParameterSpec s;
  s.name = name;
  s.doc = doc;
  s.file_to_internal = scale;
  s.min_value = lo;
  s.max_value = hi;
  s.real_field = field;
  s.section = section;
  s.advanced = advanced;
  return s;
}

ParameterSpec integer(const char* name, int FilterConfig::*field, int lo, int hi,
                      const char* section, bool advanced, const char* doc) {
  ParameterSpec s;
  s.name = name;
  s.doc = doc;
  s.min_value = lo;
  s.max_value = hi;
  s.is_integer = true;
  s.integer_field = field;
  s.section = section;
  s.advanced = advanced;
  return s;
}

}  // namespace

double ParameterSpec::get(const FilterConfig& config) const {
  if (is_integer) return static_cast<double>(config.*integer_field);
  return config.*real_field / file_to_internal;
}

void ParameterSpec::set(FilterConfig* config, double file_value) const {
  if (is_integer) {
    config->*integer_field = static_cast<int>(std::lround(file_value));
  } else {
    config->*real_field = file_value * file_to_internal;
  }
}

const std::vector<ParameterSpec>& filterParameterTable() {
  using C = FilterConfig;
  static const std::vector<ParameterSpec> table = {
      real("ut_alpha", &C::ut_alpha, 1.0, 1e-3, 1.0, kUnscentedTransform, kAdvanced,
           "scaled unscented transform: sigma-point spread"),
      real("ut_beta", &C::ut_beta, 1.0, 0.0, 10.0, kUnscentedTransform, kAdvanced,
           "scaled unscented transform: 2 for Gaussian priors"),
      real("ut_kappa", &C::ut_kappa, 1.0, 0.0, 10.0, kUnscentedTransform, kAdvanced,
           "scaled unscented transform: secondary scaling"),
      real("reference_period_s", &C::reference_period, 1.0, 1e-3, 10.0, kRigAndNoise, kUser,
           "the step the per-step sigmas refer to (the seed's 10 Hz); a step of dt scales their "
           "variances by dt / this"),
      real("caml_translation_drift_m", &C::caml_translation_drift, 1.0, 0.0, 1.0, kRigAndNoise,
           kUser,
           "how far the vehicle->left camera translation may drift per reference step (random "
           "walk, eq. 10)"),
      real("caml_rotation_drift_deg", &C::caml_rotation_drift, kDeg, 0.0, 10.0, kRigAndNoise, kUser,
           "how far the vehicle->left camera rotation may drift per reference step (random walk, "
           "eq. 11)"),
      real("camr_translation_drift_m", &C::camr_translation_drift, 1.0, 0.0, 1.0, kRigAndNoise,
           kUser,
           "how far the left->right translation (the baseline) may drift per reference step "
           "(random walk, eq. 12)"),
      real("camr_rotation_drift_deg", &C::camr_rotation_drift, kDeg, 0.0, 10.0, kRigAndNoise, kUser,
           "how far the left->right rotation may drift per reference step (random walk, eq. 13)"),
      real("point_position_noise_m", &C::point_position_noise, 1.0, 0.0, 10.0, kRigAndNoise,
           kAdvanced, "sigma_p: point position noise per step (eq. 14)"),
      real("motion_rotation_noise_deg", &C::motion_rotation_noise, kDeg, 0.0, 10.0, kRigAndNoise,
           kUser,
           "1 sigma of the odometry's rotation error per vehicle axis per reference step (the "
           "seed's sigma_IMU, eq. 15)"),
      real("motion_translation_noise_m", &C::motion_translation_noise, 1.0, 0.0, 10.0, kRigAndNoise,
           kUser,
           "1 sigma of the odometry's translation error per vehicle axis per reference step "
           "(motion_noise_model shared; the seed has none)"),
      integer("motion_relinearizations", &C::motion_relinearizations, 0, 5, kOdometryModel,
              kAdvanced,
              "shared model: repeat the step linearised at the corrected motion while the "
              "vehicle is slower than 2 m/s (0 = off)"),
      real("motion_excitation_window_s", &C::motion_excitation_window, 1.0, 0.0, 1e4,
           kOdometryModel, kAdvanced,
           "window of the measured rotation's mean square; rotation within the motion noise is "
           "not excitation of the camera position (0 = off, as the paper)"),
      real("pixel_noise_px", &C::pixel_noise, 1.0, 1e-3, 100.0, kRigAndNoise, kUser,
           "1 sigma of a feature's position in the raw image (measurements without a sigma of "
           "their own, as the image front end's, use it); the lens model stretches it for the "
           "undistorted pixels the filter measures"),
      real("outlier_gate", &C::outlier_gate, 1.0, 1.0, 1e6, kPoints, kAdvanced,
           "chi-square(4) bound on a point's stereo innovation; beyond it the point is an outlier"),
      real("initial_caml_translation_sigma_m", &C::initial_caml_translation_sigma, 1.0, 1e-6, 100.0,
           kStartPriors, kUser,
           "1 sigma per axis of the guessed vehicle->left camera translation (where the camera is "
           "mounted)"),
      real("initial_caml_rotation_sigma_deg", &C::initial_caml_rotation_sigma, kDeg, 1e-6, 90.0,
           kStartPriors, kUser,
           "1 sigma per axis of the guessed vehicle->left camera rotation (how it is mounted)"),
      real("initial_camr_translation_sigma_m", &C::initial_camr_translation_sigma, 1.0, 1e-6, 10.0,
           kStartPriors, kUser,
           "1 sigma per axis of the guessed left->right translation (the baseline)"),
      real("initial_camr_rotation_sigma_deg", &C::initial_camr_rotation_sigma, kDeg, 1e-6, 90.0,
           kStartPriors, kUser, "1 sigma per axis of the guessed left->right rotation"),
      real("min_point_depth_m", &C::min_point_depth, 1.0, 0.01, 1e4, kPoints, kUser,
           "new points closer than this to the left camera are not added"),
      real("max_point_depth_m", &C::max_point_depth, 1.0, 0.01, 1e5, kPoints, kUser,
           "new points farther than this from the left camera are not added"),
      integer("max_points", &C::max_points, 1, 100000, kPoints, kUser,
              "points kept in the filter state (the time per frame grows steeply with them)"),
      integer("inverse_depth_points", &C::inverse_depth_points, 0, 1, kPoints, kAdvanced,
              "1: points as inverse depth (x/z, y/z, 1/z), 0: as positions (the seed's)"),
      integer("baseline_scaled_points", &C::baseline_scaled_points, 0, 1, kPoints, kAdvanced,
              "1: points in units of the baseline (what stereo measures), 0: metric (the seed's)"),
      real("max_speed_mps", &C::max_speed, 1.0, 0.0, 1e4, kInputChecks, kUser,
           "a motion increment faster than this is rejected as corrupt"),
      real("max_angular_rate_dps", &C::max_angular_rate, kDeg, 0.0, 1e5, kInputChecks, kUser,
           "a motion increment turning faster than this is rejected as corrupt (default: 3 rad/s)"),
      real("max_frame_interval_s", &C::max_frame_interval, 1.0, 1e-3, 1e4, kInputChecks, kUser,
           "a longer gap between image pairs is rejected (motion unusable)"),
      real("jump_rejected_fraction", &C::jump_rejected_fraction, 1.0, 0.0, 1.0, kChangeDetection,
           kAdvanced, "fraction of gated-out points that signals a sudden calibration change"),
      integer("jump_min_points", &C::jump_min_points, 1, 100000, kChangeDetection, kAdvanced,
              "least number of tested points for the jump test"),
      real("jump_sustained_rejected_fraction", &C::jump_sustained_rejected_fraction, 1.0, 0.0, 1.0,
           kChangeDetection, kAdvanced,
           "a smaller fraction of gated-out points that signals a sudden calibration change "
           "when it holds jump_sustained_frames frames in a row"),
      integer("jump_sustained_frames", &C::jump_sustained_frames, 0, 100000, kChangeDetection,
              kAdvanced, "frames in a row for that (0 = off)"),
      real("jump_rotation_sigma_deg", &C::jump_rotation_sigma, kDeg, 0.0, 90.0, kChangeDetection,
           kAdvanced, "rotation 1 sigma re-opened after a detected jump"),
      real("jump_translation_sigma_m", &C::jump_translation_sigma, 1.0, 0.0, 10.0, kChangeDetection,
           kAdvanced, "translation 1 sigma re-opened after a detected jump"),
      real("jump_fit_rotation_sigma_deg", &C::jump_fit_rotation_sigma, kDeg, 0.0, 90.0,
           kChangeDetection, kAdvanced,
           "x_caml after a jump seen by most tracked points at once: its rotation is fitted "
           "to their left bearings and each axis re-opened to max(this, what it turned) "
           "instead of jump_rotation_sigma_deg (0 = off: every axis to that)"),
      real("jump_settle_time_s", &C::jump_settle_time, 1.0, 0.0, 1e6, kChangeDetection, kAdvanced,
           "time after a block's start or re-opening from which its rotation alone decides "
           "whether a jump can re-open it (a translation the motion cannot tell stays wide)"),
      real("jump_score_false_alarm", &C::jump_score_false_alarm, 1.0, 0.0, 0.5, kChangeDetection,
           kAdvanced,
           "false-alarm probability per update of the test that x_camr's rotation moved beyond "
           "its covariance (its score statistic, consistency_monitor.h); 0 = off"),
      integer("jump_score_updates", &C::jump_score_updates, 1, 1000, kChangeDetection, kAdvanced,
              "updates in a row beyond that bound before x_camr's rotation is widened"),
      real("jump_score_widening", &C::jump_score_widening, 1.0, 0.1, 100.0, kChangeDetection,
           kAdvanced,
           "x_camr's rotation variance grows by (this x the indicated rotation shift)^2 per axis"),
      real("epipolar_knock_false_alarm", &C::epipolar_knock_false_alarm, 1.0, 0.0, 0.5,
           kChangeDetection, kAdvanced,
           "false-alarm probability per image pair of the test that the stereo pairs left "
           "x_camr's epipolar lines (a knocked right camera; epipolar_consistency.h); 0 = off"),
      integer("epipolar_knock_pairs", &C::epipolar_knock_pairs, 1, 1000, kChangeDetection,
              kAdvanced,
              "image pairs in a row beyond that bound before x_camr's rotation is re-opened"),
      integer("relinearization_frames", &C::relinearization_frames, 0, 100000, kLinearisationGuard,
              kAdvanced,
              "frames between checks whether the estimate left its start (linearisation) "
              "point; 0 = never restart"),
      real("relinearization_threshold", &C::relinearization_threshold, 1.0, 0.0, 100.0,
           kLinearisationGuard, kAdvanced,
           "restart from the current estimate with the start's covariance when it moved more "
           "than this many start sigmas"),
      real("relinearization_nis", &C::relinearization_nis, 1.0, 0.0, 1e6, kLinearisationGuard,
           kAdvanced,
           "... and the updates' mean NIS per measured coordinate over those frames was above "
           "this (1 = as expected)"),
      real("relinearization_far_threshold", &C::relinearization_far_threshold, 1.0, 0.0, 100.0,
           kLinearisationGuard, kAdvanced,
           "a move of more than this many start sigmas restarts at the lower gate "
           "relinearization_far_nis (a start's wide sigmas hide a far-off linearisation from "
           "the innovations); until the first restart; 0 = off"),
      real("relinearization_far_nis", &C::relinearization_far_nis, 1.0, 0.0, 1e6,
           kLinearisationGuard, kAdvanced,
           "the NIS gate of such a far move, in place of relinearization_nis (below 1: "
           "innovations a little smaller than the start's sigmas predict still restart)"),
      integer("max_relinearizations", &C::max_relinearizations, 0, 1000, kLinearisationGuard,
              kAdvanced, "restarts at most after one start or re-opening"),
      real("max_sigma_shrink_per_update", &C::max_sigma_shrink_per_update, 1.0, 0.0, 1e6,
           kLinearisationGuard, kAdvanced,
           "largest factor by which one update may shrink a calibration sigma; a larger "
           "shrink (a start or re-opening far off) is tempered and spread over frames; "
           "0 = off"),
      integer("min_points_to_update", &C::min_points_to_update, 0, 100000, kPoints, kAdvanced,
              "a pair with fewer stereo pairs than this (tracked and new) does not update the "
              "calibration (the filter predicts; its points start afresh); 0 = update on any "
              "point"),
      integer("baseline_from_motion", &C::baseline_from_motion, 0, 1, kStart, kAdvanced,
              "while no point can be initialised (a baseline guess far off), measure the "
              "baseline's length from the left camera's motion at the odometry's scale and "
              "restart x_camr's translation from it; 0 = off"),
      real("initial_time_offset_ms", &C::initial_time_offset, 1e-3, -1000.0, 1000.0, kOdometryModel,
           kUser,
           "prior mean of the camera clock minus the odometry clock (the odometry's sample "
           "stamped t holds the vehicle at camera time t + offset; a late-stamping odometry "
           "has a negative offset)"),
      real("initial_time_offset_sigma_ms", &C::initial_time_offset_sigma, 1e-3, 0.0, 1000.0,
           kOdometryModel, kUser,
           "prior 1 sigma of that offset (0 = not estimated: the offset is taken as "
           "initial_time_offset_ms)"),
      real("max_time_offset_ms", &C::max_time_offset, 1e-3, 0.0, 1000.0, kOdometryModel, kUser,
           "the time offset's estimate is kept within +- this (a larger offset is a configuration "
           "error)"),
      real("time_offset_drift_ms", &C::time_offset_drift, 1e-3, 0.0, 1000.0, kOdometryModel,
           kAdvanced, "random walk of the time offset per reference step"),
      integer("read_odometry_at_offset", &C::read_odometry_at_offset, 0, 1, kOdometryModel,
              kAdvanced,
              "1: the odometry is read at the image stamps minus the current time-offset "
              "estimate, so that the first-order offset correction covers only its error; 0: "
              "read at the image stamps"),
      real("time_offset_model_noise", &C::time_offset_model_noise, 1.0, 0.0, 100.0, kOdometryModel,
           kAdvanced,
           "factor on the motion noise added for the error of the first-order time-offset "
           "correction (grows with the offset squared and with how fast the twist changes; "
           "0 = off)"),
      real("odometry_velocity_bias_sigma_mps", &C::odometry_velocity_bias_sigma, 1.0, 0.0, 10.0,
           kOdometryModel, kUser,
           "steady-state 1 sigma of a slowly varying odometry velocity error (wheel slip, a tilted "
           "or drifting IMU), estimated per lateral and vertical vehicle axis (0 = not "
           "estimated); no smaller than your odometry's: a larger error is taken for a tilted "
           "camera"),
      real("odometry_forward_velocity_bias_sigma_mps", &C::odometry_forward_velocity_bias_sigma,
           1.0, 0.0, 10.0, kOdometryModel, kUser,
           "the same for the forward vehicle axis (a scale error on a car, not on a drone; 0 = "
           "not estimated)"),
      real("odometry_bias_correlation_time_s", &C::odometry_bias_correlation_time, 1.0, 0.1, 1e6,
           kOdometryModel, kAdvanced,
           "correlation time of the odometry's velocity error "
           "(odometry_*velocity_bias_sigma_mps; first-order Gauss-Markov)"),
      real("odometry_scale_sigma_percent", &C::odometry_scale_sigma, 1e-2, 0.0, 50.0,
           kOdometryModel, kUser,
           "1 sigma of the odometry's scale error, which images cannot tell: added to the "
           "reported uncertainty of the translations (0 = the odometry's scale is exact)"),
      real("odometry_noise_window_s", &C::odometry_noise_window, 1.0, 0.0, 1e4, kOdometryModel,
           kUser,
           "window over which the odometry's noise is learned from the innovations: the "
           "configured motion noise is raised when the data show more (0 = used as configured)"),
      real("camr_rotation_drift_rate_sigma_deg_per_min", &C::camr_rotation_drift_rate_sigma,
           kDeg / 60.0, 0.0, 1e4, kRigAndNoise, kUser,
           "steady-state 1 sigma per axis of the rate at which the left->right rotation drifts "
           "(a slow, steady thermal drift), estimated as a state (0 = not estimated); a drift "
           "several times faster is followed with a lag"),
      real("camr_drift_rate_correlation_time_s", &C::camr_drift_rate_correlation_time, 1.0, 0.1,
           1e6, kRigAndNoise, kAdvanced,
           "correlation time of the left->right rotation's drift rate "
           "(camr_rotation_drift_rate_sigma_deg_per_min; first-order Gauss-Markov)"),
      real("consistency_window_s", &C::consistency_window, 1.0, 0.0, 1e4, kConsistencyMonitor,
           kAdvanced,
           "window of the per-block score test of the updates' consistency (0 = off, as the "
           "paper; consistency_monitor.h)"),
      real("consistency_false_alarm", &C::consistency_false_alarm, 1.0, 1e-9, 0.5,
           kConsistencyMonitor, kAdvanced,
           "probability that a consistent filter's window statistic exceeds its chi-square bound"),
      real("max_drift_inflation", &C::max_drift_inflation, 1.0, 1.0, 1e6, kConsistencyMonitor,
           kAdvanced,
           "largest factor on the variance of a calibration block's random walk (eq. 10-13) "
           "while its measurements disagree with the model"),
      real("drift_inflation_decade_s", &C::drift_inflation_decade, 1.0, 1e-3, 1e4,
           kConsistencyMonitor, kAdvanced,
           "time for that factor to grow tenfold while the block's statistic is above its bound"),
      real("drift_inflation_relax_s", &C::drift_inflation_relax, 1.0, 0.0, 1e6, kConsistencyMonitor,
           kAdvanced,
           "time constant of the factor's logarithm relaxing to 0 once consistent (0 = at once)"),
      real("unobserved_gap_s", &C::unobserved_gap, 1.0, 0.0, 1e6, kConsistencyMonitor, kAdvanced,
           "a stretch this long without a point measured leaves the calibration unobserved; "
           "after it x_caml is re-opened if the consistency monitor's x_caml statistic "
           "exceeds its bound within consistency_window_s (0 = off)"),
      // --- hand-eye rotation at start (issue 14) ---
      integer("hand_eye_start", &C::hand_eye_start, 0, 1, kStart, kAdvanced,
              "1: determine x_caml's rotation from the camera's and the vehicle's motion at the "
              "start and, if the estimate disagrees, start afresh from the guess with it (a "
              "camera mounted backwards or sideways); 0: off"),
      real("hand_eye_max_sigma_deg", &C::hand_eye_max_sigma, kDeg, 1e-3, 90.0, kStart, kAdvanced,
           "the hand-eye rotation is determined when its worst axis' 1 sigma is below this"),
      real("hand_eye_min_restart_sigma_deg", &C::hand_eye_min_restart_sigma, kDeg, 0.0, 90.0,
           kStart, kAdvanced,
           "least 1 sigma per axis of the hand-eye rotation, for the comparison with the "
           "filter and for the restart"),
      real("hand_eye_restart_distance", &C::hand_eye_restart_distance, 1.0, 0.0, 1e6, kStart,
           kAdvanced,
           "restart x_caml when its rotation is farther from the hand-eye one than this "
           "Mahalanobis distance (3 dof)"),
      real("hand_eye_restart_translation_sigma_m", &C::hand_eye_restart_translation_sigma, 1.0, 0.0,
           100.0, kStart, kAdvanced,
           "least translation 1 sigma x_caml is restarted with after such a restart (the "
           "camera is likely elsewhere too)"),
      // --- x_camr's rotation from a whole-image stereo fit at start (issue 14) ---
      integer("stereo_fit_start", &C::stereo_fit_start, 0, 1, kStart, kAdvanced,
              "1: at a start or re-opening of x_camr, fit its rotation over the whole images "
              "(image level) and re-seed it from the fit if the estimate disagrees; 0: off"),
      real("stereo_fit_restart_distance", &C::stereo_fit_restart_distance, 1.0, 0.0, 1e6, kStart,
           kAdvanced,
           "re-seed x_camr's rotation when it is farther from the fit's than this Mahalanobis "
           "distance (3 dof), or when its epipolar band held (almost) no match"),
      real("stereo_fit_min_sigma_deg", &C::stereo_fit_min_sigma, kDeg, 0.0, 90.0, kStart, kAdvanced,
           "1 sigma added in quadrature per axis to the fit's rotation"),
      real("stereo_fit_min_sigma_along_lines_deg", &C::stereo_fit_min_sigma_along_lines, kDeg, 0.0,
           90.0, kStart, kAdvanced,
           "1 sigma added about the axis across the baseline and the view (yaw_r of a horizontal "
           "rig), which one pair barely determines"),
      integer("stereo_fit_attempts", &C::stereo_fit_attempts, 1, 1000, kStart, kAdvanced,
              "pairs in which the fit is tried after a start before giving up"),
  };
  static const bool sections_checked =
      (requireKnownSections(table, filterParameterSections(), "filterParameterTable"), true);
  (void)sections_checked;
  return table;
}

const std::vector<ParameterSection>& filterParameterSections() {
  static const std::vector<ParameterSection> sections = {
      {kRigAndNoise,
       "how accurate the odometry and the features are, and how fast the mounting may drift"},
      {kStartPriors, "how far the guessed calibration may be off at the start (1 sigma per axis)"},
      {kOdometryModel,
       "the odometry's own errors: time offset, velocity error, scale (0 sigma = not estimated)"},
      {kPoints, "which stereo points the filter keeps in its state"},
      {kInputChecks, "motion that breaks these is rejected as corrupt"},
      {kStart,
       "helpers at a start: the mounting rotation from the motion (hand-eye), x_camr's rotation "
       "from a whole-image stereo fit, the baseline from the motion"},
      {kLinearisationGuard,
       "restarts and tempered updates while the filter is linearised far from the truth"},
      {kChangeDetection,
       "a sudden change of the calibration (a knock): when to re-open it, and how wide"},
      {kConsistencyMonitor,
       "tests the updates against the model and widens the drift noise while they disagree"},
      {kUnscentedTransform, "the scaled unscented transform (Julier 2002) of every nonlinear step"},
  };
  return sections;
}

std::vector<std::string> FilterConfig::validate() const {
  std::vector<std::string> problems;
  for (const ParameterSpec& spec : filterParameterTable()) {
    const double value = spec.get(*this);
    if (!std::isfinite(value) || value < spec.min_value || value > spec.max_value) {
      std::ostringstream message;
      message << spec.name << " = " << value << " is outside the allowed range [" << spec.min_value
              << ", " << spec.max_value << "] (" << spec.doc << ")";
      problems.push_back(message.str());
    }
  }
  if (std::abs(initial_time_offset) > max_time_offset) {
    std::ostringstream message;
    message << "initial_time_offset_ms = " << initial_time_offset * 1e3
            << " must lie within +- max_time_offset_ms = " << max_time_offset * 1e3;
    problems.push_back(message.str());
  }
  if (max_sigma_shrink_per_update > 0.0 && max_sigma_shrink_per_update <= 1.0) {
    std::ostringstream message;
    message << "max_sigma_shrink_per_update = " << max_sigma_shrink_per_update
            << " must be 0 (off) or above 1 (a factor by which a sigma may shrink)";
    problems.push_back(message.str());
  }
  if (min_point_depth >= max_point_depth) {
    std::ostringstream message;
    message << "min_point_depth_m = " << min_point_depth
            << " must be below max_point_depth_m = " << max_point_depth;
    problems.push_back(message.str());
  }
  return problems;
}

MotionNoiseModel motionNoiseModelFromName(const std::string& name) {
  if (name == "per_point") return MotionNoiseModel::kPerPoint;
  if (name == "shared") return MotionNoiseModel::kShared;
  throw std::invalid_argument("motion_noise_model = '" + name +
                              "' is not one of: per_point (paper eq. 15-27), shared");
}

std::string motionNoiseModelName(MotionNoiseModel model) {
  return model == MotionNoiseModel::kPerPoint ? "per_point" : "shared";
}

FilterConfig paperFilterConfig() {
  FilterConfig config;
  config.point_position_noise = 0.2;        // eq. 14
  config.camr_translation_drift = 0.01e-3;  // eq. 12
  config.motion_noise_model = MotionNoiseModel::kPerPoint;
  config.motion_translation_noise = 0.0;      // "not considered in this paper"
  config.motion_excitation_window = 0.0;      // the paper linearises at the measured motion
  config.motion_relinearizations = 0;         // ... once
  config.consistency_window = 0.0;            // the paper's random walk is fixed
  config.unobserved_gap = 0.0;                // ... and nothing tests it after a gap
  config.jump_score_false_alarm = 0.0;        // ... and its knocks found by gated points
  config.epipolar_knock_false_alarm = 0.0;    // ... only
  config.relinearization_frames = 0;          // the paper's filter runs on from its start
  config.max_sigma_shrink_per_update = 0.0;   // ... and updates as the UKF does
  config.min_points_to_update = 0;            // ... on however few points
  config.baseline_from_motion = 0;            // ... and the baseline from its points alone
  config.initial_time_offset_sigma = 0.0;     // the paper takes the odometry as synchronised
  config.odometry_scale_sigma = 0.0;          // ... and exact in scale
  config.odometry_noise_window = 0.0;         // ... with the noise it was told
  config.odometry_velocity_bias_sigma = 0.0;  // ... and without a velocity error
  config.odometry_forward_velocity_bias_sigma = 0.0;
  config.camr_rotation_drift_rate_sigma = 0.0;  // ... and a right camera that does not drift
  config.inverse_depth_points = 0;              // the paper's points are positions
  config.baseline_scaled_points = 0;            // ... in metres
  return config;
}

}  // namespace osc
