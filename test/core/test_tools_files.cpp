/// Tests of the tools library: calibration YAML, estimates/reference CSV, evaluation.
#include <dirent.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include "temp_dir.h"

#include "online_stereo_calibration/core/geometry/rotation.h"
#include "online_stereo_calibration/core/sim/measurement_simulator.h"
#include "online_stereo_calibration/tools/calibration_file.h"
#include "online_stereo_calibration/tools/command_line.h"
#include "online_stereo_calibration/tools/drive_simulation.h"
#include "online_stereo_calibration/tools/estimates_csv.h"
#include "online_stereo_calibration/tools/estimator_config_yaml.h"
#include "online_stereo_calibration/tools/evaluation.h"
#include "online_stereo_calibration/tools/filter_config_yaml.h"
#include "online_stereo_calibration/tools/output_directory.h"
#include "online_stereo_calibration/tools/scenario_file.h"
#include "online_stereo_calibration/tools/tum_trajectory.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

/// Expects @p fn to throw an exception of type E whose message contains every fragment.
template <typename E>
void expectThrowMentioning(const std::function<void()>& fn,
                           std::initializer_list<std::string> fragments) {
  try {
    fn();
    ADD_FAILURE() << "expected an exception mentioning " << *fragments.begin();
  } catch (const E& e) {
    const std::string message = e.what();
    for (const std::string& fragment : fragments) {
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "'" << fragment << "' not in: " << message;
    }
  }
}

/// Random parameters in the RPY chart's regular region (|pitch| < pi/2).
Vector12d randomParameters(std::mt19937& rng) {
  std::uniform_real_distribution<double> metres(-3.0, 3.0);
  std::uniform_real_distribution<double> angle(-3.1, 3.1);
  std::uniform_real_distribution<double> pitch(-1.5, 1.5);
  Vector12d p;
  for (int block = 0; block < 2; ++block) {
    p.segment<3>(6 * block) << metres(rng), metres(rng), metres(rng);
    p.segment<3>(6 * block + 3) << angle(rng), pitch(rng), angle(rng);
  }
  return p;
}

CalibrationFile sampleCalibration(std::mt19937& rng) {
  CalibrationFile file;
  file.extrinsics = StereoExtrinsics::fromParameters(randomParameters(rng));
  std::uniform_real_distribution<double> sigma(1e-7, 0.5);
  Vector12d sigmas;
  for (int i = 0; i < 12; ++i) sigmas(i) = sigma(rng);
  sigmas(0) = 1e-5;  // no '.' in its shortest form
  sigmas(1) = 0.0;
  file.sigmas = sigmas;
  file.stamp = 1700000000.123456789;
  return file;
}

/// The extrinsics a reader gets back when the file holds exactly e.toParameters().
void expectSameBits(const StereoExtrinsics& read, const StereoExtrinsics& written) {
  const StereoExtrinsics expected = StereoExtrinsics::fromParameters(written.toParameters());
  EXPECT_TRUE(read.T_veh_caml.matrix() == expected.T_veh_caml.matrix());
  EXPECT_TRUE(read.T_caml_camr.matrix() == expected.T_caml_camr.matrix());
}

const std::string kValidYaml =
    "vehicle_to_left: [1.5, 0.25, 1.25, 0.0, 0.125, -0.5]\n"
    "left_to_right: [0.0, -0.5, 0.0, 0.0, 0.0, 0.0]\n";

// ---------------------------------------------------------------------------------------
// Calibration YAML
// ---------------------------------------------------------------------------------------

TEST(CalibrationFile, ParsesTheInterfaceExample) {
  const CalibrationFile file = parseCalibrationYaml(kValidYaml + "other_key: 3\n", "inline");
  Vector12d expected;
  expected << 1.5, 0.25, 1.25, 0.0, 0.125, -0.5, 0.0, -0.5, 0.0, 0.0, 0.0, 0.0;
  EXPECT_TRUE(file.extrinsics.toParameters().isApprox(expected, 1e-15))
      << file.extrinsics.toParameters().transpose();
  EXPECT_NEAR(file.extrinsics.T_caml_camr.translation().y(), -0.5, 0.0);
  EXPECT_FALSE(file.sigmas.has_value());
  EXPECT_FALSE(file.stamp.has_value());
}

TEST(CalibrationFile, AtomicWriteThenReadIsBitExact) {
  TempDir dir;
  std::mt19937 rng(42);
  const CalibrationFile written = sampleCalibration(rng);
  const std::string path = dir.file("calibration.yaml");
  writeCalibrationFileAtomic(path, written);

  const CalibrationFile read = readCalibrationFile(path);
  expectSameBits(read.extrinsics, written.extrinsics);
  ASSERT_TRUE(read.sigmas.has_value());
  for (int i = 0; i < 12; ++i) EXPECT_EQ((*read.sigmas)(i), (*written.sigmas)(i)) << i;
  ASSERT_TRUE(read.stamp.has_value());
  EXPECT_EQ(*read.stamp, *written.stamp);
  EXPECT_FALSE(read.time_offset.has_value());  // only written when estimated

  const std::string text = readText(path);
  EXPECT_EQ(text.rfind("# ", 0), 0u) << "starts with a comment line";
  EXPECT_NE(text.find("metres and radians"), std::string::npos);
  EXPECT_NE(text.find("1.0000000000000001e-05"), std::string::npos) << text;
  EXPECT_EQ(dir.entries(), std::set<std::string>({"calibration.yaml"})) << "no temp file left";
}

TEST(CalibrationFile, TimeOffsetIsSavedAndReadBack) {
  TempDir dir;
  std::mt19937 rng(7);
  CalibrationFile written = sampleCalibration(rng);
  written.time_offset = -0.0123456789;
  written.time_offset_sigma = 0.0004;
  const std::string path = dir.file("calibration.yaml");
  writeCalibrationFileAtomic(path, written);
  const CalibrationFile read = readCalibrationFile(path);
  ASSERT_TRUE(read.time_offset && read.time_offset_sigma);
  EXPECT_EQ(*read.time_offset, *written.time_offset);
  EXPECT_EQ(*read.time_offset_sigma, *written.time_offset_sigma);
  expectThrowMentioning<std::runtime_error>(
      [&] {
        parseCalibrationYaml(
            "vehicle_to_left: [0, 0, 0, 0, 0, 0]\nleft_to_right: [0, -0.5, 0, 0, 0, 0]\n"
            "sigma_time_offset: -1\n",
            "neg.yaml");
      },
      {"neg.yaml", "sigma_time_offset"});
}

TEST(CalibrationFile, ARunsFinalRowKeepsTheTimeOffsetOnlyWhenEstimated) {
  EstimateRow row;
  row.parameters << 1.5, 0.1, 1.3, 0.01, 0.02, 0.03, 0.0, -0.3, 0.0, 0.001, 0.002, 0.003;
  row.sigmas.setConstant(0.01);
  row.stamp = 12.5;
  row.time_offset = 0.004;
  row.time_offset_sigma = 0.0;  // not estimated
  const CalibrationFile without = calibrationFileOf(row);
  EXPECT_TRUE(without.extrinsics.toParameters().isApprox(row.parameters, 1e-12));
  EXPECT_EQ(*without.stamp, 12.5);
  EXPECT_FALSE(without.time_offset.has_value());
  row.time_offset_sigma = 0.001;
  const CalibrationFile with = calibrationFileOf(row);
  ASSERT_TRUE(with.time_offset && with.time_offset_sigma);
  EXPECT_EQ(*with.time_offset, 0.004);
  EXPECT_EQ(*with.time_offset_sigma, 0.001);
}

TEST(CalibrationFile, FormattedTextParsesBackBitExactForManyValues) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    CalibrationFile written = sampleCalibration(rng);
    (*written.sigmas)(2) = 1e20;  // formatted as 1.0e+20 (a float to YAML 1.1 readers too)
    (*written.sigmas)(3) = 5e-324;
    written.stamp = std::uniform_real_distribution<double>(0.0, 2e9)(rng);
    const std::string text = formatCalibrationYaml(written);
    const CalibrationFile read = parseCalibrationYaml(text, "trial");
    expectSameBits(read.extrinsics, written.extrinsics);
    ASSERT_TRUE(read.sigmas && read.stamp);
    EXPECT_TRUE(*read.sigmas == *written.sigmas) << text;
    EXPECT_EQ(*read.stamp, *written.stamp) << text;
    ASSERT_NE(text.find("1.0e+20"), std::string::npos) << text;
  }
}

TEST(CalibrationFile, MissingKeyIsNamed) {
  expectThrowMentioning<std::runtime_error>(
      [] { parseCalibrationYaml("vehicle_to_left: [1, 2, 3, 4, 5, 6]\n", "guess.yaml"); },
      {"guess.yaml", "missing", "left_to_right"});
  expectThrowMentioning<std::runtime_error>(
      [] { parseCalibrationYaml("left_to_right: [1, 2, 3, 4, 5, 6]\n", "guess.yaml"); },
      {"guess.yaml", "missing", "vehicle_to_left"});
}

