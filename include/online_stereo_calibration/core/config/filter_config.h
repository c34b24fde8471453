/// @file filter_config.h
/// @brief Every tunable of the estimator in one struct, with one table that names each
/// parameter, its unit, its allowed range, its meaning, its section and whether a user sets
/// it. The YAML loader, the ROS parameter loader, validate() and the generated
/// config/default.yaml all read that table, so a name exists once.
#pragma once

#include <string>
#include <vector>

#include "online_stereo_calibration/core/config/parameter_section.h"

namespace osc {

/// How the error of the measured vehicle motion enters the prediction of the points.
enum class MotionNoiseModel {
  /// Seed eq. 15-27: an independent 3x3 noise per point. Treats one common motion error as
  /// N independent ones, which lets N points average it away: overconfident.
  kPerPoint,
  /// Ours: the motion error of a step is one 6-DoF random variable shared by all points,
  /// estimated jointly with the calibration during the step and then marginalised.
  kShared,
};

/// The estimator's configuration. Internal units are SI (m, rad, s, px); the parameter
/// table converts from the file units named in each key (e.g. `_deg`).
struct FilterConfig {
  // --- scaled unscented transform (Julier 2002), used for every nonlinear step ---
  double ut_alpha = 0.5;  ///< spread of the sigma points
  double ut_beta = 2.0;   ///< prior knowledge of the distribution (2 = Gaussian)
  double ut_kappa = 0.0;  ///< secondary scaling

  /// The step length (s) to which the per-step noise sigmas below refer (paper: 10 Hz).
  /// Variances scale with dt / reference_period.
  double reference_period = 0.1;

  // --- calibration drift per reference step, seed eq. 10-13 ---
  double caml_translation_drift = 0.05e-3;                     ///< m
  double caml_rotation_drift = 0.005 * 0.0174532925199432958;  ///< rad
  /// m. The paper's 0.01 mm per step left the image-level filter overconfident in zr (a
  /// slowly varying 0.2-0.3 mm front-end bias about a 0.16 mm 1 sigma; docs/RESULTS.md);
  /// 0.03 mm covers it and follows thermal drift sooner.
  double camr_translation_drift = 0.03e-3;
  double camr_rotation_drift = 0.0005 * 0.0174532925199432958;  ///< rad

  // --- points, seed eq. 14-27 ---
  /// sigma_p of eq. 14 per step (m). The paper's 0.2 m makes every point forget its
  /// position each step; points are static, so ours only covers model error.
  double point_position_noise = 0.002;
  MotionNoiseModel motion_noise_model = MotionNoiseModel::kShared;
  double motion_rotation_noise = 0.02 * 0.0174532925199432958;  ///< rad per axis per step (eq. 15)
  double motion_translation_noise = 0.002;  ///< m per axis per step (shared model only)
  /// Shared model: repeat a step this many times, linearised at the motion corrected by the
  /// pass before (0 = off), while the vehicle is slower than 2 m/s: its measured translation
  /// per step is then mostly the odometry's noise, and depth times that noise fakes a metric
  /// parallax (the baseline of a standing car or a hovering rig pulled 5-18 sigma off). Each
  /// pass costs as much as the first; at speed a second pass moved the estimate by < 0.1
  /// sigma. (Not needed against the information the motion noise fakes on a flat road:
  /// motion_excitation_window handles that.)
  int motion_relinearizations = 1;
  /// Window (s) of the running mean square of the measured rotation per vehicle axis; an
  /// axis rotating no more than motion_rotation_noise is not taken as excitation of the
  /// camera position (motion_excitation.h). 0 = off (the paper: zl learned from noise on a
  /// flat road).
  double motion_excitation_window = 5.0;

  // --- measurements, seed eq. 29-30 ---
  /// px, default sigma of a feature position in the raw image (CameraModel::
  /// undistortedPixelVariance stretches it for the undistorted pixels the filter measures)
  double pixel_noise = 0.5;
  double outlier_gate = 18.47;  ///< chi-square(4) of a stereo innovation; 18.47 = 99.9 %

