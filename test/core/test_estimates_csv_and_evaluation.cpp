/// Tests of the tools library's estimates/reference CSV (estimates_csv.h) and of the
/// evaluation against the reference (evaluation.h): errors with wrapped angles, RMSE and
/// consistency, frames to converge, the paper's table.
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "temp_dir.h"
#include "tools_test_support.h"

#include "online_stereo_calibration/tools/estimates_csv.h"
#include "online_stereo_calibration/tools/evaluation.h"

namespace osc {
namespace {

constexpr double kDeg = M_PI / 180.0;

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

}  // namespace
}  // namespace osc
