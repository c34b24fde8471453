/// Tests of the tools library's calibration YAML (calibration_file.h): parsing, bit-exact
/// atomic writes, the time offset and covariance keys, named errors, and failed writes that
/// keep the old file.
#include <dirent.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "temp_dir.h"
#include "tools_test_support.h"

#include "online_stereo_calibration/tools/calibration_file.h"
#include "online_stereo_calibration/tools/estimates_csv.h"
#include "online_stereo_calibration/tools/output_directory.h"

namespace osc {
namespace {

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

}  // namespace
}  // namespace osc
