#include "online_stereo_calibration/tools/campaign_csv.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "online_stereo_calibration/tools/campaign_ranges.h"

namespace osc {

namespace {

const std::vector<std::string>& scoreColumns() {
  static const std::vector<std::string> columns = {"run",
                                                   "seed",
                                                   "frames",
                                                   "share_within_3sigma",
                                                   "frames_beyond_5sigma",
                                                   "frames_beyond_5sigma_unseen",
                                                   "max_z",
                                                   "max_z_parameter",
                                                   "first_frame_beyond_5sigma",
                                                   "nees_mean",
                                                   "converged_frame",
                                                   "frames_converged",
                                                   "frames_converged_beyond_3sigma",
                                                   "time_ms_median"};
  return columns;
}

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.10g", value);
  return text;
}

std::string clean(std::string value) {
  for (char& c : value) {
    if (c == ',') c = ';';
    if (c == '\n' || c == '\r') c = ' ';
  }
  return value;
}

std::vector<std::string> splitLine(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) fields.push_back(field);
  if (!line.empty() && line.back() == ',') fields.push_back("");
  return fields;
}

}  // namespace

bool CampaignRow::honest() const {
  return ok() && score.share_within_3sigma >= kHonestShare && score.frames_beyond_5sigma == 0;
}

CampaignRow failedCampaignRow(int run, unsigned seed, int frames, const CampaignSettings& settings,
                              const std::string& reason) {
  CampaignRow row;
  row.run = run;
  row.seed = seed;
  row.frames = frames;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  row.score.share_within_3sigma = row.score.max_z = row.score.nees_mean = nan;
  row.score.time_ms_median = nan;
  row.score.frames_beyond_5sigma = row.score.frames_beyond_5sigma_unseen = -1;
  row.score.frames_converged = row.score.frames_converged_beyond_3sigma = -1;
  row.score.max_z_parameter = "-";
  row.score.rmse.fill(nan);
  row.score.mean_z.fill(nan);
  row.settings = settings;
  row.status = "failed: " + clean(reason);
  return row;
}

std::vector<std::string> campaignCsvColumns(const std::vector<std::string>& setting_names) {
  std::vector<std::string> columns = scoreColumns();
  for (const std::string& p : campaignParameterNames()) columns.push_back("rmse_" + p);
  for (const std::string& p : campaignParameterNames()) columns.push_back("mean_z_" + p);
  columns.insert(columns.end(), setting_names.begin(), setting_names.end());
  columns.push_back("run_s");
  columns.push_back("status");
  return columns;
}

std::string campaignCsvHeader(const std::vector<std::string>& setting_names) {
  std::string header;
  for (const std::string& c : campaignCsvColumns(setting_names)) {
    header += (header.empty() ? "" : ",") + c;
  }
  return header;
}

std::string formatCampaignCsvLine(const CampaignRow& row,
                                  const std::vector<std::string>& setting_names) {
  const CampaignScore& s = row.score;
  std::ostringstream line;
  line << row.run << ',' << row.seed << ',' << row.frames << ',' << number(s.share_within_3sigma)
       << ',' << s.frames_beyond_5sigma << ',' << s.frames_beyond_5sigma_unseen << ','
       << number(s.max_z) << ',' << s.max_z_parameter << ',' << s.first_frame_beyond_5sigma << ','
       << number(s.nees_mean) << ',' << s.converged_frame << ',' << s.frames_converged << ','
       << s.frames_converged_beyond_3sigma << ',' << number(s.time_ms_median);
  for (double r : s.rmse) line << ',' << number(r);
  for (double z : s.mean_z) line << ',' << number(z);
  for (size_t i = 0; i < setting_names.size(); ++i) {
    line << ',';
    if (row.settings.empty()) continue;
    if (i >= row.settings.size() || row.settings[i].first != setting_names[i]) {
      throw std::invalid_argument("formatCampaignCsvLine: setting '" + setting_names[i] +
                                  "' missing or out of order in run " + std::to_string(row.run));
    }
    line << clean(row.settings[i].second);
  }
  line << ',' << number(row.run_seconds) << ',' << clean(row.status);
  return line.str();
}

