/// @file evaluate_main.cpp
/// @brief Runs the calibration pipeline over a bag as fast as possible, without a ROS master
/// (interface.md, "Offline evaluation"):
///
///   evaluate --bag DRIVE.bag --out DIR [--initial-guess GUESS.yaml] [--config PARAMS.yaml]
///            [--reference REF.yaml | --truth-topic TOPIC] [--window FIRST LAST]
///            [--stereo-ns NS] [--left-image T] [--right-image T] [--left-info T]
///            [--right-info T] [--odom T]
///
/// Reads NS/{left,right}/image_raw and camera_info (NS = /stereo) and /odom (poses interpolated
/// to the image stamps, linear + SLERP), pairs the images by exact stamp and writes
/// DIR/estimates.csv
/// and DIR/calibration.yaml (the final estimate). With a reference also DIR/reference.csv,
/// DIR/table.txt (Table I, consistency, convergence after a step, time per frame; also on
/// stdout) and the plots of scripts/plot_convergence.py. Without --initial-guess the file
/// initial_guess.yaml next to the bag is used (as `simulate` writes it).
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/Image.h>
#include <opencv2/core/utility.hpp>

#include "bag_io.h"
#include "online_stereo_calibration/core/pipeline/calibration_pipeline.h"
#include "online_stereo_calibration/tools/bag_evaluation.h"
#include "online_stereo_calibration/tools/calibration_file.h"
#include "online_stereo_calibration/tools/command_line.h"
#include "online_stereo_calibration/tools/estimates_csv.h"
#include "online_stereo_calibration/tools/estimator_config_yaml.h"
#include "online_stereo_calibration/tools/evaluation.h"
#include "online_stereo_calibration/tools/output_directory.h"
#include "online_stereo_calibration/tools/package_files.h"

