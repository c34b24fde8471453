/// @file evaluate_main.cpp
/// @brief Runs the calibration pipeline over a bag or a KITTI raw drive folder as fast as
/// possible, without a ROS master (interface.md, "Offline evaluation"):
///
///   evaluate --bag DRIVE.bag --out DIR [--initial-guess GUESS.yaml] [--config PARAMS.yaml]
///            [--reference REF.yaml | --truth-topic TOPIC] [--window FIRST LAST]
///            [--stereo-ns NS] [--left-image T] [--right-image T] [--left-info T]
///            [--right-info T] [--odom T]
///   evaluate --kitti-raw DIR --out OUT [--initial-guess GUESS.yaml] [--config PARAMS.yaml]
///            [--window FIRST LAST] [--oxts-position velocity|gps] [--oxts-max-gap S]
///
/// A bag: reads NS/{left,right}/image_raw and camera_info (NS = /stereo) and /odom (poses
/// interpolated to the image stamps, linear + SLERP), pairs the images by exact stamp. A KITTI
/// raw folder (tools/kitti_raw_drive.h): image_00/01, the OXTS motion, KITTI's calibration
/// chain as the reference; the frames it skips are listed. Both then run the same loop
/// (tools/drive_evaluation.h): DIR/estimates.csv and DIR/calibration.yaml (the final
/// estimate); with a reference also DIR/reference.csv, DIR/table.txt (Table I, consistency,
/// convergence after a step, time per frame; also on stdout) and the plots of
/// scripts/plot_convergence.py. Without --initial-guess the file initial_guess.yaml next to
/// the bag (as `simulate` writes it), or in the KITTI folder, is used.
#include <unistd.h>
#include <algorithm>
#include <cstdint>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/Image.h>
#include <opencv2/core/utility.hpp>

#include "bag_io.h"
#include "online_stereo_calibration/tools/calibration_file.h"
#include "online_stereo_calibration/tools/command_line.h"
#include "online_stereo_calibration/tools/drive_evaluation.h"
#include "online_stereo_calibration/tools/estimator_config_yaml.h"
#include "online_stereo_calibration/tools/kitti_raw_source.h"
#include "online_stereo_calibration/tools/output_directory.h"