  // --- initial uncertainty of the guess (1 sigma) ---
  double initial_caml_translation_sigma = 0.5;                        ///< m
  double initial_caml_rotation_sigma = 10.0 * 0.0174532925199432958;  ///< rad
  double initial_camr_translation_sigma = 0.1;                        ///< m
  double initial_camr_rotation_sigma = 2.0 * 0.0174532925199432958;   ///< rad

  // --- new points (Sec. II-A) ---
  double min_point_depth = 1.0;   ///< m
  double max_point_depth = 80.0;  ///< m
  int max_points = 150;           ///< points kept in the state
  /// 1: points are stored as inverse depth (x/z, y/z, 1/z) in the left optical frame, whose
  /// uncertainty stays close to Gaussian while the depth is +-100 % uncertain (a new point
  /// under a wide x_camr prior, a far point); 0: as positions (x, y, z), the seed's choice.
  int inverse_depth_points = 1;
  /// 1: points are stored in units of the baseline (the left-to-right camera distance |t_r|):
  /// a point p is kept as p / |t_r|, which is what a stereo pair measures. Two images of a
  /// static scene then say nothing about the baseline, exactly and at any linearisation
  /// point; the baseline enters only where it physically does, through the metric motion
  /// (the camera's translation / |t_r|). 0: metric points (the seed's): a point's regression
  /// on the baseline (depth ~ 1 / |t_r|) is a linearisation that is not re-evaluated as the
  /// estimate moves, and re-looks at points then "measure" the baseline (a slow drone: yr
  /// 100 mm off with a 4 mm sigma after three frames; docs/RESULTS.md).
  /// On by default: the default campaign goes 81 -> 99 of 200 honest runs. A new point's
  /// depth is judged in metres (the UT mean of its metric triangulation) as with metric
  /// points, so small rigs under a baseline prior as wide as the baseline do not accept
  /// points the metric filter would reject (docs/RESULTS.md "Points in units of the
  /// baseline").
  int baseline_scaled_points = 1;

  // --- input sanity ---
  double max_speed = 70.0;          ///< m/s; a motion increment faster than this is rejected
  double max_angular_rate = 3.0;    ///< rad/s; likewise
  double max_frame_interval = 1.0;  ///< s; a longer gap between image pairs is rejected