TEST(CalibrationFile, WrongLengthIsNamed) {
  expectThrowMentioning<std::runtime_error>(
      [] {
        parseCalibrationYaml("vehicle_to_left: [1, 2, 3]\nleft_to_right: [1, 2, 3, 4, 5, 6]\n",
                             "short.yaml");
      },
      {"short.yaml", "vehicle_to_left", "6"});
  expectThrowMentioning<std::runtime_error>(
      [] {
        parseCalibrationYaml(
            "vehicle_to_left: [1, 2, 3, 4, 5, 6]\nleft_to_right: [1, 2, 3, 4, 5, 6, 7]\n",
            "long.yaml");
      },
      {"long.yaml", "left_to_right"});
  expectThrowMentioning<std::runtime_error>(
      [] {
        parseCalibrationYaml("vehicle_to_left: 1.0\nleft_to_right: [1, 2, 3, 4, 5, 6]\n", "s");
      },
      {"vehicle_to_left"});
}

TEST(CalibrationFile, NanAndNonNumbersAreNamed) {
  expectThrowMentioning<std::runtime_error>(
      [] {
        parseCalibrationYaml(
            "vehicle_to_left: [1, 2, 3, 4, 5, 6]\nleft_to_right: [0, 0, .nan, 0, 0, 0]\n",
            "nan.yaml");
      },
      {"nan.yaml", "left_to_right[2]", "NaN"});
  expectThrowMentioning<std::runtime_error>(
      [] {
        parseCalibrationYaml(
            "vehicle_to_left: [1, 2, 3, abc, 5, 6]\nleft_to_right: [0, 0, 0, 0, 0, 0]\n",
            "word.yaml");
      },
      {"word.yaml", "vehicle_to_left[3]", "not a number"});
  expectThrowMentioning<std::runtime_error>(
      [] { parseCalibrationYaml(kValidYaml + "stamp: .inf\n", "stamp.yaml"); },
      {"stamp.yaml", "stamp"});
}

TEST(CalibrationFile, SigmaKeysAreChecked) {
  expectThrowMentioning<std::runtime_error>(
      [] { parseCalibrationYaml(kValidYaml + "sigma_vehicle_to_left: [1, 1, 1, 1, 1, 1]\n", "a"); },
      {"missing", "sigma_left_to_right"});
  expectThrowMentioning<std::runtime_error>(
      [] {
        parseCalibrationYaml(kValidYaml +
                                 "sigma_vehicle_to_left: [1, 1, 1, 1, 1, 1]\n"
                                 "sigma_left_to_right: [1, 1, 1, 1, -1, 1]\n",
                             "b");
      },
      {"sigma_left_to_right[4]", "negative"});
}

/// A random symmetric positive definite 12x12 covariance with strong correlations.
Matrix12d sampleCovariance(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Matrix12d A;
  for (int i = 0; i < 144; ++i) A(i / 12, i % 12) = 1e-2 * normal(rng);
  return A * A.transpose() + 1e-6 * Matrix12d::Identity();
}

TEST(CalibrationFile, FullCovarianceRoundTripsBitExactlyAndOldKeysStayReadable) {
  TempDir dir;
  std::mt19937 rng(11);
  CalibrationFile written = sampleCalibration(rng);
  const Matrix12d covariance = sampleCovariance(rng);
  written.covariance = covariance;
  written.sigmas = covariance.diagonal().cwiseSqrt();
  const std::string path = dir.file("with_covariance.yaml");
  writeCalibrationFileAtomic(path, written);

  const CalibrationFile read = readCalibrationFile(path);
  ASSERT_TRUE(read.covariance.has_value());
  for (int i = 0; i < 144; ++i) {
    EXPECT_EQ((*read.covariance)(i / 12, i % 12), covariance(i / 12, i % 12)) << i;
  }
  ASSERT_TRUE(parameterCovariance(read).has_value());
  EXPECT_TRUE(*parameterCovariance(read) == covariance);

  // A reader that predates the key (here: the same text without it) gets the same
  // extrinsics and sigmas; the extra key is only more information.
  const std::string text = readText(path);
  const std::size_t at = text.find("covariance:");
  ASSERT_NE(at, std::string::npos) << text;
  EXPECT_EQ(text.find("covariance:", at + 1), std::string::npos) << "one key only";
  const CalibrationFile old = parseCalibrationYaml(text.substr(0, at), "old");
  expectSameBits(old.extrinsics, written.extrinsics);
  ASSERT_TRUE(old.sigmas.has_value());
  EXPECT_TRUE(*old.sigmas == *written.sigmas);
  EXPECT_FALSE(old.covariance.has_value());
}

TEST(CalibrationFile, WithoutCovarianceTheSigmasGiveADiagonalOne) {
  std::mt19937 rng(5);
  CalibrationFile file = sampleCalibration(rng);
  ASSERT_TRUE(file.sigmas.has_value());
  const std::optional<Matrix12d> covariance = parameterCovariance(file);
  ASSERT_TRUE(covariance.has_value());
  for (int i = 0; i < 12; ++i) {
    for (int j = 0; j < 12; ++j) {
      EXPECT_EQ((*covariance)(i, j), i == j ? (*file.sigmas)(i) * (*file.sigmas)(i) : 0.0);
    }
  }
  file.sigmas.reset();
  EXPECT_FALSE(parameterCovariance(file).has_value());
}

TEST(CalibrationFile, CovarianceIsChecked) {
  std::mt19937 rng(9);
  const Matrix12d good = sampleCovariance(rng);
  const auto yaml = [](const Matrix12d& c, int count) {
    std::ostringstream out;
    out.precision(17);
    out << "covariance: [";
    for (int i = 0; i < count; ++i) out << (i ? ", " : "") << c(i / 12, i % 12);
    out << "]\n";
    return out.str();
  };
  EXPECT_NO_THROW(parseCalibrationYaml(kValidYaml + yaml(good, 144), "good"));
  expectThrowMentioning<std::runtime_error>(
      [&] { parseCalibrationYaml(kValidYaml + yaml(good, 143), "short.yaml"); },
      {"short.yaml", "covariance", "144"});
  Matrix12d asymmetric = good;
  asymmetric(0, 5) += 1e-3;
  expectThrowMentioning<std::runtime_error>(
      [&] { parseCalibrationYaml(kValidYaml + yaml(asymmetric, 144), "asym.yaml"); },
      {"asym.yaml", "covariance", "symmetric"});
  Matrix12d indefinite = good;
  indefinite(4, 4) = -1e-3;
  expectThrowMentioning<std::runtime_error>(
      [&] { parseCalibrationYaml(kValidYaml + yaml(indefinite, 144), "indef.yaml"); },
      {"indef.yaml", "covariance", "positive definite"});
  Matrix12d with_nan = good;
  with_nan(7, 7) = std::nan("");
  expectThrowMentioning<std::runtime_error>(
      [&] { parseCalibrationYaml(kValidYaml + yaml(with_nan, 144), "nan.yaml"); },
      {"nan.yaml", "covariance[91]"});
  // Sigmas that disagree with the covariance's diagonal (a hand-edited sigma).
  expectThrowMentioning<std::runtime_error>(
      [&] {
        parseCalibrationYaml(kValidYaml + yaml(good, 144) +
                                 "sigma_vehicle_to_left: [1, 1, 1, 1, 1, 1]\n"
                                 "sigma_left_to_right: [1, 1, 1, 1, 1, 1]\n",
                             "stale.yaml");
      },
      {"stale.yaml", "covariance[0]", "sigma"});
}

TEST(CalibrationFile, BadYamlAndMissingFileNameTheSource) {
  expectThrowMentioning<std::runtime_error>(
      [] { parseCalibrationYaml("vehicle_to_left: [1, 2\n", "broken.yaml"); }, {"broken.yaml"});
  expectThrowMentioning<std::runtime_error>([] { parseCalibrationYaml("- 1\n- 2\n", "list.yaml"); },
                                            {"list.yaml"});
  expectThrowMentioning<std::runtime_error>(
      [] { readCalibrationFile("/nonexistent/dir/calib.yaml"); }, {"/nonexistent/dir/calib.yaml"});
}

TEST(CalibrationFile, OverwriteReplacesTheOldContents) {
  TempDir dir;
  std::mt19937 rng(3);
  const std::string path = dir.file("result.yaml");
  writeCalibrationFileAtomic(path, sampleCalibration(rng));
  const CalibrationFile second = sampleCalibration(rng);
  writeCalibrationFileAtomic(path, second);
  expectSameBits(readCalibrationFile(path).extrinsics, second.extrinsics);
  EXPECT_EQ(dir.entries().size(), 1u);
}