namespace {

struct Options {
  std::string bag, kitti_raw, out, initial_guess, config, reference, truth_topic;
  int window_first = -1, window_last = -1;
  int max_pairs = -1;  ///< stop after this many stereo pairs (-1: all)
  int threads = 1;     ///< OpenCV's worker threads (cv::setNumThreads)
  /// Topics (interface.md: left/image_raw, ... relative to the stereo namespace, and odom).
  std::string stereo_ns = "/stereo";
  std::string left_image, right_image, left_info, right_info, odom = "/odom";
  /// KITTI raw: where the positions come from, and the longest OXTS gap bridged (s).
  osc::KittiRawCommandLine kitti_raw_reader;
};

/// Odometry further than this (s) beyond an image stamp is not extrapolated.
constexpr double kOdomTolerance = 0.02;

/// The options that only a bag or only a KITTI folder takes.
const std::vector<std::string> kBagOnlyOptions = {"--reference",  "--truth-topic", "--stereo-ns",
                                                  "--left-image", "--right-image", "--left-info",
                                                  "--right-info", "--odom"};
const std::vector<std::string> kKittiOnlyOptions = {"--oxts-position", "--oxts-max-gap"};

/// The command line (`--help` prints it).
osc::CommandLine commandLine(Options* o) {
  osc::CommandLine cli(
      "evaluate",
      "Runs the calibration pipeline (front end + filter, as the nodelet) over a bag or a KITTI "
      "raw drive\nfolder as fast as possible, without a ROS master; writes DIR/estimates.csv and "
      "calibration.yaml,\nand with a reference reference.csv, table.txt (Table I) and "
      "convergence plots.");
  cli.option("--bag", &o->bag, "DRIVE.bag", "input bag (or --kitti-raw)");
  cli.option("--kitti-raw", &o->kitti_raw, "DIR",
             "input KITTI raw drive folder (image_00/01, oxts, calib_*.txt; or --bag): KITTI's "
             "calibration is the reference");
  cli.option("--out", &o->out, "DIR", "output directory").required();
  cli.option("--initial-guess", &o->initial_guess, "GUESS.yaml",
             "initial calibration (default: initial_guess.yaml beside the bag or in the KITTI "
             "folder)");
  cli.option("--config", &o->config, "PARAMS.yaml",
             "estimator parameters: filter keys (config/default.yaml) and a front_end: map");
  cli.option("--reference", &o->reference, "REF.yaml", "fixed true calibration (--bag)");
  cli.option("--truth-topic", &o->truth_topic, "TOPIC",
             "per-frame truth (StereoCalibration), e.g. /ground_truth/calibration (--bag)");
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
  o->kitti_raw_reader.addTo(&cli, "KITTI raw: ");
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
void finishOptions(const osc::CommandLine& cli, Options* o) {
  if (o->bag.empty() == o->kitti_raw.empty()) {
    throw osc::CommandLineError(o->bag.empty() ? "give --bag DRIVE.bag or --kitti-raw DIR"
                                               : "give --bag or --kitti-raw, not both");
  }
  const std::vector<std::string>& foreign = o->bag.empty() ? kBagOnlyOptions : kKittiOnlyOptions;
  for (const std::string& name : foreign) {
    if (cli.given(name)) {
      throw osc::CommandLineError(
          name + " applies to " + (o->bag.empty() ? "--bag" : "--kitti-raw") + " only" +
          (o->bag.empty() && (name == "--reference" || name == "--truth-topic")
               ? " (a KITTI raw drive's reference is KITTI's own calibration)"
               : ""));
    }
  }
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

/// First CameraInfo on a topic.
osc::CameraIntrinsics readCameraInfo(const rosbag::Bag& bag, const std::string& topic) {
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& m : view) {
    const auto info = m.instantiate<sensor_msgs::CameraInfo>();
    if (info) return online_stereo_calibration::intrinsicsFromCameraInfo(*info);  // validated
  }
  throw std::runtime_error("no sensor_msgs/CameraInfo on " + topic);
}

/// A bag as the evaluation's input: image pairs by exact stamp, odometry poses interpolated
/// (and their twists), the reference from a file or a truth topic.
class BagSource : public osc::DriveSource {
 public:
  explicit BagSource(const Options& options) : path_(options.bag) {
    topics_.left_image = options.left_image;
    topics_.right_image = options.right_image;
    topics_.left_info = options.left_info;
    topics_.right_info = options.right_info;
    topics_.odom = options.odom;
    bag_.open(options.bag, rosbag::bagmode::Read);
    std::vector<osc::bag::RequiredTopic> required = {
        {"--left-image", topics_.left_image, "sensor_msgs/Image"},
        {"--right-image", topics_.right_image, "sensor_msgs/Image"},
        {"--left-info", topics_.left_info, "sensor_msgs/CameraInfo"},
        {"--right-info", topics_.right_info, "sensor_msgs/CameraInfo"},
        {"--odom", topics_.odom, "nav_msgs/Odometry"}};
    if (!options.truth_topic.empty()) {
      required.push_back(
          {"--truth-topic", options.truth_topic, "online_stereo_calibration/StereoCalibration"});
    }
    osc::bag::requireTopics(bag_, options.bag, required);
    osc::makeDirectories(options.out);
    left_camera_ = readCameraInfo(bag_, topics_.left_info);
    right_camera_ = readCameraInfo(bag_, topics_.right_info);
    // One pass over the bag for both (see readOdometryAndCalibration).
    inputs_ = osc::bag::readOdometryAndCalibration(bag_, topics_.odom, options.truth_topic);
    for (const auto& [stamp, parameters] : inputs_.calibration) truth_[stamp] = parameters;
    if (inputs_.odometry.size() < 2)
      throw std::runtime_error("fewer than 2 odometry poses on " + topics_.odom);
    if (!options.truth_topic.empty() && truth_.empty()) {
      throw std::runtime_error("no StereoCalibration on " + options.truth_topic);
    }
    if (!options.reference.empty()) {
      constant_reference_ = osc::readCalibrationFile(options.reference).extrinsics.toParameters();
    }
    pair_count_ =
        static_cast<int>(rosbag::View(bag_, rosbag::TopicQuery(topics_.left_image)).size());
    images_ = std::make_unique<rosbag::View>(
        bag_, rosbag::TopicQuery({topics_.left_image, topics_.right_image}));
    next_ = images_->begin();
  }

  /// What the bag holds, on @p log (the run's first lines).
  void describe(std::ostream& log, const std::string& detector) const {
    log << "evaluating " << path_ << ": " << pair_count_ << " left images on " << topics_.left_image
        << ", " << inputs_.odometry.size() << " odometry poses on " << topics_.odom << ", "
        << left_camera_.width << "x" << left_camera_.height << ", " << detector << " front end\n";
    if (inputs_.samples_without_twist > 0) {
      log << "evaluate: " << inputs_.samples_without_twist << " of " << inputs_.odometry.size()
          << " odometry messages without a usable twist (" << inputs_.twist_problem
          << "): the time offset uses the trend of earlier increments there\n";
    }
  }

  std::string name() const override { return "Bag " + path_; }
  osc::CameraIntrinsics leftCamera() const override { return left_camera_; }
  osc::CameraIntrinsics rightCamera() const override { return right_camera_; }
  int pairCount() const override { return pair_count_; }

  bool next(osc::StereoPairInput* pair) override {
    for (; next_ != images_->end(); ++next_) {
      const auto image = next_->instantiate<sensor_msgs::Image>();
      if (!image) continue;
      const std::int64_t key = static_cast<std::int64_t>(image->header.stamp.toNSec());
      const bool is_left = next_->getTopic() == topics_.left_image;
      auto& mine = is_left ? pending_left_ : pending_right_;
      auto& other = is_left ? pending_right_ : pending_left_;
      const auto match = other.find(key);
      if (match == other.end()) {
        mine[key] = image;
        continue;
      }
      const sensor_msgs::ImageConstPtr left = is_left ? image : match->second;
      const sensor_msgs::ImageConstPtr right = is_left ? match->second : image;
      other.erase(other.begin(), std::next(match));  // older unmatched images never pair now
      mine.erase(mine.begin(), mine.lower_bound(key));
      ++next_;
      auto holders =
          std::make_shared<std::pair<cv_bridge::CvImageConstPtr, cv_bridge::CvImageConstPtr>>();
      pair->stamp = left->header.stamp.toSec();
      pair->stamp_ns = key;
      pair->left = toMat(left, &holders->first);
      pair->right = toMat(right, &holders->second);
      pair->owner = holders;
      return true;
    }
    return false;
  }

  std::optional<osc::MotionIncrement> motionBetween(double from, double to) const override {
    auto increment = inputs_.odometry.motionBetween(from, to, kOdomTolerance);
    if (increment) {
      // The odometry's own twists at both stamps for the time offset, as the node does.
      increment->has_twists = inputs_.odometry_twists.twistAt(from, &increment->twist_start) &&
                              inputs_.odometry_twists.twistAt(to, &increment->twist_end);
    }
    return increment;
  }

  bool hasReference() const override { return constant_reference_ || !truth_.empty(); }

  std::optional<osc::Vector12d> referenceAt(std::int64_t stamp_ns) const override {
    if (truth_.empty()) return constant_reference_;
    const auto t = truth_.find(stamp_ns);
    if (t == truth_.end()) return std::nullopt;
    return t->second;
  }

 private:
  static cv::Mat toMat(const sensor_msgs::ImageConstPtr& msg, cv_bridge::CvImageConstPtr* holder) {
    const std::string& e = msg->encoding;
    if (e == "mono8" || e == "mono16" || e == "bgr8" || e == "bgra8") {
      *holder = cv_bridge::toCvShare(msg);
    } else {
      *holder = cv_bridge::toCvShare(msg, "bgr8");
    }
    return (*holder)->image;
  }

  std::string path_;
  osc::bag::DriveTopics topics_;
  rosbag::Bag bag_;
  osc::CameraIntrinsics left_camera_, right_camera_;
  osc::bag::OdometryAndCalibration inputs_;
  std::map<std::int64_t, osc::Vector12d> truth_;  // the latest message of a stamp wins
  std::optional<osc::Vector12d> constant_reference_;
  int pair_count_ = 0;
  std::unique_ptr<rosbag::View> images_;
  rosbag::View::iterator next_;
  std::map<std::int64_t, sensor_msgs::ImageConstPtr> pending_left_, pending_right_;
};

/// The KITTI raw folder, read.
std::unique_ptr<osc::KittiRawSource> kittiRawSource(const Options& options) {
  return std::make_unique<osc::KittiRawSource>(
      osc::readKittiRawDrive(options.kitti_raw, options.kitti_raw_reader.options()));
}

/// The tool itself, after the command line.
int evaluate(const Options& options) {
  cv::setNumThreads(options.threads);
  std::string guess_path = options.initial_guess;
  if (guess_path.empty()) {
    guess_path = options.bag.empty() ? options.kitti_raw + "/initial_guess.yaml"
                                     : osc::directoryOf(options.bag) + "/initial_guess.yaml";
  }
  if (!osc::isRegularFile(guess_path)) {
    throw std::invalid_argument("no initial guess: give --initial-guess GUESS.yaml");
  }
  const osc::CalibrationFile guess = osc::readCalibrationFile(guess_path);
  const osc::EstimatorConfig config = options.config.empty()
                                          ? osc::EstimatorConfig()
                                          : osc::readEstimatorConfigFile(options.config);

  osc::DriveEvaluationOptions run;
  run.out = options.out;
  run.window_first = options.window_first;
  run.window_last = options.window_last;
  run.max_pairs = options.max_pairs;
  run.progress_bar = isatty(STDERR_FILENO) != 0;
  std::unique_ptr<osc::DriveSource> source;
  if (!options.bag.empty()) {
    auto bag = std::make_unique<BagSource>(options);
    bag->describe(std::cerr, config.front_end.detector);
    source = std::move(bag);
  } else {
    auto kitti = kittiRawSource(options);
    const osc::KittiRawDrive& drive = kitti->drive();
    std::cerr << "evaluating " << drive.summary() << "  " << config.front_end.detector
              << " front end\n";
    for (const std::string& line : drive.skippedLines()) std::cerr << "  skipped " << line << "\n";
    run.notes.push_back("Frames of " + options.kitti_raw + " skipped by the reader (" +
                        std::to_string(drive.skipped.size()) + "; the CSV's frame counts the " +
                        std::to_string(drive.frames.size()) + " pairs used):");
    for (const std::string& line : drive.skippedLines()) run.notes.push_back("  " + line);
    source = std::move(kitti);
  }
  return osc::evaluateDrive(*source, config, guess.extrinsics, run, std::cout, std::cerr);
}

}  // namespace

int main(int argc, char** argv) {
  Options parsed;
  osc::CommandLine cli = commandLine(&parsed);
  return osc::runTool(
      "evaluate", [&] { return cli.usage(); },
      [&] {
        if (!cli.parse(argc, argv)) return 0;
        finishOptions(cli, &parsed);
        return evaluate(parsed);
      });
}