  // --- sudden calibration change (a knock, seed Sec. III frame 774) ---
  double jump_rejected_fraction = 0.6;  ///< fraction of gated-out points that signals a jump
  int jump_min_points = 8;              ///< ... when at least this many points were tested
  /// A smaller fraction that signals a jump when it holds jump_sustained_frames frames in a
  /// row (0 frames = off). A knock during a stretch without points leaves no tracked point
  /// to contradict it: the new points are triangulated with the old calibration, and of
  /// their next measurements 30-60 % were gated out per frame, never 60 % (default campaign
  /// run 94: roll_r 137 sigma off for 50 frames). Moving objects alone stay below it.
  double jump_sustained_rejected_fraction = 0.3;
  int jump_sustained_frames = 3;
  double jump_rotation_sigma = 10.0 * 0.0174532925199432958;  ///< rad, re-opened 1 sigma
  double jump_translation_sigma = 0.02;                       ///< m, re-opened 1 sigma
  /// x_caml after a jump found at once: its rotation is fitted to the tracked points' left
  /// bearings (bearing_rotation_fit.h) and each axis re-opened to max(this, what it turned),
  /// at most jump_rotation_sigma, instead of jump_rotation_sigma on every axis. 0 = off.
  /// The fit is within 0.01-0.04 deg of 2-10 deg steps; the floor is for what the axes that
  /// did not turn were already off: at 0.1 deg yaw-step campaign runs reached CONVERGED with
  /// such errors kept (2.0 % of CONVERGED frames beyond 3 sigma, 1.6 % at 0.3; RESULTS
  /// "Session 31").
  double jump_fit_rotation_sigma = 0.3 * 0.0174532925199432958;  ///< rad
  /// s since a block was started or re-opened after which its rotation alone decides
  /// whether it can be re-opened again: a translation the motion cannot determine (zl on a
  /// flat road) never gets below jump_translation_sigma; requiring that as well left an
  /// x_caml yaw step on urban drives undetected (CalibrationFilter::canReopen).
  double jump_settle_time = 5.0;
  /// x_camr re-opened on evidence (issue 14: a knock is measurements that contradict the
  /// current x_camr beyond its covariance for some frames in a row). x_camr's partial score
  /// statistic of one update (consistency_monitor.h; divided by the update's unexplained
  /// rest per degree of freedom when above 1) beyond the chi-square bound of this false-alarm
  /// probability in jump_score_updates updates in a row adds (jump_score_widening x the
  /// rotation shift the update indicates)^2 to x_camr's rotation variances; the points are
  /// kept. A 0.15 deg knock gates out no point (roll_r 40 sigma off with sigma 0.003 deg)
  /// and was followed over 30 frames; it is now caught in the first two. A full re-opening
  /// (jump_rotation_sigma_deg) lost yaw_r, which one update cannot determine. 0 = off.
  double jump_score_false_alarm = 1e-6;
  int jump_score_updates = 2;
  double jump_score_widening = 3.0;
  /// x_camr re-opened when the stereo pairs leave its epipolar lines (epipolar_consistency.h):
  /// their statistic beyond the chi-square bound of this false-alarm probability in
  /// epipolar_knock_pairs image pairs in a row (at least jump_min_points stereo pairs each)
  /// re-opens x_camr's rotation to 3 times the indicated rotation and forgets the points.
  /// The epipolar lines depend on x_camr alone: a knock inside a stretch without points,
  /// which the new points' gating blamed on x_caml (default campaign run 102: yaw_r 193
  /// sigma off), is found in the first pair after it. 0 = off.
  double epipolar_knock_false_alarm = 1e-6;
  /// 1 since session 24: with 2, each knock's first pair was tens of sigmas off (default
  /// campaign runs 2, 23, 57, 180: 26-126 sigma for that frame); with 1 the default campaign
  /// has 163 instead of 156 of 200 runs honest and 192 instead of 285 frames beyond 5 sigma
  /// (docs/RESULTS.md "Session 24"). Widening x_camr's rotation on the first pair, points
  /// kept, instead of re-opening was worse: yaw_r, which one pair hardly shows, then locked
  /// 12-14 sigma off after real knocks (runs 62, 139).
  int epipolar_knock_pairs = 1;