TEST(CalibrationFile, WriteIntoMissingDirectoryFailsCleanly) {
  TempDir dir;
  const std::string path = dir.file("no_such_dir/result.yaml");
  std::mt19937 rng(4);
  expectThrowMentioning<std::runtime_error>(
      [&] { writeCalibrationFileAtomic(path, sampleCalibration(rng)); }, {path});
  EXPECT_TRUE(dir.entries().empty());
}

TEST(CalibrationFile, NonFiniteValuesAreRefusedAndOldFileKept) {
  TempDir dir;
  const std::string path = dir.file("result.yaml");
  writeText(path, kValidYaml);
  std::mt19937 rng(5);
  CalibrationFile bad = sampleCalibration(rng);
  (*bad.sigmas)(4) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(writeCalibrationFileAtomic(path, bad), std::runtime_error);
  EXPECT_EQ(readText(path), kValidYaml);
  EXPECT_EQ(dir.entries(), std::set<std::string>({"result.yaml"}));
}

/// Restores the file size limit and SIGXFSZ disposition on scope exit.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &saved_);
    old_handler_ = ::signal(SIGXFSZ, SIG_IGN);
    rlimit limit = saved_;
    limit.rlim_cur = bytes;
    ok_ = ::setrlimit(RLIMIT_FSIZE, &limit) == 0;
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &saved_);
    ::signal(SIGXFSZ, old_handler_);
  }
  bool ok() const { return ok_; }

 private:
  rlimit saved_{};
  void (*old_handler_)(int) = nullptr;
  bool ok_ = false;
};

// A write that fails half-way (file size limit; works as root too) must keep the old file
// and leave no temporary file behind.
TEST(CalibrationFile, FailedWriteKeepsOldFileAndLeavesNoTemp) {
  TempDir dir;
  const std::string path = dir.file("result.yaml");
  writeText(path, kValidYaml);
  std::mt19937 rng(6);
  const CalibrationFile next = sampleCalibration(rng);
  {
    FileSizeLimit limit(64);
    ASSERT_TRUE(limit.ok());
    expectThrowMentioning<std::runtime_error>([&] { writeCalibrationFileAtomic(path, next); },
                                              {path, "write"});
  }
  EXPECT_EQ(readText(path), kValidYaml);
  EXPECT_EQ(dir.entries(), std::set<std::string>({"result.yaml"}));
}

TEST(CalibrationFile, ReadOnlyDirectoryFailsCleanly) {
  TempDir dir;
  const std::string path = dir.file("result.yaml");
  writeText(path, kValidYaml);
  ASSERT_EQ(::chmod(dir.path().c_str(), 0555), 0);
  if (::access(dir.path().c_str(), W_OK) == 0) {
    GTEST_SKIP() << "running as root: permissions do not stop writes (see the file size test)";
  }
  std::mt19937 rng(8);
  EXPECT_THROW(writeCalibrationFileAtomic(path, sampleCalibration(rng)), std::runtime_error);
  EXPECT_EQ(readText(path), kValidYaml);
  EXPECT_EQ(dir.entries(), std::set<std::string>({"result.yaml"}));
}

// ---------------------------------------------------------------------------------------
// CSV
// ---------------------------------------------------------------------------------------

TEST(EstimatesCsv, HeaderIsExactlyTheInterface) {
  const std::string interface_header = std::string(
      "frame,stamp,xl,yl,zl,roll_l,pitch_l,yaw_l,xr,yr,zr,roll_r,pitch_r,yaw_r,"
      "sigma_xl,sigma_yl,sigma_zl,sigma_roll_l,sigma_pitch_l,sigma_yaw_l,"
      "sigma_xr,sigma_yr,sigma_zr,sigma_roll_r,sigma_pitch_r,sigma_yaw_r,tracked_points,time_ms");
  // interface.md allows further columns: the time offset (issue 15).
  EXPECT_EQ(estimatesCsvHeader(), interface_header + ",time_offset_ms,sigma_time_offset_ms");
  EXPECT_EQ(referenceCsvHeader(),
            "frame,stamp,xl,yl,zl,roll_l,pitch_l,yaw_l,xr,yr,zr,roll_r,pitch_r,yaw_r");

  TempDir dir;
  { EstimatesCsvWriter writer(dir.file("estimates.csv")); }
  { ReferenceCsvWriter writer(dir.file("reference.csv")); }
  EXPECT_EQ(readText(dir.file("estimates.csv")), estimatesCsvHeader() + "\n");
  EXPECT_EQ(readText(dir.file("reference.csv")), referenceCsvHeader() + "\n");
}

TEST(EstimatesCsv, RoundTripIsExact) {
  TempDir dir;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> positive(1e-9, 1.0);
  std::vector<EstimateRow> estimates;
  std::vector<ReferenceRow> reference;
  for (int frame = 0; frame < 50; ++frame) {
    EstimateRow row;
    row.frame = frame;
    row.stamp = (frame % 2 == 0) ? 1700000000.0 + frame * 0.1 : frame * 0.1;  // 0.1 * 3 etc.
    row.parameters = randomParameters(rng);
    for (int i = 0; i < 12; ++i) row.sigmas(i) = positive(rng);
    row.tracked_points = frame * 3;
    row.time_ms = positive(rng) * 100.0;
    estimates.push_back(row);
    reference.push_back({frame, row.stamp, randomParameters(rng)});
  }
  {
    EstimatesCsvWriter writer(dir.file("estimates.csv"));
    for (const EstimateRow& row : estimates) writer.write(row);
    writer.flush();
    ReferenceCsvWriter reference_writer(dir.file("reference.csv"));
    for (const ReferenceRow& row : reference) reference_writer.write(row);
  }
  const std::vector<EstimateRow> read = readEstimatesCsv(dir.file("estimates.csv"));
  ASSERT_EQ(read.size(), estimates.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].frame, estimates[i].frame);
    EXPECT_EQ(read[i].stamp, estimates[i].stamp) << i;
    EXPECT_TRUE(read[i].parameters == estimates[i].parameters) << i;
    EXPECT_TRUE(read[i].sigmas == estimates[i].sigmas) << i;
    EXPECT_EQ(read[i].tracked_points, estimates[i].tracked_points);
    EXPECT_EQ(read[i].time_ms, estimates[i].time_ms);
  }
  const std::vector<ReferenceRow> read_reference = readReferenceCsv(dir.file("reference.csv"));
  ASSERT_EQ(read_reference.size(), reference.size());
  for (std::size_t i = 0; i < reference.size(); ++i) {
    EXPECT_EQ(read_reference[i].frame, reference[i].frame);
    EXPECT_EQ(read_reference[i].stamp, reference[i].stamp);
    EXPECT_TRUE(read_reference[i].parameters == reference[i].parameters) << i;
  }

  // Every stamp has at least nanosecond digits.
  std::istringstream lines(readText(dir.file("estimates.csv")));
  std::string line;
  std::getline(lines, line);
  while (std::getline(lines, line)) {
    const std::string stamp =
        line.substr(line.find(',') + 1, line.find(',', line.find(',') + 1) - line.find(',') - 1);
    ASSERT_NE(stamp.find('.'), std::string::npos) << stamp;
    EXPECT_GE(stamp.size() - stamp.find('.') - 1, 9u) << stamp;
  }
}

TEST(EstimatesCsv, ReaderAcceptsExtraColumnsAndNan) {
  TempDir dir;
  std::string line = "7,0.700000000";
  for (int i = 0; i < 24; ++i) line += i == 5 ? ",nan" : ",0.5";
  line += ",12,3.25,extra\r\n";
  writeText(dir.file("e.csv"), estimatesCsvHeader() + ",note\r\n" + line + "\n");
  const std::vector<EstimateRow> rows = readEstimatesCsv(dir.file("e.csv"));
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].frame, 7);
  EXPECT_TRUE(std::isnan(rows[0].parameters(5)));
  EXPECT_EQ(rows[0].tracked_points, 12);
  EXPECT_EQ(rows[0].time_ms, 3.25);
}

TEST(EstimatesCsv, ReaderRejectsBadHeaderAndBadFields) {
  TempDir dir;
  writeText(dir.file("bad_header.csv"), "frame,stamp,xl\n1,2,3\n");
  expectThrowMentioning<std::runtime_error>([&] { readEstimatesCsv(dir.file("bad_header.csv")); },
                                            {"bad_header.csv", "header"});
  std::string row = "1,0.1";
  for (int i = 0; i < 24; ++i) row += i == 8 ? ",x1" : ",0";
  row += ",3,1.0\n";
  writeText(dir.file("bad_field.csv"), estimatesCsvHeader() + "\n" + row);
  expectThrowMentioning<std::runtime_error>([&] { readEstimatesCsv(dir.file("bad_field.csv")); },
                                            {"line 2", "'zr'"});
  writeText(dir.file("short.csv"), referenceCsvHeader() + "\n1,2,3\n");
  expectThrowMentioning<std::runtime_error>([&] { readReferenceCsv(dir.file("short.csv")); },
                                            {"short.csv", "line 2"});
  EXPECT_THROW(EstimatesCsvWriter(dir.file("missing/e.csv")), std::runtime_error);
  EXPECT_THROW(readReferenceCsv(dir.file("missing.csv")), std::runtime_error);
}

