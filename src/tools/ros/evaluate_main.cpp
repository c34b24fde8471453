/// @file evaluate_main.cpp
/// @brief Runs the calibration pipeline over a bag as fast as possible, without a ROS master
/// (interface.md, "Offline evaluation"):
///
///   evaluate --bag DRIVE.bag --out DIR [--initial-guess GUESS.yaml] [--config PARAMS.yaml]
///            [--reference REF.yaml | --truth-topic TOPIC] [--window FIRST LAST]
///
/// Reads /stereo/{left,right}/image_raw and camera_info and /odom (poses interpolated to the
/// image stamps, linear + SLERP), pairs the images by exact stamp and writes DIR/estimates.csv
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

#include <cv_bridge/cv_bridge.h>
#include <ros/package.h>
#include <sensor_msgs/Image.h>

#include "bag_io.h"
#include "online_stereo_calibration/tools/output_directory.h"
#include "online_stereo_calibration/core/pipeline/calibration_pipeline.h"
#include "online_stereo_calibration/tools/bag_evaluation.h"
#include "online_stereo_calibration/tools/calibration_file.h"
#include "online_stereo_calibration/tools/estimates_csv.h"
#include "online_stereo_calibration/tools/evaluation.h"
#include "online_stereo_calibration/tools/filter_config_yaml.h"

namespace {

struct Options {
  std::string bag, out, initial_guess, config, reference, truth_topic;
  int window_first = -1, window_last = -1;
};

/// Odometry further than this (s) beyond an image stamp is not extrapolated.
constexpr double kOdomTolerance = 0.02;

void usage() {
  std::cerr << "usage: evaluate --bag DRIVE.bag --out DIR [--initial-guess GUESS.yaml]\n"
               "         [--config PARAMS.yaml] [--reference REF.yaml | --truth-topic TOPIC]\n"
               "         [--window FIRST LAST]\n";
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&](const char* name) -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(std::string(name) + " needs a value");
      return argv[++i];
    };
    if (a == "--bag")
      o.bag = value("--bag");
    else if (a == "--out")
      o.out = value("--out");
    else if (a == "--initial-guess")
      o.initial_guess = value("--initial-guess");
    else if (a == "--config")
      o.config = value("--config");
    else if (a == "--reference")
      o.reference = value("--reference");
    else if (a == "--truth-topic")
      o.truth_topic = value("--truth-topic");
    else if (a == "--window") {
      o.window_first = std::stoi(value("--window"));
      o.window_last = std::stoi(value("--window"));
      if (o.window_first < 0 || o.window_last < o.window_first) {
        throw std::invalid_argument("--window wants 0 <= FIRST <= LAST");
      }
    } else if (a == "--help" || a == "-h") {
      usage();
      std::exit(0);
    } else {
      throw std::invalid_argument("unknown argument '" + a + "'");
    }
  }
  if (o.bag.empty() || o.out.empty()) throw std::invalid_argument("--bag and --out are required");
  if (!o.reference.empty() && !o.truth_topic.empty()) {
    throw std::invalid_argument("give --reference or --truth-topic, not both");
  }
  return o;
}

bool isFile(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}


std::string directoryOf(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : path.substr(0, slash);
}

/// scripts/plot_convergence.py: $OSC_PLOT_SCRIPT, the package path (ROS_PACKAGE_PATH), the
/// current directory, or the source tree this executable was built from.
std::string findPlotScript() {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("OSC_PLOT_SCRIPT")) candidates.push_back(env);
  if (std::getenv("ROS_PACKAGE_PATH")) {  // rospack complains loudly without it
    const std::string package = ros::package::getPath("online_stereo_calibration");
    if (!package.empty()) candidates.push_back(package + "/scripts/plot_convergence.py");
  }
  candidates.push_back("scripts/plot_convergence.py");
  candidates.push_back(directoryOf(__FILE__) + "/../../../scripts/plot_convergence.py");
  for (const std::string& c : candidates) {
    if (isFile(c)) return c;
  }
  return "";
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
    if (info) return osc::bag::fromCameraInfo(*info);
  }
  throw std::runtime_error("no sensor_msgs/CameraInfo on " + topic);
}