namespace {

struct Options {
  std::string bag, out, initial_guess, config, reference, truth_topic;
  int window_first = -1, window_last = -1;
  int max_pairs = -1;  ///< stop after this many stereo pairs (-1: all)
  int threads = 1;     ///< OpenCV's worker threads (cv::setNumThreads)
  /// Topics (interface.md: left/image_raw, ... relative to the stereo namespace, and odom).
  std::string stereo_ns = "/stereo";
  std::string left_image, right_image, left_info, right_info, odom = "/odom";
};

/// Odometry further than this (s) beyond an image stamp is not extrapolated.
constexpr double kOdomTolerance = 0.02;

/// The command line (`--help` prints it).
osc::CommandLine commandLine(Options* o) {
  osc::CommandLine cli(
      "evaluate",
      "Runs the calibration pipeline (front end + filter, as the nodelet) over a bag as fast as "
      "possible,\nwithout a ROS master; writes DIR/estimates.csv and calibration.yaml, and with "
      "a reference\nreference.csv, table.txt (Table I) and convergence plots.");
  cli.option("--bag", &o->bag, "DRIVE.bag", "input bag").required();
  cli.option("--out", &o->out, "DIR", "output directory").required();
  cli.option("--initial-guess", &o->initial_guess, "GUESS.yaml",
             "initial calibration (default: initial_guess.yaml beside the bag)");
  cli.option("--config", &o->config, "PARAMS.yaml",
             "estimator parameters: filter keys (config/default.yaml) and a front_end: map");
  cli.option("--reference", &o->reference, "REF.yaml", "fixed true calibration");
  cli.option("--truth-topic", &o->truth_topic, "TOPIC",
             "per-frame truth (StereoCalibration), e.g. /ground_truth/calibration");
  cli.option("--window", &o->window_first, &o->window_last, "FIRST LAST",
             "frames of the Table I RMSE (default 1000 1150, clipped to the drive)")
      .range(0, 1e9)
      .defaultText("");
  cli.option("--stereo-ns", &o->stereo_ns, "NS",
             "namespace of left/ and right/ image_raw and camera_info");
  cli.option("--left-image", &o->left_image, "TOPIC", "left images (default NS/left/image_raw)");
  cli.option("--right-image", &o->right_image, "TOPIC",
             "right images (default NS/right/image_raw)");
  cli.option("--left-info", &o->left_info, "TOPIC",
             "left CameraInfo (default NS/left/camera_info)");
  cli.option("--right-info", &o->right_info, "TOPIC",
             "right CameraInfo (default NS/right/camera_info)");
  cli.option("--odom", &o->odom, "TOPIC", "vehicle odometry (nav_msgs/Odometry)");
  cli.option("--frames", &o->max_pairs, "N", "evaluate only the first N stereo pairs")
      .range(1, 1e9)
      .defaultText("all");
  // One by default: the speed figures (docs/benchmarks.md) are one core's, and a second
  // thread inside OpenCV would make them look better than one core delivers.
  cli.option("--threads", &o->threads, "N", "threads OpenCV may use (detection, filtering)")
      .range(1, 256);
  return cli;
}

/// Checks the option combinations and fills the topics left to the namespace.
void finishOptions(Options* o) {
  if (!o->reference.empty() && !o->truth_topic.empty()) {
    throw osc::CommandLineError("give --reference or --truth-topic, not both");
  }
  if (o->window_first >= 0 && o->window_last < o->window_first) {
    throw osc::CommandLineError("--window wants FIRST <= LAST");
  }
  std::string ns = o->stereo_ns;
  while (!ns.empty() && ns.back() == '/') ns.pop_back();
  const auto fill = [&](std::string* topic, const char* relative) {
    if (topic->empty()) *topic = ns + "/" + relative;
  };
  fill(&o->left_image, "left/image_raw");
  fill(&o->right_image, "right/image_raw");
  fill(&o->left_info, "left/camera_info");
  fill(&o->right_info, "right/camera_info");
}

cv::Mat toMat(const sensor_msgs::ImageConstPtr& msg, cv_bridge::CvImageConstPtr* holder) {
  const std::string& e = msg->encoding;
  if (e == "mono8" || e == "mono16" || e == "bgr8" || e == "bgra8") {
    *holder = cv_bridge::toCvShare(msg);
  } else {
    *holder = cv_bridge::toCvShare(msg, "bgr8");
  }
  return (*holder)->image;
}

/// First CameraInfo on a topic.
osc::CameraIntrinsics readCameraInfo(const rosbag::Bag& bag, const std::string& topic) {
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& m : view) {
    const auto info = m.instantiate<sensor_msgs::CameraInfo>();
    if (info) return online_stereo_calibration::intrinsicsFromCameraInfo(*info);  // validated
  }
  throw std::runtime_error("no sensor_msgs/CameraInfo on " + topic);
}

std::string quote(const std::string& s) { return "'" + s + "'"; }