// ---------------------------------------------------------------------------------------
// Evaluation
// ---------------------------------------------------------------------------------------

TEST(Evaluation, ParameterErrorsWrapAnglesAcrossPiAndLeaveTranslations) {
  Vector12d estimate = Vector12d::Zero(), truth = Vector12d::Zero();
  estimate(5) = 179.0 * kDeg;  // yaw_l just below +180 deg ...
  truth(5) = -179.0 * kDeg;    // ... truth just above -180 deg: 2 deg apart, not 358
  estimate(9) = 1e-9;          // roll_r: a converged error, kept to the last bit
  estimate(1) = 7.0;           // yl: a translation is never wrapped
  const Vector12d e = parameterErrors(estimate, truth);
  EXPECT_NEAR(e(5), -2.0 * kDeg, 1e-12);
  EXPECT_EQ(e(9), 1e-9);
  EXPECT_EQ(e(1), 7.0);
  EXPECT_EQ(parameterError(estimate, truth, 5), e(5));
  for (int k = 0; k < 12; ++k) EXPECT_EQ(isAngleParameter(k), k % 6 >= 3) << k;
}

EstimateRow estimate(int frame, const Vector12d& parameters, double sigma) {
  EstimateRow row;
  row.frame = frame;
  row.parameters = parameters;
  row.sigmas = Vector12d::Constant(sigma);
  return row;
}

ReferenceRow truth(int frame, const Vector12d& parameters) { return {frame, 0.0, parameters}; }

TEST(Evaluation, RmseAndConsistencyMatchAHandComputation) {
  Vector12d ref = Vector12d::Zero();
  ref(7) = -0.5;  // yr
  std::vector<ReferenceRow> reference;
  for (int f = 0; f <= 12; ++f) reference.push_back(truth(f, ref));
  reference.erase(reference.begin() + 11);  // frame 11 has no reference

  // xl errors 0.1, -0.3, 0.2 on frames 10, 12, 9 (given out of order); sigma 0.06 -> 2 sigma
  // 0.12: only the first is within. yr errors 0.01, 0.01, 0.05 with sigma 0.02: 2 of 3 within.
  std::vector<EstimateRow> estimates;
  Vector12d p = ref;
  p(0) = 0.1, p(7) = -0.49;
  estimates.push_back(estimate(10, p, 0.06));
  p(0) = -0.3, p(7) = -0.49;
  estimates.push_back(estimate(12, p, 0.06));
  estimates.back().sigmas(7) = 0.02;
  estimates.back().sigmas(0) = 0.07;
  p(0) = 0.2, p(7) = -0.45;
  estimates.push_back(estimate(9, p, 0.06));
  p(0) = 5.0;
  estimates.push_back(estimate(11, p, 0.06));  // no reference: not used
  estimates.push_back(estimate(3, p, 0.06));   // outside the window
  for (EstimateRow& row : estimates) row.sigmas(7) = 0.02;

  const EvaluationReport report = evaluateWindow(estimates, reference, 9, 12);
  EXPECT_EQ(report.first_frame, 9);
  EXPECT_EQ(report.last_frame, 12);
  EXPECT_EQ(report.frames_used, 3);
  const ParameterStatistics& xl = report.parameters[0];
  EXPECT_NEAR(xl.rmse, std::sqrt((0.01 + 0.09 + 0.04) / 3.0), 1e-15);
  EXPECT_NEAR(xl.within_2sigma, 1.0 / 3.0, 1e-15);
  EXPECT_NEAR(xl.max_abs_error, 0.3, 1e-15);
  EXPECT_EQ(xl.sigma_at_last, 0.07);  // frame 12 is the last
  const ParameterStatistics& yr = report.parameters[7];
  EXPECT_NEAR(yr.rmse, std::sqrt((0.0001 + 0.0001 + 0.0025) / 3.0), 1e-12);
  EXPECT_NEAR(yr.within_2sigma, 2.0 / 3.0, 1e-15);
  EXPECT_EQ(report.parameters[1].rmse, 0.0);
  EXPECT_EQ(report.parameters[1].within_2sigma, 1.0);

  // Diagonal NEES by hand: per frame sum_k (e_k / sigma_k)^2 / 12.
  const double nees_10 = (std::pow(0.1 / 0.06, 2) + std::pow(0.01 / 0.02, 2)) / 12.0;
  const double nees_12 = (std::pow(0.3 / 0.07, 2) + std::pow(0.01 / 0.02, 2)) / 12.0;
  const double nees_9 = (std::pow(0.2 / 0.06, 2) + std::pow(0.05 / 0.02, 2)) / 12.0;
  EXPECT_NEAR(report.mean_nees, (nees_10 + nees_12 + nees_9) / 3.0, 1e-9);
}

TEST(Evaluation, AngleErrorsAreWrapped) {
  std::vector<ReferenceRow> reference = {truth(0, Vector12d::Zero()), truth(1, Vector12d::Zero())};
  reference[1].parameters(11) = -179.0 * kDeg;  // yaw_r
  Vector12d p0 = Vector12d::Zero();
  p0(5) = 359.0 * kDeg;  // yaw_l: error -1 deg, not 359 deg
  p0(11) = 0.0;
  Vector12d p1 = p0;
  p1(5) = -359.0 * kDeg;  // error +1 deg
  p1(11) = 179.0 * kDeg;  // error -2 deg, not 358 deg
  const EvaluationReport report =
      evaluateWindow({estimate(0, p0, 1.0), estimate(1, p1, 1.0)}, reference, 0, 1);
  EXPECT_NEAR(report.parameters[5].rmse, 1.0 * kDeg, 1e-12);
  EXPECT_NEAR(report.parameters[5].max_abs_error, 1.0 * kDeg, 1e-12);
  EXPECT_NEAR(report.parameters[11].rmse, std::sqrt(4.0 / 2.0) * kDeg, 1e-12);
  EXPECT_NEAR(report.parameters[11].max_abs_error, 2.0 * kDeg, 1e-12);
  // Translations are not wrapped.
  p0(0) = 2.0 * M_PI;
  EXPECT_NEAR(evaluateWindow({estimate(0, p0, 1.0)}, reference, 0, 0).parameters[0].rmse,
              2.0 * M_PI, 1e-12);
}

TEST(Evaluation, EmptyWindowAndDuplicatesThrow) {
  const std::vector<ReferenceRow> reference = {truth(0, Vector12d::Zero())};
  const std::vector<EstimateRow> estimates = {estimate(0, Vector12d::Zero(), 1.0)};
  EXPECT_THROW(evaluateWindow(estimates, reference, 1, 5), std::invalid_argument);
  EXPECT_THROW(evaluateWindow(estimates, reference, 1, 0), std::invalid_argument);
  EXPECT_THROW(evaluateWindow(estimates, {}, 0, 5), std::invalid_argument);
  EXPECT_THROW(evaluateWindow({estimates[0], estimates[0]}, reference, 0, 0),
               std::invalid_argument);
  EXPECT_THROW(evaluateWindow(estimates, {reference[0], reference[0]}, 0, 0),
               std::invalid_argument);
}

