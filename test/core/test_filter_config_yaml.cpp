// Config files: the shipped YAMLs equal the code's defaults, list every key once in its
// section (a user's keys first), and bad files are refused with the key named.
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

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

// ... and the paper's file to paperFilterConfig(), and both files' front_end: maps to the
// built-in FrontEndConfig, bit for bit.
TEST(FilterConfigYaml, ShippedFilesReadBackExactlyWithTheirFrontEnd) {
  EstimatorConfig paper;
  paper.filter = paperFilterConfig();
  const std::vector<std::pair<std::string, EstimatorConfig>> files = {
      {"/config/default.yaml", EstimatorConfig()}, {"/config/paper.yaml", paper}};
  for (const auto& [file, expected] : files) {
    const EstimatorConfig read = readEstimatorConfigFile(std::string(OSC_SOURCE_DIR) + file);
    EXPECT_EQ(read.filter.motion_noise_model, expected.filter.motion_noise_model) << file;
    for (const ParameterSpec& spec : filterParameterTable()) {
      if (spec.real_field) {
        EXPECT_EQ(read.filter.*spec.real_field, expected.filter.*spec.real_field)
            << file << " " << spec.name;
      } else {
        EXPECT_EQ(read.filter.*spec.integer_field, expected.filter.*spec.integer_field)
            << file << " " << spec.name;
      }
    }
    for (const FrontEndParameterSpec& spec : frontEndParameterTable()) {
      EXPECT_EQ(spec.format(read.front_end), spec.format(expected.front_end))
          << file << " " << spec.name;
      if (spec.real_field) {
        EXPECT_EQ(read.front_end.*spec.real_field, expected.front_end.*spec.real_field)
            << file << " " << spec.name;
      }
    }
  }
}

// Every key has a section (the component that uses it) that the files list, and every section
// holds a key: a key without one would be left out of the generated files.
TEST(ConfigSections, EveryKeyHasAListedSection) {
  std::set<std::string> filter_sections;
  for (const ParameterSection& section : filterParameterSections()) {
    EXPECT_TRUE(filter_sections.insert(section.name).second) << section.name;
    EXPECT_FALSE(section.description.empty()) << section.name;
  }
  std::set<std::string> used = {kMotionNoiseModelSection};
  EXPECT_TRUE(filter_sections.count(kMotionNoiseModelSection));
  for (const ParameterSpec& spec : filterParameterTable()) {
    EXPECT_TRUE(filter_sections.count(spec.section)) << spec.name << ": '" << spec.section << "'";
    used.insert(spec.section);
  }
  EXPECT_EQ(used, filter_sections);

  std::set<std::string> front_end_sections;
  for (const ParameterSection& section : frontEndParameterSections()) {
    EXPECT_TRUE(front_end_sections.insert(section.name).second) << section.name;
    EXPECT_FALSE(section.description.empty()) << section.name;
  }
  used.clear();
  for (const FrontEndParameterSpec& spec : frontEndParameterTable()) {
    EXPECT_TRUE(front_end_sections.count(spec.section))
        << spec.name << ": '" << spec.section << "'";
    used.insert(spec.section);
  }
  EXPECT_EQ(used, front_end_sections);

  // A table whose row names no listed section is refused naming the key.
  std::vector<ParameterSpec> table = filterParameterTable();
  table[3].section = "nowhere";
  try {
    requireKnownSections(table, filterParameterSections(), "t");
    ADD_FAILURE() << "a key without a listed section must be refused";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find(table[3].name), std::string::npos) << e.what();
  }
}

// Issue "One estimator a newcomer can read", step 4: at most ~60 keys a user has to read.
TEST(ConfigSections, UserFacingKeysAreFew) {
  int user = kMotionNoiseModelAdvanced ? 0 : 1;
  int advanced = kMotionNoiseModelAdvanced ? 1 : 0;
  for (const ParameterSpec& spec : filterParameterTable()) (spec.advanced ? advanced : user)++;
  for (const FrontEndParameterSpec& spec : frontEndParameterTable()) {
    (spec.advanced ? advanced : user)++;
  }
  EXPECT_LE(user, 60);
  EXPECT_GT(user, 0);
  EXPECT_EQ(user + advanced,
            static_cast<int>(filterParameterTable().size() + frontEndParameterTable().size()) + 1);
}

// The generated file lists each key once: the user's keys, then the advanced banner, then the
// advanced keys (the front end's inside its map, indented; the filter's at the top level).
TEST(ConfigSections, ShippedFileListsUserKeysBeforeTheAdvancedPart) {
  const std::string file = readText(std::string(OSC_SOURCE_DIR) + "/config/default.yaml");
  const size_t banner = file.find("\n# ADVANCED: ");
  ASSERT_NE(banner, std::string::npos);
  EXPECT_EQ(file.find("\n# ADVANCED: ", banner + 1), std::string::npos);
  const auto position = [&](const std::string& line) {
    const size_t at = file.find("\n" + line);
    EXPECT_NE(at, std::string::npos) << line;
    EXPECT_EQ(file.find("\n" + line, at + 1), std::string::npos) << line << " twice";
    return at;
  };
  const auto expectPart = [&](const std::string& line, bool advanced) {
    if (advanced) {
      EXPECT_GT(position(line), banner) << line << " is advanced";
    } else {
      EXPECT_LT(position(line), banner) << line << " is a user's key";
    }
  };
  expectPart("motion_noise_model: ", kMotionNoiseModelAdvanced);
  for (const ParameterSpec& spec : filterParameterTable()) {
    expectPart(spec.name + ": ", spec.advanced);
  }
  for (const FrontEndParameterSpec& spec : frontEndParameterTable()) {
    expectPart("  " + spec.name + ": ", spec.advanced);
  }
  for (const ParameterSection& section : filterParameterSections()) {
    EXPECT_NE(file.find("# ==== " + section.name), std::string::npos) << section.name;
  }
  for (const ParameterSection& section : frontEndParameterSections()) {
    EXPECT_NE(file.find("  # ==== front_end: " + section.name), std::string::npos) << section.name;
  }
}

// docs/configuration.md's tables list every key a user may set.
TEST(ConfigSections, UserGuideNamesEveryUserKey) {
  const std::string guide = readText(std::string(OSC_SOURCE_DIR) + "/docs/configuration.md");
  ASSERT_FALSE(guide.empty());
  for (const ParameterSpec& spec : filterParameterTable()) {
    if (spec.advanced) continue;
    EXPECT_NE(guide.find("| `" + spec.name + "` |"), std::string::npos) << spec.name;
  }
  for (const FrontEndParameterSpec& spec : frontEndParameterTable()) {
    if (spec.advanced) continue;
    EXPECT_NE(guide.find("| `" + spec.name + "` |"), std::string::npos) << spec.name;
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

TEST(FilterConfigYaml, EveryKeyOutOfRangeIsAnErrorNamingIt) {
  for (const ParameterSpec& spec : filterParameterTable()) {
    std::ostringstream text;
    text << spec.name << ": " << spec.min_value - 1.0 << "\n";
    try {
      parseEstimatorConfigYaml(text.str(), "low.yaml");
      ADD_FAILURE() << spec.name << " below its range was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(spec.name + " = "), std::string::npos) << e.what();
    }
  }
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