  // --- re-linearisation after a start or a re-opening (issue 14) ---
  /// Every this many frames after a start (or a re-opened block), the estimator compares the
  /// estimate with the point the filter was started (linearised) at; 0 = never. A guess far
  /// off (a few prior sigmas) gives new points and first updates linearised far from the
  /// truth, which can lock the filter onto a wrong answer with a small sigma (x_camr angles
  /// 5 deg off: 176 sigma wrong). Restarting from the current estimate with the start's
  /// covariance, as an iterated filter re-linearises, avoids that.
  int relinearization_frames = 15;
  /// ... and restarts when some tangent component moved more than this many of the start's
  /// 1 sigmas since then.
  double relinearization_threshold = 0.5;
  /// ... and the mean normalised innovation squared of those frames' updates, per measured
  /// coordinate, was above this (1 = as the model expects): a consistent filter converging
  /// from a good guess also moves, a badly linearised one also mispredicts. 1.05 with
  /// inverse-depth points, whose innovations are closer to their model than those of
  /// positions (for which 1.15 was chosen): at 1.15 paper_offroad's 0.5 m / 10 deg x_caml
  /// start was not restarted and xl sat 3-4 sigma off for frames 40-90 (docs/RESULTS.md).
  double relinearization_nis = 1.05;
  /// A move of more than this many start sigmas restarts at the lower innovation gate
  /// relinearization_far_nis; 0 = off. A start's wide sigmas dominate the expected
  /// innovations, so a linearisation far off need not show in them: default campaign run 143
  /// moved 2.1 start sigmas by frame 30 at 0.96 of the expected innovations and locked yr 11
  /// sigma off. A start within its prior moves about 1 sigma (paper_offroad: 1.0-1.3). Only
  /// until the first restart after a start or re-opening, i.e. while the filter is still
  /// linearised at the guess: at every check it restarted a sideways camera guessed forward a
  /// second time and left xl 3.3 sigma off (HandEyeStart acceptance test, 227/250 frames).
  double relinearization_far_threshold = 2.0;
  /// The innovation gate of such a far move, in place of relinearization_nis: below 1, so that
  /// innovations a little smaller than the start's wide sigmas predict still restart (run
  /// 143's rescuing restart came at 0.96). At 0.8 far moves that converge well restart too
  /// (default campaign: run 40 0 -> 134 frames beyond 5 sigma; session 27).
  double relinearization_far_nis = 0.95;
  /// ... at most this many times after one start or re-opening.
  int max_relinearizations = 4;
  /// Largest factor by which one update may shrink a calibration parameter's 1 sigma; an
  /// update that would shrink one more is tempered (its measurement noise scaled up,
  /// update_tempering.h), so that a start or re-opening far from the truth converges over a
  /// few frames, each linearised where the last left it. 0 = off (the paper). Measured on
  /// the default campaign (200 runs, docs/RESULTS.md "Session 15"): 112 -> 123 honest runs,
  /// frames beyond 5 sigma 4101 -> 2566, RMSE unchanged or better.
  double max_sigma_shrink_per_update = 3.0;
  /// A pair with fewer stereo pairs than this, tracked and new together (a texture-poor view,
  /// a dim image, blur), does not update the calibration (issue 14: "keep the estimate, do not
  /// update, report too few points and wait"): the filter only predicts, and its tracked
  /// points start afresh as new ones. The new ones count: a start whose guess triangulates
  /// few of many pairs is thin evidence (tempering), not a texture-poor view; counting the
  /// tracked ones alone held such starts back (default campaign run 56: 500 frames beyond 5 sigma).
  /// Measured on a rendered drive with a dim 7 s stretch of 1-4 correct points per pair: updated on
  /// them, roll_l walked from 1.9 to 3.5 sigma off while its sigma shrank 6 %; held, it stayed
  /// within 2.3 sigma (docs/RESULTS.md "Session 19"). 0 = update on any point (the paper).
  int min_points_to_update = 5;
  /// While stereo pairs come but not one point can be initialised (a baseline prior as wide
  /// as a good part of its guess: 0.15 +- 0.1 m for a 0.3 m rig gives sigma points with
  /// nearly no baseline), measure the baseline's length from the left camera's motion at the
  /// odometry's scale (baseline_from_motion.h) and restart x_camr's translation from it
  /// (issue 14: "a guess 50 % off must converge"). 0 = off (the paper).
  int baseline_from_motion = 1;