TEST(Evaluation, FramesToConverge) {
  const std::vector<double> xl_errors = {5, 4, 0.5, 3, 0.5, 0.4, 0.3, 0.2, 0.1, 0.05};
  std::vector<EstimateRow> estimates;
  std::vector<ReferenceRow> reference;
  for (int f = 0; f < static_cast<int>(xl_errors.size()); ++f) {
    Vector12d p = Vector12d::Zero();
    p(0) = xl_errors[f];
    p(3) = 2.0 * M_PI - 0.01;  // roll_l: wrapped error -0.01
    estimates.push_back(estimate(f, p, 1.0));
    reference.push_back(truth(f, Vector12d::Zero()));
  }
  EXPECT_EQ(framesToConverge(estimates, reference, 0, 1.0, 0), 4);
  EXPECT_EQ(framesToConverge(estimates, reference, 0, 1.0, 6), 6);
  EXPECT_EQ(framesToConverge(estimates, reference, 0, 0.35, 0), 6);
  EXPECT_EQ(framesToConverge(estimates, reference, 0, 10.0, 0), 0);
  EXPECT_EQ(framesToConverge(estimates, reference, 0, 0.01, 0), -1);
  EXPECT_EQ(framesToConverge(estimates, reference, 3, 0.02, 0), 0);
  EXPECT_EQ(framesToConverge(estimates, reference, 0, 1.0, 100), -1);

  estimates[7].parameters(0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(framesToConverge(estimates, reference, 0, 1.0, 0), 8);
  EXPECT_THROW(framesToConverge(estimates, reference, 12, 1.0, 0), std::invalid_argument);
}

TEST(Evaluation, PaperTableAndFormatting) {
  EXPECT_DOUBLE_EQ(paperTableRmse()[0], 0.0608);
  EXPECT_DOUBLE_EQ(paperTableRmse()[4], 0.7061 * kDeg);
  EXPECT_DOUBLE_EQ(paperTableRmse()[11], 0.0193 * kDeg);
  EXPECT_DOUBLE_EQ(paperTableSigma()[7], 0.0013);
  EXPECT_DOUBLE_EQ(paperTableSigma()[9], 0.0100 * kDeg);

  EvaluationReport report;
  report.first_frame = 1000;
  report.last_frame = 1150;
  report.frames_used = 151;
  for (int k = 0; k < 12; ++k) report.parameters[k].rmse = paperTableRmse()[k] * 0.5;
  report.parameters[4].rmse = paperTableRmse()[4] * 2.0;  // pitch_l worse than the paper
  const std::string table = formatTableI(report);
  EXPECT_NE(table.find("1000..1150"), std::string::npos) << table;
  EXPECT_NE(table.find("151 used"), std::string::npos) << table;
  // pitch_l: ours 1.4122 deg, paper 0.7061 deg, not below.
  const std::size_t pitch = table.find("pitch_l");
  ASSERT_NE(pitch, std::string::npos);
  const std::string pitch_line = table.substr(pitch, table.find('|', pitch) - pitch);
  EXPECT_NE(pitch_line.find("1.41220"), std::string::npos) << pitch_line;
  EXPECT_NE(pitch_line.find("0.70610"), std::string::npos) << pitch_line;
  EXPECT_NE(pitch_line.find(" no"), std::string::npos) << pitch_line;
  const std::size_t xl = table.find("xl ");
  ASSERT_NE(xl, std::string::npos);
  EXPECT_NE(table.substr(xl, table.find('|', xl) - xl).find(" yes"), std::string::npos) << table;
}

// ---------------------------------------------------------------------------------------
// CommandLine: the offline tools' one argument parser.

/// Parses a list of words (argv[0] is added) and returns the error message, "" on success,
/// "help" when --help was asked for.
std::string parseWords(CommandLine* cli, std::vector<std::string> words,
                       std::ostream* help_out = nullptr) {
  words.insert(words.begin(), "tool");
  std::vector<const char*> argv;
  for (const std::string& w : words) argv.push_back(w.c_str());
  std::ostringstream sink;
  try {
    return cli->parse(static_cast<int>(argv.size()), argv.data(), help_out ? help_out : &sink)
               ? ""
               : "help";
  } catch (const CommandLineError& e) {
    return e.what();
  }
}

struct ToolOptions {
  std::string out, mode = "fast";
  int frames = 100;
  double rate = 2.5;
  int first = 1000, last = 1150;
  bool verbose = false;
  int hidden = -1;
};

CommandLine makeCli(ToolOptions* o) {
  CommandLine cli("tool", "Does a thing.");
  cli.option("--out", &o->out, "DIR", "output directory").required();
  cli.option("--frames", &o->frames, "N", "frames").range(1, 100000);
  cli.option("--rate", &o->rate, "HZ", "rate").range(0.0, 1000.0);
  cli.option("--mode", &o->mode, "MODE", "mode").choices({"fast", "slow"});
  cli.option("--window", &o->first, &o->last, "FIRST LAST", "window").range(0, 1e9);
  cli.flag("--verbose", &o->verbose, "talk");
  cli.option("--hidden", &o->hidden, "N", "no default shown").defaultText("");
  return cli;
}

TEST(CommandLine, TypedValuesAndDefaults) {
  ToolOptions o;
  CommandLine cli = makeCli(&o);
  EXPECT_EQ(parseWords(&cli, {"--out", "d", "--frames", "42", "--rate", "-0", "--window", "3", "7",
                              "--verbose", "--mode", "slow"}),
            "");
  EXPECT_EQ(o.out, "d");
  EXPECT_EQ(o.frames, 42);
  EXPECT_DOUBLE_EQ(o.rate, 0.0);
  EXPECT_EQ(o.first, 3);
  EXPECT_EQ(o.last, 7);
  EXPECT_TRUE(o.verbose);
  EXPECT_EQ(o.mode, "slow");
  EXPECT_TRUE(cli.given("--frames"));

  ToolOptions d;
  CommandLine defaults = makeCli(&d);
  EXPECT_EQ(parseWords(&defaults, {"--out", "x"}), "");
  EXPECT_EQ(d.frames, 100);
  EXPECT_DOUBLE_EQ(d.rate, 2.5);
  EXPECT_EQ(d.first, 1000);
  EXPECT_FALSE(d.verbose);
  EXPECT_FALSE(defaults.given("--frames"));
}

TEST(CommandLine, ErrorsNameTheOption) {
  const auto error = [](std::vector<std::string> words) {
    ToolOptions o;
    CommandLine cli = makeCli(&o);
    return parseWords(&cli, std::move(words));
  };
  EXPECT_EQ(error({"--out", "d", "--framez", "3"}),
            "unknown option '--framez' (--help lists the options)");
  EXPECT_EQ(error({"--frames", "3"}), "missing required option(s): --out");
  EXPECT_EQ(error({"--out"}), "--out needs a value (DIR)");
  EXPECT_EQ(error({"--out", "d", "--window", "3"}), "--window needs 2 values (FIRST LAST)");
  EXPECT_EQ(error({"--out", "d", "--frames", "12x"}), "--frames: '12x' is not an integer");
  EXPECT_EQ(error({"--out", "d", "--frames", "99999999999"}),
            "--frames: '99999999999' is not an integer");
  EXPECT_EQ(error({"--out", "d", "--frames", "0"}), "--frames: 0 is outside [1, 100000]");
  EXPECT_EQ(error({"--out", "d", "--rate", "nan"}), "--rate: 'nan' is not a finite number");
  EXPECT_EQ(error({"--out", "d", "--rate", "1e9"}), "--rate: 1e9 is outside [0, 1000]");
  EXPECT_EQ(error({"--out", "d", "--window", "5", "-1"}),
            "--window: -1 is outside [0, 1000000000]");
  EXPECT_EQ(error({"--out", "d", "--mode", "medium"}), "--mode: 'medium' is not one of fast, slow");
  EXPECT_EQ(error({"--out", "d", "--out", "e"}), "--out given twice");
  EXPECT_EQ(error({"--out", "d", "stray"}), "unexpected argument 'stray'");
  EXPECT_EQ(error({"--out=d"}), "--out: write '--out VALUE', not '--out=d'");
}

TEST(CommandLine, HelpListsEveryOptionWithDefaultsAndRanges) {
  ToolOptions o;
  CommandLine cli = makeCli(&o);
  std::ostringstream help;
  EXPECT_EQ(parseWords(&cli, {"--frames", "5", "--help"}, &help), "help");
  const std::string text = help.str();
  EXPECT_EQ(text, cli.help());
  EXPECT_EQ(text.rfind("usage: tool --out DIR [--frames N]", 0), 0u) << text;
  EXPECT_NE(text.find("Does a thing."), std::string::npos);
  EXPECT_NE(text.find("--frames N"), std::string::npos);
  EXPECT_NE(text.find("[1, 100000]; default 100"), std::string::npos) << text;
  EXPECT_NE(text.find("{fast|slow}; default fast"), std::string::npos) << text;
  EXPECT_NE(text.find("(required)"), std::string::npos);
  EXPECT_NE(text.find("--window FIRST LAST"), std::string::npos);
  EXPECT_NE(text.find("-h, --help"), std::string::npos);
  EXPECT_NE(text.find("no default shown\n"), std::string::npos) << text;
  for (const std::string& line : {cli.usage()}) {
    std::istringstream lines(line);
    std::string l;
    while (std::getline(lines, l)) EXPECT_LE(l.size(), 100u) << l;
  }
}

TEST(CommandLine, PositionalArguments) {
  std::vector<std::string> dirs;
  CommandLine cli("write", "Writes.");
  cli.positional(&dirs, 1, "CONFIG_DIR", "where");
  EXPECT_EQ(parseWords(&cli, {"config"}), "");
  ASSERT_EQ(dirs.size(), 1u);
  EXPECT_EQ(dirs[0], "config");
  EXPECT_EQ(parseWords(&cli, {}), "expected 1 CONFIG_DIR, got 0");
  EXPECT_EQ(parseWords(&cli, {"a", "b"}), "expected 1 CONFIG_DIR, got 2");
  EXPECT_EQ(parseWords(&cli, {"--x"}), "unknown option '--x' (--help lists the options)");
}

TEST(CommandLine, RunToolMapsErrorsToExitCodes) {
  EXPECT_EQ(runTool(
                "t", [] { return std::string("usage: t\n"); }, [] { return 0; }),
            0);
  EXPECT_EQ(runTool(
                "t", [] { return std::string("usage: t\n"); },
                []() -> int { throw CommandLineError("bad"); }),
            2);
  EXPECT_EQ(runTool(
                "t", [] { return std::string("usage: t\n"); },
                []() -> int { throw std::runtime_error("io"); }),
            1);
}

// ---------------------------------------------------------------------------------------
// EstimatorConfig: filter keys at the top level, the front end's under front_end:.

TEST(EstimatorConfigYaml, ReadsFilterAndFrontEndKeysFromOneFile) {
  const EstimatorConfig c = parseEstimatorConfigYaml(
      "pixel_noise_px: 1.5\n"
      "front_end:\n  detector: FAST_ORB\n  max_features: 1234\n  ratio: 0.7\n",
      "both.yaml");
  EXPECT_DOUBLE_EQ(c.filter.pixel_noise, 1.5);
  EXPECT_EQ(c.front_end.detector, "FAST_ORB");
  EXPECT_EQ(c.front_end.max_features, 1234);
  EXPECT_DOUBLE_EQ(c.front_end.ratio, 0.7);
  EXPECT_DOUBLE_EQ(c.front_end.min_band, FrontEndConfig().min_band);  // not given: default
  EXPECT_DOUBLE_EQ(c.filter.outlier_gate, FilterConfig().outlier_gate);
  // The filter-only reader accepts (and checks) the same file.
  EXPECT_DOUBLE_EQ(
      parseFilterConfigYaml("pixel_noise_px: 1.5\nfront_end: {ratio: 0.7}\n", "f").pixel_noise,
      1.5);
  EXPECT_THROW(parseFilterConfigYaml("front_end: {ratio: 7}\n", "f"), std::runtime_error);
  // An empty file and an empty section are the defaults.
  EXPECT_EQ(parseEstimatorConfigYaml("", "empty").front_end.max_features,
            FrontEndConfig().max_features);
  EXPECT_EQ(parseEstimatorConfigYaml("front_end:\n", "empty").front_end.detector, "ORB");
}

TEST(EstimatorConfigYaml, EveryFrontEndKeyRoundTrips) {
  FrontEndConfig fe;
  fe.detector = "AKAZE";
  fe.max_features = 777;
  fe.orb_scale_factor = 1.37;
  fe.max_track_window = 55.5;
  fe.min_contrast = 3.25;
  const EstimatorConfig c = parseEstimatorConfigYaml(formatFrontEndConfigYaml(fe), "round");
  EXPECT_EQ(formatFrontEndConfigYaml(c.front_end), formatFrontEndConfigYaml(fe));
  EXPECT_EQ(c.front_end.detector, "AKAZE");
  EXPECT_EQ(c.front_end.max_features, 777);
  EXPECT_DOUBLE_EQ(c.front_end.orb_scale_factor, 1.37);
  // The new fields (bool, refinement, track gate) are read from a file too.
  const EstimatorConfig n = parseEstimatorConfigYaml(
      "front_end:\n  search_lost_tracks: true\n  track_gate_chi2_2dof: 9.2\n"
      "  patch_half_size: 6\n  min_patch_eigen_ratio: 0.1\n",
      "new");
  EXPECT_TRUE(n.front_end.search_lost_tracks);
  EXPECT_DOUBLE_EQ(n.front_end.track_gate_chi2_2dof, 9.2);
  EXPECT_EQ(n.front_end.patch_half_size, 6);
  EXPECT_DOUBLE_EQ(n.front_end.min_patch_eigen_ratio, 0.1);
}

// One field's value made different from the default, within its allowed range.
void setDistinctValidValue(const FrontEndParameterSpec& spec, FrontEndConfig* config) {
  using Type = FrontEndParameterSpec::Type;
  switch (spec.type) {
    case Type::kString:
      ASSERT_GE(spec.allowed_values.size(), 2u) << spec.name;
      spec.setString(config, spec.getString(*config) == spec.allowed_values[0]
                                 ? spec.allowed_values[1]
                                 : spec.allowed_values[0]);
      break;
    case Type::kBool:
      spec.setBool(config, !spec.getBool(*config));
      break;
    case Type::kInteger:
    case Type::kReal: {
      const double low =
          spec.min_from_field != nullptr ? config->*spec.min_from_field : spec.min_value;
      const double current = spec.getNumber(*config);
      // Reals: the midpoint of [low, current] (of [current, max] at the bottom of the range);
      // integers: one more (one less at the top). Keeps min_* below the matching max_*.
      double value = current > low ? 0.5 * (low + current) : 0.5 * (current + spec.max_value);
      if (spec.type == Type::kInteger) value = current < spec.max_value ? current + 1 : current - 1;
      spec.setNumber(config, value);
      break;
    }
  }
}

TEST(FrontEndParameterTable, CoversEveryFieldOnce) {
  // Every field of FrontEndConfig (front_end_config.h), in declaration order. A new field
  // must be added to frontEndParameterTable() and here.
  const std::vector<std::string> fields = {"detector",
                                           "max_features",
                                           "fast_threshold",
                                           "orb_levels",
                                           "orb_scale_factor",
                                           "detection_grid",
                                           "border",
                                           "band_sigmas",
                                           "min_band",
                                           "max_band",
                                           "pixel_sigma",
                                           "max_descriptor_distance",
                                           "ratio",
                                           "patch_half_size",
                                           "max_refinement_shift",
                                           "max_temporal_shift",
                                           "max_anchor_shift",
                                           "min_patch_ncc",
                                           "search_lost_tracks",
                                           "min_search_ncc",
                                           "max_forward_backward",
                                           "discontinuity_search",
                                           "min_patch_eigen_ratio",
                                           "refined_pixel_sigma",
                                           "bucket_cols",
                                           "bucket_rows",
                                           "max_new_points_per_frame",
                                           "min_distance_to_track",
                                           "min_parallax_deg",
                                           "corner_half_size",
                                           "max_corner_shift",
                                           "track_window_sigmas",
                                           "min_track_window",
                                           "max_track_window",
                                           "max_track_descriptor_distance",
                                           "track_ratio",
                                           "track_gate_chi2_2dof",
                                           "reacquire_below_fraction",
                                           "min_image_size",
                                           "min_contrast"};
  const std::vector<FrontEndParameterSpec>& table = frontEndParameterTable();
  ASSERT_EQ(table.size(), fields.size());
  for (size_t i = 0; i < fields.size(); ++i) EXPECT_EQ(table[i].name, fields[i]);

  // Setting each entry through the table on a default config changes exactly one field,
  // each a different one, and keeps the config valid.
  const FrontEndConfig defaults;
  const std::string default_yaml = formatFrontEndConfigYaml(defaults);
  std::set<std::string> changed_lines;
  for (const FrontEndParameterSpec& spec : table) {
    EXPECT_FALSE(spec.doc.empty()) << spec.name;
    EXPECT_EQ(spec.check(defaults), "") << spec.name;
    FrontEndConfig c;
    setDistinctValidValue(spec, &c);
    EXPECT_NE(spec.format(c), spec.format(defaults)) << spec.name;
    EXPECT_TRUE(c.validate().empty()) << spec.name << ": " << c.validate().front();
    // Exactly this key's line differs in the formatted section.
    const std::string yaml = formatFrontEndConfigYaml(c);
    int differing = 0;
    std::istringstream a(default_yaml), b(yaml);
    for (std::string la, lb; std::getline(a, la) && std::getline(b, lb);) {
      if (la != lb) {
        ++differing;
        EXPECT_EQ(lb.rfind("  " + spec.name + ": ", 0), 0u) << lb;
        changed_lines.insert(lb);
      }
    }
    EXPECT_EQ(differing, 1) << spec.name;
    // ... and the file round trip carries it.
    EXPECT_EQ(formatFrontEndConfigYaml(parseEstimatorConfigYaml(yaml, spec.name).front_end), yaml)
        << spec.name;
  }
  EXPECT_EQ(changed_lines.size(), table.size());
}

TEST(FrontEndParameterTable, ValidateRejectsOutOfRangeNamingTheKey) {
  using Type = FrontEndParameterSpec::Type;
  for (const FrontEndParameterSpec& spec : frontEndParameterTable()) {
    if (spec.type == Type::kBool) continue;  // every value is allowed
    FrontEndConfig c;
    if (spec.type == Type::kString) {
      spec.setString(&c, "NOT_A_" + spec.name);
    } else {
      // Just below the range (max_band: below min_band); above it, a min_* would also push
      // its max_* out of range.
      const double low = spec.min_from_field != nullptr ? c.*spec.min_from_field : spec.min_value;
      spec.setNumber(&c, spec.min_open ? low : low - 1.0);
    }
    const std::vector<std::string> problems = c.validate();
    ASSERT_EQ(problems.size(), 1u) << spec.name;
    EXPECT_EQ(problems[0].rfind(spec.name + " = ", 0), 0u) << problems[0];
    EXPECT_FALSE(spec.check(c).empty()) << spec.name;
    // The YAML loader refuses the same value naming front_end.<key>.
    try {
      parseEstimatorConfigYaml("front_end:\n  " + spec.name + ": " + spec.format(c) + "\n", "r");
      ADD_FAILURE() << spec.name << " out of range was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("front_end." + spec.name + " = "), std::string::npos)
          << e.what();
    }
  }
  FrontEndConfig c;
  c.track_gate_chi2_2dof = 0.0;  // open lower bound
  ASSERT_EQ(c.validate().size(), 1u);
  EXPECT_EQ(c.validate()[0], "track_gate_chi2_2dof = 0 is outside (0, 1000]");
  c = FrontEndConfig();
  c.max_band = 1.0;  // below min_band
  ASSERT_EQ(c.validate().size(), 1u);
  EXPECT_EQ(c.validate()[0], "max_band = 1 is outside [1.5, 500]");
}

TEST(EstimatorConfigYaml, BadFrontEndKeysAreNamed) {
  try {
    parseEstimatorConfigYaml(
        "pixel_noise_px: 1\n"
        "front_end:\n  detectr: ORB\n  max_features: 12.5\n  ratio: 3\n  detector: [a]\n"
        "  min_band: wide\n  search_lost_tracks: maybe\n  patch_half_size: 99\n",
        "bad.yaml");
    FAIL() << "a bad front_end section must be refused";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("bad.yaml: invalid configuration"), std::string::npos) << m;
    EXPECT_NE(m.find("front_end.detectr: unknown parameter"), std::string::npos) << m;
    EXPECT_NE(m.find("front_end.max_features: '12.5' is not an integer"), std::string::npos) << m;
    EXPECT_NE(m.find("front_end.ratio = 3 is outside (0, 1]"), std::string::npos) << m;
    EXPECT_NE(m.find("front_end.detector: "), std::string::npos) << m;
    EXPECT_NE(m.find("front_end.min_band: 'wide' is not a number"), std::string::npos) << m;
    EXPECT_NE(m.find("front_end.search_lost_tracks: 'maybe' is not a boolean"), std::string::npos)
        << m;
    EXPECT_NE(m.find("front_end.patch_half_size = 99 is outside [1, 15]"), std::string::npos) << m;
  }
  EXPECT_THROW(parseEstimatorConfigYaml("front_end: 3\n", "s"), std::runtime_error);
  EXPECT_THROW(parseEstimatorConfigYaml("front_end: {detector: BRISK}\n", "s"), std::runtime_error);
  EXPECT_THROW(parseEstimatorConfigYaml("frontend: {detector: ORB}\n", "s"), std::runtime_error);
  EXPECT_THROW(readEstimatorConfigFile("/nonexistent/params.yaml"), std::runtime_error);
  // The shipped filter files load as estimator configs.
  EXPECT_NO_THROW(readEstimatorConfigFile(std::string(OSC_SOURCE_DIR) + "/config/default.yaml"));
  EXPECT_NO_THROW(readEstimatorConfigFile(std::string(OSC_SOURCE_DIR) + "/config/paper.yaml"));
}

