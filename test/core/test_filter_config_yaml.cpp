// Config files: the shipped YAMLs equal the code's defaults, and bad files are refused with
// the key named.
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "online_stereo_calibration/tools/estimator_config_yaml.h"
#include "online_stereo_calibration/tools/filter_config_yaml.h"

namespace osc {
namespace {

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void expectSameConfig(const FilterConfig& a, const FilterConfig& b) {
  EXPECT_EQ(a.motion_noise_model, b.motion_noise_model);
  for (const ParameterSpec& spec : filterParameterTable()) {
    EXPECT_NEAR(spec.get(a), spec.get(b), 1e-9 * std::max(1.0, std::abs(spec.get(b)))) << spec.name;
  }
}

TEST(FilterConfigYaml, ShippedFilesAreUpToDateWithTheCode) {
  // Regenerate with: write_default_configs config
  const std::string file = readText(std::string(OSC_SOURCE_DIR) + "/config/default.yaml");
  const std::string title = file.substr(2, file.find('\n') - 2);
  EXPECT_EQ(file, formatEstimatorConfigYaml(EstimatorConfig(), title));
  const std::string paper = readText(std::string(OSC_SOURCE_DIR) + "/config/paper.yaml");
  EstimatorConfig paper_config;
  paper_config.filter = paperFilterConfig();
  EXPECT_EQ(paper, formatEstimatorConfigYaml(paper_config, paper.substr(2, paper.find('\n') - 2)));
  expectSameConfig(readFilterConfigFile(std::string(OSC_SOURCE_DIR) + "/config/default.yaml"),
                   FilterConfig());
  expectSameConfig(readFilterConfigFile(std::string(OSC_SOURCE_DIR) + "/config/paper.yaml"),
                   paperFilterConfig());
}

// Bit for bit, not within a tolerance: a run with --config config/default.yaml must equal one
// without (a _deg key printed with 12 digits read back 2.99999999999569 rad/s for 3).
TEST(FilterConfigYaml, ShippedDefaultFileReadsBackToTheBuiltInDefaultsExactly) {
  const FilterConfig defaults;
  const FilterConfig read =
      readFilterConfigFile(std::string(OSC_SOURCE_DIR) + "/config/default.yaml");
  for (const ParameterSpec& spec : filterParameterTable()) {
    if (spec.real_field) {
      EXPECT_EQ(read.*spec.real_field, defaults.*spec.real_field) << spec.name;
    } else {
      EXPECT_EQ(read.*spec.integer_field, defaults.*spec.integer_field) << spec.name;
    }
  }
}

TEST(FilterConfigYaml, PaperFileHoldsThePapersNumbers) {
  const std::string text = readText(std::string(OSC_SOURCE_DIR) + "/config/paper.yaml");
  EXPECT_NE(text.find("point_position_noise_m: 0.2\n"), std::string::npos);      // eq. 14
  EXPECT_NE(text.find("motion_rotation_noise_deg: 0.02\n"), std::string::npos);  // eq. 15
  EXPECT_NE(text.find("caml_rotation_drift_deg: 0.005\n"), std::string::npos);   // eq. 11
  EXPECT_NE(text.find("camr_translation_drift_m: 1e-05\n"), std::string::npos);  // eq. 12
  EXPECT_NE(text.find("motion_noise_model: per_point\n"), std::string::npos);
}

TEST(FilterConfigYaml, RoundTripOfEveryKey) {
  FilterConfig c;
  c.point_position_noise = 0.0123;
  c.max_points = 77;
  c.motion_noise_model = MotionNoiseModel::kPerPoint;
  expectSameConfig(parseFilterConfigYaml(formatFilterConfigYaml(c, "t"), "roundtrip"), c);
}

TEST(FilterConfigYaml, PartialFileKeepsOtherDefaults) {
  const FilterConfig c = parseFilterConfigYaml("pixel_noise_px: 1.5\n", "partial");
  EXPECT_DOUBLE_EQ(c.pixel_noise, 1.5);
  EXPECT_DOUBLE_EQ(c.outlier_gate, FilterConfig().outlier_gate);
}

TEST(FilterConfigYaml, BadFilesNameEveryProblem) {
  try {
    parseFilterConfigYaml(
        "pixel_noise_px: -1\nmax_points: many\nsigma_typo_m: 3\nmotion_noise_model: wild\n",
        "bad.yaml");
    FAIL() << "a bad file must be refused";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("bad.yaml"), std::string::npos);
    EXPECT_NE(m.find("pixel_noise_px"), std::string::npos);
    EXPECT_NE(m.find("max_points"), std::string::npos);
    EXPECT_NE(m.find("sigma_typo_m: unknown parameter"), std::string::npos);
    EXPECT_NE(m.find("motion_noise_model"), std::string::npos);
  }
  EXPECT_THROW(parseFilterConfigYaml("[1, 2", "broken.yaml"), std::runtime_error);
  EXPECT_THROW(readFilterConfigFile("/nonexistent/params.yaml"), std::runtime_error);
}

}  // namespace
}  // namespace osc