std::vector<CampaignRow> parseCampaignCsv(const std::string& text, const std::string& source_name) {
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(source_name + ": empty, no header");
  const std::vector<std::string> header = splitLine(line);
  const std::vector<std::string>& first = scoreColumns();
  const size_t fixed = first.size() + 12;
  bool header_ok = header.size() >= fixed + 2 && header.back() == "status" &&
                   header[header.size() - 2] == "run_s";
  for (size_t i = 0; header_ok && i < fixed; ++i) {
    header_ok =
        header[i] ==
        (i < first.size() ? first[i] : "rmse_" + campaignParameterNames()[i - first.size()]);
  }
  if (!header_ok) {
    throw std::runtime_error(source_name +
                             ": line 1: not a campaign CSV header (run,seed,...,status)");
  }
  // The mean_z_<p> columns came later (session 32): a file written before has none, and its
  // rows read back with NaN there.
  bool has_mean_z = header.size() >= fixed + 12 + 2;
  for (size_t p = 0; has_mean_z && p < 12; ++p) {
    has_mean_z = header[fixed + p] == "mean_z_" + campaignParameterNames()[p];
  }
  std::vector<CampaignRow> rows;
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty()) continue;
    const std::vector<std::string> f = splitLine(line);
    const std::string where = source_name + ": line " + std::to_string(line_number) + ": ";
    if (f.size() != header.size()) {
      throw std::runtime_error(where + std::to_string(f.size()) + " fields, the header has " +
                               std::to_string(header.size()));
    }
    size_t column = 0;
    const auto real = [&](size_t i) {
      try {
        size_t used = 0;
        const double v = std::stod(f[i], &used);
        if (used == f[i].size()) return v;
      } catch (const std::exception&) {
      }
      if (f[i] == "nan" || f[i] == "-nan") return std::numeric_limits<double>::quiet_NaN();
      throw std::runtime_error(where + header[i] + ": '" + f[i] + "' is not a number");
    };
    const auto integer = [&](size_t i) {
      const double v = real(i);
      if (v != std::floor(v)) throw std::runtime_error(where + header[i] + ": not an integer");
      return static_cast<long long>(v);
    };
    CampaignRow row;
    row.run = static_cast<int>(integer(column++));
    row.seed = static_cast<unsigned>(integer(column++));
    row.frames = static_cast<int>(integer(column++));
    row.score.share_within_3sigma = real(column++);
    row.score.frames_beyond_5sigma = static_cast<int>(integer(column++));
    row.score.frames_beyond_5sigma_unseen = static_cast<int>(integer(column++));
    row.score.max_z = real(column++);
    row.score.max_z_parameter = f[column++];
    row.score.first_frame_beyond_5sigma = static_cast<int>(integer(column++));
    row.score.nees_mean = real(column++);
    row.score.converged_frame = static_cast<int>(integer(column++));
    row.score.frames_converged = static_cast<int>(integer(column++));
    row.score.frames_converged_beyond_3sigma = static_cast<int>(integer(column++));
    row.score.time_ms_median = real(column++);
    for (int p = 0; p < 12; ++p) row.score.rmse[p] = real(column++);
    row.score.mean_z.fill(std::numeric_limits<double>::quiet_NaN());
    if (has_mean_z) {
      for (int p = 0; p < 12; ++p) row.score.mean_z[p] = real(column++);
    }
    for (; column + 2 < f.size(); ++column) row.settings.emplace_back(header[column], f[column]);
    row.run_seconds = real(column++);
    row.status = f[column];
    rows.push_back(row);
  }
  return rows;
}

std::vector<CampaignRow> readCampaignCsv(const std::string& path) {
  return parseCampaignCsv(readTextFile(path), path);
}

}  // namespace osc