// ---------------------------------------------------------------------------------------------
// Scenario files: the campaign keys (stops, odometry errors, blind frames, moving points)
// ---------------------------------------------------------------------------------------------

/// The parse error of a scenario text, or "" if it parses.
std::string scenarioError(const std::string& text, const std::string& directory = ".") {
  try {
    parseScenarioYaml(text, "test.yaml", directory);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(ScenarioFileCampaignKeys, ParseIntoTheMeasurementScenario) {
  const SimulationScenario s = parseScenarioYaml(
      "frames: 400\n"
      "motion: {speed: 5, stops: [[10, 4.5], [25, 2]], stop_ramp: 1.5, yaw_phase: 3.1}\n"
      "odometry_error: {time_offset: -0.03, scale_error: 0.01, rotation_rate_bias: 1e-4,\n"
      "                 velocity_bias: 0.02, bias_correlation_time: 12}\n"
      "blind_frames: [[100, 109], [300, 300]]\n"
      "moving_point_fraction: 0.2\n"
      "moving_point_speed: 1.5\n",
      "test.yaml", ".");
  const MeasurementScenario& m = s.measurement;
  ASSERT_EQ(m.motion.stops.size(), 2u);
  EXPECT_EQ(m.motion.stops[0].start, 10.0);
  EXPECT_EQ(m.motion.stops[0].duration, 4.5);
  EXPECT_EQ(m.motion.stops[1].start, 25.0);
  EXPECT_EQ(m.motion.stops[1].duration, 2.0);
  EXPECT_EQ(m.motion.stop_ramp, 1.5);
  EXPECT_EQ(m.motion.speed, 5.0);
  EXPECT_EQ(m.motion.yaw_phase, 3.1);
  EXPECT_EQ(m.odometry_error.time_offset, -0.03);
  EXPECT_EQ(m.odometry_error.scale_error, 0.01);
  EXPECT_EQ(m.odometry_error.rotation_rate_bias, 1e-4);
  EXPECT_EQ(m.odometry_error.velocity_bias, 0.02);
  EXPECT_EQ(m.odometry_error.bias_correlation_time, 12.0);
  ASSERT_EQ(m.blind_frames.size(), 2u);
  EXPECT_EQ(m.blind_frames[0].first, 100);
  EXPECT_EQ(m.blind_frames[0].last, 109);
  EXPECT_EQ(m.blind_frames[1].first, 300);
  EXPECT_EQ(m.blind_frames[1].last, 300);
  EXPECT_EQ(m.moving_point_fraction, 0.2);
  EXPECT_EQ(m.moving_point_speed, 1.5);
  EXPECT_FALSE(m.recorded_trajectory);
  // Left out: the preset's values.
  const SimulationScenario plain = parseScenarioYaml("frames: 400\n", "plain.yaml", ".");
  EXPECT_TRUE(plain.measurement.motion.stops.empty());
  EXPECT_EQ(plain.measurement.motion.yaw_phase, 0.0);
  EXPECT_EQ(plain.measurement.odometry_error.scale_error, 0.0);
  EXPECT_TRUE(plain.measurement.blind_frames.empty());
}

TEST(ScenarioFileCampaignKeys, ErrorsNameTheKey) {
  const std::pair<const char*, const char*> cases[] = {
      {"motion: {stops: 3}\n", "motion.stops"},
      {"motion: {stops: [[1, 2], [5]]}\n", "motion.stops[1]"},
      {"motion: {stops: [[1, x]]}\n", "motion.stops[0].duration"},
      {"motion: {stops: [[20, 1], [10, 1]]}\n", "motion.stops[1]"},
      {"motion: {stops: [[1, 2]], stop_ramp: -1}\n", "motion.stop_ramp"},
      {"motion: {yaw_phase: .nan}\n", "motion.yaw_phase"},
      {"odometry_error: {time_ofset: 0.1}\n", "odometry_error.time_ofset"},
      {"odometry_error: 0.1\n", "odometry_error"},
      {"odometry_error: {time_offset: 0.9}\n", "odometry_error.time_offset"},
      {"odometry_error: {scale_error: 0.5}\n", "odometry_error.scale_error"},
      {"odometry_error: {rotation_rate_bias: -1}\n", "odometry_error.rotation_rate_bias"},
      {"odometry_error: {velocity_bias: many}\n", "odometry_error.velocity_bias"},
      {"odometry_error: {bias_correlation_time: 0}\n", "odometry_error.bias_correlation_time"},
      {"blind_frames: [[5, 3]]\n", "blind_frames[0].last"},
      {"blind_frames: [[5, 1.5]]\n", "blind_frames[0].last"},
      {"blind_frames: [[10, 20], [15, 30]]\n", "blind_frames[1].first"},
      {"frames: 100\nblind_frames: [[90, 100]]\n", "blind_frames[0].last"},
      {"blind_frames: 7\n", "blind_frames"},
      {"moving_point_fraction: 2\n", "moving_point_fraction"},
      {"moving_point_speed: fast\n", "moving_point_speed"},
      {"moving_point_speed: -1\n", "moving_point_speed"},
  };
  for (const auto& c : cases) {
    const std::string error = scenarioError(c.first);
    EXPECT_NE(error.find(c.second), std::string::npos) << c.first << " gave: " << error;
  }
}

/// Writes a TUM file of a VehicleTrajectory sampled at 20 Hz for @p seconds.
void writeTum(const std::string& path, double seconds) {
  const VehicleTrajectory trajectory{VehicleMotionProfile()};
  std::ofstream out(path);
  out << "# t x y z qx qy qz qw\n";
  out.precision(17);
  for (int k = 0; k * 0.05 <= seconds + 1e-9; ++k) {
    const Eigen::Isometry3d pose = trajectory.pose(k * 0.05);
    const Eigen::Quaterniond q(pose.rotation());
    out << 500.0 + k * 0.05 << " " << pose.translation().transpose() << " " << q.x() << " " << q.y()
        << " " << q.z() << " " << q.w() << "\n";
  }
}

TEST(ScenarioFileCampaignKeys, TumTrajectoryBecomesTheMeasurementSimulatorsDrive) {
  TempDir dir;
  writeTum(dir.path() + "/drive.tum", 12.0);
  const std::string text =
      "frames: 100\nstep_frame: -1\ntrajectory: {tum_file: drive.tum, start_offset: 1.5}\n";
  const SimulationScenario s = parseScenarioYaml(text, "test.yaml", dir.path());
  ASSERT_TRUE(s.measurement.recorded_trajectory);
  EXPECT_EQ(s.measurement.recorded_start_offset, 1.5);
  const PoseTrajectory file = readTumTrajectory(dir.path() + "/drive.tum");
  MeasurementSimulator sim(s.measurement);
  SimulatedFrame frame;
  while (sim.nextFrame(&frame)) {
    ASSERT_TRUE(frame.T_world_veh.isApprox(*file.at(501.5 + frame.index * 0.1), 1e-12));
  }
  // Too short for the frames from that offset: the error names the fields.
  const std::string error = scenarioError(
      "frames: 120\ntrajectory: {tum_file: drive.tum, start_offset: 1.5}\n", dir.path());
  EXPECT_NE(error.find("frames"), std::string::npos) << error;
  EXPECT_NE(error.find("start_offset"), std::string::npos) << error;
  // A recording replaces the analytic motion, stops included.
  EXPECT_NE(scenarioError("frames: 50\nmotion: {stops: [[1, 1]]}\n"
                          "trajectory: {tum_file: drive.tum}\n",
                          dir.path())
                .find("motion.stops"),
            std::string::npos);
}

// formatTumTrajectory writes what readTumTrajectory reads back: the stamps to the nanosecond
// at KITTI's ~1.3e9 s, positions to 0.1 mm, rotations to ~1e-9 rad; the comment as '#' lines.
TEST(TumTrajectory, FormattedPosesAreReadBack) {
  std::vector<StampedPose> poses;
  for (int k = 0; k < 5; ++k) {
    StampedPose p;
    p.stamp = 1317045935.706851006 + 0.0103 * k;
    p.pose.linear() = expSO3(Eigen::Vector3d(0.01 * k, -0.2, 1.0 + 0.3 * k));
    p.pose.translation() = Eigen::Vector3d(1234.5678 + k, -0.25 * k, 3.0);
    poses.push_back(p);
  }
  const std::string text = formatTumTrajectory(poses, "first line\nsecond line");
  EXPECT_EQ(text.rfind("# first line\n# second line\n", 0), 0u) << text;
  TempDir dir;
  const std::string path = dir.path() + "/poses.tum";
  writeTextFileAtomic(path, text);
  const PoseTrajectory back = readTumTrajectory(path);
  ASSERT_EQ(back.size(), poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    EXPECT_NEAR(back.poses()[k].stamp, poses[k].stamp, 1e-6) << k;
    EXPECT_LT((back.poses()[k].pose.translation() - poses[k].pose.translation()).norm(), 1e-4);
    EXPECT_LT(logSO3(back.poses()[k].pose.linear().transpose() * poses[k].pose.linear()).norm(),
              1e-8);
  }
}

TEST(ScenarioFileCampaignKeys, RealRecordedTrajectoryDrivesTheMeasurementSimulator) {
  const std::string path =
      std::string(OSC_SOURCE_DIR) + "/../shared/data/trajectories/udel_gore_rep103.tum";
  if (!std::ifstream(path)) GTEST_SKIP() << "no " << path;
  const SimulationScenario s = parseScenarioYaml(
      "frames: 400\nrate_hz: 20\nstep_frame: -1\nodometry_error: {time_offset: 0.1}\n"
      "motion_rotation_noise: 0\nmotion_translation_noise: 0\n"
      "trajectory: {tum_file: " +
          path + ", start_offset: 30}\n",
      "udel.yaml", ".");
  const PoseTrajectory file = readTumTrajectory(path);
  MeasurementSimulator sim(s.measurement);
  SimulatedFrame f;
  int observed = 0;
  while (sim.nextFrame(&f)) {
    // The stamps are ~1.5e9 s: summed in another order they differ by ~1e-7 s (~1e-7 m).
    const double stamp = file.firstStamp() + 30.0 + f.index / 20.0;
    ASSERT_LT((f.T_world_veh.matrix() - file.at(stamp)->matrix()).norm(), 1e-5) << f.index;
    if (f.index > 0) {
      const Eigen::Isometry3d shifted =
          file.at(stamp - 0.05 + 0.1)->inverse() * *file.at(stamp + 0.1);
      ASSERT_LT((f.measured_motion.T_prev_curr.matrix() - shifted.matrix()).norm(), 1e-5)
          << "frame " << f.index;
    }
    observed += static_cast<int>(f.observations.size());
  }
  EXPECT_GT(observed, 400 * 80);  // the points follow the walk
}

/// A small, fast image-level drive for the odometry and rendering checks.
SimulationScenario smallDrive(const std::string& extra, int frames = 30) {
  return parseScenarioYaml(
      "frames: " + std::to_string(frames) +
          "\nmotion_rotation_noise: 0\nmotion_translation_noise: 0\n"
          "left_camera: {width: 160, height: 120, fx: 150, fy: 150, cx: 79.5, cy: 59.5}\n"
          "right_camera: {width: 160, height: 120, fx: 150, fy: 150, cx: 79.5, cy: 59.5}\n"
          "rendering: {supersampling: 1, odom_rate_hz: 100}\n" +
          extra,
      "small.yaml", ".");
}

TEST(DriveSimulation, OdometryCarriesTheTimeOffsetAndScaleError) {
  const DriveSimulator plain(smallDrive(""));
  const DriveSimulator erred(smallDrive("odometry_error: {time_offset: 0.07, scale_error: 0.1}\n"));
  const std::vector<StampedPose> a = plain.odometry(), b = erred.odometry();
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 290u);
  for (size_t k = 1; k < b.size(); ++k) {
    // Same stamps; the sample stamped start + t holds the motion up to t + time_offset,
    // with the translation scaled by 1 + scale_error.
    ASSERT_EQ(a[k].stamp, b[k].stamp);
    const double t0 = (k - 1) * 0.01, t1 = k * 0.01;
    const Eigen::Isometry3d truth = erred.truePose(t0 + 0.07).inverse() * erred.truePose(t1 + 0.07);
    const Eigen::Isometry3d reported = b[k - 1].pose.inverse() * b[k].pose;
    ASSERT_LT((reported.translation() - 1.1 * truth.translation()).norm(), 1e-9) << k;
    ASSERT_TRUE(reported.linear().isApprox(truth.linear(), 1e-9)) << k;
    // Without errors (and noise) the odometry is the true motion.
    const Eigen::Isometry3d exact = a[k - 1].pose.inverse() * a[k].pose;
    ASSERT_TRUE(exact.isApprox(plain.truePose(t0).inverse() * plain.truePose(t1), 1e-9)) << k;
  }
}

TEST(DriveSimulation, OdometryBiasesAreTheSameGaussMarkovProcess) {
  // Per axis, the velocity bias seen in the odometry increments has the configured std.
  const DriveSimulator sim(
      smallDrive("odometry_error: {velocity_bias: 0.05, bias_correlation_time: 0.5}\n", 1500));
  const std::vector<StampedPose> odometry = sim.odometry();
  std::vector<double> bias;
  for (size_t k = 1; k < odometry.size(); ++k) {
    const double t0 = (k - 1) * 0.01, t1 = k * 0.01;
    const Eigen::Isometry3d truth = sim.truePose(t0).inverse() * sim.truePose(t1);
    const Eigen::Isometry3d reported = odometry[k - 1].pose.inverse() * odometry[k].pose;
    bias.push_back((reported.translation() - truth.translation()).y() / 0.01);
  }
  double sum = 0.0, sum2 = 0.0;
  for (double b : bias) {
    sum += b;
    sum2 += b * b;
  }
  const double m = sum / bias.size();
  EXPECT_NEAR(std::sqrt(sum2 / bias.size() - m * m), 0.05, 0.01);  // 300 correlation times: ~4 %
}

TEST(DriveSimulation, BlindFramesAreRenderedAlmostBlack) {
  const DriveSimulator sim(smallDrive("blind_frames: [[10, 12]]\n"));
  const SimulatedImagePair seen = sim.renderFrame(9), blind = sim.renderFrame(11);
  const double seen_mean = cv::mean(seen.left)[0], blind_mean = cv::mean(blind.left)[0];
  EXPECT_GT(seen_mean, 40.0);
  EXPECT_LT(blind_mean, 0.05 * seen_mean + 1.0);
  EXPECT_LT(cv::mean(blind.right)[0], 0.05 * cv::mean(seen.right)[0] + 1.0);
  // Its structure is gone: the image's std is about the pixel noise.
  cv::Scalar mean, stddev;
  cv::meanStdDev(blind.left, mean, stddev);
  EXPECT_LT(stddev[0], 3.0);
}

}  // namespace
}  // namespace osc