/// The tool itself, after the command line.
int evaluateBag(const Options& options) {
  cv::setNumThreads(options.threads);
  osc::bag::DriveTopics topics;
  topics.left_image = options.left_image;
  topics.right_image = options.right_image;
  topics.left_info = options.left_info;
  topics.right_info = options.right_info;
  topics.odom = options.odom;
  std::string guess_path = options.initial_guess;
  if (guess_path.empty()) guess_path = osc::directoryOf(options.bag) + "/initial_guess.yaml";
  if (!osc::isRegularFile(guess_path)) {
    throw std::invalid_argument("no initial guess: give --initial-guess GUESS.yaml");
  }
  const osc::CalibrationFile guess = osc::readCalibrationFile(guess_path);
  const osc::EstimatorConfig config = options.config.empty()
                                          ? osc::EstimatorConfig()
                                          : osc::readEstimatorConfigFile(options.config);

  rosbag::Bag bag(options.bag, rosbag::bagmode::Read);
  std::vector<osc::bag::RequiredTopic> required = {
      {"--left-image", topics.left_image, "sensor_msgs/Image"},
      {"--right-image", topics.right_image, "sensor_msgs/Image"},
      {"--left-info", topics.left_info, "sensor_msgs/CameraInfo"},
      {"--right-info", topics.right_info, "sensor_msgs/CameraInfo"},
      {"--odom", topics.odom, "nav_msgs/Odometry"}};
  if (!options.truth_topic.empty()) {
    required.push_back(
        {"--truth-topic", options.truth_topic, "online_stereo_calibration/StereoCalibration"});
  }
  osc::bag::requireTopics(bag, options.bag, required);
  osc::makeDirectories(options.out);
  const osc::CameraIntrinsics left_camera = readCameraInfo(bag, topics.left_info);
  const osc::CameraIntrinsics right_camera = readCameraInfo(bag, topics.right_info);
  // One pass over the bag for both (see readOdometryAndCalibration).
  osc::bag::OdometryAndCalibration inputs =
      osc::bag::readOdometryAndCalibration(bag, topics.odom, options.truth_topic);
  const osc::PoseTrajectory odometry = std::move(inputs.odometry);
  const online_stereo_calibration::PoseBuffer& odometry_twists = inputs.odometry_twists;
  std::map<std::int64_t, osc::Vector12d> truth;  // the latest message of a stamp wins
  for (const auto& [stamp, parameters] : inputs.calibration) truth[stamp] = parameters;
  if (odometry.size() < 2)
    throw std::runtime_error("fewer than 2 odometry poses on " + topics.odom);
  if (!options.truth_topic.empty() && truth.empty()) {
    throw std::runtime_error("no StereoCalibration on " + options.truth_topic);
  }
  const bool have_reference = !options.reference.empty() || !truth.empty();
  osc::Vector12d constant_reference = osc::Vector12d::Zero();
  if (!options.reference.empty()) {
    constant_reference = osc::readCalibrationFile(options.reference).extrinsics.toParameters();
  }

  osc::CalibrationPipeline pipeline(config.filter, config.front_end, left_camera, right_camera,
                                    guess.extrinsics);
  int total = static_cast<int>(rosbag::View(bag, rosbag::TopicQuery(topics.left_image)).size());
  if (options.max_pairs > 0) total = std::min(total, options.max_pairs);
  std::cerr << "evaluating " << options.bag << ": " << total << " left images on "
            << topics.left_image << ", " << odometry.size() << " odometry poses on " << topics.odom
            << ", " << left_camera.width << "x" << left_camera.height << ", "
            << config.front_end.detector << " front end\n";
  if (inputs.samples_without_twist > 0) {
    std::cerr << "evaluate: " << inputs.samples_without_twist << " of " << odometry.size()
              << " odometry messages without a usable twist (" << inputs.twist_problem
              << "): the time offset uses the trend of earlier increments there\n";
  }

  osc::EstimatesCsvWriter estimates_csv(options.out + "/estimates.csv");
  std::vector<osc::EstimateRow> estimates;
  std::vector<osc::ReferenceRow> reference;
  std::vector<double> times;
  std::map<std::int64_t, sensor_msgs::ImageConstPtr> pending_left, pending_right;
  int frame = 0, skipped = 0;
  // The estimator's events echoed to the progress output, each kind at most once every
  // kEventRepeatPairs pairs (a baseline guess that triangulates nothing says so every pair).
  struct EventEcho {
    int last_pair = -1;
    int suppressed = 0;
  };
  constexpr int kEventRepeatPairs = 50;
  std::map<osc::FrameEvent, EventEcho> echoes;
  double previous_stamp = 0.0;
  bool have_previous = false;
  const auto start = std::chrono::steady_clock::now();
  auto last_report = start;
  // A terminal gets a progress bar redrawn twice a second; a log file a line every 10 s.
  const bool terminal = isatty(STDERR_FILENO) != 0;
  const auto report_every =
      terminal ? std::chrono::milliseconds(500) : std::chrono::milliseconds(10000);
  rosbag::View images(bag, rosbag::TopicQuery({topics.left_image, topics.right_image}));
  for (const rosbag::MessageInstance& m : images) {
    if (options.max_pairs > 0 && frame >= options.max_pairs) break;
    const auto image = m.instantiate<sensor_msgs::Image>();
    if (!image) continue;
    const std::int64_t key = static_cast<std::int64_t>(image->header.stamp.toNSec());
    const bool is_left = m.getTopic() == topics.left_image;
    auto& mine = is_left ? pending_left : pending_right;
    auto& other = is_left ? pending_right : pending_left;
    const auto match = other.find(key);
    if (match == other.end()) {
      mine[key] = image;
      continue;
    }
    const sensor_msgs::ImageConstPtr left = is_left ? image : match->second;
    const sensor_msgs::ImageConstPtr right = is_left ? match->second : image;
    other.erase(other.begin(), std::next(match));  // older unmatched images never pair now
    mine.erase(mine.begin(), mine.lower_bound(key));

    const double stamp = left->header.stamp.toSec();
    osc::MotionIncrement motion;
    if (have_previous) {
      // Read where the estimator believes the images were (its time offset), as the node.
      const double shift = pipeline.estimator().odometryTimeShift();
      const auto increment =
          odometry.motionBetween(previous_stamp - shift, stamp - shift, kOdomTolerance);
      if (increment) {
        motion = *increment;
        motion.time_shift = shift;
        // The odometry's own twists at both stamps for the time offset, as the node does.
        motion.has_twists = odometry_twists.twistAt(previous_stamp - shift, &motion.twist_start) &&
                            odometry_twists.twistAt(stamp - shift, &motion.twist_end);
      } else {
        std::cerr << "\nevaluate: no odometry around pair " << frame << " (stamp " << stamp
                  << "); tracking restarts\n";
        pipeline.resetTracking();
      }
    }
    cv_bridge::CvImageConstPtr left_holder, right_holder;
    const osc::PipelineResult result =
        pipeline.process(toMat(left, &left_holder), toMat(right, &right_holder), motion);
    if (!result.processed) {
      std::cerr << "\nevaluate: pair " << frame << " not used: " << result.status << "\n";
      ++skipped;
      ++frame;
      continue;
    }
    previous_stamp = stamp;
    have_previous = true;
    // What the estimator's components did, and why it cannot learn (frame_event.h), in the
    // progress output: each kind at most once every kEventRepeatPairs pairs.
    for (const osc::FrameEventLine& event : result.estimator.events) {
      EventEcho& echo = echoes[event.kind];
      if (echo.last_pair >= 0 && frame - echo.last_pair < kEventRepeatPairs) {
        ++echo.suppressed;
        continue;
      }
      std::cerr << "\nevaluate: pair " << frame << ": [" << osc::frameEventName(event.kind) << "] "
                << event.text;
      if (echo.suppressed > 0) std::cerr << " (and " << echo.suppressed << " times before)";
      std::cerr << "\n";
      echo = EventEcho{frame, 0};
    }
    osc::EstimateRow row;
    row.frame = frame;
    row.stamp = stamp;
    row.parameters = result.estimate.parameters;
    row.sigmas = result.estimate.sigmas();
    row.tracked_points = static_cast<int>(result.estimate.tracked_points);
    row.time_ms = 1000.0 * result.processing_time;
    row.time_offset = result.estimate.time_offset;
    row.time_offset_sigma = result.estimate.time_offset_sigma;
    estimates_csv.write(row);
    estimates.push_back(row);
    times.push_back(row.time_ms);
    if (have_reference) {
      osc::ReferenceRow ref;
      ref.frame = frame;
      ref.stamp = stamp;
      ref.parameters = constant_reference;
      const auto t = truth.find(key);
      if (truth.empty() || t != truth.end()) {
        if (t != truth.end()) ref.parameters = t->second;
        reference.push_back(ref);
      }
    }
    ++frame;
    const auto now = std::chrono::steady_clock::now();
    if (frame == total || now - last_report > report_every) {
      last_report = now;
      std::cerr << (terminal ? "\r  " : "  ")
                << osc::progressLine(frame, total,
                                     std::chrono::duration<double>(now - start).count())
                << "  points " << row.tracked_points << (terminal ? "" : "\n") << std::flush;
    }
  }
  if (terminal) std::cerr << "\n";
  estimates_csv.flush();
  if (estimates.empty()) throw std::runtime_error("no stereo pair was processed");
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  osc::writeCalibrationFileAtomic(options.out + "/calibration.yaml",
                                  osc::calibrationFileOf(estimates.back()));

  const osc::Percentiles timing = osc::percentiles(times);
  std::ostringstream text;
  int step_frame = -1;
  if (!reference.empty()) {
    osc::ReferenceCsvWriter reference_csv(options.out + "/reference.csv");
    for (const osc::ReferenceRow& r : reference) reference_csv.write(r);
    reference_csv.flush();
    const int last_frame = estimates.back().frame;
    int last = options.window_last >= 0 ? options.window_last : std::min(1150, last_frame);
    int first =
        options.window_first >= 0 ? options.window_first : std::min(1000, std::max(0, last - 150));
    const osc::EvaluationReport report = osc::evaluateWindow(estimates, reference, first, last);
    text << "Bag " << options.bag << ", RMSE over frames " << first << "-" << last << " ("
         << report.frames_used << " frames used):\n"
         << osc::formatTableI(report) << "\n";
    double within = 0;
    for (const auto& p : report.parameters) within += p.within_2sigma / 12.0;
    text << "Consistency: " << 100.0 * within << " % of errors within 2 sigma (95.4 % if "
         << "consistent), mean NEES " << report.mean_nees << " (1 if consistent)\n";
    step_frame = osc::detectStepFrame(reference);
    if (step_frame >= 0) {
      int stepped = 0;
      double largest = 0;
      const auto& before =
          std::find_if(reference.begin(), reference.end(),
                       [&](const osc::ReferenceRow& r) { return r.frame == step_frame; });
      for (int p = 0; p < 12 && before != reference.begin(); ++p) {
        const double d = std::abs((before->parameters(p) - (before - 1)->parameters(p)) *
                                  (osc::isAngleParameter(p) ? 1.0 : 0.1));
        if (d > largest) largest = d, stepped = p;
      }
      const double tolerance = osc::isAngleParameter(stepped) ? 0.3 * M_PI / 180.0 : 0.03;
      const int back = osc::framesToConverge(estimates, reference, stepped, tolerance, step_frame);
      text << "Step at frame " << step_frame << " (largest in "
           << osc::estimatesCsvColumns()[2 + stepped] << "): within "
           << (osc::isAngleParameter(stepped) ? "0.3 deg" : "3 cm") << " from frame " << back
           << " on (" << (back >= 0 ? back - step_frame : -1) << " frames to converge)\n";
    }
  } else {
    const osc::EstimateRow& last = estimates.back();
    text << "Bag " << options.bag << " (no reference): final estimate and 1 sigma\n";
    for (int p = 0; p < 12; ++p) {
      text << "  " << osc::estimatesCsvColumns()[2 + p] << " = " << last.parameters(p) << " +- "
           << last.sigmas(p) << "\n";
    }
  }
  text << "Pairs processed: " << estimates.size() << ", not used: " << skipped
       << "; time per frame: median " << timing.median << " ms, p95 " << timing.p95 << " ms; total "
       << elapsed << " s (" << estimates.size() / elapsed << " frames/s)\n";
  std::cout << text.str();
  std::ofstream(options.out + "/table.txt") << text.str();

  const std::string script = osc::findPackageFile("scripts/plot_convergence.py", "OSC_PLOT_SCRIPT");
  if (script.empty()) {
    std::cerr << "evaluate: warning: scripts/plot_convergence.py not found (set "
                 "OSC_PLOT_SCRIPT); no plots\n";
  } else {
    std::string command = "/usr/bin/python3 " + quote(script) + " --out " + quote(options.out);
    if (step_frame >= 0) command += " --step-frame " + std::to_string(step_frame);
    if (std::system(command.c_str()) != 0) {
      std::cerr << "evaluate: warning: the plots failed (" << command << ")\n";
    }
  }
  std::cout << "wrote " << options.out << "/estimates.csv, calibration.yaml, table.txt"
            << (reference.empty() ? "" : ", reference.csv") << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options parsed;
  osc::CommandLine cli = commandLine(&parsed);
  return osc::runTool(
      "evaluate", [&] { return cli.usage(); },
      [&] {
        if (!cli.parse(argc, argv)) return 0;
        finishOptions(&parsed);
        return evaluateBag(parsed);
      });
}