  // --- the odometry's own errors as states (issue 15; process_model.h correctedMotion) ---
  /// Prior mean (s) of the camera-odometry time offset d: the camera clock minus the
  /// odometry's, i.e. the odometry's sample stamped t holds the vehicle at camera time t + d
  /// (an odometry that stamps its samples late, by its processing delay, has d < 0).
  /// Documented as "odometry clock minus camera clock" until session 16: the sign of the
  /// words was wrong, the model and the simulators always used this one.
  double initial_time_offset = 0.0;
  /// Prior 1 sigma (s) of that offset; 0 = not estimated (the offset is taken as the prior
  /// mean). 10 ms at 10 m/s moves the camera 10 cm between what the odometry and the images
  /// say, which x_caml's translation absorbs if the offset is not a state.
  double initial_time_offset_sigma = 0.02;
  /// s: the estimate is kept within +- this (a larger offset is a configuration error).
  double max_time_offset = 0.2;
  /// s per reference step: random walk of the offset (clock drift).
  double time_offset_drift = 1e-5;
  /// Factor on the motion noise that the time-offset correction's own error adds
  /// (timeOffsetModelCovariance: it grows with the offset squared and the change of the
  /// twist over a step, so a jerky rig with an offset of tens of ms gets it, a car hardly).
  /// 0 = off. 1 matches the error measured on the recorded walking rig. Read at the stamps
  /// (read_odometry_at_offset 0) 0.5 gave the better default campaign (docs/RESULTS.md
  /// "Session 16": 123 -> 128 honest runs; with 1: 129 but two runs much worse). Read at the
  /// offset (the default) it acts only while the offset is still uncertain: 134 honest with
  /// 0.5, 137 with 0, frames beyond 5 sigma alike; kept for that and for callers that read
  /// at the stamps (the KITTI loader).
  double time_offset_model_noise = 0.5;
  /// 1: callers read the odometry at the image stamps minus the current time-offset estimate
  /// (StereoCalibrationEstimator::odometryTimeShift; the node, evaluate and the simulators
  /// do), as VINS and OpenVINS read the IMU; the first-order correction then covers only the
  /// estimate's error. 0: read at the image stamps, the correction covers the whole offset.
  int read_odometry_at_offset = 1;
  /// Steady-state 1 sigma (m/s, per vehicle axis) of a slowly varying additive error of the
  /// odometry's velocity (wheel slip, a tilted or drifting IMU): a first-order Gauss-Markov
  /// state b with correlation time odometry_bias_correlation_time; the measured translation
  /// over dt is t + b dt. 0 = not estimated. A lateral bias at low speed turns the motion's
  /// direction, which x_caml's rotation would otherwise absorb. This sigma is the lateral
  /// and the vertical axis'; the forward one has its own (below).
  /// On by default (0.01 m/s): a vertical (lateral) velocity error b at speed v tilts the
  /// measured direction of travel by b / v, as a pitched (yawed) camera does, so without
  /// the state x_caml's rotation absorbs it with a sigma that does not know it (default
  /// campaign: 33 -> 74 of 200 runs honest, docs/RESULTS.md "Odometry errors"). The price:
  /// pitch_l and yaw_l are only as certain as the odometry's direction (paper_offroad:
  /// pitch_l 0.030 -> 0.067 deg RMSE, still a tenth of Table I). 0 for odometry known to
  /// have no such error; set it to your odometry's if that is larger. 0.02 (session 30):
  /// default campaign runs whose odometry has a 15-20 mm/s error 42 -> 48 of 59 honest
  /// (164 -> 172 of 200), but paper_offroad (white-noise odometry) yl and yaw_l +32 %,
  /// runs reaching CONVERGED 91 -> 70 and a start-troubled run 25 -> 127 frames beyond
  /// 5 sigma; lateral or vertical alone does not help (docs/RESULTS.md "Session 30").
  double odometry_velocity_bias_sigma = 0.01;
  /// The same for the forward (vehicle x) axis. On a car at a steady speed a forward error
  /// is a scale error, which images cannot tell (odometry_scale_sigma); on a slow platform
  /// that moves along every axis (a drone at 0.4 m/s, where 0.02 m/s is a 5 % error along
  /// its motion) it is not, and without the state yaw_r and yr absorb it (default campaign
  /// run 40: yaw_r 39 sigma off). Half the other axes' by default: at 0.01 m/s the state
  /// takes paper_offroad's zl lever-arm signal (zl 16.9 mm pooled, above Table I's 13.2);
  /// at 0.005: default campaign 99 -> 105 of 200 honest, C_odometry 32 -> 38 of 50, zl
  /// 12.7 mm (docs/RESULTS.md "Session 12"). 0 = not estimated.
  double odometry_forward_velocity_bias_sigma = 0.005;
  /// s, correlation time of that bias.
  double odometry_bias_correlation_time = 30.0;
  /// 1 sigma of the odometry's scale error kappa (measured translation = (1 + kappa) x
  /// true). Images and odometry together cannot tell it: scaling every translation (the
  /// vehicle's, both cameras', the points') by 1 + kappa leaves every pixel where it was, so
  /// the baseline's metric length is the odometry's. The filter estimates in the odometry's
  /// scale; the reported covariance adds what kappa leaves open, kappa^2 t t^T over the
  /// translations t (StereoCalibrationEstimator::estimate). 0 = the odometry's scale is exact.
  double odometry_scale_sigma = 0.01;
  /// s, window over which the odometry noise matcher (odometry_noise_matcher.h) learns the
  /// odometry's noise from the updates' innovations: the configured motion noise times a
  /// learned factor (>= 1) per part, translation and rotation. 0 = the configured noise as it
  /// is (the paper). KITTI raw (20 s, real OXTS): it learns the rotation's variance up to 4x
  /// the configured, all 12 within 3 sigma 88 -> 96 % of the pairs; campaign runs with an
  /// odometry 1-3x noisier than assumed: 22 -> 56 of 100 honest; simulated drives whose
  /// odometry matches keep the configured noise.
  double odometry_noise_window = 20.0;