std::string quote(const std::string& s) { return "'" + s + "'"; }

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options options = parse(argc, argv);
    const osc::bag::DriveTopics topics;
    std::string guess_path = options.initial_guess;
    if (guess_path.empty()) guess_path = directoryOf(options.bag) + "/initial_guess.yaml";
    if (!isFile(guess_path)) {
      throw std::invalid_argument("no initial guess: give --initial-guess GUESS.yaml");
    }
    const osc::CalibrationFile guess = osc::readCalibrationFile(guess_path);
    const osc::FilterConfig config =
        options.config.empty() ? osc::FilterConfig() : osc::readFilterConfigFile(options.config);
    osc::makeDirectories(options.out);

    rosbag::Bag bag(options.bag, rosbag::bagmode::Read);
    const osc::CameraIntrinsics left_camera = readCameraInfo(bag, topics.left_info);
    const osc::CameraIntrinsics right_camera = readCameraInfo(bag, topics.right_info);
    const osc::PoseTrajectory odometry = osc::bag::readOdometry(bag, topics.odom);
    if (odometry.size() < 2)
      throw std::runtime_error("fewer than 2 odometry poses on " + topics.odom);
    std::map<std::int64_t, osc::Vector12d> truth;
    if (!options.truth_topic.empty()) {
      for (const auto& [stamp, p] : osc::bag::readCalibrationTopic(bag, options.truth_topic)) {
        truth[stamp] = p;
      }
      if (truth.empty()) throw std::runtime_error("no StereoCalibration on " + options.truth_topic);
    }
    const bool have_reference = !options.reference.empty() || !truth.empty();
    osc::Vector12d constant_reference = osc::Vector12d::Zero();
    if (!options.reference.empty()) {
      constant_reference = osc::readCalibrationFile(options.reference).extrinsics.toParameters();
    }

    osc::CalibrationPipeline pipeline(config, osc::FrontEndConfig(), left_camera, right_camera,
                                      guess.extrinsics);
    const int total =
        static_cast<int>(rosbag::View(bag, rosbag::TopicQuery(topics.left_image)).size());
    std::cerr << "evaluating " << options.bag << ": " << total << " left images, "
              << odometry.size() << " odometry poses, " << left_camera.width << "x"
              << left_camera.height << "\n";

    osc::EstimatesCsvWriter estimates_csv(options.out + "/estimates.csv");
    std::vector<osc::EstimateRow> estimates;
    std::vector<osc::ReferenceRow> reference;
    std::vector<double> times;
    std::map<std::int64_t, sensor_msgs::ImageConstPtr> pending_left, pending_right;
    int frame = 0, skipped = 0;
    double previous_stamp = 0.0;
    bool have_previous = false;
    const auto start = std::chrono::steady_clock::now();
    auto last_report = start;
    rosbag::View images(bag, rosbag::TopicQuery({topics.left_image, topics.right_image}));
    for (const rosbag::MessageInstance& m : images) {
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
        const auto increment = odometry.motionBetween(previous_stamp, stamp, kOdomTolerance);
        if (increment) {
          motion = *increment;
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
      osc::EstimateRow row;
      row.frame = frame;
      row.stamp = stamp;
      row.parameters = result.estimate.parameters;
      row.sigmas = result.estimate.sigmas();
      row.tracked_points = static_cast<int>(result.estimate.tracked_points);
      row.time_ms = 1000.0 * result.processing_time;
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
      if (frame == total || now - last_report > std::chrono::milliseconds(500)) {
        last_report = now;
        std::cerr << "\r  "
                  << osc::progressLine(frame, total,
                                       std::chrono::duration<double>(now - start).count())
                  << "  points " << row.tracked_points << std::flush;
      }
    }
    std::cerr << "\n";
    estimates_csv.flush();
    if (estimates.empty()) throw std::runtime_error("no stereo pair was processed");
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    osc::CalibrationFile final_calibration;
    final_calibration.extrinsics =
        osc::StereoExtrinsics::fromParameters(estimates.back().parameters);
    final_calibration.sigmas = estimates.back().sigmas;
    final_calibration.stamp = estimates.back().stamp;
    osc::writeCalibrationFileAtomic(options.out + "/calibration.yaml", final_calibration);

    const osc::Percentiles timing = osc::percentiles(times);
    std::ostringstream text;
    int step_frame = -1;
    if (!reference.empty()) {
      osc::ReferenceCsvWriter reference_csv(options.out + "/reference.csv");
      for (const osc::ReferenceRow& r : reference) reference_csv.write(r);
      reference_csv.flush();
      const int last_frame = estimates.back().frame;
      int last = options.window_last >= 0 ? options.window_last : std::min(1150, last_frame);
      int first = options.window_first >= 0 ? options.window_first
                                            : std::min(1000, std::max(0, last - 150));
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
                                    (p % 6 >= 3 ? 1.0 : 0.1));
          if (d > largest) largest = d, stepped = p;
        }
        const double tolerance = stepped % 6 >= 3 ? 0.3 * M_PI / 180.0 : 0.03;
        const int back =
            osc::framesToConverge(estimates, reference, stepped, tolerance, step_frame);
        text << "Step at frame " << step_frame << " (largest in "
             << osc::estimatesCsvColumns()[2 + stepped] << "): within "
             << (stepped % 6 >= 3 ? "0.3 deg" : "3 cm") << " from frame " << back << " on ("
             << (back >= 0 ? back - step_frame : -1) << " frames to converge)\n";
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
         << "; time per frame: median " << timing.median << " ms, p95 " << timing.p95
         << " ms; total " << elapsed << " s (" << estimates.size() / elapsed << " frames/s)\n";
    std::cout << text.str();
    std::ofstream(options.out + "/table.txt") << text.str();

    const std::string script = findPlotScript();
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
  } catch (const std::exception& e) {
    std::cerr << "evaluate: " << e.what() << "\n";
    usage();
    return 1;
  }
}
