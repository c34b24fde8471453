/// Tests of the estimator's configuration file (estimator_config_yaml.h): filter keys at the
/// top level, the front end's under front_end:, and the front end's parameter table.
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "online_stereo_calibration/tools/estimator_config_yaml.h"
#include "online_stereo_calibration/tools/filter_config_yaml.h"

namespace osc {
namespace {

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

}  // namespace
}  // namespace osc