  // --- x_camr's drift rate as a state (issue 15) ---
  /// Steady-state 1 sigma (rad/s, per axis) of the rate at which x_camr's rotation drifts:
  /// a first-order Gauss-Markov state w with correlation time camr_drift_rate_correlation_time,
  /// which the rotation integrates (its error moves by w dt per step besides the random walk
  /// of eq. 13). A thermal drift is slow and steady: a random walk follows it with a lag
  /// that its own sigma does not cover (the consistency monitor raises the walk only once the
  /// lag is significant, and lets it relax while the drift goes on), a rate state follows it
  /// without. Drift-only campaign ranges: 17 -> 24 of 40 runs honest, as many as without
  /// any drift (25); default ranges 105 -> 113 of 200. The price is the rate's own
  /// estimation error: paper_offroad yaw_r 0.0018 -> 0.0022 deg RMSE pooled. At 0.1
  /// deg/min the rate took yaw_r's slow start-up convergence on a drone for a drift (run 40
  /// without its event: 78 % of the frames within 3 sigma) (docs/RESULTS.md "Session 13").
  /// 0 = not estimated (the paper). At 0.1 and 0.2 deg/min (session 30) the drift runs get
  /// better (default campaign 38 -> 41 / 42 of 48, drift-only 32 -> 34 of 40, none beyond
  /// 5 sigma) and two other runs go beyond 5 sigma (56: yl, 144: pitch_l; 52 -> 174 frames of
  /// the filter's own), at 0.2 also 126 -> 118 of the 152 others honest.
  double camr_rotation_drift_rate_sigma = 0.05 / 60.0 * 0.0174532925199432958;  ///< rad/s
  /// s, correlation time of that rate: a thermal drift keeps its direction for long (at
  /// 300 s and 0.1 deg/min paper_offroad's yaw_r RMSE was 0.0024 deg, 0.0023 at 3000 s).
  double camr_drift_rate_correlation_time = 3000.0;

  // --- consistency monitor and adaptive drift noise (consistency_monitor.h) ---
  /// Sliding window (s) of the per-block score test of the updates; 0 = off (the paper).
  double consistency_window = 4.0;
  /// Probability that a consistent filter's window statistic exceeds its bound (per test).
  double consistency_false_alarm = 1e-3;
  /// Largest factor on the variance of a block's random walk (eq. 10-13).
  double max_drift_inflation = 100.0;
  /// s for the factor to grow tenfold while the block's statistic is above its bound.
  double drift_inflation_decade = 2.0;
  /// s, time constant of the factor's logarithm relaxing to 0 once consistent.
  double drift_inflation_relax = 30.0;
  /// s without a point measured (a dark or texture-poor stretch, a gap in the data) after
  /// which the calibration counts as unobserved: a change of x_caml in such a stretch leaves
  /// no tracked point to gate out, so the jump test cannot see it. Over the first
  /// consistency_window_s of updates after it x_caml is re-opened (jump sigmas) if the
  /// consistency monitor's x_caml statistic exceeds its bound. 0 = off.
  double unobserved_gap = 2.0;

  /// Every problem found, each naming the parameter, its value and the allowed range.
  std::vector<std::string> validate() const;

  // --- hand-eye rotation at start (issue 14) ---
  /// 1: until x_caml's rotation is determined from the motion alone (hand_eye_rotation.h),
  /// the estimator collects the left camera's and the vehicle's motion pairs, and if the
  /// filter's x_caml rotation disagrees with the rotation they give (a camera mounted
  /// backwards or sideways with a forward guess) starts the filter afresh from the guess with
  /// that rotation (mounting_from_motion.h); 0: off (the paper).
  int hand_eye_start = 1;
  /// rad: the hand-eye rotation counts as determined when its worst axis' 1 sigma is below.
  double hand_eye_max_sigma = 1.5 * 0.0174532925199432958;
  /// rad: the hand-eye rotation's 1 sigma is taken as at least this per axis, for the
  /// comparison with the filter and for the restart (its own sigma ignores the camera's lever
  /// arm: 2-3 deg off against 0.7 deg in the first second of the off-road drive).
  double hand_eye_min_restart_sigma = 3.0 * 0.0174532925199432958;
  /// Restart when the filter's rotation is farther from the hand-eye's than this Mahalanobis
  /// distance (both covariances, 3 dof).
  double hand_eye_restart_distance = 3.0;
  /// m: least translation 1 sigma x_caml is restarted with (a camera whose rotation was
  /// guessed that far off is likely elsewhere too: at the tailgate, under a mirror).
  double hand_eye_restart_translation_sigma = 1.5;

  // --- x_camr's rotation from a whole-image stereo fit at start (issue 14; image level) ---
  /// 1: when the filter starts (first pairs, a reset, a re-opening of x_camr's rotation), the
  /// image pipeline fits x_camr's rotation over the whole images without the calibration
  /// (global_stereo_fit.h) and, if the estimate disagrees with it, re-seeds x_camr's rotation
  /// from it with the fit's covariance; 0: off (the paper).
  int stereo_fit_start = 1;
  /// Re-seed when x_camr's rotation is farther from the fit's than this Mahalanobis distance
  /// (both covariances, 3 dof), or when its epipolar band held (almost) no stereo match.
  double stereo_fit_restart_distance = 3.0;
  /// rad: added in quadrature per axis to the fit's rotation 1 sigma (its own, from the
  /// inliers' spread, ignores keypoint biases and a lens model's residual).
  double stereo_fit_min_sigma = 0.05 * 0.0174532925199432958;
  /// rad: added in quadrature about the axis across the baseline and the optical axis (yaw_r
  /// for a horizontal rig), whose rotation slides points along their epipolar lines: one
  /// pair determines it only through second-order terms that model errors mimic (KITTI:
  /// 0.5 deg off with a formal 1 sigma of 0.01-0.06 deg).
  double stereo_fit_min_sigma_along_lines = 1.0 * 0.0174532925199432958;
  /// Pairs in which a fit is tried after a start before giving up (a view without texture
  /// gives none).
  int stereo_fit_attempts = 10;
};

/// One row of the parameter table.
struct ParameterSpec {
  std::string name;  ///< key in YAML / on the ROS parameter server, with its unit suffix
  std::string doc;   ///< one line for humans
  double file_to_internal = 1.0;  ///< e.g. pi/180 for `_deg` keys
  double min_value = 0.0;         ///< allowed range in file units, inclusive
  double max_value = 0.0;
  bool is_integer = false;
  double FilterConfig::*real_field = nullptr;
  int FilterConfig::*integer_field = nullptr;
  /// The component that uses the key: the name of one of filterParameterSections().
  std::string section;
  /// false: a key a user may need to set for a new rig, odometry or lens (noise, priors,
  /// what is estimated); true: an internal threshold tuned on measurements, listed in the
  /// files' advanced part (change it only with a measurement: docs/RESULTS.md).
  bool advanced = false;

  /// Value in file units.
  double get(const FilterConfig& config) const;
  /// Sets from file units (no range check; validate() does that).
  void set(FilterConfig* config, double file_value) const;
};

/// The table: every numeric parameter of FilterConfig (motion_noise_model is the one
/// non-numeric key, see motionNoiseModelFromName).
const std::vector<ParameterSpec>& filterParameterTable();

/// The sections of the filter's keys, in the order config/default.yaml lists them; every
/// ParameterSpec::section names one of them.
const std::vector<ParameterSection>& filterParameterSections();

/// motion_noise_model, the one non-numeric key, sits in this section, as an advanced key
/// (per_point is the seed's model, kept to reproduce it).
constexpr const char* kMotionNoiseModelSection = "rig and noise";
constexpr bool kMotionNoiseModelAdvanced = true;

/// "per_point" | "shared"; @throws std::invalid_argument naming the allowed values.
MotionNoiseModel motionNoiseModelFromName(const std::string& name);
std::string motionNoiseModelName(MotionNoiseModel model);

/// The seed paper's values (config/paper.yaml holds the same): sigma_p = 0.2 m and the
/// per-point motion noise of eq. 15-27.
FilterConfig paperFilterConfig();

}  // namespace osc
